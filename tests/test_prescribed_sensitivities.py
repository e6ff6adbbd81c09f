"""The exact stepping's sensitivities of LuGre and Dahl (core/src/prescribed.c with tf_friction_affine_set: one
evaluation per velocity segment, the output's partials affine in the state) on the cost study's force truths and
on models that reach every column the fits can ask for.

Oracles: the same runs without sensitivities (the general path, one evaluation of the model per sample: the force
must be the same number) and fourth-order central differences of that force, f'(p) = (f(p - 2h) - 8 f(p - h)
+ 8 f(p + h) - f(p + 2h)) / 12h at h = 1e-3 of the parameter (of the ripple's size for its amplitudes): their
truncation error is below ~1e-10 of each column's largest value here and their rounding error ~1.5 e |F| / h,
e ~1e-15 the force's own rounding. The sensitivities must agree to 1e-9 of the column's largest value plus
1e-13 |F|max / h (the rounding, with a margin; tests/test_prescribed_exact.py checks second-order differences
at 1e-6 of the column). Every sample and
every column of both fit runs of the study's force and force-ripple truths, seeds 0-9 (benchmarks/study_cost.py:
LuGre with a Stribeck effect and direction-dependent levels, drawn there; the ripple stepped by the core here)."""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT / "tests"))
import study_cost as S  # noqa: E402
from test_prescribed_exact import JOINT, jittered_motion  # noqa: E402

import thermofriction as tf  # noqa: E402
from thermofriction import _bridge  # noqa: E402
from thermofriction.measurements import make_traces, measurement_of  # noqa: E402

RIPPLE = ("ripple_cos1", "ripple_sin1")
TOLERANCE = 1e-9  # of each column's largest value
ROUNDING = 1e-13  # the differences' rounding allowance, relative to the force's largest value over h


def worst_against_differences(friction, names, runs, ripple_size=0.0):
    """The largest difference between the exact stepping's sensitivities and fourth-order central differences of
    its force, over the runs ((waveform, times) pairs), in units of the tolerance (TOLERANCE of the column's
    largest value plus the differences' rounding allowance ROUNDING |F|max / h); asserts on the way that the
    force with sensitivities is the force without, and that every column moves somewhere."""
    worst = 0.0
    for waveform, t in runs:
        spec = _bridge.model_spec(tf.Model(JOINT, friction), 30.0, waveform)
        F, dF = _bridge.prescribed_force(spec, t, list(names))
        assert np.array_equal(F, _bridge.prescribed_force(spec, t)[0])  # the same number, sample by sample
        for j, name in enumerate(names):
            value = getattr(friction, name) or 0.0
            h = 1e-3 * (ripple_size if name.startswith("ripple_") else abs(value))

            def force(k):
                moved = tf.Model(JOINT, dataclasses.replace(friction, **{name: value + k * h}))
                return _bridge.prescribed_force(_bridge.model_spec(moved, 30.0, waveform), t)[0]
            d = (force(-2) - 8 * force(-1) + 8 * force(1) - force(2)) / (12 * h)
            scale = np.max(np.abs(d))
            assert scale > 0, name
            allowed = TOLERANCE * scale + ROUNDING * np.max(np.abs(F)) / h
            worst = max(worst, np.max(np.abs(dF[:, j] - d)) / allowed)
    return worst


@pytest.mark.parametrize("kind", ["force", "force-ripple"])
def test_study_truths_sensitivities_equal_fourth_order_differences(kind):
    """Seeds 0-9 of the study's ``kind``, both fit runs: every column within its tolerance of the differences, the
    force the run's without sensitivities."""
    for seed in range(10):
        data, truth, _, _ = S.force_case(kind, seed, False)
        friction = truth.friction
        runs = [(tr.waveform, tr.time) for tr in make_traces(list(data.fit), truth, measurement_of(data))]
        assert len(runs) == 2 and all(t.size > 9_000 for _, t in runs)
        names = list(S.FORCE_NAMES) + ["delta"] + (list(RIPPLE) if kind == "force-ripple" else [])
        size = math.hypot(friction.ripple_cos1 or 0.0, friction.ripple_sin1 or 0.0)
        worst = worst_against_differences(friction, names, runs, size)
        assert worst <= 1.0, (kind, seed, worst)


LUGRE = dict(sigma0=3000.0, sigma1=0.3, fc=0.9, fs=1.4, vs=0.3, sigma2=0.35)
MODELS = {
    # sigma1(v) (vd), every negative-side value, a ripple of three harmonics stepped by the core
    "lugre-asymmetric-ripple": (tf.LuGre(**LUGRE, vd=0.2, delta=1.7, fc_neg=0.75, fs_neg=1.2, vs_neg=0.2,
                                         sigma2_neg=0.3, ripple_period=0.05, ripple_cos1=0.02, ripple_sin1=0.01,
                                         ripple_cos2=0.005, ripple_sin3=0.004),
                                ("sigma0", "sigma1", "sigma2", "fc", "fs", "vs", "delta", "vd", "fc_neg", "fs_neg",
                                 "vs_neg", "sigma2_neg", "ripple_cos1", "ripple_sin1", "ripple_cos2", "ripple_sin3")),
    # fs follows fc (fc's column carries fs's), and fs_neg follows fc_neg
    "lugre-fs-follows": (tf.LuGre(sigma0=3000.0, sigma1=0.3, fc=0.9, sigma2=0.35, fc_neg=0.8),
                         ("sigma0", "sigma1", "fc", "sigma2", "fc_neg")),
    "dahl": (tf.Dahl(sigma0=3000.0, fc=0.9), ("sigma0", "fc")),
    "dahl-asymmetric": (tf.Dahl(sigma0=3000.0, fc=0.9, fc_neg=0.7), ("sigma0", "fc", "fc_neg")),
}


@pytest.mark.parametrize("kind", list(MODELS))
def test_every_column_equals_fourth_order_differences(kind):
    """Jittered samples with reversals (tests/test_prescribed_exact.py's motion, and the same 200 times slower so
    that the bristle's transients span many samples, where vd's column is ~1e-6 of the force): every column
    within its tolerance of the differences, the force the run's without sensitivities."""
    friction, names = MODELS[kind]
    t, w = jittered_motion()
    runs = [(w, t), (tf.Sampled(w.time, 0.005 * w.value), t)]
    size = 0.02 if kind.endswith("ripple") else 0.0
    assert worst_against_differences(friction, names, runs, size) <= 1.0
