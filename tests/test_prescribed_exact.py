"""The exact stepping of friction under a prescribed motion (core/src/prescribed.c, ``_bridge.prescribed_force``)
that force-data fits use for the force and its Jacobian (docs/force-data.md#3-identification).

Oracles: the closed-form LuGre response to a constant velocity from rest (analytic); the adaptive integrator of
the C core at rtol 1e-11 (an independent algorithm: Dormand-Prince/Rodas4 with restarts at every knot and GMS's
located events) on jittered samples with velocity reversals; central differences of the force for the
sensitivities; and a fit's result on the earlier path (integrated runs, forward-difference Jacobian). The
elasto-plastic bristle's transition band is stepped numerically (core/src/prescribed_ep.c, a local error of
1e-11 per step on ln(z_ss - y)); the C core's own test checks it against a quadrature of the time to reach each
deflection."""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path
from unittest import mock

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from force_truths import make_dataset  # noqa: E402

import thermofriction as tf  # noqa: E402
from thermofriction import _bridge  # noqa: E402
from thermofriction.data.motion import motion_waveform  # noqa: E402
from thermofriction.measurements.force import Force  # noqa: E402
from thermofriction.models import PrescribedMotion  # noqa: E402
from thermofriction.models.laws import Linear  # noqa: E402
from thermofriction.models.thermal import ModelI, ModelII  # noqa: E402

JOINT = PrescribedMotion(motion="rotary")
ROT = dict(sigma0=3000.0, sigma1=0.3, fc=0.9, fs=1.4, vs=0.3, sigma2=0.35)
FRICTIONS = {
    "lugre": (tf.LuGre(**ROT, vd=0.2), ("sigma0", "sigma1", "fc", "fs", "vs", "sigma2", "vd")),
    "lugre-fs-follows": (tf.LuGre(sigma0=3000.0, sigma1=0.3, fc=0.9, sigma2=0.35), ("sigma0", "fc", "sigma2")),
    "dahl": (tf.Dahl(sigma0=3000.0, fc=0.9), ("sigma0", "fc")),
    "coulomb": (tf.Coulomb(fc=0.9, sigma2=0.35, v_smooth=0.05), ("fc", "sigma2", "v_smooth")),
    "stribeck": (tf.Stribeck(fc=0.9, fs=1.4, vs=0.3, sigma2=0.35, v_smooth=0.05), ("fc", "fs", "vs", "sigma2")),
    "gms": (tf.GMS(k=(1500.0, 1000.0, 500.0), w=(0.25, 0.35, 0.4), C=20.0, fc=0.9, fs=1.4, vs=0.3, sigma2=0.35),
            ("C", "fc", "fs", "vs", "sigma2")),
    "elastoplastic": (tf.ElastoPlastic(**ROT, vd=0.2, z_ba=1e-4),
                      ("sigma0", "sigma1", "fc", "fs", "vs", "sigma2", "vd", "z_ba")),
    # both sides' values: z_ss on the negative side from fc_neg, fs_neg, vs_neg
    "elastoplastic-asymmetric": (tf.ElastoPlastic(**ROT, z_ba=2e-4, fc_neg=0.75, fs_neg=1.2, vs_neg=0.2,
                                                  sigma2_neg=0.3),
                                 ("sigma0", "fc", "fs", "vs", "z_ba", "fc_neg", "fs_neg", "vs_neg", "sigma2_neg")),
    # fs = fc (fs follows fc): no Stribeck effect, z_ss = fc / sigma0 at every velocity; z_ba = 0
    "elastoplastic-fs-follows": (tf.ElastoPlastic(sigma0=3000.0, sigma1=0.3, fc=0.9, sigma2=0.35, z_ba=0.0),
                                 ("sigma0", "sigma1", "fc", "sigma2")),
}


def jittered_motion(n=600, duration=3.0, seed=0):
    """Jittered sample times and a velocity with reversals (a sine plus noise): the motion_waveform of them."""
    rng = np.random.default_rng(seed)
    dt = duration / (n - 1)
    t = np.maximum.accumulate(np.arange(n) * dt + rng.uniform(-0.3, 0.3, n) * dt)
    t[0] = 0.0
    v = 0.6 * np.cos(2 * math.pi * 0.8 * t) + 0.03 * rng.normal(size=n)
    return t, motion_waveform(t, v)


def integrated(model, t, waveform, T=30.0):
    spec = _bridge.model_spec(model, T, waveform)
    out = np.empty((t.size, _bridge.n_outputs(model, False)))
    _bridge.run(spec, t, out, method="auto", rtol=1e-11, max_steps=10_000_000)
    return out[:, _bridge.OUTPUT_COLUMN["friction_force"]]


def test_lugre_at_constant_velocity_is_the_closed_form():
    """From rest at constant v: z = z_ss (1 - exp(-sigma0 |v| t / g)), F = sigma0 z + sigma1 z' + sigma2 v."""
    p = dict(sigma0=2000.0, sigma1=0.5, fc=0.8, fs=1.2, vs=0.1, sigma2=0.2)
    v = 0.05
    model = tf.Model(JOINT, tf.LuGre(**p))
    t = np.linspace(0.0, 0.01, 41)
    F, _ = _bridge.prescribed_force(_bridge.model_spec(model, 25.0, tf.Sampled(np.array([0.0, 1.0]),
                                                                                np.array([0.0, v]))), t)
    g = p["fc"] + (p["fs"] - p["fc"]) * math.exp(-(v / p["vs"]) ** 2)
    r = p["sigma0"] * abs(v) / g
    z = v / r * (1.0 - np.exp(-r * t))
    zd = v * np.exp(-r * t)
    np.testing.assert_allclose(F, p["sigma0"] * z + p["sigma1"] * zd + p["sigma2"] * v, rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("kind", list(FRICTIONS))
def test_force_equals_the_integrators(kind):
    """Jittered samples, reversals: the exact stepping equals the integrator at rtol 1e-11 to 1e-8 of the range."""
    friction, _ = FRICTIONS[kind]
    model = tf.Model(JOINT, friction)
    t, w = jittered_motion()
    F, _ = _bridge.prescribed_force(_bridge.model_spec(model, 30.0, w), t)
    ref = integrated(model, t, w)
    assert np.max(np.abs(F - ref)) <= 1e-8 * np.ptp(ref)


def test_model_i_laws_act_at_the_temperature():
    """A Model I model at 60 C: the force is the integrator's with the laws evaluated there by the core."""
    model = tf.Model(JOINT, tf.LuGre(sigma0=3000.0, sigma1=0.3, fc=None, fs=1.4, vs=0.3, sigma2=None),
                     ModelI({"fc": Linear(a=-0.004, b=0.9), "sigma2": Linear(a=0.002, b=0.35)}))
    t, w = jittered_motion(n=300)
    F, _ = _bridge.prescribed_force(_bridge.model_spec(model, 60.0, w), t)
    ref = integrated(model, t, w, T=60.0)
    assert np.max(np.abs(F - ref)) <= 1e-8 * np.ptp(ref)


@pytest.mark.parametrize("kind", list(FRICTIONS))
def test_sensitivities_equal_central_differences(kind):
    """dF/dtheta for every parameter the model reads equals central differences of the exact force (relative
    1e-6 of the column's largest value; GMS 1e-5: differences across its located mode switches)."""
    friction, names = FRICTIONS[kind]
    model = tf.Model(JOINT, friction)
    t, w = jittered_motion()
    F, dF = _bridge.prescribed_force(_bridge.model_spec(model, 30.0, w), t, names)
    assert dF.shape == (t.size, len(names))
    for j, name in enumerate(names):
        value = getattr(friction, name)
        h = 1e-6 * abs(value)
        up, down = (_bridge.prescribed_force(_bridge.model_spec(
            tf.Model(JOINT, dataclasses.replace(friction, **{name: value + s})), 30.0, w), t)[0] for s in (h, -h))
        cd = (up - down) / (2 * h)
        scale = np.max(np.abs(cd))
        assert scale > 0, name
        assert np.max(np.abs(dF[:, j] - cd)) <= (1e-5 if kind == "gms" else 1e-6) * scale, name


@pytest.mark.parametrize("kind", ["elastoplastic", "elastoplastic-asymmetric"])
def test_elastoplastic_through_its_transition_band(kind):
    """A slow motion (strokes of a few steady deflections g/sigma0, so that many samples fall in the band between
    z_ba and z_ss that the core steps numerically): the force equals the integrator's at rtol 1e-11 to 1e-9 of the
    range, and every sensitivity equals central differences (relative step 1e-5) to 1e-8 of the range per unit
    relative change of the parameter."""
    friction, names = FRICTIONS[kind]
    model = tf.Model(JOINT, friction)
    t, w = jittered_motion()
    w = tf.Sampled(w.time, 0.005 * w.value)
    F, dF = _bridge.prescribed_force(_bridge.model_spec(model, 30.0, w), t, names)
    zss = friction.fc / friction.sigma0
    assert 2 * zss < np.ptp(w.value) < 10 * zss  # the strokes: a few steady deflections
    ref = integrated(model, t, w)
    assert np.max(np.abs(F - ref)) <= 1e-9 * np.ptp(ref)
    for j, name in enumerate(names):
        value = getattr(friction, name)
        h = 1e-5 * abs(value)
        up, down = (_bridge.prescribed_force(_bridge.model_spec(
            tf.Model(JOINT, dataclasses.replace(friction, **{name: value + s})), 30.0, w), t)[0] for s in (h, -h))
        cd = (up - down) / (2 * h)
        assert np.max(np.abs(cd)) > 0, name
        assert np.max(np.abs(dF[:, j] - cd)) * abs(value) <= 1e-8 * np.ptp(F), name


def test_refusals_name_the_argument():
    """Decreasing output times and a model it does not apply to are refused with the core's record."""
    model = tf.Model(JOINT, tf.LuGre(**ROT))
    t, w = jittered_motion(n=50)
    with pytest.raises(_bridge.CoreFailure, match="t_out") as e:
        _bridge.prescribed_force(_bridge.model_spec(model, 30.0, w), t[::-1])
    assert e.value.status == "bad_argument"
    m2 = tf.Model(JOINT, tf.LuGre(**ROT), ModelII(Linear(a=0.0, b=0.01)))
    assert not _bridge.prescribed_applies(_bridge.model_spec(m2, 30.0, w))
    with pytest.raises(_bridge.CoreFailure, match="model"):
        _bridge.prescribed_force(_bridge.model_spec(m2, 30.0, w), t)
    ep = tf.Model(JOINT, tf.ElastoPlastic(**ROT, z_ba=1e-4))
    assert _bridge.prescribed_applies(_bridge.model_spec(ep, 30.0, w))
    assert _bridge.prescribed_applies(_bridge.model_spec(model, 30.0, w))


@pytest.mark.parametrize("kind", ["lugre", "elastoplastic"])
def test_fit_equals_the_forward_difference_path(tmp_path, kind):
    """A LuGre (elasto-plastic) fit to reference-made joint torque: every parameter within 0.05 standard errors of
    the fit on the earlier path (integrated runs at rtol 1e-9, forward-difference Jacobian), on the same data."""
    truth = tf.Model(JOINT, tf.LuGre(**ROT) if kind == "lugre" else tf.ElastoPlastic(**ROT, z_ba=1e-4))
    folder, _ = make_dataset(tmp_path, truth, offset=0.05, n=1500, duration=2.0)
    data = tf.load_dataset(folder)
    calls = []
    real = Force._exact

    def counted(self, *a, **k):
        calls.append(1)
        return real(self, *a, **k)
    with mock.patch.object(Force, "_exact", counted):
        new = tf.identify(data, "base", friction=kind)
    assert calls  # the exact path ran
    with mock.patch.object(Force, "exact_names", staticmethod(lambda problem, model: None)):
        old = tf.identify(data, "base", friction=kind)
    for name, p in new.parameters.items():
        if p.vary:
            assert abs(p.value - old.parameters[name].value) <= 0.05 * p.stderr, (name, p.value,
                                                                                 old.parameters[name].value, p.stderr)
            assert abs(p.stderr - old.parameters[name].stderr) <= 0.05 * p.stderr, name
