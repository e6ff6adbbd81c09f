"""Identification: fit friction models and their thermal extensions to measured displacements.

    fit = tf.identify(data, method="model-i", init=model)
    fit.model, fit.report(), fit.to_json()
"""

from __future__ import annotations

from ..errors import InputError
from ..models import Model, load_model
from .engine import fit, make_traces, uncertainty
from .parameters import Parameter, Parameters
from .procedures import base_model, fit_friction, fit_law, identify_model_i, identify_model_ii, segmented_fit
from .result import FitResult

METHODS = ("base", "model-i", "model-ii")


def identify(data, method="model-i", init=None, *, parameters=None, procedure="direct", laws=None, refine=True,
             reference_temperature=None, rtol=1e-8, starts=8, seed=0, progress=None) -> FitResult:
    """Identifies a model from a dataset's ``fit`` experiments.

    method: "base" (one friction model for all experiments, no thermal model), "model-i" or
        "model-ii".
    init: the initial model (its plant, masses and input are kept); a model, a file or a preset
        name. Default: the paper's preset for the method.
    parameters: names (or a Parameters object) to fit for "base"; default sigma0, sigma1, fc.
    procedure: Model II's "direct" (default), "paper" or "both".
    laws: Model I law kinds per parameter, e.g. {"sigma0": "exp"}; default: chosen by AICc.
    rtol: the simulations' relative tolerance during the fit; starts: the multi-start size.
    """
    if method not in METHODS:
        raise InputError(f"unknown method '{method}' (one of: {', '.join(METHODS)})")
    if init is None:
        init = {"base": "li2009-base", "model-i": "li2009-model-i", "model-ii": "li2009-model-ii"}[method]
    if not isinstance(init, Model):
        init = load_model(init)
    experiments = getattr(data, "fit", data)
    if not experiments:
        raise InputError("the dataset has no experiment with role 'fit'")
    opts = dict(rtol=rtol, starts=starts, seed=seed)
    if method == "base":
        model = base_model(init)
        return fit_friction(experiments, model, parameters, method="base", progress=progress, **opts)
    if method == "model-i":
        if init.thermal is not None and not hasattr(init.thermal, "laws"):
            init = base_model(init)
        return identify_model_i(experiments, init, laws=laws, refine=refine, progress=progress, **opts)
    return identify_model_ii(experiments, init, procedure=procedure, reference_temperature=reference_temperature,
                             refine=refine, progress=progress, **opts)


__all__ = ["identify", "FitResult", "Parameter", "Parameters", "fit", "fit_friction", "fit_law", "segmented_fit",
           "identify_model_i", "identify_model_ii", "base_model", "make_traces", "uncertainty", "METHODS"]
