"""Random truths drawn away from the presets, and a study of how identification recovers them: the
errors of the recovered laws and how often their 95 % intervals cover the truth. Used by
tests/test_identify_coverage.py and benchmarks/study_identify.py."""

from __future__ import annotations

import dataclasses
import math
import tempfile
import time
from pathlib import Path

import numpy as np
import tomli_w

import thermofriction as tf
from thermofriction.models import PWL, Exp, Linear, ModelI, ModelII

FIT_T = (30.5, 33.5, 36.5, 39.5, 41.5)
SAW = tf.Sawtooth(amplitude=30, frequency=5, rise=0.999)


def random_plant(rng):
    base = tf.load_model("li2009-base").plant
    return dataclasses.replace(base, end_effector_mass=float(rng.uniform(0.03, 0.2)),
                               mass=float(rng.uniform(0.02, 0.1)))


def model_i_truth(rng):
    """Exponential sigma0 and fc, linear sigma1, all positive over 30-42 C, none near the presets."""
    T0 = 30.0
    plant = random_plant(rng)
    s0, b0 = rng.uniform(4e5, 4e6), -rng.uniform(0.02, 0.12)
    # the friction level lets the actuator slip: a fraction of m_e times the stage's acceleration (~25 m/s^2)
    f0, bf = rng.uniform(0.2, 0.8) * 25.0 * plant.end_effector_mass, -rng.uniform(0.02, 0.1)
    s1, d1 = rng.uniform(2.0, 30.0), -rng.uniform(0.0, 0.6)
    laws = {"sigma0": Exp(s0 * math.exp(-b0 * T0), b0, range=(30.0, 42.0)),
            "fc": Exp(f0 * math.exp(-bf * T0), bf, range=(30.0, 42.0)),
            "sigma1": Linear(d1 * s1 / 12.0, s1 - d1 * s1 / 12.0 * T0, range=(30.0, 42.0))}
    return tf.Model(plant, tf.LuGre(sigma0=None, sigma1=None, fc=None), ModelI(laws), SAW, name="truth")


def model_ii_truth(rng):
    """A base LuGre and dF falling (or rising) with a break between 34 and 39 C."""
    plant = random_plant(rng)
    fc = float(rng.uniform(0.2, 0.8) * 25.0 * plant.end_effector_mass)
    base = tf.LuGre(sigma0=float(rng.uniform(5e5, 4e6)), sigma1=float(rng.uniform(2.0, 30.0)), fc=fc)
    tb = float(rng.uniform(34.0, 39.0))
    mid, top = sorted(rng.uniform(-0.5, 0.3, 2) * fc, reverse=True)
    dF = PWL([30.0, tb, 42.0], [0.0, float(mid), float(top)], range=(30.0, 42.0))
    return tf.Model(plant, base, ModelII(dF), SAW, name="truth")


def plant_only_file(model, folder) -> Path:
    path = Path(folder) / "plant.toml"
    path.write_text(tomli_w.dumps({"plant": model.plant.to_dict(), "input": model.input.to_dict()}))
    return path


@dataclasses.dataclass
class Outcome:
    seed: int
    wall_time: float
    adequate: bool
    errors: dict        # parameter -> max relative error of the law over the fit temperatures
    covered: int        # (parameter, temperature) points whose 95 % interval covers the truth
    points: int
    missed: list = dataclasses.field(default_factory=list)   # (parameter, temperature) not covered


def _identify_truth(seed, make_truth, method, duration, sample_rate):
    """(truth, fit, wall time): 5 temperatures of the truth with 20 nm noise and 1 nm quantisation,
    identified from a model file that gives only the plant."""
    truth = make_truth(np.random.default_rng(seed))
    data = tf.synthesize(truth, FIT_T, duration=duration, sample_rate=sample_rate, noise=20e-9, quantization=1e-9,
                         seed=seed)
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        fit = tf.identify(data, method=method, init=plant_only_file(truth, d))
        wall = time.perf_counter() - t0
    return truth, fit, wall


def _outcome(seed, wall, fit, errors, rows):
    """Coverage of the fit's 95 % law intervals (FitResult.recovery) over ``rows``."""
    missed = [(r["parameter"], r["temperature"]) for r in rows if not r["covered"]]
    return Outcome(seed, wall, bool(fit.adequate), errors, len(rows) - len(missed), len(rows), missed)


def study_model_i(seed, duration=0.4, sample_rate=5000):
    """Each law's largest error relative to the truth over the fit temperatures."""
    truth, fit, wall = _identify_truth(seed, model_i_truth, "model-i", duration, sample_rate)
    rows = fit.recovery(truth, FIT_T)
    errors = {name: max(abs(r["value"] - r["truth"]) / abs(r["truth"]) for r in rows if r["parameter"] == name)
              for name in ("sigma0", "sigma1", "fc")}
    return _outcome(seed, wall, fit, errors, rows)


def study_model_ii(seed, duration=0.4, sample_rate=5000):
    """dF is recovered relative to the reference (lowest) temperature, its definition: compared with
    dF_true(T) - dF_true(T_ref), in units of the friction level."""
    truth, fit, wall = _identify_truth(seed, model_ii_truth, "model-ii", duration, sample_rate)
    rows = fit.recovery(truth, FIT_T)
    errors = {"dF/fc": max(abs(r["value"] - r["truth"]) for r in rows) / truth.friction.fc}
    # dF is pinned to zero at the reference: no interval there
    return _outcome(seed, wall, fit, errors, [r for r in rows if abs(r["temperature"] - FIT_T[0]) > 0.05])


__all__ = ["study_model_i", "study_model_ii", "model_i_truth", "model_ii_truth", "Outcome"]
