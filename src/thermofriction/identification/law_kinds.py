"""Model I's law kinds checked on all experiments: the per-temperature estimates choose each law's kind (linear or
exponential, by AICc), but where they are biased -- a freed end-effector mass at each temperature, with few
temperatures -- a kind they prefer by far can be the wrong one, and the joint refinement, which keeps the kinds, then
stops in a worse optimum (a random truth with an exponential sigma0 law, three temperatures, m_e freed: a linear law,
469 in chi-square worse than the exponential one, said not adequate with "try --free wn" as its advice). Where the
joint refinement's misfit exceeds the per-temperature fits' by far more than its fewer coefficients explain, each law's
other kind is tried from where the refinement stopped, and kept where it fits all experiments better."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..errors import ComputationError, InputError
from ..models import ModelI
from .laws import fit_law
from ..fitting.optimiser import fit
from ..measurements import make_traces
from ..fitting.uncertainty import inflation_of, residual_variance

#: the laws' misfit above the per-temperature fits', in chi-square less the coefficients it has fewer, beyond which
#: the other kinds are tried: this many standard deviations of that chi-square (sqrt(2 dof))
EXCESS_SIGMAS = 4.0
#: a law's other kind is taken where it fits all experiments better by at least this much in chi-square
KIND_GAIN = 4.0
OTHER_KIND = {"linear": "exp", "exp": "linear"}


@dataclasses.dataclass
class Refined:
    """The joint refinement's model, parameters, outcome and traces; the laws whose kind changed (name -> (from,
    to, chi-square gained)); the evaluations the tries took."""
    model: object
    params: object
    outcome: object
    traces: list
    switched: dict = dataclasses.field(default_factory=dict)
    nfev: int = 0
    njev: int = 0


def chi_square_unit(outcome, traces) -> float:
    """One unit of chi-square in the misfit's terms: the residuals' variance times their autocorrelation's
    inflation (on correlated residuals a difference of misfits is that much larger for the same evidence)."""
    inflation, _ = inflation_of(outcome.r, [t.n_residuals for t in traces])
    return residual_variance(outcome) * max(inflation, 1.0)


def excess_misfit(outcome, traces, per_T) -> tuple:
    """(the joint refinement's misfit above the per-temperature fits' in chi-square, less the coefficients it has
    fewer; that difference in coefficients)."""
    r = outcome.r
    dof = sum(len(res.parameters.varying) for _, res in per_T) - outcome.J.shape[1]
    return (float(r @ r) - sum(res.cost for _, res in per_T)) / chi_square_unit(outcome, traces) - dof, dof


def checked_kinds(refined: Refined, per_T, names, experiments, measurement, parameters_of, ropts, laws_details,
                  warnings) -> Refined:
    """``refined`` itself where the laws fit as the per-temperature fits do (see the module); else, best first, the
    one law of ``names`` (linear or exponential) whose other kind -- through the fitted law's values at the fit
    temperatures, the joint refinement again from there -- fits all experiments best, kept where better by
    KIND_GAIN in chi-square, and again from there while the excess remains; each change said in ``warnings`` and
    in ``laws_details`` (Model I's details["laws"]). (One law at a time in ``names``' order, each kept where better,
    stopped short: on a Stribeck truth with every law linear, sigma0 and sigma1 turned exponential, 249 and 173
    better, where fs turned linear alone would have led to the truth's kinds, 90 better still.) Model I passes no
    names where a shape constant was fitted on all experiments: its range is its profile's, made with these kinds,
    and another kind moves it along the valley such records leave it (0.4 s vs truths: coverage 88/96 -> 85/96)."""
    best = _best_kinds(refined, per_T, names, experiments, measurement, parameters_of, ropts) if names else refined
    for n, (was, now, gain) in best.switched.items():
        laws_details[n].update(chosen=now, switched_from=was)
        warnings.append(f"{n}'s law: {now}, not the {was} the per-temperature estimates preferred: it fits all "
                        f"experiments better by {gain:.3g} in chi-square")
    return best


def _best_kinds(refined, per_T, names, experiments, measurement, parameters_of, ropts) -> Refined:
    """checked_kinds' search (see there)."""
    excess, dof = excess_misfit(refined.outcome, refined.traces, per_T)
    if excess <= EXCESS_SIGMAS * math.sqrt(2.0 * max(dof, 1)):
        return refined
    Ts = np.array([T for T, _ in per_T])
    unit = chi_square_unit(refined.outcome, refined.traces)
    best, tried, spent = refined, set(), [0, 0]
    for _ in names:
        round_best = None
        for n in names:
            law = best.model.laws[n]
            if law.kind not in OTHER_KIND or (n, law.kind) in tried:
                continue
            tried.add((n, law.kind))
            trial = _with_other_kind(best, n, Ts, experiments, measurement, parameters_of, ropts, spent)
            if trial is None:
                continue
            gain = (float(best.outcome.r @ best.outcome.r) - float(trial.outcome.r @ trial.outcome.r)) / unit
            if gain >= KIND_GAIN and (round_best is None or gain > round_best[0]):
                round_best = (gain, n, law.kind, trial)
        if round_best is None:
            break
        gain, n, was, trial = round_best
        trial.switched = {**best.switched, n: (was, trial.model.laws[n].kind, gain)}
        best = trial
        if excess_misfit(best.outcome, best.traces, per_T)[0] <= EXCESS_SIGMAS * math.sqrt(2.0 * max(dof, 1)):
            break
    best.nfev, best.njev = spent
    return best


def _with_other_kind(refined, n, Ts, experiments, measurement, parameters_of, ropts, spent):
    """The joint refinement from ``refined`` with law ``n`` as its other kind (a Refined), or None where that kind
    leaves the parameter's domain or the fit fails; ``spent`` [nfev, njev] is added to."""
    law = refined.model.laws[n]
    try:
        other, _ = fit_law(Ts, law(Ts), None, (OTHER_KIND[law.kind],), parameter=n)
    except InputError:
        return None
    if other.kind != OTHER_KIND[law.kind]:  # the fallback constant: the other kind leaves the domain
        return None
    model = dataclasses.replace(refined.model, thermal=ModelI({**refined.model.laws, n: other}))
    params = parameters_of(model)
    traces = make_traces(experiments, model, measurement)
    try:
        outcome = fit(model, params, traces, near=True, **ropts)
    except (ComputationError, InputError):
        return None
    spent[0], spent[1] = spent[0] + outcome.nfev, spent[1] + outcome.njev
    return Refined(model, params, outcome, traces)


__all__ = ["checked_kinds", "excess_misfit", "chi_square_unit", "Refined", "EXCESS_SIGMAS", "KIND_GAIN"]
