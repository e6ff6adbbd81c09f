"""Validation (docs/formats.md#validation-metrics): how well a model predicts what each experiment measured
(displacement, force), per experiment; the metrics are the measurement's (thermofriction.measurements)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ._io import dump_json, jsonable
from .errors import InputError, TemperatureRangeWarning, ThermofrictionError, UnitWarning
from . import _args
from .data.experiments import Dataset, run_label
from .data.motion import check_motion_option, driven_by
from .figures.friction_plots import force_hysteresis_figure
from .figures.plots import error_figure
from .measurements import Measurement, MetricWarning, Prediction, amount, measurement_of, step_sizes
from .measurements.force import Force
from .measurements.ripple import check_phase_option
from .models import Model
from .models.fit_record import fit_record_of
from .identification.load_blind import load_findings
from .results import Finding, Result, Summary, as_text, collecting, heading, lines, table
from .unit_scale import unit_warnings


@dataclasses.dataclass
class Failure:
    """An experiment the model could not be run on, and why.

    Parameters
    ----------
    file : str
        The experiment's file.
    temperature : float
        Its temperature [C].
    role : {"fit", "validate"}
        Its role in the dataset.
    reason : str
        Why the model could not be run on it (the error's message).
    """

    file: str
    temperature: float
    role: str
    reason: str

    def metrics(self) -> dict:
        return {"file": self.file, "temperature": self.temperature, "role": self.role, "failed": self.reason}


def predict(model: Model, exp, rtol=1e-8):
    """Simulates one experiment and computes its metrics, as its measurement says.

    Parameters
    ----------
    model : Model
        The model.
    exp : Experiment or ForceExperiment
        The experiment.
    rtol : float, default 1e-8
        The simulation's relative tolerance.

    Returns
    -------
    Prediction or ForcePrediction
        The measured and predicted records and the metrics (docs/formats.md#validation-metrics).

    Raises
    ------
    InputError
        A model that cannot predict the experiment (its plant or temperature range), named.
    SolverError
        The simulation failed.
    """
    return measurement_of([exp]).predict(model, exp, rtol)


@dataclasses.dataclass
class ValidationResult(Result):
    """What :func:`validate` returns: the model, one Prediction per experiment with its metrics, the warnings,
    and the experiments it could not be run on; a table in a notebook, ``to_json``, ``to_dataframe``, ``plot``.

    Parameters
    ----------
    model : Model
        The model scored.
    predictions : list of Prediction or ForcePrediction
        One per experiment run, with its metrics.
    warnings : list of str
        "FILE: message": temperatures outside a law's calibrated range, records a power of 1000 off.
    failures : list of Failure, default []
        The experiments the model could not be run on, with why; the others are still computed.
    measurement : Measurement, optional
        What was measured: it gives the metrics, the table's columns and what the RMSE has had removed.
    scored_as : dict, default {}
        How the model was scored: the offset policy and the motion, each with where it came from ("the fit
        record", "asked", "the default").
    findings : list of Finding, default []
        The same as ``warnings``, as values with their categories (UnitWarning, TemperatureRangeWarning,
        MetricWarning).
    loads : dict, default {}
        Force runs that carry a load: file -> the run's load [N or N m] (the table's load column).
    """

    model: Model
    predictions: list
    warnings: list
    #: experiments the model could not be run on (Failure: file, reason); the others are still computed
    failures: list = dataclasses.field(default_factory=list)
    #: what was measured: it gives the metrics, the table's columns and what the RMSE has had removed
    measurement: Measurement = dataclasses.field(default_factory=lambda: measurement_of([]))
    #: how the model was scored: the offset policy and the motion, each with where it came from ("the fit record",
    #: "asked", "the default")
    scored_as: dict = dataclasses.field(default_factory=dict)
    #: the warnings as values, with their categories (results.Finding)
    findings: list = dataclasses.field(default_factory=list)
    #: file -> the run's load [N or N m], for force runs that carry one (a column of the table)
    loads: dict = dataclasses.field(default_factory=dict)

    @property
    def scoring(self) -> str:
        """How the model was scored, in words (every table says it)."""
        return scoring_note(self.scored_as)

    @property
    def unit(self) -> str:
        return self.predictions[0].unit if self.predictions and hasattr(self.predictions[0], "unit") else \
            self.measurement.unit()

    @property
    def _COLUMNS(self):  # noqa: N802 - the table's layout: the measurement's, with the unit in the headers
        m = self.measurement
        cols = m.columns_for(self.unit) if hasattr(m, "columns_for") else m.columns
        if self.loads:  # runs at several loads: each run's load beside its temperature
            at = 1 + next((i for i, c in enumerate(cols) if c[1] == "temperature"), 0)
            cols = (*cols[:at], (f"load [{self.unit}]", "load", "{:.4g}"), *cols[at:])
        return cols

    @property
    def experiments(self):
        rows = [p.metrics() for p in self.predictions]
        if self.loads:
            rows = [{**r, "load": self.loads.get(r["file"], math.nan)} for r in rows]
        return rows

    @property
    def complete(self) -> bool:
        """Every experiment was predicted."""
        return not self.failures

    title = "validation"

    def summary(self) -> Summary:
        """Per role (fit, validate): the errors over its experiments (the measurement's metrics)."""
        return Summary(self.measurement.summary(self.predictions))

    def _blocks(self) -> list:
        """The report: its title, then the table of the experiments' metrics (the measurement's columns)."""
        return [heading(self.title), self._table_block()]

    def _table_block(self):
        """The experiments' metrics as a table block (the report's and the notebook's: HTML has no indent)."""
        return table([c[0] for c in self._COLUMNS], self.rows(), indent="")

    def _frame(self) -> dict:
        """One row per experiment: its metrics."""
        rows = self.experiments
        keys = [k for k in (rows[0] if rows else {}) if k != "fit_quality"]
        return {k: [r.get(k) for r in rows] for k in keys}

    def to_dict(self) -> dict:
        d = {"model": self.model.name, "measurement": self.measurement.name, "unit": self.unit,
             "offset_removed": self.measurement.validation_removed, "experiments": self.experiments,
             "summary": self.summary(), "failed": [f.metrics() for f in self.failures], "warnings": self.warnings,
             "scored_as": self.scored_as,
             **self.measurement.validation_extras(self.model)}
        return jsonable(d)

    def to_json(self, path=None) -> str:
        """The metrics (docs/formats.md#validation-metrics) as JSON, written atomically to ``path`` when given."""
        return dump_json(self.to_dict(), path)

    def to_mat(self, path):
        """The same metrics as a MATLAB file (docs/formats.md#results-in-matlab-files)."""
        from .data.matlab_results import save_results_mat
        save_results_mat(jsonable(self.to_dict()), path)

    def rows(self):
        scale = self.measurement.column_scale
        for m in self.experiments:
            yield [fmt.format(m[key] * scale[key] if key in scale else m[key]) for _, key, fmt in self._COLUMNS]

    def table(self) -> str:
        """The experiments' metrics as a text table (the report without its title)."""
        return as_text([self._table_block()])

    def print_table(self, title=None):
        """A rich table on the terminal."""
        from rich.console import Console
        from rich.markup import escape
        from rich.measure import Measurement
        from rich.table import Table
        # (escaped: rich would take "[nm]" in a header, or brackets in a file name, for markup)
        t = Table(title=escape(title or f"Validation of {self.model.name or 'the model'}"),
                  caption=self.measurement.caption + f"; {self.scoring}; definitions: docs/formats.md#validation-metrics")
        for name, _, _ in self._COLUMNS:
            t.add_column(escape(name), justify="left" if name in ("file", "role") else "right", no_wrap=True)
        for r in self.rows():
            t.add_row(*map(escape, r))
        console = Console()
        # never cut a file name to fit 80 columns (a pipe, a CI log): the table as wide as it needs
        width = Measurement.get(console, console.options.update_width(10_000), t).maximum
        if width > console.width:
            console = Console(width=width)
        console.print(t)

    def plot(self, metric="max_error_pct", ax=None, label=None, what="errors", paper=None):
        """A matplotlib figure of ``metric`` (max_error_pct, final_error_pct, step_error_pct, nrmse,
        rmse) against temperature: fit temperatures filled, held-out ones open on pale red bands,
        and for displacement data's max error the 7-8 % of Li et al. (2009) where the errors reach 1 %
        (``paper=True``: always; False: never). Draws into ``ax`` when given. ``what="hysteresis"``
        (force data): measured and predicted friction against the measured position per experiment."""
        label = label or self.model.name or "model"
        if what == "hysteresis":
            if self.measurement.name != "force":
                raise InputError(f"what='hysteresis' needs force (torque) data; these are {self.measurement.name} data")
            return force_hysteresis_figure(self, label=label)
        if what != "errors":
            raise InputError(f"what must be 'errors' or 'hysteresis', got {what!r}")
        if paper is None and self.measurement.name != "displacement":
            paper = False  # the paper's errors are of displacement
        return error_figure([(label, self)], metric, ax=ax, paper=paper)

    def _html_blocks(self) -> list:
        """The notebook's table: the headline with the errors per role, the experiments' metrics, what the errors
        mean and how the model was scored, the warnings and the experiments not predicted."""
        summary = "; ".join(f"{role}: max error {s['max_error_pct']:.3g} %, RMSE "
                            f"{amount(s['rmse_offset_removed'], self.unit)} ({s['n']} run{'s' if s['n'] != 1 else ''})"
                            for role, s in self.summary().items())
        notes = list(self.warnings) + [f"{f.file}: not predicted: {f.reason}" for f in self.failures]
        return [heading(f"Validation of {self.model.name or 'the model'}", f"— {summary}"),
                self._table_block(),
                lines([f"{self.measurement.footer} {self.scoring}."]), lines(notes)]


def scoring_note(scored_as: dict) -> str:
    """``scored_as`` (ValidationResult.scored_as) in words: "scored as fitted (the fit record): offset shared, motion
    position"."""
    if not scored_as:
        return ""
    keys = [k for k in ("offset", "motion", "ripple_phase") if k in scored_as]
    parts = [f"{k.replace('_', ' ')} {scored_as[k]} ({scored_as[k + '_from']})" for k in keys]
    sources = {scored_as.get(k + "_from") for k in keys}
    lead = "scored as fitted" if sources == {"the fit record"} else "scored with"
    return f"{lead}: " + ", ".join(parts)


def _ripple_phase(record, ripple_phase, how):
    """The ripple's angle: as asked, else the fit record's (said in ``how``), else "auto"."""
    if ripple_phase is None and record.get("ripple_phase"):
        ripple_phase, how["ripple_phase_from"] = record["ripple_phase"], "the fit record"
        check_phase_option(ripple_phase, "the model's [provenance.fit_record] 'ripple_phase'")
    elif ripple_phase is not None and ripple_phase != "auto":
        how["ripple_phase_from"] = "asked"
    if "ripple_phase_from" in how:
        how["ripple_phase"] = ripple_phase
    return ripple_phase or "auto"


def _scoring(model, exps, offset, motion):
    """(the experiments as scored, the offset policy, ``scored_as``): what is not asked is taken from the model's
    fit record (models/fit_record.py), so that a model is scored the way it was fitted."""
    record, how = fit_record_of(model) or {}, {}
    if offset is None and record.get("offset"):
        offset, how["offset_from"] = record["offset"], "the fit record"
        try:
            measurement_of(exps, offset=offset)
        except InputError as e:
            raise InputError(f"the model's [provenance.fit_record] 'offset': {e}") from None
    else:
        how["offset_from"] = "asked" if offset is not None else "the default"
    if motion is None and record.get("motion"):
        motion, how["motion_from"] = record["motion"], "the fit record"
        check_motion_option(motion, "the model's [provenance.fit_record]")
    elif motion is not None:
        how["motion_from"] = "asked"
    if motion is not None and any(getattr(e, "force", None) is not None for e in exps):
        exps = [driven_by(e, motion) for e in exps]
        how["motion"] = motion
    else:
        how.pop("motion_from", None)
    return exps, offset, how


def _refuse_warm_up_records(exps) -> None:
    """InputError naming the first warm-up record of ``exps`` (an ambient temperature, no contact temperature):
    a model is scored at each run's contact temperature, which such a record does not have, and the heat path that
    would give it is not in the model file (docs/self-heating.md#warm-up-without-a-contact-temperature).

    Parameters
    ----------
    exps : list of Experiment or ForceExperiment
        The experiments to be scored.

    Raises
    ------
    InputError
        One of them is a warm-up record, named with how many there are.
    """
    warm = [run_label(e) for e in exps if getattr(e, "warm_up", False)]
    if warm:
        more = f" (and {len(warm) - 1} more)" if len(warm) > 1 else ""
        raise InputError(f"{warm[0]}{more}: a warm-up record (an ambient temperature, no contact temperature) cannot "
                         f"be scored: a model is scored at each record's contact temperature, and a model file "
                         f"does not hold the heat path that would give it; the warm-up fit's own residuals and "
                         f"temperature trajectory are in its results (identify --method warm-up)")


def validate(model: Model, data, experiments=None, *, offset=None, motion=None,
             ripple_phase=None) -> ValidationResult:
    """Predicts every experiment of ``data`` (or the given ones) with ``model`` and measures the
    errors (docs/formats.md#validation-metrics) as the data's measurement says.

    Displacement: about each run's zero; force: with the model's sensor offset, or with
    ``offset="per-experiment"`` each run's own, estimated on it, held-out runs included. Temperatures outside a
    law's calibrated range are reported as warnings, and so is a record whose span is a power of 1000 off the
    prediction's (unit_scale.py; also a UnitWarning).

    Parameters
    ----------
    model : Model
        The model to score (``FitResult.model`` for a fit).
    data : Dataset
        The measurements (``load_dataset``).
    experiments : Dataset or list of Experiment, optional
        The experiments to predict; default every experiment of ``data`` (fit and held out).
    offset : {"shared", "per-experiment", "none"} or bool, optional
        Force data: how the sensor offset is taken; default the model's fit record (so that a fitted model is
        scored the way ``identify`` scored it), else the model's own offset.
    motion : {"position", "velocity", "auto"}, optional
        Force data: what drives the experiments; default the model's fit record, else "auto".
    ripple_phase : {"auto", "recorded", "per-run"}, optional
        Force data's position ripple at the recorded angle ("recorded"), at each run's own phase, estimated on it
        ("per-run"), or per-run where every run starts at 0 ("auto"); default the model's fit record (the angle its
        fit took), else "auto".

    Returns
    -------
    ValidationResult
        One prediction per experiment with its metrics (RMSE in the data's unit, relative errors), the
        warnings, and ``scored_as``: how the offset, the motion and a ripple's angle were chosen.

    Raises
    ------
    InputError
        An argument of the wrong type, named; a dataset without experiments; a model that cannot predict
        these data (a stick-slip actuator for force data, say), or an ``offset`` or ``motion`` that does not
        apply; a warm-up record among the experiments (no contact temperature to score a model at), named.

    Warns
    -----
    UnitWarning
        A record a power of 1000 off the model's prediction.
    """
    exps = _checked(model, data, experiments, "experiments", motion)
    return _scored(model, exps, offset, motion, ripple_phase)


def _checked(model, data, experiments, name, motion=None, none=True) -> list:
    """The experiments scored (``experiments``, named ``name``, where given, and required unless ``none``; else
    ``data``'s), the arguments checked as :func:`validate` and :func:`heldout_score` take them."""
    _args.model(model, Model)
    _args.dataset(data, Dataset, experiments=True)
    _args.dataset(experiments, Dataset, name, experiments=True, none=none)
    if motion is not None:
        check_motion_option(motion, "motion")
    exps = list(experiments if experiments is not None else getattr(data, "experiments", data))
    if not exps:
        raise InputError("the dataset has no experiments")
    return exps


def _scored(model, exps, offset, motion, ripple_phase, fast=False) -> ValidationResult:
    """:func:`validate`'s work on its checked experiments ``exps``. ``fast``: force data predicted by the C core's
    exact stepping of the prescribed motion wherever it applies (what a fit evaluates; the adaptive simulation's
    prediction to 1e-9 of the noise on the study's held-out runs, tests/test_cost_paths5.py) instead of the
    simulation, without the simulation's own checks (its warnings are not findings here)."""
    _refuse_warm_up_records(exps)
    exps, offset, how = _scoring(model, exps, offset, motion)
    ripple_phase = _ripple_phase(fit_record_of(model) or {}, ripple_phase, how)
    measurement = measurement_of(exps, offset=offset, ripple_phase=ripple_phase)  # asked once
    how["offset"] = measurement.offset
    measurement.check_model(model, exps)
    found, preds, failures, pairs = [], [], [], []
    stepped = {"fast": True} if fast and isinstance(measurement, Force) else {}
    for exp in exps:
        with collecting() as w:  # this experiment's findings, as values (also where fits run side by side)
            try:
                preds.append(measurement.predict(model, exp, **stepped))
                pairs.append((exp, preds[-1].measured, preds[-1].predicted))
            except ThermofrictionError as e:  # one experiment the model cannot run: say why, go on
                failures.append(Failure(run_label(exp), float(exp.temperature), getattr(exp, "role", "fit"), str(e)))
        found += [Finding(x.category, f"{run_label(exp)}: {x.message}") for x in w
                  if issubclass(x.category, TemperatureRangeWarning)]
        found += [x for x in w if issubclass(x.category, MetricWarning)]
    # first: a unit off by 1000 explains every error after it (unit_warnings also warns: validate's edge)
    found = [Finding(UnitWarning, m) for m in unit_warnings(pairs)] + found + load_findings(model, exps)
    loads = {run_label(e): float(e.load) for e in exps if getattr(e, "load", None) is not None}
    return ValidationResult(model, preds, [f.message for f in found], failures, measurement, how, found, loads)


def heldout_score(model: Model, data, runs, measurement):
    """``model`` scored on ``runs`` as a fit's generalisation is (identify: the fit's offset policy and ripple angle,
    its findings kept as values), the one definition of a fit's held-out RMSE. Force data are predicted by the C
    core's exact stepping of the prescribed motion wherever it applies, the call a fit's evaluation makes (the
    adaptive simulation :func:`validate` runs agrees to 1e-9 of the noise on the cost study's held-out runs, at a
    tenth of the time; the simulation's own warnings are not run).

    Parameters
    ----------
    model : Model
        The model to score.
    data : Dataset or list of Experiment
        The dataset the runs belong to.
    runs : list of Experiment
        The held-out runs.
    measurement : Measurement
        The fit's measurement (its ``offset`` policy and, for force data, its ``ripple_phase``).

    Returns
    -------
    tuple
        (the root mean square of the runs' RMSEs, NaN where none was predicted; the ValidationResult).

    Raises
    ------
    ThermofrictionError
        As :func:`validate`.
    """
    exps = _checked(model, data, runs, "runs", none=False)
    with collecting():  # force data by the exact stepping, as the fit evaluated them (_scored)
        v = _scored(model, exps, measurement.offset if measurement.offset != "shared" else None, None,
                    getattr(measurement, "ripple_phase", "auto"), fast=True)
    rms = float(np.sqrt(np.mean([p.rmse ** 2 for p in v.predictions]))) if v.predictions else float("nan")
    return rms, v


__all__ = ["MetricWarning", "validate", "ValidationResult", "Prediction", "Failure", "predict", "step_sizes"]
