"""Advice tried before it is given: a held value the score test calls contradicted (held.py) is freed in a short refit
from the optimum, and the advice to free it is said only with the gain that refit measured ("a refit with it free
lowers the RMSE 24.8 nm -> 20.7 nm", a 2x wrong mass). A refit that gains less than MATERIAL of the misfit means the score test's direction is not
worth a parameter -- the linearization it rests on does not hold that far (a missing Stribeck effect at fs = fc
"explaining 17 % of the misfit" that a Stribeck fit then leaves where it was): the value is then not called
contradicted, and no advice is given."""

from __future__ import annotations

import copy
import dataclasses
import math

import numpy as np

from ..errors import ThermofrictionError
from ..models import ModelI
from ..fitting.optimiser import fit
from ..fitting.parameters import EXCESS, Parameters, fitted_positive, get_value, unit_of

#: the most evaluations a tried refit may take: it starts at the optimum and needs only to show the gain
TRY_EVALUATIONS = 12
#: at most this many contradicted values are tried (the most contradicted first): each costs a short fit
TRY_AT_MOST = 3


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


def tried(res, test, traces, r, rtol, stribeck_vs) -> dict | None:
    """The refit with ``test``'s held value freed: {"gain" (the share of the misfit it removes), "rmse_after" (the
    fit's RMSE times the square root of what remains), "freed", "evaluations"}, or None where it could not be run.
    ``r``: the residuals at the optimum, as the refit forms them."""
    if test["_names"] == ["fs"] and test["_columns"].shape[1] > 1:  # fs = fc: no Stribeck excess to start from
        model, names = _stribeck_start(res, test, r, stribeck_vs)
    else:
        model, names = res.model, list(test["_names"])
    try:
        params = _freed(res, names, model)
        outcome = fit(model, params, traces, rtol=rtol, starts=1, near=True, max_nfev=TRY_EVALUATIONS)
    except ThermofrictionError:
        return None
    before, after = float(r @ r), float(outcome.r @ outcome.r)
    gain = min(max(1.0 - after / max(before, 1e-300), 0.0), 1.0)
    return {"gain": gain, "rmse_after": res.rmse * math.sqrt(1.0 - gain), "freed": names,
            "evaluations": int(outcome.nfev)}


__all__ = ["tried", "TRY_EVALUATIONS", "TRY_AT_MOST"]
