"""The FitResult of Model I with laws of temperature and load (identification/load_identify.py): the package's one fit
result, as ``identify`` returns it for any force fit -- the parameters with standard errors and 95 % intervals, each
run's RMSE and quality against the noise estimated from its record, the offsets, the warnings -- and in
``details["load"]`` how the laws were fitted and which forms were chosen (docs/identification.md#laws-of-temperature-
and-load)."""

from __future__ import annotations

import math
import time

import numpy as np

from .._lazy import lazy
from ..errors import InputError
from ..fitting.parameters import Parameters, unit_of
from ..fitting.quality import fit_quality, pooled
from ..measurements import amount
from ..measurements.force_load import law_derivatives, stepped_force
from ..models.load_laws import LoadLaw
from ..models.plants import rotary_unit
from .load_identify import PREFER_SIMPLER, identify_load
from .load_kinds import form_of, law_value
from .result import FitResult

stats = lazy("scipy.stats")

#: a parameter's 95 % interval: value +- this many standard errors
Z95 = 1.959963984540054


def coefficient_unit(model, name: str, rotary: bool) -> str:
    """The unit of fitted coefficient ``name`` (``fc.a``, ``fc.load.k``, ``sigma2``); a load in N on a linear stage,
    in N m on a joint.

    Parameters
    ----------
    model : Model
        The fitted model.
    name : str
        The coefficient.
    rotary : bool
        A rotary joint (units of angle and torque).

    Returns
    -------
    str
    """
    p, _, c = name.partition(".")
    law = model.laws.get(p)
    unit = unit_of(model, p)
    unit = rotary_unit(unit) if rotary else unit
    if not isinstance(law, LoadLaw):
        return unit if not c else law.coefficient_unit(c, unit)
    load = "N m" if rotary else "N"
    if c == "load.k":
        return f"1/({load})" if law.load.combine == "product" else f"{unit}/({load})"
    if c == "load.interaction":
        return f"{unit}/(C {load})"
    base = unit if law.load.kind == "affine" else ("1" if unit == load else f"{unit}/({load})")
    return law.base.coefficient_unit(c, base)


def law_band(fit: FitResult, name: str, T, load, level: float = 0.95) -> tuple:
    """A law of temperature and load of a fit at conditions (T, load) with its ``level`` interval, by the delta
    method on the covariance of the law's coefficients (the law's own derivatives).

    Parameters
    ----------
    fit : FitResult
        A fit whose model has the law (``identify`` on runs at several loads).
    name : str
        The parameter (``fc``).
    T, load : float or array_like
        The conditions [C] and [N or N m], of one shape.
    level : float, default 0.95
        The interval's probability.

    Returns
    -------
    tuple of numpy.ndarray
        (value, lower, upper).
    """
    law = fit.model.laws[name]
    T, L = np.broadcast_arrays(np.atleast_1d(np.asarray(T, float)), np.atleast_1d(np.asarray(load, float)))
    varying = [p.name for p in fit.parameters.varying]
    own = [varying.index(f"{name}.{c}") if f"{name}.{c}" in varying else None for c in law.coefficient_names()]
    idx = [i for i in own if i is not None]
    se = np.array([fit.parameters[varying[i]].stderr or 0.0 for i in idx], float)
    cov = fit.correlation[np.ix_(idx, idx)] * np.outer(se, se)
    value, sd = np.empty(T.size), np.empty(T.size)
    for j, (t, x) in enumerate(zip(T.ravel(), L.ravel())):
        g = law_derivatives(law, t, x)[[k for k, i in enumerate(own) if i is not None]]
        value[j] = law_value(law, t, x)
        sd[j] = math.sqrt(max(float(g @ cov @ g), 0.0))
    z = float(stats.norm.ppf(0.5 + level / 2))
    return value, value - z * sd, value + z * sd


def _parameters(fit, rotary: bool) -> Parameters:
    params = Parameters()
    for n, v, s in zip(fit.names, fit.values, fit.stderr):
        q = params.add(n, float(v), unit=coefficient_unit(fit.model, n, rotary))
        q.stderr, q.ci95 = float(s), (float(v - Z95 * s), float(v + Z95 * s))
    for n, v in fit.model.friction.values().items():
        if v is not None and n not in params and n not in fit.model.laws:
            params.add(n, float(v), vary=False, unit=rotary_unit(unit_of(fit.model, n)) if rotary else
                       unit_of(fit.model, n))
    return params


def _per_run(fit, runs, offset):
    """Each run's residuals (its offset removed as the policy says) and the run's entry."""
    out, rows = [], []
    shared = 0.0
    if offset == "shared":
        raw = [stepped_force(fit.model, e)[0] - np.asarray(e.force, float) for e in runs]
        shared = float(np.mean(np.concatenate(raw)))
    for e in runs:
        r = stepped_force(fit.model, e)[0] - np.asarray(e.force, float)
        r = r - (r.mean() if offset == "per-experiment" else shared if offset == "shared" else 0.0)
        q = fit_quality(r, np.asarray(e.force, float))
        out.append(r)
        rows.append({"file": e.file, "temperature": float(e.temperature), "load": float(e.load), "role": "fit",
                     "rmse_offset_removed": q["rmse"], "rmse": q["rmse"], "fit_quality": q})
    return out, rows


def _sensor_offset(fit, offset, unit, runs) -> dict:
    """The offsets: each run's with its mean's standard error (its RMSE times sqrt(correlation time / samples))."""
    if offset == "per-experiment":
        n = {e.file: len(e.time) for e in runs}
        se = {f: fit.rmse[f] * math.sqrt(max(fit.correlation_time, 1.0) / n[f]) for f in fit.offsets}
        runs = [{"file": f, "value": v, "stderr": se[f], "ci95": (v - Z95 * se[f], v + Z95 * se[f])}
                for f, v in fit.offsets.items()]
        return {"value": float(np.mean([r["value"] for r in runs])), "stderr": None, "ci95": None,
                "per_experiment": runs, "unit": unit, "fitted": True, "policy": offset}
    value = float(np.mean(list(fit.offsets.values()))) if offset == "shared" else 0.0
    return {"value": value, "stderr": None, "ci95": None, "unit": unit, "fitted": offset == "shared",
            "policy": offset}


def _delta(d: float) -> str:
    """An AICc difference in words; a tie is the same functions (an affine product and sum with an interaction
    over a linear temperature law span them)."""
    return "the same functions" if abs(d) < 1e-6 else f"{d:+.3g}"


def _said(details: dict) -> list:
    """The forms chosen, in words (the result's warnings say what the procedure decided)."""
    out = []
    if details["why_joint"]:
        out.append(f"laws of load: {details['procedure']}: {details['why_joint']}")
    for name, rows in details["forms"].items():
        kept = next((r for r in rows if r["kept"]), rows[0])
        others = [r for r in rows if not r["kept"] and math.isfinite(r["aicc_all"])]
        if others:
            out.append(f"{name}'s law of load: {kept['form']}, chosen by AICc on all runs' effective samples (more "
                       f"coefficients only where lower by more than {PREFER_SIMPLER:g}) over "
                       + ", ".join(f"{r['form']} ({_delta(r['aicc_all'] - kept['aicc_all'])})" for r in others))
    return out


def load_fit_result(fit, details: dict, runs, offset: str, t0: float) -> FitResult:
    """The FitResult of a fit of laws of temperature and load (module docstring).

    Parameters
    ----------
    fit : LoadFit
        The joint fit kept.
    details : dict
        What identify_load chose (its second return).
    runs : list of ForceExperiment
        The fit runs.
    offset : str
        The offset policy.
    t0 : float
        ``time.perf_counter()`` at the fit's start.

    Returns
    -------
    FitResult
    """
    rotary = bool(getattr(runs[0], "rotary", False))
    unit = "N m" if rotary else "N"
    residuals, rows = _per_run(fit, runs, offset)
    r = np.concatenate(residuals)
    overall = pooled([x["fit_quality"] for x in rows], [len(e.time) for e in runs])
    unreliable = [x["fit_quality"] for x in rows if not x["fit_quality"]["noise_reliable"]]
    if 2 * len(unreliable) > len(rows):  # one sensor: its noise coloured on most runs is coloured on all
        overall.update(adequate=None, why=f"on {len(unreliable)} of {len(rows)} runs {unreliable[0]['why']}")
    warnings = []
    if overall["adequate"] is False:
        warnings.append(f"the fit is not adequate: its residuals are {overall['ratio']:.3g} times the measurement "
                        f"noise estimated from the data ({amount(overall['rmse'], unit)} against "
                        f"{amount(overall['noise'], unit)}): the laws miss what the data show")
    elif overall["adequate"] is None:
        warnings.append(f"adequacy unknown: {overall['why']}; judge the fit by its error on held-out runs")
    sd = np.where(fit.stderr > 0, fit.stderr, 1.0)
    corr = fit.covariance / np.outer(sd, sd)
    load = {**details, "laws": {n: {"form": form_of(law), **law.to_dict()} for n, law in fit.model.laws.items()},
            "loads": sorted({float(e.load) for e in runs})}
    return FitResult(method="model-i", model=fit.model, parameters=_parameters(fit, rotary), correlation=corr,
                     cost=float(r @ r), rmse=float(np.sqrt(np.mean(r ** 2))), n_points=int(r.size),
                     nfev=int(details["nfev"]), njev=int(details["nfev"]), starts=1,
                     wall_time=time.perf_counter() - t0, success=True, message=fit.message or "converged",
                     experiments=rows, warnings=warnings + _said(details),
                     statistics={"correlation_time": fit.correlation_time, "variance_inflation": fit.correlation_time},
                     details={"load": load}, fit_quality=overall, measurement="force", unit=unit,
                     removed={"per-experiment": "each experiment's offset", "shared": "the shared sensor offset",
                              "none": "nothing"}[offset], sensor_offset=_sensor_offset(fit, offset, unit, runs))


def identify_with_load(runs, init, measurement, method, parameters, laws, refine, progress=None) -> FitResult:
    """What ``identify`` returns for an initial model with laws of load (identification/load_identify.py), its
    options checked: Model I only, the law kinds of the model file (no ``laws``), always refined; the names in
    ``parameters`` without a law fitted as constants.

    Parameters
    ----------
    runs : list of ForceExperiment
        The fit runs.
    init : Model
        The initial model, with laws of load.
    measurement : Measurement
        The data's measurement (force; its offset policy).
    method, parameters, laws, refine, progress
        identify's options.

    Returns
    -------
    FitResult

    Raises
    ------
    InputError
        An option that does not apply, named; data that are not force records.
    ComputationError
        The joint fit failed.
    """
    if measurement.name != "force" or method != "model-i":
        raise InputError(f"laws of temperature and load are identified by method 'model-i' on force data "
                         f"(these: method '{method}', {measurement.name} data)")
    if laws is not None:
        raise InputError("laws: a law of load keeps the temperature kind of the model file (its [thermal] table); "
                         "its form along the load is chosen by identify itself")
    if not refine:
        raise InputError("refine=False: laws of load are always refined jointly on all runs")
    if isinstance(parameters, Parameters):
        raise InputError("parameters: name the constants to fit with the laws (a list of names), not a Parameters")
    free = [p for p in ([parameters] if isinstance(parameters, str) else parameters or ()) if p not in init.laws]
    values = init.friction.values()
    for p in free:
        if values.get(p) is None:
            raise InputError(f"parameters: '{p}' is neither a law of the initial model nor a friction parameter given "
                             f"there as a number")
    t0 = time.perf_counter()
    fit, details = identify_load(runs, init, free, measurement.offset, progress)
    res = load_fit_result(fit, details, runs, measurement.offset, t0)
    res.removed = measurement.removed
    return res


__all__ = ["load_fit_result", "coefficient_unit", "identify_with_load", "law_band"]
