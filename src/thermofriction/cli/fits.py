"""A fit read back from the results JSON that ``identify --json`` writes (docs/formats.md#results-json), for the
commands that continue from a fit (``propagate``). Every key is checked as it is read: an edited or damaged file is
one InputError naming the file and the key, never a traceback or a failure in the work that follows."""

from __future__ import annotations

import math
import os

import numpy as np

from .._reading import read_input_json
from ..errors import InputError, shorten
from ..fitting.parameters import get_value
from ..measurements import REGISTRY
from ..models.model import model_from_dict

#: the keys a results JSON must hold to be continued from
_REQUIRED = ("method", "model", "parameters", "correlation")
#: a parameter's value and the fitted model's agree to rounding (both are written from the same float)
_SAME = 1e-9


def _number(v, where, *, finite=False):
    """A JSON number, or JSON's "inf"/"-inf"/"nan" strings (how identify writes non-finite values), as a float; None
    stays None. ``finite``: the non-finite ones refused too."""
    if v is None:
        return None
    if isinstance(v, bool) or not (isinstance(v, (int, float)) or v in ("inf", "-inf", "nan")):
        raise InputError(f"{where}: must be a number, got {shorten(v)}")
    try:
        x = float(v)
    except OverflowError:  # an integer of hundreds of digits
        raise InputError(f"{where}: must be a number in the floating-point range, got an integer of "
                         f"{len(str(v))} digits") from None
    if finite and not math.isfinite(x):
        raise InputError(f"{where}: must be finite, got {shorten(v)}")
    return x


def _count(v, where) -> int:
    """A whole number, 0 or more (a count: points, evaluations, starts)."""
    if isinstance(v, bool) or not (isinstance(v, int) or isinstance(v, float) and math.isfinite(v) and v.is_integer()) \
            or v < 0:
        raise InputError(f"{where}: must be a whole number, 0 or more, got {shorten(v)}")
    return int(v)


def _typed(v, cls, what, where):
    if not isinstance(v, cls):
        raise InputError(f"{where}: must be {what}, got {shorten(v)}")
    return v


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


def _parameter(name, p, model, where):
    """(value, stderr, ci95, at_bound, vary, unit) of one parameter; its value must be the fitted model's."""
    if not isinstance(p, dict) or "value" not in p:
        raise InputError(f"{where}: must be a table with 'value', 'stderr', 'ci95' and 'vary'")
    value = _number(p["value"], f"{where}: value", finite=True)
    if value is None:
        raise InputError(f"{where}: value must be a number, got null")
    try:
        own = get_value(model, name)
    except InputError as e:  # not a parameter of the fitted model (an unknown or renamed key)
        raise InputError(f"{where}: not a parameter of the fitted model ({e})") from None
    if not abs(value - own) <= _SAME * max(abs(value), abs(own)):
        raise InputError(f"{where}: value {value!r} is not the fitted model's ({own!r}): the file was edited, or its "
                         f"'parameters' and 'model' come from different fits")
    stderr = _number(p.get("stderr"), f"{where}: stderr")
    if stderr is not None and stderr < 0 and math.isfinite(stderr):  # "-inf": identify's spelling of NaN
        raise InputError(f"{where}: stderr must be 0 or more, got {stderr!r}")
    ci = p.get("ci95")
    if ci is not None and not (isinstance(ci, list) and len(ci) == 2):
        raise InputError(f"{where}: ci95 must be a pair of numbers, got {shorten(ci)}")
    ci = None if ci is None else tuple(_number(c, f"{where}: ci95") for c in ci)
    if ci is not None and ci[0] > ci[1]:
        raise InputError(f"{where}: ci95 must be [lower, upper], got {list(ci)}")
    at_bound = p.get("at_bound")
    if at_bound not in (None, "lower", "upper"):
        raise InputError(f"{where}: at_bound must be \"lower\" or \"upper\" (or absent), got {shorten(at_bound)}")
    vary = _typed(p.get("vary", True), bool, "true or false", f"{where}: vary")
    return value, stderr, ci, at_bound, vary, _typed(p.get("unit", ""), str, "a string", f"{where}: unit")


def _parameters(d, model, path):
    from ..fitting.parameters import Parameter, Parameters

    params = Parameters()
    if not isinstance(d, dict) or not d:
        raise InputError(f"{path}: 'parameters' must be a table of the fitted parameters")
    for name, p in d.items():
        value, stderr, ci, at_bound, vary, unit = _parameter(name, p, model, f"{path}: parameters: '{name}'")
        positive = _log_scale(value, ci, at_bound)
        params[name] = Parameter(name, value, min=0.0 if positive else -math.inf, vary=vary, unit=unit,
                                 stderr=stderr, ci95=ci, at_bound=at_bound)
    return params


def _correlation(d, params, path):
    """The matrix as written; that it is a correlation matrix is checked where it is drawn from
    (scale/propagate.py: check_correlation)."""
    names = [p.name for p in params.varying]
    if not isinstance(d, dict) or d.get("names") != names:
        raise InputError(f"{path}: 'correlation' must name the fitted parameters in order ({', '.join(names)})")
    rows = d.get("matrix")
    if not (isinstance(rows, list) and len(rows) == len(names)
            and all(isinstance(r, list) and len(r) == len(names) for r in rows)):
        raise InputError(f"{path}: 'correlation' matrix must be {len(names)} x {len(names)}")
    return np.array([[_number(x, f"{path}: correlation: matrix", finite=True) for x in row] for row in rows], float)


def _quality(q, path):
    """fit_quality (optional): a table whose noise, when given, is a finite standard deviation, 0 or more."""
    if q is None:
        return None
    _typed(q, dict, "a table", f"{path}: fit_quality")
    noise = _number(q.get("noise"), f"{path}: fit_quality: noise", finite=True)
    if noise is not None and noise < 0:
        raise InputError(f"{path}: fit_quality: noise must be 0 or more, got {noise!r}")
    return {**q, "noise": noise}


def load_fit(path):
    """The fit that ``identify --json`` wrote to ``path``: a FitResult with its fitted model, parameters (values,
    standard errors, intervals), correlations and fit quality -- what ``tf.propagate`` draws from. InputError
    naming the file and the key for anything else (a model file, a validation's metrics, an edited key)."""
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
    params = _parameters(d["parameters"], model, path)
    return _fit_result(d, model, params, path)


def _fit_result(d, model, params, path):
    from ..identification.result import FitResult

    def number(key):
        return _number(d.get(key, "nan"), f"{path}: {key}")

    def count(key, default):
        return _count(d.get(key, default), f"{path}: {key}")

    def text(key, default):
        return _typed(d.get(key, default), str, "a string", f"{path}: {key}")

    warnings = _typed(d.get("warnings", []), list, "a list of strings", f"{path}: warnings")
    for w in warnings:
        _typed(w, str, "a list of strings", f"{path}: warnings")
    measurement = text("measurement", "displacement")
    if measurement not in REGISTRY:
        raise InputError(f"{path}: measurement must be one of {', '.join(REGISTRY)}, got {shorten(measurement)}")
    return FitResult(method=text("method", None), model=model, parameters=params,
                     correlation=_correlation(d["correlation"], params, path), cost=number("cost"),
                     rmse=number("rmse_offset_removed"), n_points=count("n_points", 0), nfev=count("iterations", 0),
                     njev=count("jacobian_evaluations", 0), starts=count("starts", 1), wall_time=number("wall_time"),
                     success=_typed(d.get("success", True), bool, "true or false", f"{path}: success"),
                     message=text("message", ""), warnings=list(warnings),
                     fit_quality=_quality(d.get("fit_quality"), path), measurement=measurement,
                     unit=text("unit", "m"))


__all__ = ["load_fit"]
