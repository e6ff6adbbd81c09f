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


def law_value_interval(fit, name, law, T):
    """The 95 % interval of a fitted law's value at T (the fit's own delta method)."""
    _, lo, hi = fit.law_interval(name, [T])
    return float(lo[0]), float(hi[0])


@dataclasses.dataclass
class Outcome:
    seed: int
    wall_time: float
    adequate: bool
    errors: dict        # parameter -> max relative error of the law over the fit temperatures
    covered: int        # (parameter, temperature) points whose 95 % interval covers the truth
    points: int
    missed: list = dataclasses.field(default_factory=list)   # (parameter, temperature) not covered


def study_model_i(seed, duration=0.4, sample_rate=5000):
    rng = np.random.default_rng(seed)
    truth = model_i_truth(rng)
    data = tf.synthesize(truth, FIT_T, duration=duration, sample_rate=sample_rate, noise=20e-9, quantization=1e-9,
                         seed=seed)
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        fit = tf.identify(data, method="model-i", init=plant_only_file(truth, d))
        wall = time.perf_counter() - t0
    errors, covered, points, missed = {}, 0, 0, []
    for name in ("sigma0", "sigma1", "fc"):
        law, true = fit.model.laws[name], truth.laws[name]
        errs = []
        for T in FIT_T:
            errs.append(abs(law(T) - true(T)) / abs(true(T)))
            lo, hi = law_value_interval(fit, name, law, T)
            covered += lo <= true(T) <= hi
            points += 1
            if not lo <= true(T) <= hi:
                missed.append((name, T))
        errors[name] = max(errs)
    return Outcome(seed, wall, bool(fit.adequate), errors, covered, points, missed)


def study_model_ii(seed, duration=0.4, sample_rate=5000):
    """dF is recovered relative to the reference (lowest) temperature, its definition: compared with
    dF_true(T) - dF_true(T_ref), in units of the friction level."""
    rng = np.random.default_rng(seed)
    truth = model_ii_truth(rng)
    data = tf.synthesize(truth, FIT_T, duration=duration, sample_rate=sample_rate, noise=20e-9, quantization=1e-9,
                         seed=seed)
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        fit = tf.identify(data, method="model-ii", init=plant_only_file(truth, d))
        wall = time.perf_counter() - t0
    law = fit.model.thermal.dF
    fc = truth.friction.fc
    ref = truth.thermal.dF(FIT_T[0])
    errs, covered, points, missed = [], 0, 0, []
    for T in FIT_T:
        true = truth.thermal.dF(T) - ref
        errs.append(abs(law(T) - true) / fc)
        if abs(T - FIT_T[0]) > 0.05:  # dF is pinned to zero at the reference: no interval there
            lo, hi = law_value_interval(fit, "dF", law, T)
            covered += lo <= true <= hi
            points += 1
            if not lo <= true <= hi:
                missed.append(("dF", T))
    return Outcome(seed, wall, bool(fit.adequate), {"dF/fc": max(errs)}, covered, points, missed)


__all__ = ["study_model_i", "study_model_ii", "model_i_truth", "model_ii_truth", "law_value_interval", "Outcome"]
