"""Freed plant parameters profiled at the end of a joint refinement.

A plant parameter fitted with temperature laws (an end-effector mass with Model I's laws) can leave the joint
refinement stopped where a law meets the edge of its domain (a falling sigma1 law reaching zero at the range's
end): a step of the mass would need the law to cross it, and the trust region shrinks to nothing there. Held at
its value plus or minus two standard errors, the mass no longer asks for that step, and the laws find their way:
on a Stribeck truth with the mass twice the start's, both held fits reached 150-200 (in chi-square) below the
"optimum" and the refit from the better one ended at the true mass, inside its interval. So each freed plant
parameter is held at both sides once; where one is better by more than the noise could make it, the joint
refinement starts again from there.

A shape constant fitted on all experiments (Model I's vs, where no single temperature determines it) has its range
from a profile of the per-temperature fits over it (:func:`profile_range`; a stated factor where it has none): it
is held where the joint refinement left it, at both ends of that range the rest is refitted (:func:`held_refits`),
and the shifts are the secants by which its range reaches the other intervals (held.py)."""

from __future__ import annotations

import copy
import dataclasses
import math

import numpy as np

from ..errors import ComputationError, InputError
from ..models import Model
from .held import PRIOR_FACTOR
from ..fitting.optimiser import COARSE_RTOL, fit
from ..fitting.parameters import with_values
from ..fitting.problem import Problem
from ..measurements import make_traces
from ..fitting.uncertainty import inflation_of, residual_variance, uncertainty

#: [standard errors] where each freed plant parameter is held
PROFILE_STEP = 2.0
#: [chi-square, in units of the residuals' variance at the optimum] the gain a held fit must show to start the
#: refinement again: twice what a 95 % interval allows one parameter, far above what two fits of the same
#: optimum differ by (their tolerances), small against the 150-200 seen when stuck
MIN_GAIN = 8.0
#: the evaluations of each held fit: enough to leave a blocked optimum (its gain of 150-200 came in the first few)
#: and to see a flat profile's rise, at a fraction of the refinement's cost
HELD_EVALUATIONS = 10
#: [in its log] the most the conditional step moves a positive parameter (a factor e): where the profile is
#: quadratic the held fit starts at its own optimum, and an unlucky linearization cannot throw a start far off
LOG_CLIP = 1.0
#: [in its log] where LOG_CLIP binds, the wider clip of another start tried (a factor e^4 = 55): along seed 8's
#: profile (benchmarks/study_cost.py, free-me) sigma1's poorly determined law moved its coefficient from 12.2 to
#: 1.2 and 187, the linearization said 0.66 and 225, and the starts clipped at a factor e were 12,607 and 361 in
#: chi-square above the optimum (33 and 35 clipped at e^4)
WIDE_LOG_CLIP = 4.0
#: the most a flat profile widens a standard error: beyond it the parameter is as good as undetermined, and the
#: two held fits say no more
MAX_WIDENING = 5.0


def standard_errors(params, outcome, traces, model) -> dict:
    """The standard errors the fit reports (uncertainty.py, on a copy of ``params``: the same variance,
    autocorrelation inflation and undetermined directions)."""
    copied = copy.deepcopy(params)
    uncertainty(copied, outcome, traces, model)
    return {p.name: p.stderr for p in copied.varying}


@dataclasses.dataclass
class Profiled:
    """What ``fit`` was given and returned, or the refinement started again from a better held fit; the
    evaluations spent; and per profiled parameter the factor its standard error takes where the profile is
    flatter than the linearization says (1 where it is not; only when the optimum stayed)."""
    model: Model
    params: object
    outcome: object
    traces: list
    nfev: int = 0
    njev: int = 0
    widen: dict = dataclasses.field(default_factory=dict)


def profiled(model: Model, params, outcome, traces, experiments, measurement, free, parameters_of, ropts):
    """Each freed plant parameter of ``free`` held at PROFILE_STEP standard errors either side of the joint
    refinement's optimum, the laws refitted (``parameters_of(model, free)`` makes the refinement's
    Parameters): where a held fit is better by MIN_GAIN, the refinement starts again from it; else the rise of
    the cost there, against the PROFILE_STEP**2 a quadratic profile gives, widens the parameter's standard
    error (a flat valley the Jacobian at the optimum does not show)."""
    once = {**ropts, "near": True, "starts": 1}
    names = [p.name for p in params.varying]
    optimum = with_values(model, dict(zip(names, outcome.theta)))
    variance = residual_variance(outcome)
    inflation, _ = inflation_of(outcome.r, [tr.n_residuals for tr in traces])
    errors = standard_errors(params, outcome, traces, model)
    cost = float(outcome.r @ outcome.r) / variance  # chi-square
    out = Profiled(model, params, outcome, traces)
    best, rises = None, {}
    for name in (n for n in free if n in names):
        se = errors[name]
        value = float(outcome.theta[names.index(name)])
        if not np.isfinite(se) or se <= 0 or value - PROFILE_STEP * se <= 0:
            continue
        others = [f for f in free if f != name]
        for side in (-PROFILE_STEP, PROFILE_STEP):
            held = with_values(optimum, {name: value + side * se})
            held_params = parameters_of(held, others)
            shift = conditional_step(outcome, names, name, side * se, held_params)
            wide = conditional_step(outcome, names, name, side * se, held_params, WIDE_LOG_CLIP)
            if wide != shift:  # the clip binds: the cheapest of three starts (each one run without sensitivities)
                shift, spent = cheapest_start(held, [shift, wide, {}], experiments, measurement,
                                              ropts.get("rtol", 1e-8))
                out.nfev += spent
            held, held_params, trial = _held_fit(held, shift, lambda m: parameters_of(m, others), experiments,
                                                 measurement, {**once, "max_nfev": HELD_EVALUATIONS})
            out.nfev, out.njev = out.nfev + trial.nfev, out.njev + trial.njev
            trial_cost = float(trial.r @ trial.r) / variance
            rises[name] = min(rises.get(name, np.inf), (trial_cost - cost) / inflation)
            if trial_cost < cost - MIN_GAIN and (best is None or trial_cost < best[0]):
                best = (trial_cost, with_values(held, dict(zip([p.name for p in held_params.varying], trial.theta))))
    out.widen = {n: float(min(MAX_WIDENING, max(1.0, PROFILE_STEP / np.sqrt(max(rise, 1e-12)))))
                 for n, rise in rises.items()}  # as long as the optimum stays
    if best is None:
        return out
    start = best[1]
    again_params = parameters_of(start, free)
    again_traces = make_traces(experiments, start, measurement)
    again = fit(start, again_params, again_traces, **once)
    out.nfev, out.njev = out.nfev + again.nfev, out.njev + again.njev
    if float(again.r @ again.r) / variance < cost:
        out.model, out.params, out.outcome, out.traces, out.widen = start, again_params, again, again_traces, {}
    return out


def conditional_step(outcome, names, name, step, held_params, clip=LOG_CLIP) -> dict:
    """The other fitted values where the linearization at the optimum (``outcome``: its theta and Jacobian, columns
    in ``names``) puts them with ``name`` moved by ``step``: the least-squares shift -J_o^+ J_m step, a positive
    parameter's by its log (it stays positive; the same to first order). A held fit from there starts at its own
    optimum where the profile is quadratic, and stops after one evaluation (the Gauss-Newton step below SMALL_STEP
    standard errors) instead of walking the conditional valley from the optimum in three; where the profile is not
    quadratic it goes on from there. Only the parameters ``held_params`` fits are moved, a positive one by at most
    ``clip`` in its log.

    Parameters
    ----------
    outcome : FitOutcome
        The joint refinement's optimum: its ``theta`` and Jacobian ``J`` (columns in ``names``).
    names : list of str
        The fitted parameters' names, in ``theta``'s order.
    name : str
        The parameter that is held, moved by ``step``.
    step : float
        How far ``name`` is moved [its unit].
    held_params : Parameters
        The held fit's parameters (which are fitted, which are positive, their bounds).
    clip : float, default LOG_CLIP
        The most a positive parameter's log is moved (a factor e**clip either way).

    Returns
    -------
    dict
        {name: value} of the moved parameters; empty where the linearization gives none.
    """
    theta = np.asarray(outcome.theta, float)
    J = np.asarray(outcome.J, float)
    moved = [i for i, n in enumerate(names) if n != name and n in held_params and held_params[n].vary]
    if not moved or J.ndim != 2 or J.shape[1] != len(names):
        return {}
    Jo = J[:, moved]
    scale = np.linalg.norm(Jo, axis=0)
    scale[scale == 0] = 1.0
    shift = -np.linalg.lstsq(Jo / scale, J[:, names.index(name)] * step, rcond=None)[0] / scale
    out = {}
    for i, d in zip(moved, shift):
        v = theta[i]
        if not np.isfinite(d):
            return {}
        p = held_params[names[i]]
        out[names[i]] = float(v * math.exp(np.clip(d / v, -clip, clip))) if p.positive and v > 0 \
            else float(np.clip(v + d, p.min, p.max))
    return out


def cheapest_start(held, shifts, experiments, measurement, rtol) -> tuple:
    """The shift of ``shifts`` (each {name: value} for :func:`_held_fit`; {} for ``held`` itself) whose start fits
    the experiments best, by its residuals alone (one run of each experiment without sensitivities, at the
    tolerance of a fit's first stage at least: the starts differ by far more than its integration error), and the
    evaluations spent. A start that cannot be simulated is not taken; of equal ones the first; where none can be
    simulated, the first (its held fit starts from ``held`` as before).

    Parameters
    ----------
    held : Model
        The optimum's model with the profiled parameter held.
    shifts : list of dict
        The candidate starts' values, moved from ``held``.
    experiments : list of Experiment
        The experiments the held fit fits.
    measurement : Measurement or None
        How its residuals are formed (None: the experiments' own).
    rtol : float
        The held fit's relative tolerance.

    Returns
    -------
    tuple
        (the chosen shift, the number of evaluations made).
    """
    traces = make_traces(experiments, held, measurement)
    best, spent = (math.inf, shifts[0]), 0
    for shift in shifts:
        try:
            start = with_values(held, shift)
        except InputError:
            continue
        if start.unphysical_over_range():
            continue
        problem = Problem(start, [], traces, rtol=max(rtol, COARSE_RTOL), parallel=len(traces) > 1)
        try:
            r, _ = problem.evaluate(np.array([]))
        except ComputationError:
            r = None
        spent += problem.nfev
        if r is not None and np.all(np.isfinite(r)) and float(r @ r) < best[0]:
            best = (float(r @ r), shift)
    return best[1], spent


def _held_fit(held, shift, parameters_of, experiments, measurement, opts):
    """(start, its Parameters, the fit's outcome) of a held fit from ``held`` with the others moved by ``shift``
    (:func:`conditional_step`), or from ``held`` itself where that start cannot be simulated (a linear law moved
    through zero, fs below fc) or its fit fails there."""
    if shift:
        try:
            start = with_values(held, shift)
            if not start.unphysical_over_range():
                params = parameters_of(start)
                return start, params, fit(start, params, make_traces(experiments, start, measurement), **opts)
        except (InputError, ComputationError):
            pass
    params = parameters_of(held)
    return held, params, fit(held, params, make_traces(experiments, held, measurement), **opts)


@dataclasses.dataclass
class HeldEnd:
    """A refit with a constant held at an end of its range: its fitted parameters' names and values."""
    names: list
    theta: np.ndarray


def held_refits(prof: Profiled, name: str, factors, experiments, measurement, parameters_of, ropts) -> list:
    """Refits with the constant ``name`` (a Parameter, e.g. "vs.value") held at its optimum value times each of
    ``factors`` (the two ends of its range), the rest (``parameters_of(model)``, which holds it) from the optimum,
    with 2 HELD_EVALUATIONS each: [HeldEnd, HeldEnd], or [] where one fails."""
    names = [p.name for p in prof.params.varying]
    theta = np.asarray(prof.outcome.theta, float)
    optimum = with_values(prof.model, dict(zip(names, theta)))
    value = float(theta[names.index(name)]) if name in names else float(prof.params[name].value)
    ends = []
    for side in factors:
        held = with_values(optimum, {name: value * side})
        params = parameters_of(held)
        try:
            trial = fit(held, params, make_traces(experiments, held, measurement),
                        **{**ropts, "near": True, "starts": 1, "max_nfev": 2 * HELD_EVALUATIONS})
        except (InputError, ComputationError):
            return []
        prof.nfev, prof.njev = prof.nfev + trial.nfev, prof.njev + trial.njev
        if not np.all(np.isfinite(trial.theta)):
            return []
        ends.append(HeldEnd([p.name for p in params.varying], np.asarray(trial.theta, float)))
    return ends


def secant_shifts(prof: Profiled, ends) -> list:
    """The shifts of ``prof``'s fitted parameters to each of ``ends`` (refits with a constant held at the ends of
    its stated range): the secants that replace its linearized sensitivities where the misfit is far from quadratic
    in it (a Stribeck velocity: the fitted fs moved 12 % where the linearization at the optimum gave 3 %). [] where
    the ends do not fit the same parameters."""
    names = [p.name for p in prof.params.varying]
    if len(ends) != 2 or any(e.names != names for e in ends):
        return []
    return [e.theta - np.asarray(prof.outcome.theta, float) for e in ends]


#: [relative standard error] above which a constant fitted on all experiments together counts as undetermined: its
#: 95 % interval would reach from near zero to twice its value, where the misfit is far from quadratic in it and a
#: linearized interval of the others says nothing (a Stribeck velocity 2.3x off fitted as well as the truth)
OPEN_CONSTANT = 0.5


def open_constants(prof: Profiled, joint, errors, ranged=()) -> tuple:
    """The constants of ``joint`` the joint refinement left undetermined (standard error above OPEN_CONSTANT of
    their value), and those of ``ranged`` (whose range the data leave them is known from a profile: a linearized
    interval would replace it with less), taken out of ``prof``'s fitted parameters (held at the value reached: the
    optimum is the same) so that their range reaches the others' intervals as a held law's stated range does
    (held.py). ``errors``: the standard errors at the optimum (:func:`standard_errors`). Returns (taken out, of
    which undetermined)."""
    names = [p.name for p in prof.params.varying]
    value = dict(zip(names, np.asarray(prof.outcome.theta, float)))
    undetermined = [n for n in joint if f"{n}.value" in names and not (np.isfinite(errors[f"{n}.value"]) and errors[
        f"{n}.value"] < OPEN_CONSTANT * abs(value[f"{n}.value"]))]
    open_ = [n for n in joint if n in undetermined or n in ranged and f"{n}.value" in names]
    keep = np.array([name not in {f"{n}.value" for n in open_} for name in names])
    if keep.all():
        return [], []
    for n in open_:  # held where the refinement left it (a held parameter's value is not read from theta)
        prof.params[f"{n}.value"].value = value[f"{n}.value"]
        prof.params[f"{n}.value"].vary = False
    o = prof.outcome
    at_bound = [a for a, k in zip(o.at_bound, keep) if k] if len(o.at_bound) == len(keep) else o.at_bound
    bounds = tuple(np.asarray(b)[keep] for b in o.bounds) if len(o.bounds) == 2 else o.bounds
    prof.outcome = dataclasses.replace(o, theta=np.asarray(o.theta)[keep], J=o.J[:, keep], at_bound=at_bound,
                                       bounds=bounds)
    return open_, undetermined


def settled_constants(prof: Profiled, joint, region, parameters_of, experiments, measurement, ropts):
    """The constants fitted on all experiments (``joint``) after the joint refinement: those still undetermined are
    held where reached, and refits with them held at the ends of the range the data leave them (``region``, from
    profiled_constant; else a factor PRIOR_FACTOR either way) give the secants of their effect on the others
    (held.py); a constant whose profile range is known is held so too, determined or not. Returns (held where
    reached, of which undetermined, {name: secant shifts}, {name: {value, low, high, from}}). Tried and not kept
    (before the profile): starting the refinement again from a better end (as for a freed mass, :func:`profiled`)
    -- on the 0.4 s vs truths of tests/coverage_study.py it moved 2 of 6 fits further along the flat valley (fs
    31-38 % off), coverage 75/96 against 86/96 without it."""
    names = [p.name for p in prof.params.varying]
    value_of = {n: float(prof.outcome.theta[names.index(f"{n}.value")]) for n in joint if f"{n}.value" in names}
    errors = standard_errors(prof.params, prof.outcome, prof.traces, prof.model)
    # a profile's range is used where the value reached lies inside it (else the profile saw another valley)
    ranged = [n for n in joint if region and len(joint) == 1 and n in value_of
              and region[0] < value_of[n] < region[1]]
    kept_open, undetermined = open_constants(prof, joint, errors, ranged)
    secants, ranges = {}, {}
    for n in kept_open:
        value = float(prof.params[f"{n}.value"].value)
        if n in ranged:
            # the range the data leave it: the profile's, widened to the linearized interval where that is wider
            # (the profile's points are per-temperature fits, each local and from its neighbour's values)
            se = errors.get(f"{n}.value", math.inf)
            spread = math.exp(min(1.959964 * se / value, 700.0)) if math.isfinite(se) else PRIOR_FACTOR
            factors = (min(region[0] / value, 1.0 / spread), max(region[1] / value, spread))
        else:  # the stated factor: the data say nothing
            factors = (1.0 / PRIOR_FACTOR, PRIOR_FACTOR)
        ranges[n] = {"value": value, "low": value * factors[0], "high": value * factors[1],
                     "from": "profile" if n in ranged else "stated factor"}
        ends = held_refits(prof, f"{n}.value", factors, experiments, measurement,
                           lambda m: parameters_of(m, kept_open), ropts)
        secants[n] = [list(map(float, d)) for d in secant_shifts(prof, ends)]
    return kept_open, undetermined, secants, ranges


#: the 1-D search of a constant fitted on all experiments (profiled_constant): within this factor of the start (the
#: 2-3x a rough start is off, and more), to this tolerance in its log, in at most this many points
PROFILE_RANGE = 10.0
PROFILE_XTOL = 0.05
PROFILE_POINTS = 12
CHI2_95 = 3.841  # the 95 % quantile of chi-square with one degree of freedom
#: the range the data leave the constant is found in steps of this (in its log: x1.6) from the minimum, at most
#: this many a side (then the range is taken to end at the last step: at least that wide)
PROFILE_STEP_OUT = 0.47
PROFILE_OUTWARD = 4
#: the evaluations of each temperature's fit at a point of the search (from the fit at the nearest point tried)
PROFILE_FIT_EVALUATIONS = 20


def profile_range(tried, best, cost) -> tuple:
    """(low, high) in the log of the profiled constant: where the per-temperature fits' summed misfit (``tried``:
    log value -> (misfit, fits); ``cost`` adds a point) has risen from its least (at ``best``) by 3.84 in
    chi-square (95 %, one parameter; in the best fits' residual variance times their autocorrelation's
    inflation), stepped out from the least (the search's own points cluster there), the crossing interpolated;
    at the last step where PROFILE_OUTWARD steps do not reach it."""
    fits = tried[best][1]
    n = sum(f.n_points for f in fits)
    unit = tried[best][0] / max(n - sum(len(f.parameters.varying) for f in fits), 1)
    unit *= CHI2_95 * max(f.statistics.get("variance_inflation", 1.0) for f in fits)
    ends = []
    for direction in (-1.0, 1.0):
        x, end = best, None
        for _ in range(PROFILE_OUTWARD):
            nxt = float(np.clip(x + direction * PROFILE_STEP_OUT, -math.log(PROFILE_RANGE), math.log(PROFILE_RANGE)))
            if nxt == x:
                break
            rise = (cost(nxt) - tried[best][0]) / unit
            if rise > 1.0:
                inner = (tried[x][0] - tried[best][0]) / unit
                end = x + (nxt - x) * (1.0 - inner) / max(rise - inner, 1e-12)
                break
            x = nxt
        ends.append(x if end is None else end)
    return tuple(ends)


def widened(result, factors: dict) -> None:
    """Widens ``result``'s standard error and 95 % interval of each parameter in ``factors`` (name -> factor
    from :func:`profiled`) where the factor is above 1, and says so in its warnings and details."""
    for name, factor in factors.items():
        par = result.parameters[name]
        if factor <= 1.0 or not np.isfinite(par.stderr) or par.stderr <= 0 or getattr(par, "at_bound", None):
            continue
        lo, hi = par.ci95
        par.stderr *= factor
        par.ci95 = (max(par.value - (par.value - lo) * factor, 0.0), par.value + (hi - par.value) * factor)
        result.details.setdefault("profiled", {})[name] = factor
        result.warnings.append(
            f"'{name}': the fit changes less away from {par.value:.4g} than the Jacobian at the optimum says (held at "
            f"{PROFILE_STEP:g} standard errors either side, the laws refitted): its standard error and interval "
            f"widened {factor:.3g}x, to [{par.ci95[0]:.4g}, {par.ci95[1]:.4g}]")


def fs_kept_above_fc(now: dict, changes: dict, free) -> dict:
    """``changes`` to friction values ``now``, kept inside fs >= fc (the model's rule) where a new fc or fs (a
    start restarted, a profiled constant's trial value) would cross the other.

    Parameters
    ----------
    now : dict
        The friction's values the changes apply to.
    changes : dict
        The new values (name -> value).
    free : collection of str
        The names the fit moves (not held).

    Returns
    -------
    dict
        ``changes``, with the other of fc and fs added, where it is free, moved to keep the excess fs - fc it had.

    Raises
    ------
    ComputationError
        The crossing one's partner is held: the trial is outside the model's domain (no cost).
    """
    fc, fs = changes.get("fc", now.get("fc")), changes.get("fs", now.get("fs"))
    if fs is None or fc is None or fs >= fc or ("fc" in changes) == ("fs" in changes):
        return changes
    excess = max(now["fs"] - now["fc"], 0.0)
    moved = "fs" if "fc" in changes else "fc"
    if moved not in free:
        raise ComputationError(f"fs {fs:.6g} below fc {fc:.6g} with {moved} held: outside the model's domain")
    return {**changes, moved: fc + excess if moved == "fs" else (fs - excess if fs - excess > 0 else fs)}


__all__ = ["fs_kept_above_fc", "profiled", "Profiled", "profile_range", "PROFILE_RANGE", "PROFILE_XTOL", "PROFILE_POINTS",
           "PROFILE_FIT_EVALUATIONS", "CHI2_95", "HeldEnd", "held_refits", "secant_shifts", "standard_errors", "widened",
           "open_constants", "settled_constants", "OPEN_CONSTANT",
           "PROFILE_STEP", "MIN_GAIN", "MAX_WIDENING", "HELD_EVALUATIONS", "cheapest_start",
           "LOG_CLIP", "WIDE_LOG_CLIP"]
