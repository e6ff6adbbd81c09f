"""Direction-dependent friction (fc_neg, fs_neg, vs_neg, sigma2_neg) and the position ripple
(ripple_period, ripple_cos1 ... ripple_sin3) on every friction model (docs/models.md#direction-and-position).

Oracles: the independent reference implementation (tests/reference/: on_side, ripple, written from the
definitions) for the C right-hand side, its Jacobian (five-point finite differences of the reference) and
whole simulations; finite differences of simulations for the sensitivities; closed forms (steady sliding)
for the real-time step and the FMU; tests/lookalike.py (an independent LuGre with direction-dependent levels
and a ripple, integrated by SciPy) for identification."""

from __future__ import annotations

import math
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import reference as R  # noqa: E402
import lookalike as L  # noqa: E402
from test_differential_friction import (_spec, _times, _velocity_bands, core_eval, fd_jacobian,  # noqa: E402
                                        random_case_state, sensitivity_model, term_magnitudes, x_e,
                                        x_e_and_sensitivities)

import thermofriction as tf  # noqa: E402
from thermofriction.control import friction_steps  # noqa: E402
from thermofriction.models import ModelI, ModelII  # noqa: E402

RIPPLE = dict(ripple_period=2e-3, ripple_cos1=0.05, ripple_sin1=-0.03, ripple_sin3=0.02)


def sided(kind):
    """Each model with the Canudas 1995 levels on the positive side, other levels on the negative one, and a
    three-harmonic ripple of 2 mm period."""
    neg = dict(fc_neg=1.3, fs_neg=1.8, vs_neg=2e-3, sigma2_neg=0.7)
    lugre = dict(sigma0=1e5, sigma1=math.sqrt(1e5), sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
    return {
        "coulomb": lambda: tf.Coulomb(fc=1.0, sigma2=0.4, v_smooth=1e-4, fc_neg=1.3, sigma2_neg=0.7, **RIPPLE),
        "stribeck": lambda: tf.Stribeck(fc=1.0, fs=1.5, vs=1e-3, sigma2=0.4, v_smooth=1e-4, **neg, **RIPPLE),
        "dahl": lambda: tf.Dahl(sigma0=1e5, fc=1.0, fc_neg=1.3, **RIPPLE),
        "lugre": lambda: tf.LuGre(**lugre, **neg, **RIPPLE),
        "elastoplastic": lambda: tf.ElastoPlastic(**lugre, z_ba=5e-6, **neg, **RIPPLE),
        "gms": lambda: tf.GMS(k=(1e4, 3e4, 6e4), w=(0.3, 0.3, 0.4), C=200.0, fc=1.0, fs=1.5, vs=1e-3, sigma2=0.4,
                              **neg, **RIPPLE),
    }[kind]()


KINDS = ("coulomb", "stribeck", "dahl", "lugre", "elastoplastic", "gms")
SPRING = tf.MassPlant(mass=1.0, spring_stiffness=2.0, pull_velocity=0.1)


def _model(kind, plant):
    if plant == "mass":
        return tf.Model(SPRING, sided(kind), input=tf.Sine(0.5, 1.3))
    if plant == "prescribed":
        return tf.Model(tf.PrescribedMotion(), sided(kind), input=tf.Sine(2e-3, 2.0))
    base = tf.load_model("li2009-base")
    return tf.Model(base.plant, sided(kind), input=base.input)


CASES = {f"{plant}-{kind}": (lambda kind=kind, plant=plant: _model(kind, plant), None)
         for kind in KINDS for plant in ("mass", "prescribed", "stick-slip")}
# Model I laws on negative-side parameters; Model II on top
CASES["mass-lugre-model-i-fc_neg"] = (lambda: tf.Model(
    SPRING, tf.LuGre(sigma0=1e5, sigma1=300.0, fc=1.0, fs=1.5, vs=1e-3, sigma2=0.4, fc_neg=None, sigma2_neg=0.2,
                     **RIPPLE),
    ModelI({"fc_neg": tf.Linear(-0.02, 2.0)}), input=tf.Sine(0.5, 1.3)), 35.0)
CASES["mass-gms-model-ii-scale"] = (lambda: tf.Model(
    SPRING, sided("gms"), ModelII(tf.load_model("li2009-model-ii").thermal.dF, "scale"), input=tf.Sine(0.5, 1.3)),
    40.0)


@pytest.mark.parametrize("case", list(CASES))
def test_rhs_matches_reference(case):
    """Oracle: the reference implementation (tests/reference/: on_side for the sliding direction, the ripple at
    the relative position). The C right-hand side and friction force agree to 1e-12 of the terms' magnitudes at
    100 random states of either sliding direction (GMS: random modes)."""
    make, temperature = CASES[case]
    model = make()
    rng = np.random.default_rng(zlib.crc32(case.encode()))
    signs = set()
    for t in _times(model, temperature, rng, 100):
        ref0 = R.ReferenceSystem(model, temperature)
        y, modes = random_case_state(ref0, t, rng, "mixed")
        if ref0.plant != "prescribed":  # positions over several ripple periods
            y[0] = rng.uniform(-5e-3, 5e-3)
        ref = R.ReferenceSystem(model, temperature, gms_mode=modes)
        signs.add(ref.velocity(t, y) > 0)
        dy_c, F_c, _ = core_eval(_spec(model, temperature, modes), t, y)
        dy_r = np.array(ref.rhs(t, list(y)))
        F_r = ref.friction(t, y)
        mag, F_mag = term_magnitudes(ref, t, y)
        err = np.abs(dy_c - dy_r) / np.where(mag > 0, mag, 1.0)
        assert max(err.max(initial=0.0), abs(F_c - F_r) / F_mag) < 1e-12, (case, t, y, dy_c, dy_r, F_c, F_r)
    assert signs == {True, False}


def test_reference_sides_differ():
    """The oracle itself: steady sliding of the static Stribeck map at +-v gives the two sides' closed forms
    g_+(v) + sigma2 v and -(g_-(v) + sigma2_neg v), the ripple its Fourier sum."""
    p = R.friction_params(tf.Model(tf.PrescribedMotion(), sided("stribeck")), math.nan)
    v = 3e-3
    g_pos = 1.0 + 0.5 * math.exp(-(v / 1e-3) ** 2)
    g_neg = 1.3 + 0.5 * math.exp(-(v / 2e-3) ** 2)
    assert R.base_friction("stribeck", p, v, [])[0] == pytest.approx(g_pos * math.tanh(v / 1e-4) + 0.4 * v, 1e-14)
    assert R.base_friction("stribeck", p, -v, [])[0] == pytest.approx(-g_neg * math.tanh(v / 1e-4) - 0.7 * v, 1e-14)
    x = 0.7e-3
    q = 2 * math.pi * x / 2e-3
    assert R.ripple(p, x) == pytest.approx(0.05 * math.cos(q) - 0.03 * math.sin(q) + 0.02 * math.sin(3 * q), 1e-14)


@pytest.mark.parametrize("case", [c for c in CASES if c.startswith(("mass", "stick-slip"))])
def test_jacobian_matches_finite_differences_of_reference(case):
    """Oracle: five-point central differences of the reference right-hand side (the ripple's position
    column included). The C Jacobian agrees to 1e-6 of each row's scale at 30 random states."""
    make, temperature = CASES[case]
    model = make()
    rng = np.random.default_rng(1 + zlib.crc32(case.encode()))
    for t in _times(model, temperature, rng, 30):
        ref0 = R.ReferenceSystem(model, temperature)
        y, modes = random_case_state(ref0, t, rng, "mixed", v_min=1e-7, vp_over_v=30.0, margin=1e-3)
        ref = R.ReferenceSystem(model, temperature, gms_mode=modes)
        p = R.on_side(ref.params_at_time(t), ref.velocity(t, y))
        if ref.kind == "elastoplastic":  # keep z off alpha's switching deflections on the side of v
            zss = R.stribeck_g(p, ref.velocity(t, y)) / p.sigma0
            if min(abs(abs(y[ref.nm]) - p.z_ba), abs(abs(y[ref.nm]) - zss)) < 1e-3 * ref.scales()[ref.nm]:
                continue
        _, _, J = core_eval(_spec(model, temperature, modes), t, y, jac=True)
        v = ref.velocity(t, y)
        vloc = min([abs(v), *_velocity_bands(p, ref.kind, p.dF_offset != 0.0)])
        loc = ref.scales().copy()
        if ref.plant == "stick-slip":
            loc[[1, 3]] = vloc
        else:
            loc[1] = vloc
        loc[0] = min(loc[0], 1e-4)  # a position step well inside a ripple period
        if ref.plant == "stick-slip":
            loc[2] = min(loc[2], 1e-4)
        J_fd = fd_jacobian(ref, t, y, 1e-4 * loc)
        A_c, A_fd = J * loc, J_fd * loc
        row = np.max(np.abs(A_fd), axis=1) + 1e-3 * term_magnitudes(ref, t, y)[0]
        dev = np.abs(A_c - A_fd) / row[:, None]
        assert np.all(dev <= 1e-6), (case, t, y, modes, J, J_fd, dev)


@pytest.mark.parametrize("kind", ["stribeck", "lugre", "dahl"])
def test_simulation_matches_reference(kind):
    """Oracle: the reference simulation (SciPy, rtol 1e-10) of a spring-pulled mass with each side's levels
    and the ripple, 4 s (stick-slip in both directions: the pull reverses). x agrees to 1e-5 of its range (the C
    solver at rtol 1e-9)."""
    model = tf.Model(tf.MassPlant(mass=1.0, spring_stiffness=2.0), sided(kind), input=tf.Sine(3.0, 0.5))
    t = np.linspace(0.0, 4.0, 801)
    res = tf.simulate(model, 4.0, sample_rate=200.0, controller=tf.StepSizeController(rtol=1e-9))
    ref = R.reference_simulate_system(model, t, rtol=1e-10, method="LSODA" if kind == "stribeck" else "DOP853")
    x_c, x_r = res.displacement, ref.displacement
    assert np.max(np.abs(x_c - x_r)) <= 1e-5 * np.ptp(x_r), np.max(np.abs(x_c - x_r)) / np.ptp(x_r)
    assert ref.velocity.min() < -1e-3 and ref.velocity.max() > 1e-3  # both sides slid


@pytest.mark.parametrize("kind", ["lugre", "gms"])
def test_sensitivities_match_finite_differences(kind):
    """Oracle: central differences (relative step 1e-3) of x_e(t) simulated at rtol 1e-12, as
    tests/test_differential_friction.py checks the other parameters: the LuGre actuator through the sawtooth's
    flyback (the end effector slips backwards: the negative side acts) with each side's levels and a ripple.
    The forward sensitivities to the negative side's levels and the ripple's amplitudes agree to 1e-3 of the
    largest sensitivity, and each moves x_e measurably. GMS: the elements break loose to either side's
    capacity, so the sensitivities' jumps at those switches use that side's levels."""
    m = sensitivity_model(kind)
    fc = m.friction.fc
    model = m.with_friction(fc_neg=1.2 * fc, fs_neg=1.5 * fc, vs_neg=2e-3, sigma2_neg=30.0, ripple_period=2e-6,
                            ripple_cos1=0.05 * fc, ripple_sin1=-0.03 * fc)
    names = ("fc_neg", "fs_neg", "vs_neg", "sigma2_neg", "ripple_cos1", "ripple_sin1", "fc")
    t = np.linspace(0.0, 0.21, 1051)
    x, S, _ = x_e_and_sensitivities(model, names, t)
    x_ref, _ = x_e(model, t)
    np.testing.assert_allclose(x, x_ref, atol=1e-6 * np.ptp(x_ref))
    for j, name in enumerate(names):
        v = model.friction.values()[name]
        h = 1e-3 * abs(v)
        xp, _ = x_e(model.with_friction(**{name: v + h}), t)
        xm, _ = x_e(model.with_friction(**{name: v - h}), t)
        fd = (xp - xm) / (2 * h)
        scale = np.max(np.abs(S[:, j])) + np.max(np.abs(fd))
        assert scale * abs(v) > 1e-6 * np.ptp(x_ref), f"{name} moves nothing here: the test would not see an error"
        assert np.max(np.abs(S[:, j] - fd)) / scale < 1e-3, name


def test_real_time_step_sides_and_ripple():
    """Closed form: the real-time LuGre at constant velocity reaches steady sliding, g_side(v) + sigma2_side v
    (with sign), plus the ripple at the position the steps reach (x = v t)."""
    fr = tf.LuGre(sigma0=1e5, sigma1=300.0, fc=1.0, fs=1.5, vs=1e-3, sigma2=0.4, fc_neg=1.3, sigma2_neg=0.7,
                  ripple_period=0.05, ripple_sin1=0.1)
    model = tf.Model(tf.PrescribedMotion(), fr)
    dt, n, v = 1e-4, 4000, 0.01
    for sign in (1, -1):
        F, _ = friction_steps(model, np.full(n, sign * v), dt)
        x = sign * v * dt * n
        level = (1.0 + 0.4 * v) if sign > 0 else (1.3 + 0.7 * v)
        expect = sign * level + 0.1 * math.sin(2 * math.pi * x / 0.05)
        assert F[-1] == pytest.approx(expect, abs=1e-6 * level), (sign, F[-1], expect)


def test_model_file_ripple_table_and_checks(tmp_path):
    """The model file's ripple table reads as the flat parameters and survives a round trip; a negative side
    below its Coulomb level and ripple amplitudes without a period are refused, naming the key."""
    text = """[plant]
type = "prescribed"
[friction]
model = "stribeck"
fc = 1.0
fs = 1.5
vs = 1e-3
fc_neg = 1.2
ripple = { period = 0.1257, cos = [0.01, 0.002], sin = [0.0, -0.003] }
"""
    path = tmp_path / "m.toml"
    path.write_text(text)
    m = tf.load_model(path)
    assert (m.friction.fc_neg, m.friction.ripple_period, m.friction.ripple_cos2, m.friction.ripple_sin2) == \
        (1.2, 0.1257, 0.002, -0.003)
    out = tmp_path / "out.toml"
    m.save(out)
    assert tf.load_model(out).friction == m.friction
    with pytest.raises(tf.InputError, match="fs_neg"):
        path.write_text(text.replace("fc_neg = 1.2", "fc_neg = 1.2\nfs_neg = 1.1"))
        tf.load_model(path)
    with pytest.raises(tf.InputError, match="period"):
        path.write_text(text.replace("period = 0.1257, ", ""))
        tf.load_model(path)


def test_identify_lookalike_asymmetry_and_ripple():
    """Oracle: tests/lookalike.py, an independent LuGre with fc/fs per direction and a position ripple
    (SciPy LSODA), white noise, one shared offset. A LuGre fit of fc, fc_neg, fs, fs_neg, sigma2 and the
    ripple's first sine recovers each within its 95 % interval (twice the half-width) and the held-out error
    is at the noise."""
    truth = L.Truth(ripple=0.03)
    data, runs = L.lookalike_experiments(truth=truth, offsets=(0.02, 0.02, 0.02), rho=0.0, noise=0.01,
                                         velocity_step=0.0, position_step=0.0, force_step=0.0, lag=0.0,
                                         duration=8.0, seed=4)
    init = tf.Model(tf.PrescribedMotion(motion="rotary"),
                    tf.LuGre(sigma0=100.0, sigma1=0.5, fc=0.3, fs=0.4, vs=0.08, sigma2=0.1,
                             ripple_period=truth.ripple_period, v_smooth=1e-3))
    names = ["fc", "fc_neg", "fs", "fs_neg", "sigma2", "ripple_sin1", "ripple_cos1"]
    fit = tf.identify(data, "base", init=init, parameters=names, starts=1)
    want = {"fc": truth.fc_pos, "fc_neg": truth.fc_neg, "fs": truth.fs_pos, "fs_neg": truth.fs_neg,
            "sigma2": truth.sigma2, "ripple_sin1": truth.ripple, "ripple_cos1": 0.0}
    for name in names:
        p = fit.parameters[name]
        half = 0.5 * (p.ci95[1] - p.ci95[0])
        assert abs(p.value - want[name]) <= 2 * half + 1e-12, (name, p.value, want[name], p.ci95)
    v = tf.validate(fit.model, data)
    held = [p for p in v.predictions if p.role == "validate"][0]
    assert held.rmse < 1.5 * 0.01, held.rmse


def test_fmu_with_asymmetry_and_ripple(tmp_path):
    """Oracle: tf.simulate of the same model (itself tested against the reference above). The exported
    FMU of an asymmetric LuGre mass with a ripple, run by fmpy, gives the same displacement to 2e-3 of its
    range (fmpy holds the input over each step), ten times closer than the symmetric model's, and its
    parameters include fc_neg and the ripple's amplitudes."""
    fmpy = pytest.importorskip("fmpy")
    model = tf.Model(tf.MassPlant(mass=1.0, spring_stiffness=2.0),
                     tf.LuGre(sigma0=1e5, sigma1=300.0, fc=1.0, fs=1.5, vs=1e-3, sigma2=0.4, vd=5e-3, fc_neg=1.3,
                              sigma2_neg=0.7, ripple_period=2e-3, ripple_cos1=0.05), input=tf.Sine(3.0, 0.5))
    path = tmp_path / "m.fmu"
    tf.export_fmu(model, path)
    names = {v.name for v in fmpy.read_model_description(str(path)).modelVariables}
    assert {f"friction.{n}" for n in ("fc_neg", "sigma2_neg", "ripple_cos1", "ripple_period")} <= names, sorted(names)
    t = np.arange(4001) * 5e-4
    signal = np.array(list(zip(t, model.input(t))), dtype=[("time", float), ("force", float)])
    out = fmpy.simulate_fmu(str(path), stop_time=2.0, output_interval=5e-4, input=signal, output=["displacement"])
    res = tf.simulate(model, input=tf.Sampled(t, model.input(t)), t_eval=out["time"])
    x = res.displacement
    err = np.max(np.abs(out["displacement"] - x))
    assert err <= 2e-3 * np.ptp(x), err / np.ptp(x)  # the master holds the input over each 0.5 ms step
    symmetric = model.with_friction(fc_neg=None, sigma2_neg=None, ripple_period=None, ripple_cos1=None)
    x_sym = tf.simulate(symmetric, input=tf.Sampled(t, model.input(t)), t_eval=out["time"]).displacement
    assert np.max(np.abs(out["displacement"] - x_sym)) > 10 * err  # the FMU ran the asymmetric model
