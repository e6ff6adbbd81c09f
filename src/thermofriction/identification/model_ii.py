"""Model II (docs/models.md#model-ii): the paper's procedure (displacement against temperature and
against dF, composed) and the direct one (dF per temperature on the trajectories, a law, a joint
refinement with the base parameters)."""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from ..drive import experiment_waveform
from ..errors import ComputationError, InputError
from ..models import PWL, Const, Model, ModelII
from ..models.transforms import base_model
from ..simulation import simulate
from ..fitting.optimiser import AT_NOISE, COARSE_RTOL, COARSE_STEP, fit, residual_scale
from ..fitting.problem import Problem, pool
from ..measurements import make_traces
from .laws import aicc, fit_range, segmented_fit
from ..fitting.parameters import Parameters, friction_parameters
from .procedures import (along_temperatures, counted, default_fit_parameters, fit_friction, fit_result, fitted_names,
                         stribeck_start, temperature_groups, unrefined_result)
from .result import FitResult


def _final_displacement(exp):
    """Net displacement of a run: mean of its last 1 % minus mean of its first 1 % (robust to noise)."""
    k = max(len(exp.displacement) // 100, 1)
    return float(np.mean(exp.displacement[-k:]) - np.mean(exp.displacement[:k]))


@counted
def identify_model_ii(experiments, init: Model, *, procedure="direct", reference_temperature=None, refine=True, free=(),
                      progress=None, measurement=None, parameters=None, **opts) -> FitResult:
    """Model II. ``procedure="paper"``: base model at the reference temperature; displacement
    against temperature by a segmented linear fit with an estimated breakpoint; displacement
    against dF by simulation; composed dF(T). ``"direct"``: dF fitted per temperature on the
    trajectories, then a law (linear or two segments by AICc) and a joint refinement.
    ``"both"``: the direct result, with the paper's in ``alternatives["paper"]``.

    Parameters
    ----------
    experiments : list of Experiment
        The experiments fitted (a dataset's ``fit``).
    init : Model
        The initial model.
    procedure : {"direct", "paper", "both"}, default "direct"
        As above.
    reference_temperature : float, optional
        T_0 [C]; default chosen from the data.
    refine : bool, default True
        End with the joint refinement.
    free : sequence of str, default ()
        Plant parameters fitted too, one value shared by all experiments.
    progress : callable, optional
        Called with one line of text at each stage.
    measurement : Measurement, optional
        How the residuals are formed; default the experiments' own, with its default offset policy.
    parameters : list of str, optional
        The base parameters fitted; default the friction model's.
    **opts
        Passed on to ``fit``: ``rtol``, ``starts``, ``seed``, ``max_nfev``, ...

    Returns
    -------
    FitResult

    Raises
    ------
    InputError
        Bad arguments (an unknown parameter name, no parameter to fit, an initial value outside its bounds),
        named.
    ComputationError
        The fit failed (SolverError where a simulation stopped).
    """
    if procedure not in ("direct", "paper", "both"):
        raise InputError(f"Model II procedure must be 'direct', 'paper' or 'both', got {procedure!r}")
    t0 = time.perf_counter()
    groups = temperature_groups(experiments)
    if len(groups) < 2:
        raise InputError("Model II needs fit experiments at two or more temperatures")
    if procedure != "direct" and len(groups) < 4:
        raise InputError(f"Model II's paper procedure needs fit experiments at four or more temperatures (it fits "
                         f"two straight segments to the displacement against temperature); these are at "
                         f"{len(groups)}: use procedure 'direct'")
    if reference_temperature is None:
        ref_group = groups[0]
    else:
        ref_group = min(groups, key=lambda g: abs(g[0].temperature - reference_temperature))
    T_ref = float(np.mean([e.temperature for e in ref_group]))
    if progress:
        progress(f"Model II: base model at the reference temperature {T_ref:.4g} C")
    names = fitted_names(base_model(init, T_ref), parameters)
    base_init = stribeck_start(base_model(init, T_ref), names)
    # The direct procedure's first fits (the base model here, dF at each temperature) only start its joint
    # refinement, which ends at the requested tolerance and step: they run at rtol 1e-6 (whose integration
    # error moves a Gauss-Newton step by ~0.1-0.2 standard errors on data like the paper's) and stop as
    # the coarse stage of a fit does, within a standard error. The paper's procedure keeps the base fit as it
    # is: its result is built on it.
    first_opts = opts
    if refine and procedure == "direct":
        first_opts = dict(opts, rtol=max(opts.get("rtol", 1e-8), COARSE_RTOL), small_step=COARSE_STEP)
    try:
        base_fit = fit_friction(ref_group, base_init, friction_parameters(base_init, names + list(free), excess=True),
                                method=f"base at {T_ref:.4g} C", measurement=measurement, **first_opts)
    except (InputError, ComputationError) as e:
        raise ComputationError(f"Model II: the base fit at the reference temperature {T_ref:.4g} C of "
                               f"{', '.join(names + list(free))} failed: {e}") from e
    base = base_fit.model
    details = {"reference_temperature": T_ref, "base": base_fit.to_dict()}
    results = {}
    if procedure in ("paper", "both"):
        results["paper"] = _model_ii_paper(groups, base, T_ref, details, t0, progress)
    if procedure in ("direct", "both"):
        results["direct"] = _model_ii_direct(groups, experiments, base, T_ref, details, t0, refine, progress, opts,
                                             free, first_opts, measurement, names)
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
    law = PWL(knots, dF_knots, range=fit_range(Ts))
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


def _dF_start(group, m, fc, previous, opts, measurement=None):
    """Where to start dF at one temperature: the cost in dF can have two minima (a stick-slip step
    grows and then shrinks as friction falls), so scan it across the friction level, and keep the
    neighbouring temperature's value (continuation) in the scan."""
    grid = sorted(set(np.round(np.linspace(-0.9, 0.9, 13) * fc, 12)) | {0.0, float(previous)})
    traces = make_traces(group, m, measurement)
    problem = Problem(m, ["dF.value"], traces, rtol=max(opts.get("rtol", 1e-8), COARSE_RTOL), parallel=False)

    def cost(v):
        r, _ = problem.evaluate(np.array([v]))
        return math.inf if r is None else float(r @ r)

    costs = list(pool().map(cost, grid))  # the runs are independent: one per core
    # the grid is coarse (0.15 fc) against a minimum that can be narrower (a stick-slip step's size
    # changes fast with friction): a finer look around the best point, at a few plain runs' cost, saves
    # a fit that would start in a neighbouring local minimum and stay there
    best = int(np.argmin(costs))
    step = 0.15 * fc
    local = [grid[best] + f * step for f in (-2 / 3, -1 / 3, 1 / 3, 2 / 3)]
    local = [v for v in local if -0.95 * fc < v and all(abs(v - g) > 1e-3 * step for g in grid)]
    scan = sorted(zip(list(grid) + local, costs + list(pool().map(cost, local))))
    grid, costs = [v for v, _ in scan], [c for _, c in scan]
    best = int(np.argmin(costs))
    start = float(grid[best])
    if 0 < best < len(grid) - 1 and all(math.isfinite(c) for c in costs[best - 1:best + 2]):
        # the cost is near quadratic this close to its minimum: the parabola's vertex through the best
        # point and its neighbours, kept if it is better still (one more run), starts the fit closer
        (x0, x1, x2), (c0, c1, c2) = grid[best - 1:best + 2], costs[best - 1:best + 2]
        slope_left, slope_right = (c1 - c0) / (x1 - x0), (c2 - c1) / (x2 - x1)  # at the midpoints
        if slope_right > slope_left:  # where the slope, linear in between, is zero
            vertex = 0.5 * (x0 + x1) - slope_left * 0.5 * (x2 - x0) / (slope_right - slope_left)
            vertex = float(min(max(vertex, x0), x2))
            if -0.95 * fc < vertex and cost(vertex) < costs[best]:
                start = vertex
    return start, {"grid": grid, "cost": costs}


def _dF_per_temperature(groups, base, T_ref, popts, measurement, progress):
    """dF fitted at each temperature, continued outward from the reference temperature, where dF is smallest
    (zero, which every scan tries): two chains, one per core, from it downward and upward (all on one side:
    outward from it, and inward from the farthest, whose scan starts it without a neighbour). Returns
    ([(T, result)] in the groups' order, the scans)."""
    fc = base.reference_force()
    fits, scans = {}, {}
    temperature = [float(np.mean([e.temperature for e in g])) for g in groups]
    order = sorted(range(len(groups)), key=lambda i: abs(temperature[i] - T_ref))

    def fit_from(g, T, m, start):
        params = Parameters()
        # lambda = 1 + dF/fc stays positive: friction never reverses
        params.add("dF.value", start, min=-0.95 * fc, max=10.0 * fc, unit="N")
        return fit_friction(g, dataclasses.replace(m, thermal=ModelII(Const(start))), params,
                            method=f"dF at {T:.4g} C", measurement=measurement, **popts)

    def step(i, previous, first):
        g, T = groups[i], temperature[i]
        if progress:
            progress(f"Model II (direct): dF at {T:.4g} C")
        m = dataclasses.replace(base, thermal=ModelII(Const(0.0)))
        if i == order[0]:  # the base model was fitted here: dF = 0 is its optimum, no scan needed
            scans[T] = {"grid": [], "cost": [], "note": "the reference temperature: dF = 0"}
            r = fit_from(g, T, m, 0.0)
        else:
            # from the neighbouring temperature's value first (continuation): a fit that reaches the
            # data's noise there is the optimum (no other minimum can fit meaningfully better), and the
            # scan for the right minimum is needed only when it does not
            r = fit_from(g, T, m, float(previous)) if previous is not None else None
            if r is not None and r.rmse <= AT_NOISE * residual_scale(make_traces(g, m, measurement)):
                scans[T] = {"grid": [], "cost": [], "note": "the fit from the neighbouring temperature's dF "
                                                             f"({previous:.6g} N) reached the noise: no scan"}
            else:
                start, scans[T] = _dF_start(g, m, fc, 0.0 if previous is None else previous, popts, measurement)
                first_fit, r = r, fit_from(g, T, m, start)
                if first_fit is not None:
                    r.nfev += first_fit.nfev
                    r.njev += first_fit.njev
        fits[i] = (T, r)
        # the next temperature continues from this one's dF, except from the reference's (zero by
        # definition): a fit's steps start at the scale of its start value, and from zero they crawl
        return None if i == order[0] else r.parameters["dF.value"].value

    below = [i for i in order[1:] if temperature[i] < T_ref]
    above = [i for i in order[1:] if temperature[i] >= T_ref]
    if below and above:
        chains = [[order[0]] + below, above]
    else:
        side = below or above
        chains = [[order[0]] + side[:len(side) // 2], side[len(side) // 2:][::-1]]
    along_temperatures([(c, None) for c in chains], step, alone=(order, None))  # None: no neighbour yet
    return [fits[i] for i in range(len(groups))], scans


def _dF_law(per_T):
    """dF's law through the per-temperature estimates: a line, or two segments (from four temperatures), by
    AICc. Returns (law, its details)."""
    Ts = np.array([T for T, _ in per_T])
    vals = np.array([r.parameters["dF.value"].value for _, r in per_T])
    ses = np.array([r.parameters["dF.value"].stderr for _, r in per_T])
    w = 1.0 / ses if np.all(np.isfinite(ses) & (ses > 0)) else np.ones_like(ses)
    w = w / w.mean()
    candidates = {}
    A = np.column_stack([Ts, np.ones_like(Ts)]) * w[:, None]
    coef, *_ = np.linalg.lstsq(A, vals * w, rcond=None)
    lin = PWL([Ts.min(), Ts.max()], [coef[0] * Ts.min() + coef[1], coef[0] * Ts.max() + coef[1]],
              range=fit_range(Ts))
    candidates["linear"] = (lin, aicc(float(np.sum(((lin(Ts) - vals) * w) ** 2)), len(Ts), 2))
    if len(Ts) >= 4:
        tb, seg, ssr = segmented_fit(Ts, vals, w)
        candidates["two segments"] = (seg, aicc(ssr, len(Ts), 4))
    chosen = min(candidates, key=lambda k: candidates[k][1])
    return candidates[chosen][0], {
        "temperatures": Ts, "dF": vals, "stderr": ses, "chosen": chosen,
        "candidates": {k: {"aicc": a, "law": l.to_dict()} for k, (l, a) in candidates.items()}}


def _model_ii_direct(groups, experiments, base, T_ref, details, t0, refine, progress, opts, free=(), first_opts=None,
                     measurement=None, names=None):
    popts = dict(first_opts or opts)  # the per-temperature fits (first_opts: see identify_model_ii)
    popts["starts"] = 1
    per_T, scans = _dF_per_temperature(groups, base, T_ref, popts, measurement, progress)
    law, details["direct"] = _dF_law(per_T)
    model = dataclasses.replace(base, thermal=ModelII(law))
    details["direct"]["scans"] = [{"temperature": T, **scans[T]} for T in sorted(scans)]
    params = Parameters()
    for i, v in enumerate(law.values):
        params.add(f"dF.values[{i}]", float(v), unit="N")
    if not refine:
        return unrefined_result("model-ii (direct)", model, params, experiments, measurement, t0,
                                [r for _, r in per_T], "per-temperature dF and law (no joint refinement)",
                                details=details, rtol=opts.get("rtol", 1e-8))
    if progress:
        progress("Model II (direct): joint refinement of dF(T) and the base parameters on all experiments")
    model, params, traces, warns = _refinement(model, law, params, base, T_ref, free, experiments, measurement,
                                               names or default_fit_parameters(base))
    outcome = fit(model, params, traces, **dict(opts, starts=1))
    return fit_result("model-ii (direct)", model, params, outcome, traces, t0, warns, details=details)


def _refinement(model, law, params, base, T_ref, free, experiments, measurement, names):
    """What the joint refinement fits. The base parameters are refined with dF, so that dF's intervals carry
    their uncertainty. Scaling sigma0, sigma1, fc by 1/c and shifting dF by fc (1 - 1/c) leaves the scale form
    unchanged, so dF is pinned to zero at the reference temperature (its definition: the base model holds
    there). Returns (model, parameters, traces, warnings)."""
    knots = np.asarray(law.T)
    at_ref = np.flatnonzero(np.abs(knots - T_ref) <= 0.05)
    if not at_ref.size:
        return model, params, make_traces(experiments, model, measurement), [
            f"the reference temperature {T_ref:.4g} C is not a breakpoint of dF's law: the base parameters are held "
            f"at their fit there, so dF's intervals do not include their uncertainty"]
    k = int(at_ref[0])
    model = dataclasses.replace(model, thermal=ModelII(law.with_coefficients(
        [0.0 if j == k else v for j, v in enumerate(law.values)])))
    params[f"dF.values[{k}]"].value = params[f"dF.values[{k}]"].init_value = 0.0
    params[f"dF.values[{k}]"].vary = False
    for p in friction_parameters(model, list(names) + list(free), excess=True).values():
        params.add(p.name, p.value, min=p.min, unit=p.unit)
    # the breakpoint is fitted with the values: held where the per-temperature estimates put it,
    # its error would bias dF between the measured temperatures and leave it out of the intervals
    traces = make_traces(experiments, model, measurement)
    if len(knots) > 2 and all(isinstance(t.temperature, (int, float)) for t in traces) and base.heat is None:
        margin = 0.02 * (knots[-1] - knots[0])
        for k in range(1, len(knots) - 1):
            params.add(f"dF.T[{k}]", float(knots[k]), min=float(knots[k - 1] + margin),
                       max=float(knots[k + 1] - margin), unit="C")
    return model, params, traces, []


__all__ = ["identify_model_ii"]
