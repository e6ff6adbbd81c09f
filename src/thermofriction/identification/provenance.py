"""A fitted model's name, description and provenance (docs/formats.md#provenance): the data's hash, the method,
the date, the version and the options, stamped on every result ``identify`` returns."""

from __future__ import annotations

import dataclasses
import datetime
import functools
import inspect
import os

import numpy as np

from .._version import __version__
from ..data.experiments import run_label
from ..data.files import dataset_sha256 as data_sha256
from ..measurements import measurement_of
from ..models import Model
from ..fitting.parameters import Parameters
from .record import fit_record
from .result import FitResult

METHOD_NAMES = {"plant": "the plant (xi, wn, K)", "base": "a friction model without thermal effects",
                "model-i": "Model I (temperature-dependent parameters)", "model-ii": "Model II (a thermal friction term)",
                "heat": "the self-heating model"}


def _label(data) -> str:
    name = getattr(data, "name", None)
    path = getattr(data, "path", None)
    return name or (os.path.basename(os.path.normpath(str(path))) if path is not None else "data")


def _option(v):
    if isinstance(v, Parameters):
        return [p.name for p in v.varying]
    if isinstance(v, Model):
        return v.name or "a Model object"
    if isinstance(v, dict):
        return {str(k): _option(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_option(x) for x in v]
    if isinstance(v, np.generic):  # first: np.float64 is a float too, but not a plain one (np.float64(1) != ())
        return v.item()
    if isinstance(v, (str, bool, int, float)) or v is None:
        return v
    return repr(v)


def stamp(fit, data, method: str, init, options: dict):
    """``fit`` with its model named for the data and the method, described, and its provenance
    (the data's hash, the method, the date, the version, the options); the same for its alternatives."""
    if not isinstance(getattr(fit, "model", None), Model):
        return fit
    where, digest = data_sha256(data)
    experiments = list(getattr(data, "experiments", data))
    fit_runs = [e for e in experiments if getattr(e, "role", "fit") == "fit"]
    held = [e for e in experiments if getattr(e, "role", "fit") != "fit"]
    label = _label(data)
    temps = ", ".join(f"{e.temperature:.4g}" for e in fit_runs)
    # (an option is tested once it is plain: np.int64(1) != () is an empty array, whose truth is an error)
    opts = {k: o for k, o in ((k, _option(v)) for k, v in options.items()) if o is not None and o != [] and o != ()}

    def plain(x):  # what the model file's [provenance] holds; anything else as its text (never fail a fit here)
        items = list(x.values()) if isinstance(x, dict) else x if isinstance(x, list) else [x]
        return x if all(isinstance(i, (str, bool, int, float)) for i in items) else str(x)
    opts = {k: plain(v) for k, v in opts.items()}
    date = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat().replace("+00:00", "Z")
    init_name = init.name or "a Model object" if isinstance(init, Model) else str(init)
    policy = measurement_of(fit_runs or experiments, offset=options.get("offset")).offset
    # the ripple's angle as identify decided it (on the whole dataset, as identify asks measurement_of)
    phase = getattr(measurement_of(experiments, offset=options.get("offset"),
                                   ripple_phase=options.get("ripple_phase") or "auto"), "ripple_phase", None)

    def one(f, how):
        prov = {"method": f.method, "data": where, "data_sha256": digest,
                "fit_files": [run_label(e) for e in fit_runs], "held_out_files": [run_label(e) for e in held],
                "date": date, "thermofriction": __version__, "initial_model": init_name,
                "options": {**opts, **how}}
        if isinstance(f, FitResult):  # how it was scored: validate and report score it the same way
            prov["fit_record"] = fit_record(f, fit_runs, policy, phase)
        description = (f"{METHOD_NAMES.get(f.method, f.method)} identified by thermofriction {__version__} "
                       f"from {len(fit_runs)} experiment{'s' if len(fit_runs) != 1 else ''} of {label} "
                       f"at {temps} C" + (f" ({len(held)} held out)" if held else "")
                       + f", starting from {init_name}")
        model = dataclasses.replace(f.model, name=f"{f.method} fit to {label}", description=description, provenance=prov)
        alternatives = {k: one(v, {"procedure": k}) for k, v in f.alternatives.items()}
        return dataclasses.replace(f, model=model, alternatives=alternatives)
    return one(fit, {})


def stamped(identify):
    """Decorates ``identify`` so that every fitted model it returns carries its name and provenance."""
    signature = inspect.signature(identify)

    @functools.wraps(identify)
    def wrapper(*args, **kwargs):
        fit = identify(*args, **kwargs)
        bound = signature.bind(*args, **kwargs)
        bound.apply_defaults()
        a = dict(bound.arguments)
        data, method, init = a.pop("data"), a.pop("method"), a.pop("init")
        a.pop("progress", None)
        if init is None:  # the method's default start, a preset, whose name the fitted model still has
            init = getattr(getattr(fit, "model", None), "name", None) or "the method's preset"
        return stamp(fit, data, method, init, a)
    return wrapper


__all__ = ["stamp", "stamped", "METHOD_NAMES"]
