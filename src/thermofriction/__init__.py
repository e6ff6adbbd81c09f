"""thermofriction: temperature-aware friction models for precision motion systems.

Simulate actuators with LuGre (and Coulomb, Stribeck, Dahl, elasto-plastic, GMS) friction and thermal
extensions (Li et al., Rev. Sci. Instrum. 80,
045104, 2009) on a compiled C core::

    import thermofriction as tf
    model = tf.load_model("li2009-model-i")
    res = tf.simulate(model, duration=2.0, temperature=35.0)
    res.time, res.displacement, res.step_sizes
"""

from ._version import __version__
from .errors import (ComputationError, ConditioningWarning, InputError, PassivityWarning, SolverError,
                     TemperatureRangeWarning, ThermofrictionError, UnitWarning)
from .models import (GMS, PARAMETERS, PRESETS, PWL, Const, Coulomb, Dahl, ElastoPlastic, Exp, Heat, Law, Linear, LuGre,
                     MassPlant, Model, ModelI, ModelII, Poly, PrescribedMotion, StickSlipPlant, Stribeck, Table,
                     load_model)
from .simulation import AutoSwitch, Dopri5, Rodas4, SimulationResult, StepSizeController, simulate
from .waveforms import Sampled, Sawtooth, Sine, Square, Step, Waveform, parse_waveform
from .identification import FitResult, Parameter, Parameters, identify
from .data import Dataset, Experiment, load_dataset, save_dataset, synthesize
from .validation import validate
from . import control, heating
from .reporting import report
from . import _renamed

_renamed.install(__name__)

#: scale-out (scale/, docs/scale.md): loaded on first use, so that Dask loads only when it is needed
_SCALE = ("sweep", "SweepResult", "identify_fleet", "FleetResult", "propagate", "PropagationResult")


def __getattr__(name):
    if name in _SCALE:
        from . import scale
        return getattr(scale, name)
    if name == "export_fmu":  # the FMU export likewise
        from .fmu import export_fmu
        return export_fmu
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "ComputationError", "ConditioningWarning", "InputError", "PassivityWarning", "SolverError", "TemperatureRangeWarning",
    "ThermofrictionError", "UnitWarning",
    "PARAMETERS", "PRESETS", "PWL", "Const", "Exp", "Law", "Linear", "Model", "ModelI", "ModelII", "Poly", "Table",
    "Heat", "load_model",
    "StickSlipPlant", "MassPlant", "PrescribedMotion",
    "LuGre", "Coulomb", "Stribeck", "Dahl", "ElastoPlastic", "GMS",
    "AutoSwitch", "Dopri5", "Rodas4", "SimulationResult", "StepSizeController", "simulate",
    "Sampled", "Sawtooth", "Sine", "Square", "Step", "Waveform", "parse_waveform",
    "FitResult", "Parameter", "Parameters", "identify",
    "Dataset", "Experiment", "load_dataset", "save_dataset", "synthesize", "validate", "report",
    *_SCALE, "export_fmu",
]

