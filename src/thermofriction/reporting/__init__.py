"""The HTML report: one self-contained file (figures inlined as SVG, no scripts) comparing models on a dataset.
The page is the data's measurement's: ``displacement.py`` (the paper's figures and tables) or ``force.py``
(friction-velocity map, presliding loops; a drive's command too); ``entries.py`` holds what both share."""

from __future__ import annotations

import sys

from .._io import atomic_write
from ..errors import InputError
from ..measurements import measurement_of
from ..models import Model
from .displacement import render, truth_section
from .entries import Entry, akaike, entry_label, law_at, reference_temperature  # (akaike, law_at, ...: for callers)
from .force import render_force
from .. import _args
from ..data.experiments import Dataset
from .studies import control_report, heating_report
from ..validation import validate

#: measurement name -> the page that shows it
PAGES = {"displacement": render, "force": render_force, "command": render_force}


def _check_report_arguments(models, data, path, figures_dir, command, title, truth) -> list:
    """The types of report()'s arguments (_args.py); one model or fit is a list of one."""
    if isinstance(models, (Model, Entry)) or (hasattr(models, "to_dict") and hasattr(models, "model")):
        models = [models]
    if not isinstance(models, (list, tuple)) or not models:
        _args.refuse("models", "a non-empty list of Models, FitResults or (label, Model, fit dict) entries", models)
    for m in models:
        if not (isinstance(m, (Model, Entry)) or (hasattr(m, "to_dict") and isinstance(getattr(m, "model", None), Model))
                or (isinstance(m, tuple) and len(m) == 3 and isinstance(m[0], str) and isinstance(m[1], Model)
                    and (m[2] is None or isinstance(m[2], dict)))):
            _args.refuse("models", "a list of Models, FitResults or (label, Model, fit dict) entries; one entry is", m)
    _args.dataset(data, Dataset, experiments=True)
    _args.path(path, "path")
    _args.path(figures_dir, "figures_dir", none=True)
    _args.text(command, "command", none=True)
    _args.text(title, "title", none=True)
    _args.instance(truth, dict, "truth", "a dict (label -> FitResult.recovery summary)", none=True)
    return list(models)


def report(models, data, path, *, figures_dir=None, command=None, title=None, truth=None, bands=None, offset=None,
           motion=None, ripple_phase=None) -> str:
    """Writes the HTML report comparing ``models`` on ``data`` and returns its HTML.

    Each model is scored as it was fitted (its fit record: the offset policy, the motion), unless ``offset`` or
    ``motion`` says otherwise (see ``validate``). The page is the data's measurement's (displacement: the paper's
    figures and tables; force: the friction-velocity map, hysteresis and presliding loops). The file is written
    atomically: all of it or nothing.

    Parameters
    ----------
    models : list
        The models compared: ``Model``, ``FitResult``, or (label, Model, fit dict) entries.
    data : Dataset
        The measurements the models are scored on.
    path : str or os.PathLike
        The HTML file written (one self-contained page: figures inline, no network needed).
    figures_dir : str or os.PathLike, optional
        A folder where the figures are also written as SVG and PNG files.
    command : str, optional
        The command line shown as how the report was made; default the running program's.
    title : str, optional
        The page's title.
    truth : dict, optional
        For data made from a known model: label -> ``FitResult.recovery`` summary; adds a section saying
        whether the fits recover it.
    bands : PropagationResult, optional
        What ``tf.propagate`` returns: adds a section with the prediction bands.
    offset : {"shared", "per-experiment", "none"} or bool, optional
        Force data: how the sensor offset is taken, for every model (``validate``'s ``offset``).
    motion : {"position", "velocity", "auto"}, optional
        Force data: what drives the experiments, for every model (``validate``'s ``motion``).
    ripple_phase : {"auto", "recorded", "per-run"}, optional
        Force data with a position ripple: its angle, for every model (``validate``'s ``ripple_phase``); default
        each model's fit record, else "auto".

    Returns
    -------
    str
        The page's HTML, as written to ``path``.

    Raises
    ------
    InputError
        An argument of the wrong type, named; no model; a path that cannot be written (``OutputError``, an
        InputError, naming it).
    ComputationError
        A model's predictions failed.
    """
    models = _check_report_arguments(models, data, path, figures_dir, command, title, truth)
    entries = []
    for m in models:
        if isinstance(m, Entry):
            entries.append(m)
        elif isinstance(m, Model):
            entries.append(Entry(entry_label(m), m))
        elif hasattr(m, "to_dict") and hasattr(m, "model"):
            d = m.to_dict()
            entries.append(Entry(entry_label(m.model, d), m.model, d))
        else:
            label, model, fit = m
            entries.append(Entry(label, model, fit))
    if not entries:
        raise InputError("give at least one model")
    for e in entries:  # each scored as it was fitted, unless asked otherwise (validation.py: _scoring)
        if e.validation is None:
            e.validation = validate(e.model, data, offset=offset, motion=motion, ripple_phase=ripple_phase)
    render_page = PAGES[measurement_of(data).name]  # the page of what the data measured
    text = render_page(entries, data, figures_dir=figures_dir, command=command or " ".join(sys.argv), title=title,
                       truth=truth, bands=bands)
    with atomic_write(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    return text


__all__ = ["report", "render", "render_force", "PAGES", "Entry", "heating_report", "control_report"]
