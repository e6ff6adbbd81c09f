"""Friction models compared on one dataset: each fitted (method base) to the fit experiments and judged by
AICc and by its error on the held-out ones."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ThermofrictionError
from ..validate import validate
from .front import identify


def compare_friction_models(data, kinds=("coulomb", "stribeck", "lugre"), init=None, *, offset=True, **opts) -> dict:
    """Fits each friction model of ``kinds`` (method base) to the fit experiments and predicts the held-out ones:
    ``{kind: {"aicc", "delta_aicc", "rmse", "heldout_rmse", "n_parameters", "result"}}``, delta_aicc against
    the best. A model that fails to fit is reported with its reason (``failed``)."""
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
    fitted = [e["aicc"] for e in out.values() if "aicc" in e and math.isfinite(e["aicc"])]
    best = min(fitted) if fitted else math.nan
    for e in out.values():
        if "aicc" in e:
            e["delta_aicc"] = e["aicc"] - best
    return out


__all__ = ["compare_friction_models"]
