"""One small case of every registered kind, for the conformance suites (tests/test_conformance_*.py).

The suites are parametrized over the package's registries -- ``thermofriction.measurements.REGISTRY``,
``thermofriction.models.FRICTION_MODELS`` and the subclasses of ``thermofriction.results.Result`` -- so that a new
kind is tested by being registered. What a suite cannot derive from the registry is here, one entry per kind:

- ``MEASUREMENT_CASES``: a model and a few short experiments the measurement recognises, and the attribute that
  holds their record;
- ``FRICTION_CASES``: an instance of each friction model with every parameter it takes given (direction-dependent
  levels and the position ripple included), and ``DOMAINS``, each parameter's domain as the documentation states
  it (docs/models.md#friction-models and the classes' docstrings), written here independently of the package's own
  checks;
- ``RESULT_CASES``: how to make one small instance of each result class.

A kind registered without its case here fails its suite with a message that says to add one (``case_of``).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import tomli_w

import thermofriction as tf


def case_of(cases: dict, name: str, what: str):
    """The case of registered kind ``name``, or a failure saying where to add it."""
    if name not in cases:
        pytest.fail(f"{what} {name!r} is registered but has no case in tests/conformance_cases.py: add one there "
                    f"(the conformance suites then test it)")
    return cases[name]


def problem_api():
    """(Problem, its module): the fitting engine's problem, wherever the package keeps it (issue 39 moves it from
    identification/ to fitting/)."""
    try:
        from thermofriction.fitting import problem as module
    except ImportError:
        from thermofriction.identification import problem as module
    return module.Problem


# -- measurements ------------------------------------------------------------------------------------------------

#: a joint's LuGre friction (N m, rad/s), the command tests' (tests/test_identify_command.py) levels
JOINT_LUGRE = dict(sigma0=60.0, sigma1=0.04, fc=0.2, fs=0.28, vs=0.3, sigma2=0.02)


def _two_sines(t, k):
    """Position and velocity of the k-th run's motion: two sines summed (a velocity sweep with reversals)."""
    (a1, f1), (a2, f2) = ((0.5, 0.5), (0.1, 2.3)) if k == 0 else ((0.4, 0.7), (0.08, 3.1))
    w1, w2 = 2 * math.pi * f1, 2 * math.pi * f2
    return (a1 * np.sin(w1 * t) + a2 * np.sin(w2 * t), a1 * w1 * np.cos(w1 * t) + a2 * w2 * np.cos(w2 * t))


def _joint_dataset(folder: Path, column: str, samples: int, dt: float = 1e-3):
    """Two runs of a joint under two-sine motions, read back through the package's reader (data/force.py). The
    recorded column is a placeholder of the right sign (the suites replace it by the model's own prediction)."""
    folder.mkdir(parents=True, exist_ok=True)
    entries = []
    for k in range(2):
        t = np.arange(samples) * dt
        x, v = _two_sines(t, k)
        placeholder = 0.2 * np.tanh(v / 0.05) + 0.02 * v + 0.05
        name = f"run{k}.csv"
        np.savetxt(folder / name, np.column_stack([t, x, v, placeholder]), delimiter=",", comments="",
                   fmt="%.15g", header=f"time[s],position[rad],velocity[rad/s],{column}")
        entries.append({"file": name, "temperature": 25.0, "role": "fit"})
    (folder / "dataset.toml").write_text(tomli_w.dumps({"name": folder.name, "experiment": entries}))
    return list(tf.load_dataset(folder).experiments)


def _actuator_experiments(folder: Path, samples: int):
    """Two noise-free runs of the li2009-base actuator (35 and 38 C) at 1 kHz: 400 samples see the first flyback
    of its 5 Hz sawtooth (at 0.2 s), where the end effector slips (before it, it sticks: presliding alone)."""
    data = tf.synthesize(tf.load_model("li2009-base"), [35.0, 38.0], duration=(samples - 0.5) / 1e3,
                         sample_rate=1e3, noise=0.0)
    return list(data.experiments)


@dataclasses.dataclass(frozen=True)
class MeasurementCase:
    """``model()``: the model a measurement is held against; ``experiments(folder, samples)``: runs it
    recognises, ``samples`` long each; ``record``: the experiment's attribute that holds what was measured."""

    model: object
    experiments: object
    record: str


MEASUREMENT_CASES = {
    "displacement": MeasurementCase(lambda: tf.load_model("li2009-base"), _actuator_experiments, "displacement"),
    "force": MeasurementCase(
        lambda: tf.Model(tf.PrescribedMotion(motion="rotary", sensor_offset=0.05), tf.LuGre(**JOINT_LUGRE)),
        lambda folder, samples: _joint_dataset(folder, "friction_torque[N*m]", samples), "force"),
    "command": MeasurementCase(
        lambda: tf.Model(tf.PrescribedMotion(motion="rotary", sensor_offset=0.03, inertia=0.012),
                         tf.LuGre(**JOINT_LUGRE)),
        lambda folder, samples: _joint_dataset(folder, "command_torque[N*m]", samples), "force"),
}


# -- friction models ---------------------------------------------------------------------------------------------

#: the Canudas de Wit et al. (1995) levels, and the position ripple and negative side every model takes
CANUDAS = dict(sigma0=1e5, sigma1=math.sqrt(1e5), sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
SIDES = dict(fc_neg=0.9, fs_neg=1.3, vs_neg=1.2e-3, sigma2_neg=0.35)
RIPPLE = dict(ripple_period=2e-3, ripple_cos1=0.05, ripple_sin1=-0.02, ripple_cos2=0.01, ripple_sin2=0.004,
              ripple_cos3=-0.003, ripple_sin3=0.002)

#: every friction model with every parameter it takes given
FRICTION_CASES = {
    "coulomb": lambda: tf.Coulomb(fc=1.0, sigma2=0.4, v_smooth=1e-4, fc_neg=0.9, sigma2_neg=0.35, **RIPPLE),
    "stribeck": lambda: tf.Stribeck(fc=1.0, fs=1.5, vs=1e-3, delta=2.0, sigma2=0.4, v_smooth=1e-4, **SIDES,
                                    **RIPPLE),
    "dahl": lambda: tf.Dahl(sigma0=1e5, fc=1.0, v_smooth=1e-4, fc_neg=0.9, **RIPPLE),
    "lugre": lambda: tf.LuGre(**CANUDAS, delta=2.0, vd=1e-3, v_smooth=1e-4, **SIDES, **RIPPLE),
    "elastoplastic": lambda: tf.ElastoPlastic(**CANUDAS, z_ba=3e-6, delta=2.0, vd=1e-3, v_smooth=1e-4, **SIDES,
                                              **RIPPLE),
    "gms": lambda: tf.GMS(k=(1e4, 3e4, 6e4), w=(0.3, 0.3, 0.4), C=200.0, fc=1.0, fs=1.5, vs=1e-3, delta=2.0,
                          sigma2=0.4, v_smooth=1e-4, **SIDES, **RIPPLE),
}


@dataclasses.dataclass(frozen=True)
class Domain:
    """A parameter's domain, always finite: ``lower`` its bound and whether the bound itself is in (``closed``);
    ``at_least`` another parameter it must not fall below; ``below`` a strict upper bound (z_ba < fc/sigma0, on
    each side of a direction-dependent model); none of them: any finite value, of either sign. An array's
    domain is each element's."""

    lower: float | None = None
    closed: bool = False
    at_least: str | None = None
    below: str | None = None


POSITIVE = Domain(lower=0.0, closed=False)
NON_NEGATIVE = Domain(lower=0.0, closed=True)
FINITE = Domain()

#: Each friction parameter's domain as docs/models.md and the classes' docstrings state it ("> 0", ">= 0",
#: "fs >= fc", "0 <= z_ba < fc/sigma0", "vs > 0, needed where fs > fc"; the negative side as the positive one;
#: the ripple's period positive, its amplitudes of either sign). Written here, not read from the package: the
#: package's checks are what is tested.
DOMAINS = {
    "sigma0": POSITIVE, "sigma1": NON_NEGATIVE, "sigma2": NON_NEGATIVE, "fc": POSITIVE,
    "fs": Domain(at_least="fc"), "vs": POSITIVE, "delta": POSITIVE, "vd": POSITIVE, "v_smooth": POSITIVE,
    "z_ba": Domain(lower=0.0, closed=True, below="fc/sigma0"), "C": POSITIVE,
    "fc_neg": POSITIVE, "fs_neg": Domain(at_least="fc_neg"), "vs_neg": POSITIVE, "sigma2_neg": NON_NEGATIVE,
    "ripple_period": POSITIVE, **{f"ripple_{f}{k}": FINITE for k in (1, 2, 3) for f in ("cos", "sin")},
    "k": POSITIVE, "w": POSITIVE,
}

#: the values a domain test starts from where a case's own would meet another parameter's bound first: an
#: elasto-plastic z_ba of 0 (its lower bound), so that fc and sigma0 can each be taken to their own bound (z_ba
#: < fc/sigma0 would otherwise refuse fc just above 0)
DOMAIN_START = {"elastoplastic": {"z_ba": 0.0}}


# -- results -----------------------------------------------------------------------------------------------------

def _fit():
    # 0.2 s: on 0.05 s fc is all but undetermined (its cost flat within one standard error from 0 to 0.24 N), and a
    # fit that stops anywhere on that plateau has a standard error too large for propagate to draw from
    data = tf.synthesize(tf.load_model("li2009-base"), [35.0], duration=0.2, seed=1)
    return tf.identify(data, "base", starts=1, parameters=["fc"])


def _plant_fit():
    try:
        from thermofriction.identification.plant import fit_plant, step_response
    except ImportError:  # (wherever issue 39 leaves the plant's identification)
        from thermofriction.identification import fit_plant, step_response
    t = np.arange(0, 5e-3, 1e-5)
    u = np.where(t >= 1e-3, 10.0, 0.0)
    return fit_plant(t, u, step_response(t, 0.1, 2e4, 1e-6, 10.0, t[100]), hold="zoh")


def _fleet():
    base = tf.load_model("li2009-base")
    units = [dataclasses.replace(base, friction=dataclasses.replace(base.friction, fc=base.friction.fc * f))
             for f in (0.9, 1.1)]
    data = [tf.synthesize(m, [35.0], duration=0.05, noise=20e-9, seed=k) for k, m in enumerate(units)]
    return tf.identify_fleet(data, "base", scheduler="sequential", starts=1, parameters=["fc"])


def _heating():
    from thermofriction.heating import simulate_heating
    return simulate_heating(tf.load_model("li2009-self-heating"), 2.0, samples=50)


def _loop():
    from thermofriction import control
    return control.simulate_loop(tf.load_model("stage-model-i"), control.sine_reference(1e-3, 0.5, 0.2),
                                 temperature=30.0)


def _temperature_estimate():
    from thermofriction import control
    stage = tf.load_model("stage-model-i")
    t = np.arange(0.0, 0.2, 1e-3)
    v = 2e-3 * np.sin(2 * np.pi * 5.0 * t)
    est = control.TemperatureEstimator(C_th=5e-4, R_th=3e4, r_F=1e-4)
    F, _ = control.friction_steps(stage, v, 1e-3, temperature=35.0)
    return est.run(stage, v, dt=1e-3, ambient=30.0, start=33.0, measured_force=F)


#: class name -> a small instance of it, made cheaply (short simulations, one-parameter fits)
RESULT_CASES = {
    "SimulationResult": lambda: tf.simulate(tf.load_model("li2009-base"), 0.02, temperature=35.0),
    "FitResult": _fit,
    "ValidationResult": lambda: tf.validate(tf.load_model("li2009-base"),
                                            tf.synthesize(tf.load_model("li2009-base"), [35.0, 38.0], duration=0.05,
                                                          seed=2)),
    "HeatingResult": _heating,
    "LoopResult": _loop,
    "TemperatureEstimate": _temperature_estimate,
    "PlantFit": _plant_fit,
    "SweepResult": lambda: tf.sweep(tf.load_model("li2009-base"), {"fc": [0.8, 0.9]}, duration=0.05,
                                    sample_rate=2000, scheduler="sequential"),
    "FleetResult": _fleet,
    "PropagationResult": lambda: tf.propagate(_fit(), [35.0], draws=3, duration=0.05, scheduler="sequential"),
}

#: the result classes that should follow the protocol and do not yet (issue 39 names them): their suite is a
#: strict xfail while they are not ``Result`` subclasses, so that it fails the day they are and do not conform
NOT_YET_ON_THE_PROTOCOL = ("PlantFit", "SweepResult", "FleetResult", "PropagationResult")
