"""Identification procedures: a base friction model, Model I and Model II (docs/models.md#thermal-extensions), built on
the engine's fit()."""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from ..drive import experiment_waveform
from ..errors import InputError
from ..models import PWL, Const, Model, ModelI, ModelII
from ..simulate import simulate
from .engine import Problem, fit, make_traces, uncertainty
from .laws import _aicc, fit_law, segmented_fit
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


def default_fit_parameters(model: Model) -> list:
    """The default fitted parameters of ``model``'s friction model (FRICTION_FIT_PARAMETERS), less
    those it leaves unset or at zero; under Model I, those with a law (if any has one)."""
    names = FRICTION_FIT_PARAMETERS.get(model.friction.model, DEFAULT_FRICTION_PARAMETERS)
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
        quality = fit_quality(seg[:n], tr.displacement)
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
                        f"noise estimated from the data ({overall['rmse'] * 1e9:.4g} nm against "
                        f"{overall['noise'] * 1e9:.3g} nm; not adequate in {len(bad)} of {len(per)} experiments): "
                        f"the model misses what the data show. Try: {advice(model)}")
    cost = float(outcome.r @ outcome.r)
    return FitResult(method=method, model=fitted, parameters=params, correlation=corr, cost=cost,
                     rmse=math.sqrt(cost / len(outcome.r)), n_points=len(outcome.r), nfev=outcome.nfev,
                     njev=outcome.njev, starts=outcome.starts, wall_time=time.perf_counter() - t0,
                     success=outcome.success, message=str(outcome.message), experiments=per,
                     warnings=first + list(extra_warnings) + warns, statistics=stats, details=details or {},
                     fit_quality=overall)


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


def identify_heat(experiments, init: Model, parameters=None, **opts) -> FitResult:
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
    names = list(parameters or DEFAULT_HEAT_PARAMETERS)
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


def identify_model_i(experiments, init: Model, *, laws=None, refine=True, progress=None, **opts) -> FitResult:
    """Model I: per-temperature fits, a law per parameter (linear or exponential by AICc unless
    ``laws`` names one), then a joint refinement of the law coefficients on all experiments."""
    t0 = time.perf_counter()
    groups = _groups(experiments)
    if len(groups) < 2:
        raise InputError("Model I needs fit experiments at two or more temperatures")
    names = _fit_parameter_names(init)
    per_T, previous, held, warns = [], None, [], []
    for i, group in enumerate(groups):
        T = float(np.mean([e.temperature for e in group]))
        base = base_model(init, T) if previous is None else previous
        base = dataclasses.replace(base, thermal=None)
        if held:  # parameters the data cannot determine follow the initial model's law
            base = base.with_friction(**{n: base_model(init, T).friction.values()[n] for n in held})
        if progress:
            progress(f"Model I: fitting {', '.join(n for n in names if n not in held)} at {T:.4g} C")
        first = dict(opts)
        if previous is not None:  # continuation from the neighbouring temperature
            first["starts"] = 1
        res = fit_friction(group, base, _friction_parameters(base, names, fixed=held),
                           method=f"base at {T:.4g} C", **first)
        if i == 0:
            undetermined = [n for n in names if not math.isfinite(res.parameters[n].stderr)
                            or res.parameters[n].stderr > abs(res.parameters[n].value)]
            if undetermined and len(undetermined) < len(names):
                held = undetermined
                warns.append(f"{', '.join(held)} cannot be determined from these data (standard error above 100 % "
                             f"at {T:.4g} C): held at the initial model's law")
                res = fit_friction(group, base.with_friction(**{n: base_model(init, T).friction.values()[n]
                                                                for n in held}),
                                   _friction_parameters(base, names, fixed=held), method=f"base at {T:.4g} C", **opts)
        previous = res.model
        per_T.append((T, res))
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
    details["laws"] = law_tables
    friction = dataclasses.replace(base_model(init, float(Ts.mean())).friction, **{n: None for n in names})
    model = dataclasses.replace(init, friction=friction, thermal=ModelI(new_laws))
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
    traces = make_traces(experiments, model)
    ropts = dict(opts)
    ropts["starts"] = 1
    ropts.setdefault("max_nfev", 30)
    outcome = fit(model, params, traces, **ropts)
    res = _result("model-i", model, params, outcome, traces, t0, warns, details)
    res.nfev += sum(r.nfev for _, r in per_T)
    res.njev += sum(r.njev for _, r in per_T)
    return res




def _final_displacement(exp):
    """Net displacement of a run: mean of its last 1 % minus mean of its first 1 % (robust to noise)."""
    k = max(len(exp.displacement) // 100, 1)
    return float(np.mean(exp.displacement[-k:]) - np.mean(exp.displacement[:k]))


def identify_model_ii(experiments, init: Model, *, procedure="direct", reference_temperature=None, refine=True,
                      progress=None, **opts) -> FitResult:
    """Model II. ``procedure="paper"``: base model at the reference temperature; displacement
    against temperature by a segmented linear fit with an estimated breakpoint; displacement
    against dF by simulation; composed dF(T). ``"direct"``: dF fitted per temperature on the
    trajectories, then a law (linear or two segments by AICc) and a joint refinement.
    ``"both"``: the direct result, with the paper's in ``alternatives["paper"]``."""
    if procedure not in ("direct", "paper", "both"):
        raise InputError(f"Model II procedure must be 'direct', 'paper' or 'both', got {procedure!r}")
    t0 = time.perf_counter()
    groups = _groups(experiments)
    if len(groups) < 2:
        raise InputError("Model II needs fit experiments at two or more temperatures")
    if reference_temperature is None:
        ref_group = groups[0]
    else:
        ref_group = min(groups, key=lambda g: abs(g[0].temperature - reference_temperature))
    T_ref = float(np.mean([e.temperature for e in ref_group]))
    if progress:
        progress(f"Model II: base model at the reference temperature {T_ref:.4g} C")
    base_init = base_model(init, T_ref)
    base_fit = fit_friction(ref_group, base_init, _fit_parameter_names(base_init),
                            method=f"base at {T_ref:.4g} C", **opts)
    base = base_fit.model
    details = {"reference_temperature": T_ref, "base": base_fit.to_dict()}
    results = {}
    if procedure in ("paper", "both"):
        results["paper"] = _model_ii_paper(groups, base, T_ref, details, t0, progress)
    if procedure in ("direct", "both"):
        results["direct"] = _model_ii_direct(groups, experiments, base, T_ref, details, t0, refine, progress, opts)
    main = results["direct" if procedure != "paper" else "paper"]
    if procedure == "both":
        main.alternatives["paper"] = results["paper"]
    main.wall_time = time.perf_counter() - t0
    return main


def _model_ii_paper(groups, base, T_ref, details, t0, progress):
    if progress:
        progress("Model II (paper): displacement against temperature and against dF")
    Ts = np.array([np.mean([e.temperature for e in g]) for g in groups])
    D = np.array([np.mean([_final_displacement(e) for e in g]) for g in groups])
    tb, D_law, ssr_seg = segmented_fit(Ts, D)
    sst = float(np.sum((D - D.mean()) ** 2))
    r2_seg = 1.0 - ssr_seg / sst if sst > 0 else math.nan
    # displacement against dF, by simulating the base model with a constant dF
    ref = groups[0][0]
    fc = base.reference_force()
    dFs = np.linspace(-0.5 * fc, 0.2 * fc, 8)
    waveform = experiment_waveform(ref, base)
    D_sim = []
    for dF in dFs:
        m = dataclasses.replace(base, thermal=ModelII(Const(float(dF))))
        res = simulate(m, t_eval=ref.time, temperature=T_ref, input=waveform)
        D_sim.append(res.displacement[-1] - res.displacement[0])
    D_sim = np.array(D_sim)
    beta, alpha = np.polyfit(dFs, D_sim, 1)
    r2 = 1 - np.sum((alpha + beta * dFs - D_sim) ** 2) / np.sum((D_sim - D_sim.mean()) ** 2)
    knots = D_law.T
    dF_knots = (D_law.values - alpha) / beta
    law = PWL(knots, dF_knots, range=(float(Ts.min()), float(Ts.max())))
    model = dataclasses.replace(base, thermal=ModelII(law))
    details["paper"] = {"temperatures": Ts, "displacement": D, "breakpoint": tb,
                        "displacement_law": D_law.to_dict(), "dF_grid": dFs, "displacement_vs_dF": D_sim,
                        "linear_fit": {"slope": beta, "intercept": alpha, "r2": r2}, "dF_law": law.to_dict()}
    params = Parameters()
    for i, v in enumerate(dF_knots):
        params.add(f"dF.values[{i}]", float(v), unit="N")
    warns = [] if r2 > 0.98 else [f"displacement is not linear in dF (R^2 = {r2:.3f}): the paper's procedure "
                                  f"assumes it is"]
    if not (r2_seg >= 0.9):
        warns.append(f"the two-segment fit of displacement against temperature is poor (R^2 = {r2_seg:.3f}): the "
                     f"paper's procedure assumes two straight segments")
    success, message = True, "paper's procedure (no trajectory fit, no intervals)"
    worst = float(np.max(np.abs(dF_knots)))
    if not np.all(np.isfinite(dF_knots)) or worst >= fc or np.any(1.0 + dF_knots / fc <= 0):
        # beyond the friction level the scale form reverses friction: not a model of these data
        success = False
        message = (f"refused: the paper's procedure gives |dF| up to {worst:.4g} N, beyond the friction level "
                   f"fc = {fc:.4g} N (the displacement hardly depends on dF here; use --procedure direct)")
        warns.insert(0, message)
    details["paper"]["segmented_r2"] = r2_seg
    return FitResult("model-ii (paper)", model, params, np.full((len(params), len(params)), np.nan), math.nan,
                     math.nan, 0, len(dFs), 0, 0, time.perf_counter() - t0, success, message, warnings=warns,
                     details=details)


def _dF_start(group, m, fc, previous, opts):
    """Where to start dF at one temperature: the cost in dF can have two minima (a stick-slip step
    grows and then shrinks as friction falls), so scan it across the friction level, and keep the
    neighbouring temperature's value (continuation) in the scan."""
    grid = sorted(set(np.round(np.linspace(-0.9, 0.9, 13) * fc, 12)) | {0.0, float(previous)})
    traces = make_traces(group, m)
    problem = Problem(m, ["dF.value"], traces, rtol=max(opts.get("rtol", 1e-8), 1e-6))
    costs = []
    for v in grid:
        r, _ = problem.evaluate(np.array([v]))
        costs.append(math.inf if r is None else float(r @ r))
    return float(grid[int(np.argmin(costs))]), {"grid": grid, "cost": costs}


def _model_ii_direct(groups, experiments, base, T_ref, details, t0, refine, progress, opts):
    per_T = []
    popts = dict(opts)
    popts["starts"] = 1
    fc = base.reference_force()
    # continuation outward from the reference temperature, where dF is smallest
    order = sorted(range(len(groups)), key=lambda i: abs(float(np.mean([e.temperature for e in groups[i]])) - T_ref))
    previous, fits, scans = 0.0, {}, {}
    for i in order:
        g = groups[i]
        T = float(np.mean([e.temperature for e in g]))
        if progress:
            progress(f"Model II (direct): dF at {T:.4g} C")
        m = dataclasses.replace(base, thermal=ModelII(Const(0.0)))
        start, scans[T] = _dF_start(g, m, fc, previous, popts)
        params = Parameters()
        # lambda = 1 + dF/fc stays positive: friction never reverses
        params.add("dF.value", start, min=-0.95 * fc, max=10.0 * fc, unit="N")
        r = fit_friction(g, dataclasses.replace(m, thermal=ModelII(Const(start))), params,
                         method=f"dF at {T:.4g} C", **popts)
        fits[i] = (T, r)
        previous = r.parameters["dF.value"].value
    per_T = [fits[i] for i in range(len(groups))]
    Ts = np.array([T for T, _ in per_T])
    vals = np.array([r.parameters["dF.value"].value for _, r in per_T])
    ses = np.array([r.parameters["dF.value"].stderr for _, r in per_T])
    w = 1.0 / ses if np.all(np.isfinite(ses) & (ses > 0)) else np.ones_like(ses)
    w = w / w.mean()
    candidates = {}
    A = np.column_stack([Ts, np.ones_like(Ts)]) * w[:, None]
    coef, *_ = np.linalg.lstsq(A, vals * w, rcond=None)
    lin = PWL([Ts.min(), Ts.max()], [coef[0] * Ts.min() + coef[1], coef[0] * Ts.max() + coef[1]],
              range=(float(Ts.min()), float(Ts.max())))
    candidates["linear"] = (lin, _aicc(float(np.sum(((lin(Ts) - vals) * w) ** 2)), len(Ts), 2))
    if len(Ts) >= 4:
        tb, seg, ssr = segmented_fit(Ts, vals, w)
        candidates["two segments"] = (seg, _aicc(ssr, len(Ts), 4))
    chosen = min(candidates, key=lambda k: candidates[k][1])
    law = candidates[chosen][0]
    details["direct"] = {"temperatures": Ts, "dF": vals, "stderr": ses, "chosen": chosen,
                         "candidates": {k: {"aicc": a, "law": l.to_dict()} for k, (l, a) in candidates.items()}}
    model = dataclasses.replace(base, thermal=ModelII(law))
    details["direct"]["scans"] = [{"temperature": T, **scans[T]} for T in sorted(scans)]
    params = Parameters()
    for i, v in enumerate(law.values):
        params.add(f"dF.values[{i}]", float(v), unit="N")
    if not refine:
        return FitResult("model-ii (direct)", model, params, np.full((len(params),) * 2, np.nan), math.nan,
                         math.nan, 0, sum(r.nfev for _, r in per_T), 0, 0, time.perf_counter() - t0, True,
                         "per-temperature dF and law (no joint refinement)", details=details)
    if progress:
        progress("Model II (direct): joint refinement of dF(T) and the base parameters on all experiments")
    # The base parameters are refined with dF, so that dF's intervals carry their uncertainty. Scaling
    # sigma0, sigma1, fc by 1/c and shifting dF by fc (1 - 1/c) leaves the scale form unchanged, so
    # dF is pinned to zero at the reference temperature (its definition: the base model holds there).
    knots = np.asarray(law.T)
    at_ref = np.flatnonzero(np.abs(knots - T_ref) <= 0.05)
    warns = []
    if at_ref.size:
        k = int(at_ref[0])
        model = dataclasses.replace(model, thermal=ModelII(law.with_coefficients(
            [0.0 if j == k else v for j, v in enumerate(law.values)])))
        params[f"dF.values[{k}]"].value = params[f"dF.values[{k}]"].init_value = 0.0
        params[f"dF.values[{k}]"].vary = False
        for name in _fit_parameter_names(base):
            params.add(name, get_value(model, name), min=0.0, unit=unit_of(model, name))
    else:
        warns.append(f"the reference temperature {T_ref:.4g} C is not a breakpoint of dF's law: the base parameters "
                     f"are held at their fit there, so dF's intervals do not include their uncertainty")
    traces = make_traces(experiments, model)
    outcome = fit(model, params, traces, **popts)
    res = _result("model-ii (direct)", model, params, outcome, traces, t0, warns, details=details)
    res.nfev += sum(r.nfev for _, r in per_T)
    return res
