"""Freed plant parameters profiled at the end of a joint refinement.

A plant parameter fitted with temperature laws (an end-effector mass with Model I's laws) can leave the joint
refinement stopped where a law meets the edge of its domain (a falling sigma1 law reaching zero at the range's
end): a step of the mass would need the law to cross it, and the trust region shrinks to nothing there. Held at
its value plus or minus two standard errors, the mass no longer asks for that step, and the laws find their way:
on a Stribeck truth with the mass twice the start's, both held fits reached 150-200 (in chi-square) below the
"optimum" and the refit from the better one ended at the true mass, inside its interval. So each freed plant
parameter is held at both sides once; where one is better by more than the noise could make it, the joint
refinement starts again from there.

A constant fitted on all experiments that stays undetermined (Model I's shape constants, e.g. vs) is held at both
ends of its stated range and the rest refitted (:func:`held_refits`): the shifts are the secants by which its range
reaches the other intervals (held.py)."""

from __future__ import annotations

import copy
import dataclasses

import numpy as np

from ..errors import ComputationError, InputError
from ..models import Model
from .optimiser import fit
from .parameters import with_values
from .problem import make_traces
from .uncertainty import inflation_of, uncertainty

#: [standard errors] where each freed plant parameter is held
PROFILE_STEP = 2.0
#: [chi-square, in units of the residuals' variance at the optimum] the gain a held fit must show to start the
#: refinement again: twice what a 95 % interval allows one parameter, far above what two fits of the same
#: optimum differ by (their tolerances), small against the 150-200 seen when stuck
MIN_GAIN = 8.0
#: the evaluations of each held fit: enough to leave a blocked optimum (its gain of 150-200 came in the first few)
#: and to see a flat profile's rise, at a fraction of the refinement's cost
HELD_EVALUATIONS = 10
#: the most a flat profile widens a standard error: beyond it the parameter is as good as undetermined, and the
#: two held fits say no more
MAX_WIDENING = 5.0


def _variance(outcome) -> float:
    """The residuals' variance at the optimum (sum of squares over the degrees of freedom)."""
    return float(outcome.r @ outcome.r) / max(outcome.r.size - outcome.J.shape[1], 1)


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
    variance = _variance(outcome)
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
            trial = fit(held, held_params, make_traces(experiments, held, measurement),
                        **{**once, "max_nfev": HELD_EVALUATIONS})
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


@dataclasses.dataclass
class HeldEnd:
    """A refit with a constant held at an end of its range: its fitted parameters' names and values."""
    names: list
    theta: np.ndarray


def held_refits(prof: Profiled, name: str, factor: float, experiments, measurement, parameters_of, ropts) -> list:
    """Refits with the constant ``name`` (a Parameter, e.g. "vs.value") held at its optimum value divided and
    multiplied by ``factor``, the rest (``parameters_of(model)``, which holds it) from the optimum, with 2
    HELD_EVALUATIONS each: [HeldEnd, HeldEnd], or [] where one fails."""
    names = [p.name for p in prof.params.varying]
    theta = np.asarray(prof.outcome.theta, float)
    optimum = with_values(prof.model, dict(zip(names, theta)))
    value = float(theta[names.index(name)]) if name in names else float(prof.params[name].value)
    ends = []
    for side in (1.0 / factor, factor):
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
            f"widened {factor:.2g}x, to [{par.ci95[0]:.4g}, {par.ci95[1]:.4g}]")


__all__ = ["profiled", "Profiled", "HeldEnd", "held_refits", "secant_shifts", "standard_errors", "widened",
           "PROFILE_STEP", "MIN_GAIN", "MAX_WIDENING", "HELD_EVALUATIONS"]
