"""Identification: fit friction models and their thermal extensions to measured displacements or forces.

    fit = tf.identify(data, method="model-i", init=model)
    fit.model, fit.report(), fit.to_json()

The procedures (``procedures``, ``model_i``, ``model_ii``, ``laws``, ``law_kinds``, ``held``, ``profile``,
``plant``, ``compare``, the warm-up fit ``warm_up``, laws of temperature and load: ``load_identify``, ``load_kinds``,
``load_result``, ``load_fit``, ``load_blind``) and the front door ``front`` (docs/architecture.md#identification), over the fitting
engine (thermofriction.fitting: parameters, problem, optimiser, uncertainty) and the measurements
(thermofriction.measurements: what the residuals are, each one's initial model and completion of the result).
"""

from __future__ import annotations

from ..fitting.optimiser import fit
from ..fitting.parameters import Parameter, Parameters
from ..fitting.uncertainty import uncertainty
from ..measurements import make_traces
from ..measurements.force import force_start
from ..models.transforms import base_model, with_friction_model
from .compare import compare_friction_models
from .front import MAX_STARTS, METHODS, identify
from .laws import fit_law, segmented_fit
from .load_blind import check_load_blind
from .load_fit import fit_load_laws
from .model_i import identify_model_i
from .model_ii import identify_model_ii
from .plant import PlantFit, fit_plant, step_response
from .procedures import fit_friction, identify_heat
from .result import FitResult
from .warm_up import identify_warm_up

__all__ = ["with_friction_model", "fit_plant", "PlantFit", "step_response", "identify", "FitResult", "Parameter",
           "Parameters", "fit", "fit_friction", "fit_law", "segmented_fit", "identify_model_i", "identify_model_ii",
           "identify_heat", "base_model", "make_traces", "uncertainty", "compare_friction_models", "force_start",
           "METHODS", "MAX_STARTS", "identify_warm_up", "fit_load_laws", "check_load_blind"]
