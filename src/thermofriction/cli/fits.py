"""A fit read back from the results JSON that ``identify --json`` writes (docs/formats.md#results-json), for the
commands that continue from a fit (``propagate``)."""

from __future__ import annotations

import math
import os

import numpy as np

from .._reading import read_input_json
from ..errors import InputError
from ..models.model import model_from_dict

#: the keys a results JSON must hold to be continued from
_REQUIRED = ("method", "model", "parameters", "correlation")


def _number(v, where):
    """A JSON number, or JSON's "inf"/"-inf"/"nan" strings, as a float; None stays None."""
    if v is None:
        return None
    if isinstance(v, bool) or not (isinstance(v, (int, float)) or v in ("inf", "-inf", "nan")):
        raise InputError(f"{where}: must be a number, got {v!r}")
    return float(v)


def _log_scale(value, ci95, at_bound) -> bool:
    """Whether a parameter was fitted on a log scale (identify's parameters bounded below by zero): its 95 %
    interval is then multiplicative, value/f to value*f, so that its ends' product is the value squared (an additive
    interval's is value^2 - (t se)^2), or, at a bound, one-sided from zero. The results JSON records the interval,
    not the bound."""
    if not value > 0 or ci95 is None:
        return False
    lo, hi = ci95
    if at_bound == "upper":
        return lo == 0.0
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo <= 0:
        return False
    return abs(lo * hi / value ** 2 - 1.0) < 1e-9


def _parameters(d, path):
    from ..identification.parameters import Parameter, Parameters

    params = Parameters()
    if not isinstance(d, dict) or not d:
        raise InputError(f"{path}: 'parameters' must be a table of the fitted parameters")
    for name, p in d.items():
        where = f"{path}: parameters: '{name}'"
        if not isinstance(p, dict) or "value" not in p:
            raise InputError(f"{where}: must be a table with 'value', 'stderr', 'ci95' and 'vary'")
        value = _number(p["value"], f"{where}: value")
        if value is None:
            raise InputError(f"{where}: value must be a number, got null")
        ci = p.get("ci95")
        if ci is not None and not (isinstance(ci, list) and len(ci) == 2):
            raise InputError(f"{where}: ci95 must be a pair of numbers, got {ci!r}")
        ci = None if ci is None else tuple(_number(c, f"{where}: ci95") for c in ci)
        at_bound = p.get("at_bound")
        positive = _log_scale(value, ci, at_bound)
        params[name] = Parameter(name, value, min=0.0 if positive else -math.inf, vary=bool(p.get("vary", True)),
                                 unit=str(p.get("unit", "")), stderr=_number(p.get("stderr"), f"{where}: stderr"),
                                 ci95=ci, at_bound=at_bound)
    return params


def _correlation(d, params, path):
    names = [p.name for p in params.varying]
    if not isinstance(d, dict) or d.get("names") != names:
        raise InputError(f"{path}: 'correlation' must name the fitted parameters in order ({', '.join(names)})")
    try:
        m = np.array([[_number(x, f"{path}: correlation") for x in row] for row in d.get("matrix", [])], float)
    except TypeError:
        m = np.zeros((0, 0))
    if m.shape != (len(names), len(names)):
        raise InputError(f"{path}: 'correlation' matrix must be {len(names)} x {len(names)}")
    return m


def load_fit(path):
    """The fit that ``identify --json`` wrote to ``path``: a FitResult with its fitted model, parameters (values,
    standard errors, intervals), correlations and fit quality -- what ``tf.propagate`` draws from. InputError
    naming the file and the key for anything else (a model file, a validation's metrics)."""
    from ..identification.result import FitResult

    if os.fspath(path).lower().endswith(".mat"):
        raise InputError(f"{path}: a MATLAB file; the fit is read from the results JSON (identify --json RESULTS.json)")
    d = read_input_json(path, "results JSON")
    missing = [k for k in _REQUIRED if not isinstance(d, dict) or k not in d]
    if missing:
        raise InputError(f"{path}: not an identification's results (no '{missing[0]}'): give the JSON that "
                         f"'thermofriction identify --json RESULTS.json' writes")
    if not isinstance(d["model"], dict):
        raise InputError(f"{path}: 'model' must be a table (the fitted model)")
    model = model_from_dict(d["model"], f"{path}: model", base_dir=os.path.dirname(os.fspath(path)))
    params = _parameters(d["parameters"], path)
    quality = d.get("fit_quality") if isinstance(d.get("fit_quality"), dict) else None
    if quality is not None:
        quality = {**quality, "noise": _number(quality.get("noise"), f"{path}: fit_quality: noise")}
    try:
        return _fit_result(FitResult, d, model, params, quality, path)
    except (TypeError, ValueError) as e:  # (an InputError is a ValueError: it names its key already)
        if isinstance(e, InputError):
            raise
        raise InputError(f"{path}: not an identification's results as identify --json writes them ({e})") from None


def _fit_result(FitResult, d, model, params, quality, path):
    return FitResult(method=str(d["method"]), model=model, parameters=params,
                     correlation=_correlation(d["correlation"], params, path),
                     cost=_number(d.get("cost", "nan"), f"{path}: cost"),
                     rmse=_number(d.get("rmse_offset_removed", "nan"), f"{path}: rmse_offset_removed"),
                     n_points=int(d.get("n_points", 0)), nfev=int(d.get("iterations", 0)),
                     njev=int(d.get("jacobian_evaluations", 0)), starts=int(d.get("starts", 1)),
                     wall_time=_number(d.get("wall_time", "nan"), f"{path}: wall_time"),
                     success=bool(d.get("success", True)), message=str(d.get("message", "")),
                     warnings=list(d.get("warnings", [])), fit_quality=quality,
                     measurement=str(d.get("measurement", "displacement")), unit=str(d.get("unit", "m")))


__all__ = ["load_fit"]
