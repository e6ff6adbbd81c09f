"""Identification procedures: a base friction model, Model I and Model II (docs/models.md#thermal-extensions), built on
the engine's fit()."""

from __future__ import annotations

import dataclasses
import math
import os
import time

import numpy as np

from ..errors import InputError
from ..models import Const, Model, ModelI
from ..models.friction import in_domain
from .engine import fit, make_traces, uncertainty
from .laws import fit_law
from .parameters import Parameters, get_value, unit_of, with_values
from .quality import advice, fit_quality, pooled
from .result import FitResult

DEFAULT_FRICTION_PARAMETERS = ("sigma0", "sigma1", "fc")  # LuGre's (the paper's)
#: The parameters fitted by default for each friction model (docs/identification.md#friction-models):
#: what sets the level and the presliding stiffness, which displacement data determine; the shape
#: parameters (delta, vd, v_smooth, GMS's element stiffnesses k and capacities w) are kept. A
#: parameter the initial model leaves unset or at zero (vs, sigma2) is kept too: fitted in log
#: space it needs a positive start, and zero means "not in the model". fs and z_ba are bound to
#: other parameters (fs >= fc, z_ba < fc/sigma0), which a step of the fit may break, and the engine
#: does not yet treat such a step as unphysical (it stops): they are kept unless named.
FRICTION_FIT_PARAMETERS = {
    "lugre": DEFAULT_FRICTION_PARAMETERS,
    "elastoplastic": ("sigma0", "sigma1", "fc"),
    "dahl": ("sigma0", "fc"),
    "coulomb": ("fc", "sigma2"),
    "stribeck": ("fc", "vs", "sigma2"),
    "gms": ("C", "fc"),
}

#: Force data see the whole friction-velocity map: the Stribeck and viscous parameters are fitted too.
FORCE_FIT_PARAMETERS = {
    "lugre": ("sigma0", "sigma1", "fc", "fs", "vs", "sigma2"),
    "elastoplastic": ("sigma0", "sigma1", "fc", "fs", "vs", "sigma2"),
    "dahl": ("sigma0", "fc"),
    "coulomb": ("fc", "sigma2"),
    "stribeck": ("fc", "fs", "vs", "sigma2"),
    "gms": ("C", "fc", "fs", "vs", "sigma2"),
}


def default_fit_parameters(model: Model) -> list:
    """The default fitted parameters of ``model``'s friction model (FRICTION_FIT_PARAMETERS; for prescribed
    motion, fitted to force data, FORCE_FIT_PARAMETERS), less those it leaves unset or at zero; under Model I,
    those with a law (if any has one)."""
    table = FORCE_FIT_PARAMETERS if model.plant.type == "prescribed" else FRICTION_FIT_PARAMETERS
    names = table.get(model.friction.model, DEFAULT_FRICTION_PARAMETERS)
    laws = model.laws if isinstance(model.thermal, ModelI) else {}
    values = model.friction.values()
    if model.friction.model in ("stribeck", "gms", "lugre", "elastoplastic") and \
            values.get("fs") in (None, values.get("fc")) and "fs" not in laws:
        values = {k: v for k, v in values.items() if k not in ("fs", "vs")}  # no Stribeck effect to fit
    names = [n for n in names if n in laws or (values.get(n) or 0.0) > 0.0]
    with_law = [n for n in names if n in laws]
    return with_law or names


def _result(method, model, params, outcome, traces, t0, extra_warnings=(), details=None):
    corr, warns, stats = uncertainty(params, outcome, traces, model)
    values = {p.name: p.value for p in params.values()}
    fitted = with_values(model, values)
    per, qualities, start = [], [], 0
    for tr in traces:
        n = len(tr.time)
        seg = outcome.r[start:start + tr.n_residuals]
        start += tr.n_residuals
        # the displacement residuals of a trace have their mean (the sensor's zero) removed
        quality = fit_quality(seg[:n], tr.measured)
        qualities.append(quality)
        per.append({"file": tr.name, "temperature": tr.nominal_temperature, "role": tr.role,
                    "rmse_offset_removed": quality["rmse"], "fit_quality": quality})
        if tr.measured_temperature is not None:  # [K], unweighted
            per[-1]["temperature_rmse"] = float(np.sqrt(np.mean(seg[n:] ** 2))) / tr.temperature_weight
    overall = pooled(qualities, [len(tr.time) for tr in traces])
    first = []
    if not overall["adequate"]:
        bad = [p["file"] for p, q in zip(per, qualities) if not q["adequate"]]
        first.append(f"the fit is not adequate: its residuals are {overall['ratio']:.3g} times the measurement "
                        f"noise estimated from the data ({_amount(overall['rmse'], traces)} against "
                        f"{_amount(overall['noise'], traces)}; not adequate in {len(bad)} of {len(per)} experiments): "
                        f"the model misses what the data show. Try: {_advice(model, traces)}")
    cost = float(outcome.r @ outcome.r)
    return FitResult(method=method, model=fitted, parameters=params, correlation=corr, cost=cost,
                     rmse=math.sqrt(cost / len(outcome.r)), n_points=len(outcome.r), nfev=outcome.nfev,
                     njev=outcome.njev, starts=outcome.starts, wall_time=time.perf_counter() - t0,
                     success=outcome.success, message=str(outcome.message), experiments=per,
                     warnings=first + list(extra_warnings) + warns, statistics=stats, details=details or {},
                     fit_quality=overall)


def _amount(value, traces) -> str:
    """A residual in the traces' unit: nm for displacements, N or N m for forces (identify/force.py)."""
    unit = getattr(traces[0], "unit", None)
    return f"{value:.4g} {unit}" if unit else f"{value * 1e9:.4g} nm"


def _advice(model, traces) -> str:
    """What to try when a fit is not adequate (force data: identify/force.py)."""
    if getattr(traces[0], "unit", None):
        from .force import FORCE_ADVICE
        return FORCE_ADVICE
    return advice(model)


def _friction_parameters(model: Model, names, fixed=()):
    params = Parameters()
    for name in names:
        v = get_value(model, name)
        positive = not name.startswith("dF") and "." not in name
        params.add(name, v, min=0.0 if positive else -math.inf, vary=name not in fixed,
                   unit=unit_of(model, name))
    return params


def base_model(model: Model, temperature=None) -> Model:
    """The model without its thermal extension: a Model I's laws evaluated at ``temperature``."""
    if isinstance(model.thermal, ModelI):
        if temperature is None:
            lo_hi = model.temperature_range()
            temperature = 0.5 * (lo_hi[0] + lo_hi[1]) if lo_hi else 35.0
        p = model.parameters_at(temperature)
        fr = dataclasses.replace(model.friction, **{k: p[k] for k in model.laws})
        return dataclasses.replace(model, friction=fr, thermal=None)
    return dataclasses.replace(model, thermal=None)


def fit_friction(experiments, model: Model, parameters=None, *, method="base", **opts) -> FitResult:
    """Fits the named friction parameters (default sigma0, sigma1, fc) of ``model`` jointly on
    ``experiments``: one set of values shared by all of them."""
    t0 = time.perf_counter()
    traces = make_traces(experiments, model)
    if isinstance(parameters, Parameters):
        params = parameters
    else:
        params = _friction_parameters(model, parameters or default_fit_parameters(model))
    outcome = fit(model, params, traces, **opts)
    return _result(method, model, params, outcome, traces, t0)


DEFAULT_HEAT_PARAMETERS = ("C_th", "R_th", "eta")


def identify_heat(experiments, init: Model, parameters=None, free=(), **opts) -> FitResult:
    """Fits the lumped thermal model (docs/models.md#self-heating) -- by default C_th, R_th and eta; friction
    parameters named too are fitted jointly -- to the recorded temperatures and displacements.

    The two records have different units and noise, so the fit runs twice: first with each
    record weighted by its range, then with each weighted by its residual scatter at that first
    optimum (so that both carry unit variance, which the intervals assume), from there.
    Without a known heat input (the model's P_ext) the records fix only eta R_th and R_th C_th:
    then one of the three gets an infinite interval and a warning, as it should."""
    if init.heat is None:
        raise InputError("the heat fit needs an initial model with a [heat] section (C_th, R_th, eta guesses)")
    t0 = time.perf_counter()
    traces = make_traces(experiments, init)
    starts = [tr.initial_temperature for tr in traces]
    names = list(parameters or DEFAULT_HEAT_PARAMETERS) + list(free)
    if parameters is None and max(starts) - min(starts) < 0.1:
        # every run starts at one temperature (thermal equilibrium): estimate it with the rest, the
        # displacement pins it far better than a thermometer's first samples (0.3 um/K per cycle)
        names.append("T_0")
        init = dataclasses.replace(init, heat=dataclasses.replace(init.heat, initial_temperature=float(np.mean(starts))))
    if isinstance(parameters, Parameters):
        params = parameters
    else:
        params = Parameters()
        for name in names:
            v = get_value(init, name)
            if name == "T_0":
                params.add(name, v, unit="C")
            else:
                params.add(name, v, min=0.0, max=1.0 if name == "eta" else math.inf, unit=unit_of(init, name))
    for tr in traces:  # first pass: each record by its range
        tr.temperature_weight = max(float(np.ptp(tr.displacement)), 1e-12) / max(
            float(np.ptp(tr.measured_temperature)), 1e-3)
    first = fit(init, params, traces, **opts)
    model = with_values(init, dict(zip([p.name for p in params.varying], first.theta)))
    start = 0
    for tr in traces:  # second pass: each record by its residual scatter
        n = len(tr.time)
        seg = first.r[start:start + 2 * n]
        start += 2 * n
        sx = float(np.sqrt(np.mean(seg[:n] ** 2)))
        sT = float(np.sqrt(np.mean(seg[n:] ** 2))) / tr.temperature_weight
        tr.temperature_weight = max(sx, 1e-15) / max(sT, 1e-9)
    for p, v in zip(params.varying, first.theta):
        p.value = float(min(max(v, p.min), p.max))
    outcome = fit(model, params, traces, **dict(opts, starts=1))
    outcome.nfev += first.nfev
    outcome.njev += first.njev
    return _result("heat", init, params, outcome, traces, t0,
                   details={"temperature_weights_m_per_K": [tr.temperature_weight for tr in traces]})


def _groups(experiments):
    """Fit experiments grouped by temperature (0.05 C apart count as one)."""
    exps = sorted(experiments, key=lambda e: e.temperature)
    groups = []
    for e in exps:
        if groups and abs(e.temperature - groups[-1][0].temperature) < 0.05:
            groups[-1].append(e)
        else:
            groups.append([e])
    return groups


def _fit_parameter_names(model):
    return default_fit_parameters(model)


LOG_SPACE_BELOW = 0.3  # relative standard error below which a parameter's misfit is taken as quadratic in its log


def _laws_on_information(Ts, per_T, laws: dict) -> dict:
    """The laws' coefficients refitted to the per-temperature estimates weighted by each temperature's
    full covariance (in log space, where the fits were made), not by its standard errors alone: the
    per-temperature estimates are strongly correlated (sigma0 with fc), and the joint refinement then
    starts near its optimum instead of some standard errors away. The law kinds stay as chosen; a law
    is kept as it was if this fails or leaves its parameter's physical domain."""
    from scipy import optimize

    names = list(laws)
    blocks = []
    for T, res in per_T:
        varying = [p.name for p in res.parameters.varying]
        if not all(n in varying for n in names):
            return laws
        idx = [varying.index(n) for n in names]
        value = np.array([res.parameters[n].value for n in names])
        se = np.array([res.parameters[n].stderr for n in names], float)
        if np.any(value <= 0) or res.correlation.shape != (len(varying), len(varying)):
            return laws
        known = np.isfinite(se) & (se > 0)  # a parameter this temperature leaves open adds nothing
        corr = res.correlation[np.ix_(idx, idx)][np.ix_(known, known)]
        if not known.any() or not np.all(np.isfinite(corr)):
            continue
        # well-determined parameters in log space (where the fits were made), a poorly determined one
        # (sigma1, often) in its own: its misfit is nearer quadratic there
        log = se[known] < LOG_SPACE_BELOW * value[known]
        unit = np.where(log, value[known], 1.0)
        cov = corr * np.outer(se[known] / unit, se[known] / unit)
        try:
            root = np.linalg.cholesky(np.linalg.inv(cov))  # W = root root^T
        except np.linalg.LinAlgError:
            continue
        blocks.append((T, np.flatnonzero(known), log, np.where(log, np.log(value[known]), value[known]), root))
    if not blocks:
        return laws
    sizes = [len(laws[n].coefficients()) for n in names]
    c0 = np.concatenate([laws[n].coefficients() for n in names])

    def with_coefficients(c):
        out, k = {}, 0
        for n, size in zip(names, sizes):
            out[n] = laws[n].with_coefficients(c[k:k + size])
            k += size
        return out

    def residuals(c):
        trial = with_coefficients(c)
        out = []
        for T, known, log, estimate, root in blocks:
            predicted = np.array([float(trial[names[i]](T)) for i in known])
            if np.any(~np.isfinite(predicted)) or np.any(predicted <= 0):
                return np.full(sum(len(b[1]) for b in blocks), 1e6)
            out.append(root.T @ (np.where(log, np.log(predicted), predicted) - estimate))
        return np.concatenate(out)

    try:
        res = optimize.least_squares(residuals, c0, x_scale=np.where(c0 != 0, np.abs(c0), 1.0))
    except (ValueError, np.linalg.LinAlgError):
        return laws
    if not res.success or 2 * res.cost >= float(np.sum(residuals(c0) ** 2)):
        return laws
    refined = with_coefficients(res.x)
    grid = np.linspace(float(np.min(Ts)), float(np.max(Ts)), 41)
    return {n: refined[n] if in_domain(n, refined[n](grid)).all() else laws[n] for n in names}


def identify_model_i(experiments, init: Model, *, laws=None, refine=True, progress=None, free=(), **opts) -> FitResult:
    """Model I: per-temperature fits, a law per parameter (linear or exponential by AICc unless
    ``laws`` names one), then a joint refinement of the law coefficients on all experiments.
    ``free``: plant parameters (e.g. m_e) fitted too, one value shared by all experiments (per
    temperature first; their median starts the joint refinement)."""
    free = list(free)
    t0 = time.perf_counter()
    groups = _groups(experiments)
    if len(groups) < 2:
        raise InputError("Model I needs fit experiments at two or more temperatures")
    names = _fit_parameter_names(init)
    held, warns = [], []

    def fit_at(group, previous, first_of_all=False, neighbour=True):
        """The fit at one temperature, from the neighbouring temperature's model (continuation) or,
        without one, from the initial model's values there with the multi-start; returns (T, result,
        the model the next temperature continues from)."""
        nonlocal held
        T = float(np.mean([e.temperature for e in group]))
        if previous is None:
            base = base_model(init, T)
        else:
            # the neighbour's values carried along the initial model's laws (by their ratio, which a
            # wrong level of a law does not change): the paper's sigma0 and fc change by a third over
            # 3 C, many standard errors that a plain continuation would leave for the fit to walk
            T_prev, base = previous
            shifts = {n: float(init.laws[n](T) / init.laws[n](T_prev)) for n in names
                      if n in init.laws and n not in held}
            shifts = {n: f for n, f in shifts.items() if math.isfinite(f) and f > 0}
            if shifts:
                values = base.friction.values()
                base = base.with_friction(**{n: values[n] * f for n, f in shifts.items()})
        base = dataclasses.replace(base, thermal=None)
        if held:  # parameters the data cannot determine follow the initial model's law
            base = base.with_friction(**{n: base_model(init, T).friction.values()[n] for n in held})
        if progress:
            progress(f"Model I: fitting {', '.join(n for n in names if n not in held)} at {T:.4g} C")
        first = dict(opts)
        if previous is not None and neighbour:  # continuation from the neighbouring temperature
            first["starts"] = 1
        res = fit_friction(group, base, _friction_parameters(base, names + free, fixed=held),
                           method=f"base at {T:.4g} C", **first)
        if first_of_all:
            undetermined = [n for n in names if not math.isfinite(res.parameters[n].stderr)
                            or res.parameters[n].stderr > abs(res.parameters[n].value)]
            if undetermined and len(undetermined) < len(names):
                held = undetermined
                warns.append(f"{', '.join(held)} cannot be determined from these data (standard error above 100 % "
                             f"at {T:.4g} C): held at the initial model's law")
                res = fit_friction(group, base.with_friction(**{n: base_model(init, T).friction.values()[n]
                                                                for n in held}),
                                   _friction_parameters(base, names + free, fixed=held), method=f"base at {T:.4g} C",
                                   **opts)
        # continuation carries only what this temperature determined: a parameter the data leave open
        # (standard error above its value, e.g. sigma1 run to its bound) restarts from the initial model,
        # or the next fit spends most of its evaluations walking back from a bound
        open_ = [n for n in names if n in res.parameters and n not in held
                 and not (res.parameters[n].stderr is not None and math.isfinite(res.parameters[n].stderr)
                          and res.parameters[n].stderr < abs(res.parameters[n].value))]
        following = res.model.with_friction(**{n: base_model(init, T).friction.values()[n] for n in open_
                                               if n in base_model(init, T).friction.values()}) if open_ else res.model
        return T, res, (T, following)

    def chain(order, previous, neighbour=True):
        out = []
        for k, i in enumerate(order):
            T, res, previous = fit_at(groups[i], previous, neighbour=neighbour or k > 0)
            out.append((T, res))
        return out

    # the lowest temperature first (it decides what the data cannot determine); then two continuation
    # chains, one per core: upward from it, and downward from the highest temperature, which starts from
    # the lowest temperature's fit carried there along the initial model's laws (not a neighbour: with
    # the multi-start)
    T0, res0, following = fit_at(groups[0], None, first_of_all=True)
    rest = list(range(1, len(groups)))
    up, down = rest[:(len(rest) + 1) // 2], rest[(len(rest) + 1) // 2:][::-1]
    if down and (os.cpu_count() or 1) > 1:
        from concurrent.futures import ThreadPoolExecutor
        with ThreadPoolExecutor(max_workers=2, thread_name_prefix="thermofriction-model-i") as chains:
            lower = chains.submit(chain, up, following)
            upper = chains.submit(chain, down, following, False)
            per_T = [(T0, res0)] + lower.result() + upper.result()
    else:
        per_T = [(T0, res0)] + chain(rest, following)
    per_T.sort(key=lambda tr: tr[0])
    details = {"per_temperature": [
        {"temperature": T, "files": [x["file"] for x in r.experiments], "rmse_offset_removed": r.rmse,
         "parameters": r.parameters.to_dict(), "warnings": r.warnings, "wall_time": r.wall_time} for T, r in per_T]}
    Ts = np.array([T for T, _ in per_T])
    new_laws, law_tables = {}, {}
    for n in names:
        if n in held:
            new_laws[n] = init.laws[n] if n in init.laws else Const(init.friction.values()[n])
            law_tables[n] = {"chosen": "held at the initial model", "law": new_laws[n].to_dict()}
            continue
        vals = np.array([r.parameters[n].value for _, r in per_T])
        ses = np.array([r.parameters[n].stderr for _, r in per_T])
        kinds = (laws or {}).get(n)
        kinds = (kinds,) if isinstance(kinds, str) else (kinds or ("linear", "exp"))
        prefer = init.laws[n].kind if n in init.laws else None
        law, table = fit_law(Ts, vals, ses, kinds, prefer=prefer, parameter=n)
        new_laws[n] = law
        law_tables[n] = {"chosen": law.kind, "candidates": table, "temperatures": Ts, "values": vals,
                         "stderr": ses}
    fitted = [n for n in names if n not in held]
    refined = _laws_on_information(Ts, per_T, {n: new_laws[n] for n in fitted})
    for n in fitted:
        if refined[n] is not new_laws[n]:  # the candidates' coefficients are by standard errors alone
            new_laws[n] = refined[n]
            law_tables[n]["weighted_by_covariance"] = new_laws[n].to_dict()
    details["laws"] = law_tables
    friction = dataclasses.replace(base_model(init, float(Ts.mean())).friction, **{n: None for n in names})
    model = dataclasses.replace(init, friction=friction, thermal=ModelI(new_laws))
    if free:  # one plant for all temperatures: the median of the per-temperature estimates
        model = with_values(model, {n: float(np.median([r.parameters[n].value for _, r in per_T])) for n in free})
    if not refine:
        params = Parameters()
        for n, law in new_laws.items():
            for cname, v in zip(law.coefficient_names(), law.coefficients()):
                params.add(f"{n}.{cname}", v, unit=unit_of(model, f"{n}.{cname}"))
        res = FitResult("model-i", model, params, np.full((0, 0), np.nan), math.nan, math.nan, 0,
                        sum(r.nfev for _, r in per_T), sum(r.njev for _, r in per_T), 0,
                        time.perf_counter() - t0, True, "per-temperature fits and laws (no joint refinement)",
                        warnings=warns, details=details)
        return res
    if progress:
        progress("Model I: joint refinement of the law coefficients on all experiments")
    params = Parameters()
    for n, law in new_laws.items():
        for cname, v in zip(law.coefficient_names(), law.coefficients()):
            name = f"{n}.{cname}"
            positive = law.kind == "exp" and cname == "a" and v > 0
            params.add(name, v, min=0.0 if positive else -math.inf, unit=unit_of(model, name), vary=n not in held)
    for n in free:
        params.add(n, get_value(model, n), min=0.0, unit=unit_of(model, n))
    traces = make_traces(experiments, model)
    ropts = dict(opts)
    ropts["starts"] = 1
    ropts.setdefault("max_nfev", 30)
    # from laws through the per-temperature optima weighted by their covariances: near the optimum
    outcome = fit(model, params, traces, near=True, **ropts)
    res = _result("model-i", model, params, outcome, traces, t0, warns, details)
    res.nfev += sum(r.nfev for _, r in per_T)
    res.njev += sum(r.njev for _, r in per_T)
    return res
