"""Identification: fit friction models and their thermal extensions to measured displacements or forces.

    fit = tf.identify(data, method="model-i", init=model)
    fit.model, fit.report(), fit.to_json()

Layers, each importing only those below it (docs/architecture.md#identification): ``parameters``; ``problem``
(traces and residuals, formed by the data's measurement, thermofriction.measurements); ``optimiser``;
``uncertainty``; the procedures (``procedures``, ``model_i``, ``model_ii``, ``start``, ``laws``, ``plant``,
``setup``, ``compare``) and the front door ``front``.
"""

from __future__ import annotations

from .compare import compare_friction_models
from .front import MAX_STARTS, METHODS, identify
from .laws import fit_law, segmented_fit
from .model_i import identify_model_i
from .model_ii import identify_model_ii
from .optimiser import fit
from .parameters import Parameter, Parameters
from .plant import PlantFit, fit_plant, step_response
from .problem import make_traces
from .procedures import base_model, fit_friction, identify_heat
from .result import FitResult
from .start import force_start, with_friction_model
from .uncertainty import uncertainty

__all__ = ["with_friction_model", "fit_plant", "PlantFit", "step_response", "identify", "FitResult", "Parameter",
           "Parameters", "fit", "fit_friction", "fit_law", "segmented_fit", "identify_model_i", "identify_model_ii",
           "identify_heat", "base_model", "make_traces", "uncertainty", "compare_friction_models", "force_start",
           "METHODS", "MAX_STARTS"]
