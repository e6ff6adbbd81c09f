"""Friction models (docs/models.md#friction-models): one module per model, its parameters as dataclass fields
and its description (``Description``: name, title, the core's id, states, arrays, what measurements fit by
default), from which the model file's keys, the checks, the report's rows and the FMU's variables are derived;
the registry ``FRICTION_MODELS``; the physical checks from the one domain rule per parameter (models/domains.py);
the Stribeck curve and the dissipativity test."""

from ..._bridge import PARAMETER_UNITS, PARAMETERS
from ..domains import PARAMETER_DOMAIN, in_domain
from .base import Array, Description, friction_model
from .checks import check_friction_values
from .coulomb import Coulomb
from .curves import dissipativity_violation, stribeck_curve
from .dahl import Dahl
from .elastoplastic import ElastoPlastic
from .gms import GMS
from .lugre import LuGre
from .registry import FRICTION_MODELS
from .stribeck import Stribeck

# PARAMETERS and PARAMETER_UNITS (the one table of units: files, reports and fit results use it) come
# from the core's parameter list (friction.h, TF_PARAMETERS).

__all__ = ["PARAMETERS", "PARAMETER_UNITS", "LuGre", "Coulomb", "Stribeck", "Dahl", "ElastoPlastic", "GMS",
           "FRICTION_MODELS", "check_friction_values", "stribeck_curve", "dissipativity_violation",
           "PARAMETER_DOMAIN", "in_domain", "Description", "Array", "friction_model"]
