"""Advice tried before it is given: a held value the score test calls contradicted (held.py) is freed in a short refit
from the optimum, and the advice to free it is said only with the gain that refit measured out of sample: on the
dataset's held-out runs, scored as the fit's generalisation is (front.py: validate, the fit's offset policy): "freeing
m_e lowers the held-out RMSE 23.16 nm -> 20.54 nm (fit runs 24.8 nm -> 20.7 nm; a refit of 12 evaluations)", a 2x
wrong mass. Where the dataset holds no run out, the gain is said as measured on the fit runs, and that it is.

A refit that gains less than MATERIAL of the misfit on the fit runs means the score test's direction is not worth a
parameter -- the linearization it rests on does not hold that far (a missing Stribeck effect at fs = fc "explaining 17
% of the misfit" that a Stribeck fit then leaves where it was). A refit whose gain does not hold out of sample (holds)
is a freed parameter absorbing another misfit of the fit runs (the demo's Model II on Model I data: fs freed removes
4.3 % of the fit runs' misfit, 1.4 % of the held-out runs'): in both cases the value is not called contradicted, and
no advice is given. Only runs held out tell a missing effect from a parameter absorbing a misfit the same in every
run. A blocked cross-validation within the fit runs was measured and dropped: it cost 4 refits of the fit and of each
value tried (the demo's Model II fit 32 s -> 92 s, a 3-run Model I fit 4.4 s -> 11.8 s) and passed the false cases it
was meant to catch (the demo's fs: 5.3 %; fs on a 2x wrong mass: 27 %)."""

from __future__ import annotations

import copy
import dataclasses
import math

import numpy as np

from ..errors import ThermofrictionError
from ..models import ModelI
from ..validation import heldout_score
from ..fitting.optimiser import fit
from ..fitting.problem import Problem
from ..fitting.parameters import EXCESS, Parameters, fitted_positive, get_value, unit_of, with_values

#: the most evaluations of a tried refit: it starts at the optimum and needs only to show the gain
TRY_EVALUATIONS = 12
#: at most this many contradicted values are tried (the most contradicted first): each costs a short fit
TRY_AT_MOST = 3
#: a held value is contradicted (held.py) only where freeing it would remove at least this fraction of the misfit
#: (linearized: the statistic over the cost in units of s^2 tau; and a refit must remove as much, on the fit runs and
#: out of sample): at 10^4-10^5 samples a right model's small misfits (a law's shape exp where the
#: truth's is linear) are significant in some held direction, and yet not what the held value is (a 2x wrong mass
#: removes ~20 %, a missing Stribeck effect fs = 1.5 fc ~3 %, a law shape ~0.2 %)
MATERIAL = 0.01
#: a value whose linearized gain (the score test's share of the misfit) is below this fraction of MATERIAL is tried by
#: a Gauss-Newton step from the optimum (halved until it agrees), its gain on the fit runs measured by an exact run (no
#: sensitivities), and kept where that gain is the linearization's within STEP_AGREES of MATERIAL: the linearization,
#: borne out there, puts the most any step could gain below MATERIAL, where the refit it replaces (refits from the
#: optimum follow the same linearization) found 0.00-0.18 % on the study's force fits. Otherwise, and for every value
#: that may be contradicted, the refit of at most TRY_EVALUATIONS.
#: A fit that is not adequate tries its held values whatever their score (held.py): on look-alike force data, delta
#: with 0.00-0.19 % of the misfit, whose 12-evaluation refits (with sensitivities) were a third of the fit's time
STEP_BELOW = 0.5
STEP_AGREES = 0.25
#: the step is halved until its exact run agrees with the linearization, at most this many runs (then the refit)
STEP_TRIES = 4
#: the basis of a try by one step (STEP_BELOW)
STEPPED = (f"fit runs only: a Gauss-Newton step from the optimum, its gain measured by an exact run as the "
           f"linearization predicts it, below {100 * MATERIAL:g} %")
#: the smallest share of its in-sample gain a refit must keep on held-out runs. Measured (truths by the reference
#: implementation, two seeds each; tests/test_advice_holds.py): a missing parameter keeps 0.65-1.17 of it (a 2x wrong
#: mass: m_e 0.65-0.70, wn 0.73-0.82; a Stribeck effect held at fc: 1.06-1.14), a parameter absorbing another misfit
#: 0.32 at most (fs on the 2x mass 0.06-0.32; Model II on Model I data: fs in the demo 0.07, 0.32 by the direct
#: procedure alone, -0.15 to -0.14 on reference runs)
HOLDS = 0.5
#: the bases of the out-of-sample score, as said and in the JSON
HELD_OUT = "held-out runs"
NO_RUN_HELD_OUT = "fit runs only: no run is held out (role validate) to check it on other runs"
#: the basis of a refit not scored out of sample, said with its gain
NOT_SCORED = "fit runs only: the runs held out could not be predicted with it"


def _freed(res, names, model) -> Parameters:
    """The fit's parameters at its optimum with ``names`` freed too (the others as they were)."""
    params = copy.deepcopy(res.parameters)
    for p in params.values():  # from the model the refit starts at (the optimum's values)
        try:
            p.value = get_value(model, p.name)
        except ThermofrictionError:
            pass
    for n in names:
        if n in params:
            params[n].vary = True
            continue
        v = get_value(model, n)
        positive = fitted_positive(n)
        params.add(n, v, min=0.0 if positive and v >= 0 else -math.inf, unit=unit_of(model, n))
    return params


def _stribeck_start(res, test, r, stribeck_vs):
    """(model, names): the fitted model with a Stribeck excess (fs a tenth above fc) at the vs of ``stribeck_vs``
    (the ones held.py tests, one column each) whose direction the residuals point along most, and the names that
    fit it."""
    cols = test["_columns"]
    scores = [abs(float(c @ r)) / max(float(np.linalg.norm(c)), 1e-300) for c in cols.T]
    vs = stribeck_vs[int(np.argmax(scores))]
    model = res.model
    if isinstance(model.thermal, ModelI) and "fc" in model.laws:
        fc_law = model.laws["fc"]
        model = dataclasses.replace(model, friction=dataclasses.replace(model.friction, fs=None, vs=vs),
                                    thermal=ModelI({**model.laws, "fs": fc_law.scaled(1.1)}))
        return model, [f"fs.{c}" for c in fc_law.coefficient_names()] + ["vs"]
    fc = model.friction.values()["fc"]
    return model.with_friction(fs=1.1 * fc, vs=vs), [EXCESS, "vs"]


def _completed(res, model, experiments, measurement):
    """``model`` with what the measurement estimates at an optimum besides the fitted parameters (a shared offset,
    a drive's inertia and delay) estimated on ``experiments``, as the fit's own result was (Measurement.complete),
    without the sensitivities its standard errors need."""
    light = dataclasses.replace(res, model=model, parameters=copy.deepcopy(res.parameters), n_points=0,
                                experiments=[dict(e) for e in res.experiments], details=dict(res.details),
                                warnings=[])
    return measurement.complete(light, experiments, res.model).model


class OutOfSample:
    """How a tried refit is scored out of sample (one per fit, shared by the values tried): on the dataset's
    held-out runs (``heldout`` of ``data``), as front.py scores the fit's generalisation (validate, the fit's offset
    policy).

    Parameters
    ----------
    res : FitResult
        The fit, completed (its model's offset as fitted).
    experiments : list of Experiment
        Its fit runs.
    measurement : Measurement
        The data's measurement, with the fit's offset policy.
    data : Dataset, optional
        The dataset, for validate.
    heldout : list of Experiment
        The held-out runs (role "validate").
    """

    def __init__(self, res, experiments, measurement, data, heldout):
        self.res, self.measurement, self.data = res, measurement, data
        self.experiments, self.heldout = list(experiments), list(heldout)
        self._before = None

    def before(self) -> float | None:
        """The fit's own RMSE on the held-out runs."""
        if self._before is None:
            self._before = self._validated(self.res.model)
        return self._before

    def after(self, model, params, theta) -> float | None:
        """The freed refit's (``theta`` of ``params``, from ``model``, on every fit run) RMSE on the held-out runs."""
        fitted = with_values(model, dict(zip([p.name for p in params.varying], theta)))
        return self._validated(_completed(self.res, fitted, self.experiments, self.measurement))

    def _validated(self, model) -> float | None:
        """The held-out RMSE as the fit's generalisation has it (validation.heldout_score); None where a run could
        not be predicted."""
        rms, v = heldout_score(model, self.data if self.data is not None else self.heldout, self.heldout,
                               self.measurement)
        return rms if len(v.predictions) == len(self.heldout) else None



def tried(res, test, traces, r, rtol, stribeck_vs, outside=None) -> dict | None:
    """The refit with ``test``'s held value freed: {"gain" (the share of the misfit it removes on the fit runs),
    "rmse_after" (the fit's RMSE times the square root of what remains), "freed", "evaluations", "basis", and out
    of sample (``outside``, an OutOfSample; where the in-sample gain is at least MATERIAL) "heldout_before",
    "heldout_after", "heldout_gain"} (:func:`holds` says whether the gain is worth the parameter), or None where it
    could not be run. ``r``: the residuals at the optimum, as the refit forms them."""
    if test["_names"] == ["fs"] and test["_columns"].shape[1] > 1:  # fs = fc: no Stribeck excess to start from
        model, names = _stribeck_start(res, test, r, stribeck_vs)
    elif test.get("misfit_share", math.inf) < STEP_BELOW * MATERIAL:
        stepped = _stepped(res, test, traces, r, rtol)
        if stepped is not None:
            return stepped
        model, names = res.model, list(test["_names"])
    else:
        model, names = res.model, list(test["_names"])
    try:
        params = _freed(res, names, model)
        outcome = fit(model, params, traces, rtol=rtol, starts=1, near=True, max_nfev=TRY_EVALUATIONS)
    except ThermofrictionError:
        return None
    before, after = float(r @ r), float(outcome.r @ outcome.r)
    gain = min(max(1.0 - after / max(before, 1e-300), 0.0), 1.0)
    out = {"gain": gain, "rmse_after": res.rmse * math.sqrt(1.0 - gain), "freed": names,
           "evaluations": int(outcome.nfev), "basis": f"fit runs only: it gains less than {100 * MATERIAL:g} % there"}
    if gain >= MATERIAL:
        out.update(_out_of_sample(model, params, outcome, outside) if outside is not None else
                   {"basis": NO_RUN_HELD_OUT})
    return out


def _stepped(res, test, traces, r, rtol) -> dict | None:
    """The try of a held value whose linearized gain is small (STEP_BELOW): the Gauss-Newton step from the optimum on
    the fitted and freed columns at the optimum (``test``'s, which the score test used), in the fitted coordinates
    (a positive parameter's log) and shortened to move none of those by more than a factor e, its residuals on the
    fit runs from one exact run. The trial (as :func:`tried`'s, one evaluation) where the gain so measured is the
    linearization's within STEP_AGREES of MATERIAL; None (the refit decides) where it is not, or the step leaves a
    parameter's bounds or cannot be run."""
    names = list(test["_names"])
    params = _freed(res, names, res.model)
    order = [p.name for p in res.parameters.varying] + names
    if [p.name for p in params.varying] != order or not float(r @ r) > 0:  # (a freed name among the fitted ones)
        return None
    theta = np.array([p.value for p in params.varying], float)
    logs = np.array([p.positive for p in params.varying], bool)
    A = np.column_stack([test["_J"], test["_columns"]]) * np.where(logs, theta, 1.0)  # d r / d phi
    if not np.all(np.isfinite(A)):
        return None
    step = np.linalg.lstsq(A, -r, rcond=None)[0]
    share = float(np.sum((A @ step) ** 2)) / float(r @ r)  # the linearization's gain of the whole step
    alpha = min(1.0, 1.0 / max(float(np.max(np.abs(step[logs]), initial=0.0)), 1e-300))
    problem = Problem(res.model, order, traces, rtol=rtol, parallel=len(traces) > 1)
    for tries in range(1, STEP_TRIES + 1):  # halved until the exact run bears the linearization out
        predicted = (2.0 * alpha - alpha * alpha) * share  # |r + a A s|^2 = |r|^2 - (2a - a^2)|A s|^2
        gain = _gain_at(problem, params, np.where(logs, theta * np.exp(alpha * step), theta + alpha * step), r)
        if gain is None:
            return None
        if abs(gain - predicted) <= STEP_AGREES * MATERIAL:
            break
        alpha /= 2.0
    else:
        return None
    if not gain < MATERIAL:
        return None
    gain = min(max(gain, 0.0), 1.0)
    return {"gain": gain, "rmse_after": res.rmse * math.sqrt(1.0 - gain), "freed": names, "evaluations": tries,
            "basis": STEPPED, "stepped": True, "linearized": share}


def _gain_at(problem, params, theta, r) -> float | None:
    """The share of ``r``'s sum of squares that ``problem``'s residuals at ``theta`` remove (one exact run, no
    sensitivities); None where ``theta`` is outside ``params``' bounds or cannot be run."""
    for p, v in zip(params.varying, theta):
        if not (p.min <= v <= p.max and (v > 0 or not p.positive)):
            return None
    try:
        after, _ = problem.evaluate(theta)
    except ThermofrictionError:
        return None
    if after is None or after.shape != r.shape:
        return None
    return 1.0 - float(after @ after) / float(r @ r)


def _out_of_sample(model, params, outcome, outside) -> dict:
    """The tried refit scored out of sample (OutOfSample)."""
    try:
        before, after = outside.before(), outside.after(model, params, outcome.theta)
    except ThermofrictionError:
        return {"basis": NOT_SCORED}
    if before is None or after is None or not before > 0:
        return {"basis": NOT_SCORED}
    return {"basis": HELD_OUT, "heldout_before": before, "heldout_after": after,
            "heldout_gain": 1.0 - (after / before) ** 2}


def holds(trial) -> bool:
    """Whether a tried refit's gain is worth the parameter: at least MATERIAL of the misfit on the fit runs, and where
    it was scored out of sample, at least MATERIAL of the misfit there and, on held-out runs (scored against the fit
    itself, not a refit), HOLDS of the in-sample gain.

    Parameters
    ----------
    trial : dict or None
        A tried refit (:func:`tried`).

    Returns
    -------
    bool
        Whether the advice to free it may be given.
    """
    if trial is None or trial["gain"] < MATERIAL:
        return False
    if "heldout_gain" not in trial:
        return True
    return trial["heldout_gain"] >= max(MATERIAL, HOLDS * trial["gain"])


__all__ = ["tried", "holds", "OutOfSample", "TRY_EVALUATIONS", "TRY_AT_MOST", "MATERIAL", "HOLDS", "HELD_OUT",
           "STEPPED",
           "NO_RUN_HELD_OUT"]
