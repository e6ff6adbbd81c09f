"""Friction models compared on one dataset: each fitted (method base) to the fit experiments and judged by
AICc and by its error on the held-out ones."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ThermofrictionError
from ..models import FRICTION_MODELS, LuGre
from ..validation import validate
from .front import identify

#: The friction models compared by default: the static maps through a smoothed sign (their descriptions'
#: ``smoothed_sign``), then LuGre, the paper's.
COMPARED = (*(n for n, c in FRICTION_MODELS.items() if c.description.smoothed_sign), LuGre.model)


def compare_friction_models(data, kinds=COMPARED, init=None, *, offset=True, **opts) -> dict:
    """Fits each friction model of ``kinds`` (method base) to the fit experiments and predicts the held-out ones.
    ``delta_aicc`` is against the best, divided by the residuals' integrated autocorrelation time where they are
    correlated; ``rank`` by ``basis``: AICc, or the held-out RMSE where the residuals are far from white (an
    autocorrelation time above 2) and every model predicted the held-out runs. A model that fails to fit is
    reported with its reason (``failed``).

    Parameters
    ----------
    data : Dataset
        The measurements.
    kinds : sequence of str, default ``COMPARED``
        The friction models compared; default ("coulomb", "stribeck", "lugre"): the static maps through a smoothed
        sign, then LuGre.
    init : Model or str or os.PathLike, optional
        The initial model, as for ``identify``.
    offset : str or bool, default True
        Force data: the offset policy, as for ``identify``.
    **opts
        Passed on to ``identify``.

    Returns
    -------
    dict
        ``{kind: {"aicc", "delta_aicc", "rmse", "heldout_rmse", "n_parameters", "result", "rank", "basis"}}``, or
        ``{kind: {"failed": reason}}``.

    Raises
    ------
    InputError
        A dataset that cannot be validated on; a model's failure to fit is recorded, not raised.
    """
    out = {}
    held = list(getattr(data, "validate", []))
    for kind in kinds:
        try:
            res = identify(data, "base", init, friction=kind, offset=offset, **opts)
        except ThermofrictionError as e:
            out[kind] = {"failed": str(e)}
            continue
        entry = {"aicc": res.aicc, "rmse": res.rmse, "n_parameters": len(res.parameters.varying), "result": res,
                 "heldout_rmse": math.nan}
        if held:
            v = validate(res.model, data, held)
            errs = [p.rmse for p in v.predictions]
            entry["heldout_rmse"] = float(np.sqrt(np.mean(np.square(errs)))) if errs else math.nan
        out[kind] = entry
    fitted = {k: e for k, e in out.items() if "aicc" in e and math.isfinite(e["aicc"])}
    if not fitted:
        return out
    # correlated residuals carry less information than their count: the differences divided by the most general
    # fit's integrated autocorrelation time (QAIC's overdispersion); far from white, held-out error decides
    general = max(fitted.values(), key=lambda e: (e["n_parameters"], -e["aicc"]))
    c = max(general["result"].statistics.get("variance_inflation", 1.0), 1.0)
    best = min(e["aicc"] for e in fitted.values())
    by_heldout = c > 2.0 and all(math.isfinite(e["heldout_rmse"]) for e in fitted.values())
    basis = ("held-out RMSE (the residuals are correlated: c = %.3g)" % c if by_heldout else
             "AICc" + (" divided by c = %.3g, the residuals' integrated autocorrelation time" % c if c > 1.5 else ""))
    ranked = sorted(fitted, key=lambda k: fitted[k]["heldout_rmse"] if by_heldout else fitted[k]["aicc"])
    for k, e in fitted.items():
        e["delta_aicc"] = (e["aicc"] - best) / c
        e["basis"] = basis
        e["rank"] = ranked.index(k) + 1
    return out

__all__ = ["compare_friction_models", "COMPARED"]
