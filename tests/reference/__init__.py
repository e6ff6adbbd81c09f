"""An independent reference implementation of the simulated physics, in plain Python/NumPy/SciPy.

It exists only to test the C core (tests/test_differential*.py, test_heating.py, test_control.py)
and as the plain-SciPy baseline of benchmarks/: the same equations (docs/models.md,
docs/formats.md#inputs) written out again, without calling the C core. It reads parameters from
thermofriction's model objects (attributes only) and never evaluates a law or a waveform through
them (no ``Law.__call__``/``evaluate``, no ``Waveform.__call__``/``corners``, no
``thermofriction._core``).

    waveforms   waveform_value, waveform_corners, waveform_slope          inputs
    laws        law_value, law_slope, temperature_value                   temperature laws
    friction    friction_params, stribeck_g, elastoplastic_alpha,         every friction model and the
                base_friction, thermal_friction, on_side, ripple          thermal extensions (the only copy),
                                                                          direction and position
    plants      ReferenceSystem (any plant), ReferenceModel (LuGre on     right-hand sides
                the stick-slip actuator, with the C core's (X, V, Z) scales)
    solve       friction_force, rhs, default_atol, reference_simulate,    solve_ivp, restarted at corners;
                reference_simulate_system                                 GMS switches as events
    thermal     ReferenceHeatedSystem, reference_simulate_heated          self-heating
    control     reference_closed_loop, disturbance_observer               the closed loop of control.h, its friction measurement

``import reference as R`` (tests/ on sys.path) gives all of them.
"""

from .control import disturbance_observer, reference_closed_loop
from .friction import (FrictionParams, base_friction, elastoplastic_alpha, friction_params, on_side, ripple,
                       stribeck_g, thermal_friction)
from .laws import law_slope, law_value, temperature_value
from .plants import ReferenceModel, ReferenceSystem
from .solve import (ReferenceResult, ReferenceSystemResult, default_atol, friction_force, reference_simulate,
                    reference_simulate_system, rhs)
from .thermal import ReferenceHeatedSystem, reference_simulate_heated
from .waveforms import waveform_corners, waveform_slope, waveform_value

__all__ = ["waveform_value", "waveform_corners", "waveform_slope", "law_value", "law_slope", "temperature_value",
           "FrictionParams", "friction_params", "stribeck_g", "elastoplastic_alpha", "base_friction", "on_side", "ripple",
           "thermal_friction", "ReferenceSystem", "ReferenceModel", "friction_force", "rhs", "default_atol",
           "ReferenceResult", "reference_simulate", "ReferenceSystemResult", "reference_simulate_system",
           "ReferenceHeatedSystem", "reference_simulate_heated", "reference_closed_loop", "disturbance_observer"]
