"""Truths with a Stribeck effect for identification tests (issue 30), simulated by the independent SciPy reference
(tests/reference/, which never calls the C core): the paper's actuator with LuGre whose sigma0, fc, fs = 1.5 fc and
a rising sigma1 are each linear in temperature, vs = 6 mm/s, sigma2 = 2 N s/m (so that the model is dissipative
with the Stribeck drop), 20 nm white noise."""

from __future__ import annotations

import dataclasses
import types

import numpy as np

import reference as R
import thermofriction as tf
from thermofriction.models import Linear, ModelI

RANGE = (30.0, 42.0)
FIT_T = (31.0, 34.0, 37.0, 40.0)


def linear(v30, v42) -> Linear:
    """The line through v30 at 30 C and v42 at 42 C."""
    a = (v42 - v30) / 12.0
    return Linear(a, v30 - a * 30.0, range=RANGE)


TRUE_LAWS = {"sigma0": (1.2e6, 0.7e6), "fc": (0.40, 0.28), "fs": (0.60, 0.42), "sigma1": (1.5, 3.0)}


def stribeck_truth(vs=6e-3, end_effector_mass=None) -> tf.Model:
    base = tf.load_model("li2009-model-i")
    plant = base.plant if end_effector_mass is None else dataclasses.replace(
        base.plant, end_effector_mass=end_effector_mass)
    laws = {n: linear(*v) for n, v in TRUE_LAWS.items()}
    return tf.Model(plant, tf.LuGre(sigma0=None, sigma1=None, fc=None, fs=None, vs=vs, sigma2=2.0), ModelI(laws),
                    base.input, name="stribeck truth")


def start_from(truth: tf.Model, factors: dict, vs=None, laws=None, plant=None) -> tf.Model:
    """A start whose laws are the truth's times ``factors`` (a law absent from ``factors`` is dropped and held at
    the truth's value at 36 C; ``laws``: names kept exactly); fs at fc's where ``factors`` has no fs."""
    keep = set(laws or ())
    new = {n: Linear(law.a * factors[n], law.b * factors[n], range=RANGE) for n, law in truth.laws.items()
           if n in factors}
    new.update({n: truth.laws[n] for n in keep})
    at = truth.parameters_at(36.0)
    held = {n: at[n] for n in truth.laws if n not in new and n != "fs"}
    vs = truth.friction.vs if vs is None else vs
    friction = tf.LuGre(**{"sigma0": None, "sigma1": None, "fc": None, **held}, sigma2=2.0,
                        fs=None if "fs" in new else held.get("fc"), vs=vs if "fs" in new else None)
    return tf.Model(plant or truth.plant, friction, ModelI(new), truth.input, name="start")


def reference_experiments(truth: tf.Model, temperatures=FIT_T, duration=0.4, sample_rate=10_000.0, noise=20e-9,
                          seed=0):
    """Runs of ``truth`` at each temperature by the reference implementation, plus white noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration + 0.5 / sample_rate, 1.0 / sample_rate)
    exps = []
    for T in temperatures:
        res = R.reference_simulate(truth, t, temperature=float(T), rtol=1e-9)
        exps.append(types.SimpleNamespace(file=f"T{T:g}.csv", time=t, voltage=np.array([R.waveform_value(
            truth.input, x) for x in t]), temperature=float(T), role="fit",
            displacement=res.displacement + noise * rng.standard_normal(t.size)))
    return exps


def friction_level_errors(fitted: tf.Model, truth: tf.Model, temperatures=FIT_T, names=("fc", "fs")) -> dict:
    """name -> the largest relative error of the fitted value over ``temperatures``."""
    out = {}
    for n in names:
        out[n] = max(abs(fitted.parameters_at(T)[n] / truth.parameters_at(T)[n] - 1.0) for T in temperatures)
    return out
