"""Models: laws of temperature, plants, friction models, thermal extensions, and the model with its
file (docs/models.md, docs/formats.md#model-files).

A :class:`Model` is one actuator: a plant, a friction model, an optional thermal extension, an
optional input waveform and an optional self-heating model. It loads from and saves to a model
file (TOML); ``load_model`` also takes the name of a shipped preset (``li2009-model-i``, ...).

Each friction model is described once (``models/friction/``, a module each, registered in ``FRICTION_MODELS``);
each friction parameter's domain is one rule (``models/domains.py``).
"""

from .friction import (FRICTION_MODELS, GMS, PARAMETER_UNITS, PARAMETERS, Coulomb, Dahl, ElastoPlastic, LuGre,
                       Stribeck, check_friction_values, dissipativity_violation, stribeck_curve)
from .laws import LAWS, PWL, Const, Exp, Law, Linear, Poly, Table, law_from_dict
from .load_laws import LoadLaw, LoadRangeWarning, LoadTerm
from .model import PRESETS, Model, load_model, model_from_dict, preset_path, require_actuator
from .plants import PLANTS, MassPlant, PrescribedMotion, StickSlipPlant, plant_from_dict
from .thermal import Heat, ModelI, ModelII

__all__ = ["Law", "Const", "Linear", "Exp", "Poly", "PWL", "Table", "LAWS", "law_from_dict", "StickSlipPlant",
           "MassPlant", "PrescribedMotion", "PLANTS", "plant_from_dict", "LuGre", "Coulomb", "Stribeck", "Dahl",
           "ElastoPlastic", "GMS", "FRICTION_MODELS", "check_friction_values", "stribeck_curve",
           "dissipativity_violation", "ModelI", "ModelII", "Heat", "Model", "load_model", "model_from_dict",
           "require_actuator", "preset_path", "PARAMETERS", "PARAMETER_UNITS", "PRESETS", "LoadLaw", "LoadTerm",
           "LoadRangeWarning"]
