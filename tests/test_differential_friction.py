"""Differential tests of the friction-model library: the C core against an independent reference.

The oracle is tests/reference/ (ReferenceSystem, reference_simulate_system): the equations of
docs/models.md (#plants, #friction-models, #thermal-extensions) written again in plain
Python/NumPy/SciPy -- Coulomb and Stribeck static maps (tanh(v/v_smooth) sign), Dahl, LuGre,
elasto-plastic (Dupont 2002), generalized Maxwell-slip (GMS: stick/slip switches as solve_ivp
terminal events, restarted in the new modes), on the stick-slip actuator, the spring-pulled /
force-driven mass and prescribed motion, with Model I laws and both Model II forms -- without
calling the C core or the library's law and waveform evaluation. The reference itself is checked
against closed forms first (section 0). Each test's docstring names its oracle.
"""

from __future__ import annotations

import functools
import math
import sys
import warnings
import zlib
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from thermofriction import _bridge
from thermofriction.models import ModelI, ModelII

sys.path.insert(0, str(Path(__file__).resolve().parent))
import reference as R  # noqa: E402

# ---------------------------------------------------------------------------------------------
# Models: the Canudas de Wit et al. (1995) set on a spring-pulled mass and under prescribed
# motion; the Li et al. (2009) actuator (the li2009-base preset's plant and input)
# ---------------------------------------------------------------------------------------------

CANUDAS = dict(sigma0=1e5, sigma1=math.sqrt(1e5), sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)


def canudas_friction(kind):
    """Each model with the Canudas 1995 levels: fc = 1 N, fs = 1.5 N, vs = 1 mm/s, sigma0 = 1e5 N/m,
    sigma2 = 0.4 N s/m (static maps smoothed over 0.1 mm/s; GMS: three elements of unequal
    stiffness/capacity ratio, so that they break loose one after the other)."""
    return {
        "coulomb": lambda: tf.Coulomb(fc=1.0, sigma2=0.4, v_smooth=1e-4),
        "stribeck": lambda: tf.Stribeck(fc=1.0, fs=1.5, vs=1e-3, sigma2=0.4, v_smooth=1e-4),
        "dahl": lambda: tf.Dahl(sigma0=1e5, fc=1.0),
        "lugre": lambda: tf.LuGre(**CANUDAS),
        "elastoplastic": lambda: tf.ElastoPlastic(**CANUDAS, z_ba=5e-6),
        "gms": lambda: tf.GMS(k=(1e4, 3e4, 6e4), w=(0.3, 0.3, 0.4), C=200.0, fc=1.0, fs=1.5, vs=1e-3, sigma2=0.4),
    }[kind]()


def actuator_friction(kind):
    """Each model at the li2009-base preset's levels (sigma0 = 1.95e6 N/m, sigma1 = 2.3 N s/m,
    fc = 0.9 N; Stribeck fs = 1.5 fc, vs = 1 mm/s where the model has it)."""
    p = tf.load_model("li2009-base").friction
    s0, s1, fc = p.sigma0, p.sigma1, p.fc
    return {
        "coulomb": lambda: tf.Coulomb(fc=fc, v_smooth=1e-5),
        "stribeck": lambda: tf.Stribeck(fc=fc, fs=1.5 * fc, vs=1e-3, v_smooth=1e-5),
        "dahl": lambda: tf.Dahl(sigma0=s0, fc=fc),
        "lugre": lambda: p,
        "elastoplastic": lambda: tf.ElastoPlastic(sigma0=s0, sigma1=s1, fc=fc, z_ba=0.4 * fc / s0),
        "gms": lambda: tf.GMS(k=(3e5, 6e5, 1e6), w=(0.3, 0.3, 0.4), C=1e4, fc=fc, fs=1.5 * fc, vs=1e-3),
    }[kind]()


KINDS = ("coulomb", "stribeck", "dahl", "lugre", "elastoplastic", "gms")
SPRING = tf.MassPlant(mass=1.0, spring_stiffness=2.0, pull_velocity=0.1)
SINE_20UM = tf.Sine(2e-5, 2.0)
TRIANGLE_1MM = tf.Sawtooth(1e-3, 1.0, rise=0.5, offset=-5e-4)


def mass_model(kind, input=None):
    return tf.Model(SPRING, canudas_friction(kind), input=input)


def prescribed_model(kind, input=SINE_20UM):
    return tf.Model(tf.PrescribedMotion(), canudas_friction(kind), input=input)


def actuator_model(kind):
    base = tf.load_model("li2009-base")
    return tf.Model(base.plant, actuator_friction(kind), input=base.input)


# Model I and Model II variants
RAMP = tf.Sampled(np.array([0.0, 0.3, 1.0]), np.array([30.0, 36.0, 40.0]))


def ep_model_i(plant=SPRING, input=None):
    """Elasto-plastic with Model I laws for sigma0, sigma1, fc, fs (1e5 N/m, 316 N s/m, 1 N, 1.5 N at
    30 C, falling with temperature)."""
    laws = {"sigma0": tf.Exp(1e5 * math.exp(0.3), -0.01), "sigma1": tf.Linear(-3.0, 406.2),
            "fc": tf.Linear(-0.02, 1.6), "fs": tf.Linear(-0.03, 2.4)}
    fr = tf.ElastoPlastic(sigma0=None, sigma1=None, fc=None, z_ba=4e-6, sigma2=0.4, vs=1e-3)
    return tf.Model(plant, fr, ModelI(laws), input=input)


def gms_model_i(plant=SPRING, input=None):
    """GMS with Model I laws for C and fc (fs follows fc)."""
    fr = tf.GMS(k=(1e4, 3e4, 6e4), w=(0.3, 0.3, 0.4), C=None, fc=None, sigma2=0.4)
    return tf.Model(plant, fr, ModelI({"C": tf.Linear(5.0, 50.0), "fc": tf.Exp(1.0 * math.exp(0.6), -0.02)}),
                    input=input)


def dahl_model_i():
    """Dahl on the actuator with the paper's Model I laws for sigma0 and fc (Eqs. 9, 11)."""
    m = tf.load_model("li2009-model-i")
    laws = {k: v for k, v in m.thermal.laws.items() if k in ("sigma0", "fc")}
    return tf.Model(m.plant, tf.Dahl(sigma0=None, fc=None), ModelI(laws), input=m.input)


DF_PAPER = tf.load_model("li2009-model-ii").thermal.dF  # Eq. 13 (pwl), -0.23 N at 40 C


def with_model_ii(model, form):
    return tf.Model(model.plant, model.friction, ModelII(DF_PAPER, form), input=model.input)


# ---------------------------------------------------------------------------------------------
# 0. the oracle against closed forms
# ---------------------------------------------------------------------------------------------

def test_reference_gms_single_element_closed_form():
    """Oracle: closed form. One GMS element (k, w = 1, no Stribeck) under a triangle x_r of
    slope +-V: stuck, F = k V t until F = fc at t1 = fc/(k V); slipping at its capacity (F' = 0);
    stuck again at the corner and unloaded at -k V; breaks loose at -fc after 2 fc/(k V) more.
    The reference's event handling reproduces this to 1e-9 fc, with the break-away times. (At rtol
    1e-12: the slipping phase's global error is ~200 rtol fc -- 2.2e-9 at 1e-11 on one machine, under 1e-9
    on another -- so 1e-11 left no margin.)"""
    k, fc, V = 1e4, 1.0, 2e-3
    model = tf.Model(tf.PrescribedMotion(), tf.GMS(k=(k,), w=(1.0,), C=200.0, fc=fc),
                     input=tf.Sawtooth(1e-3, 1.0, rise=0.5, offset=-5e-4))
    t = np.linspace(0.0, 1.0, 2001)
    ref = R.reference_simulate(model, t, rtol=1e-12)
    t1, t2 = fc / (k * V), 0.5 + 2 * fc / (k * V)
    exact = np.where(t <= t1, k * V * t, np.where(t <= 0.5, fc, np.where(t <= t2, fc - k * V * (t - 0.5), -fc)))
    np.testing.assert_allclose(ref.friction_force, exact, rtol=0, atol=1e-9 * fc)
    assert ref.events == 2


def test_reference_dahl_and_lugre_ramp_closed_form():
    """Oracle: closed form. Under a constant sliding velocity V (prescribed ramp), Dahl's state is
    z(t) = fc/sigma0 (1 - exp(-sigma0 V t/fc)); LuGre's the same with g(V), F = sigma0 z + sigma1 z'
    + sigma2 V. The reference integrates both to 1e-9 of the force."""
    V = 2e-4
    ramp = tf.Sampled(np.array([0.0, 1.0]), np.array([0.0, V]))
    t = np.linspace(0.0, 0.5, 501)
    for fr in (tf.Dahl(sigma0=1e5, fc=1.0), tf.LuGre(**CANUDAS)):
        ref = R.reference_simulate(tf.Model(tf.PrescribedMotion(), fr, input=ramp), t, rtol=1e-11)
        g = 1.0 if fr.model == "dahl" else 1.0 + 0.5 * math.exp(-((V / 1e-3) ** 2))
        z = g / fr.sigma0 * (1 - np.exp(-fr.sigma0 * V * t / g))
        zd = V * np.exp(-fr.sigma0 * V * t / g)
        F = fr.sigma0 * z + (0.0 if fr.model == "dahl" else fr.sigma1 * zd + fr.sigma2 * V)
        np.testing.assert_allclose(ref.friction_force, F, rtol=0, atol=1e-9 * g)


def test_reference_system_equals_the_lugre_actuator_reference():
    """Oracle self-check: the reference's two drivers agree. reference_simulate (ReferenceModel, LuGre
    on the actuator: t_eval output, the input taken at t) and reference_simulate_system (dense output,
    the input's left limit at segment ends) share one friction implementation; they give the same
    rhs and, integrated, the same motion (1e-9 of the range)."""
    model = tf.load_model("li2009-model-i")
    T = 35.0
    a, b = R.ReferenceModel(model, T), R.ReferenceSystem(model, T)
    rng = np.random.default_rng(5)
    for _ in range(50):
        y = [rng.normal() * 1e-6, rng.normal() * 1e-2, rng.normal() * 1e-6, rng.normal() * 1e-2, rng.normal() * 1e-6]
        t = rng.uniform(0, 1)
        np.testing.assert_allclose(b.rhs(t, y), a.rhs(t, y), rtol=1e-15, atol=0)
    t = np.arange(2001) / 10_000
    ra = R.reference_simulate(model, t, T)
    rb = R.reference_simulate_system(model, t, T)
    assert np.max(np.abs(ra.y[:, 2] - rb.displacement)) < 1e-9 * np.ptp(ra.y[:, 2])


def test_reference_static_maps_and_elastoplastic_alpha():
    """Oracle: the formulas of docs/models.md#friction-models evaluated directly: Coulomb
    fc tanh(v/v_smooth) + sigma2 v; Stribeck g(v) tanh(v/v_smooth) + sigma2 v; the elasto-plastic
    alpha is 0 below z_ba and for z against v, 1 at and beyond g(v)/sigma0, 1/2 halfway, and
    continuous."""
    for v in (-3e-3, -2e-5, 0.0, 7e-5, 1e-2):
        p = R.friction_params(mass_model("stribeck"), math.nan)
        g = 1.0 + 0.5 * math.exp(-((v / 1e-3) ** 2))
        assert R.base_friction("stribeck", p, v, [])[0] == pytest.approx(g * math.tanh(v / 1e-4) + 0.4 * v, rel=1e-15)
        p = R.friction_params(mass_model("coulomb"), math.nan)
        assert R.base_friction("coulomb", p, v, [])[0] == pytest.approx(math.tanh(v / 1e-4) + 0.4 * v, rel=1e-15)
    v0 = 2 * math.pi * 2.0 * 2e-5  # the 20 um, 2 Hz sine's slope at t = 0
    assert R.friction_force(prescribed_model("coulomb"), 0.0, []) == pytest.approx(math.tanh(v0 / 1e-4) + 0.4 * v0,
                                                                                  rel=1e-15)
    p = R.friction_params(mass_model("elastoplastic"), math.nan)
    v = 5e-4
    zss = R.stribeck_g(p, v) / p.sigma0
    assert R.elastoplastic_alpha(p, 0.99 * p.z_ba, v, R.stribeck_g(p, v)) == 0.0
    assert R.elastoplastic_alpha(p, -0.5 * zss, v, R.stribeck_g(p, v)) == 0.0
    assert R.elastoplastic_alpha(p, 0.8 * zss, -v, R.stribeck_g(p, v)) == 0.0
    assert R.elastoplastic_alpha(p, zss, v, R.stribeck_g(p, v)) == 1.0
    assert R.elastoplastic_alpha(p, 0.5 * (zss + p.z_ba), v, R.stribeck_g(p, v)) == pytest.approx(0.5, abs=1e-15)
    assert R.elastoplastic_alpha(p, -0.5 * (zss + p.z_ba), -v, R.stribeck_g(p, v)) == pytest.approx(0.5, abs=1e-15)
    zz = np.linspace(p.z_ba, zss, 10001)
    a = np.array([R.elastoplastic_alpha(p, z, v, R.stribeck_g(p, v)) for z in zz])
    assert np.all(np.diff(a) >= 0) and np.max(np.abs(np.diff(a))) < 2e-3


# ---------------------------------------------------------------------------------------------
# a. right-hand side and Jacobian, every model x plant
# ---------------------------------------------------------------------------------------------

# name: (model factory, temperature, GMS modes: None, "stuck", "slipping" or "mixed")
RHS_CASES = {}
for _kind in KINDS:
    _modes = ("stuck", "slipping", "mixed") if _kind == "gms" else (None,)
    for _mode in _modes:
        _sfx = f"-{_mode}" if _mode else ""
        RHS_CASES[f"mass-{_kind}{_sfx}"] = (functools.partial(mass_model, _kind, tf.Sine(0.5, 1.3)), None, _mode)
        RHS_CASES[f"prescribed-{_kind}{_sfx}"] = (functools.partial(prescribed_model, _kind), None, _mode)
        RHS_CASES[f"prescribed-triangle-{_kind}{_sfx}"] = (
            functools.partial(prescribed_model, _kind, TRIANGLE_1MM), None, _mode)
        RHS_CASES[f"stick-slip-{_kind}{_sfx}"] = (functools.partial(actuator_model, _kind), None, _mode)
RHS_CASES.update({
    "mass-elastoplastic-model-i-ramp": (ep_model_i, RAMP, None),
    "prescribed-elastoplastic-model-i-ramp": (lambda: ep_model_i(tf.PrescribedMotion(), SINE_20UM), RAMP, None),
    "mass-gms-model-i-ramp-mixed": (gms_model_i, RAMP, "mixed"),
    "mass-gms-model-i-ramp-slipping": (gms_model_i, RAMP, "slipping"),
    "stick-slip-dahl-model-i-ramp": (dahl_model_i, RAMP, None),
    "mass-lugre-model-ii-scale": (lambda: with_model_ii(mass_model("lugre"), "scale"), 40.0, None),
    "mass-stribeck-model-ii-offset": (lambda: with_model_ii(mass_model("stribeck"), "offset"), RAMP, None),
    "prescribed-gms-model-ii-scale-mixed": (lambda: with_model_ii(prescribed_model("gms"), "scale"), RAMP, "mixed"),
    "prescribed-dahl-model-ii-offset": (lambda: with_model_ii(prescribed_model("dahl"), "offset"), 33.0, None),
    "stick-slip-elastoplastic-model-ii-scale": (lambda: with_model_ii(actuator_model("elastoplastic"), "scale"),
                                                RAMP, None),
    "stick-slip-coulomb-model-ii-offset": (lambda: with_model_ii(actuator_model("coulomb"), "offset"), 37.0, None),
})


def _velocity_bands(p, kind, offset):
    """The velocity scales over which the friction law changes (for finite-difference steps)."""
    b = []
    if kind in ("coulomb", "stribeck") or offset:
        b.append(p.v_smooth)
    if p.fs != p.fc:
        b.append(p.vs)
    if p.vd is not None:
        b.append(p.vd)
    return b


def random_case_state(ref, t, rng, modes_kind, v_min=1e-9, vp_over_v=None, margin=0.0):
    """A random state (and GMS modes) on each state's natural scale: |v_r| log-uniform in
    [v_min, 0.1] m/s with a random sign (prescribed: v_r is the input's slope at t); z within
    1.5 fc/sigma0 (GMS element forces within 1.2 w_i fs). margin > 0 keeps the elasto-plastic z
    that far (relative) from alpha's switching deflections."""
    sc = ref.scales()
    p = ref.params_at_time(t)
    nm = ref.nm
    y = np.zeros(ref.n)
    v = math.copysign(10 ** rng.uniform(math.log10(v_min), -1), rng.standard_normal())
    if ref.plant == "stick-slip":
        v_p = sc[1] * rng.standard_normal()
        if vp_over_v is not None:
            v_p = math.copysign(min(abs(v_p), vp_over_v * abs(v)), v_p)
        y[:4] = [sc[0] * rng.uniform(-1, 1), v_p, sc[0] * rng.uniform(-1, 1), v_p + v]
    elif ref.plant == "mass":
        y[:2] = [rng.uniform(-0.5, 0.5), v]
    else:
        v = ref.velocity(t, y)
    modes = None
    if ref.kind == "gms":
        y[nm:] = np.array(p.w) * p.fs * rng.uniform(-1.2, 1.2, ref.nz)
        s = 1 if v > 0 else -1
        modes = {"stuck": [0] * ref.nz, "slipping": [s] * ref.nz,
                 "mixed": [int(rng.integers(0, 2)) * s for _ in range(ref.nz)]}[modes_kind]
    elif ref.nz:
        Z = sc[nm]
        while True:
            z = Z * rng.uniform(-1.5, 1.5)
            if ref.kind != "elastoplastic" or margin == 0.0:
                break
            zss = R.stribeck_g(p, v) / p.sigma0
            if min(abs(abs(z) - p.z_ba), abs(abs(z) - zss)) > margin * Z:
                break
        y[nm] = z
    return y, modes


def term_magnitudes(ref, t, y):
    """For each dy_i and for F, the sum of the absolute values of the terms (their rounding scale)."""
    p = ref.params_at_time(t)
    v = ref.velocity(t, y)
    z = y[ref.nm:]
    k = ref.kind
    if k in ("coulomb", "stribeck"):
        F = R.stribeck_g(p, v) + p.sigma2 * abs(v)
        zd = []
    elif k == "dahl":
        zd = [abs(v) + p.sigma0 * abs(v) * abs(z[0]) / p.fc]
        F = p.sigma0 * abs(z[0])
    elif k in ("lugre", "elastoplastic"):
        zd = [abs(v) + p.sigma0 * abs(v) * abs(z[0]) / R.stribeck_g(p, v)]
        F = p.sigma0 * abs(z[0]) + p.sigma1 * zd[0] + p.sigma2 * abs(v)
    else:
        g = R.stribeck_g(p, v)
        zd = [kk * abs(v) if m == 0 else p.C * (w + abs(Fi) / g) for kk, w, Fi, m in zip(p.k, p.w, z, ref.modes)]
        F = float(np.sum(np.abs(z))) + p.sigma2 * abs(v)
    F = abs(p.lam) * F + abs(p.dF_offset)
    if ref.plant == "stick-slip":
        u = abs(ref.input_value(t))
        mech = [abs(y[1]), (ref.c * abs(y[1]) + ref.k * abs(y[0]) + abs(ref.T_em) * u + F) / ref.m, abs(y[3]),
                F / ref.m_e]
    elif ref.plant == "mass":
        mech = [abs(y[1]), (abs(ref.input_value(t)) + ref.k_s * (abs(ref.v_0 * t) + abs(y[0])) + F) / ref.m]
    else:
        mech = []
    return np.array(mech + list(zd), float), F


def core_eval(spec, t, y, jac=False):
    n = len(y)
    dy = np.empty(n)
    J = np.empty((n, n)) if jac else None
    F = _bridge.rhs_jac(spec, float(t), np.ascontiguousarray(y, float), dy, J)
    return dy, F, J


def _spec(model, temperature, modes):
    spec = _bridge.model_spec(model, temperature, None)
    if modes is not None:
        spec["gms_mode"] = np.array(modes, float)
    return spec


def _times(model, temperature, rng, n):
    """Random times in [0, 1], the first ones replaced by the input's corners (a triangle's: v_r
    is its right-hand slope there) and the temperature's knots."""
    times = list(rng.uniform(0.0, 1.0, n))
    extra = list(R.waveform_corners(model.input, 0.0, 1.0, include_start=True)) if model.input is not None else []
    if isinstance(temperature, tf.Sampled):
        extra += list(temperature.time)
    times[: len(extra)] = extra
    return times


@pytest.mark.parametrize("case", list(RHS_CASES))
def test_rhs_matches_reference(case):
    """Oracle: independent reference implementation (tests/reference/, ReferenceSystem: every
    friction model on every plant, Model I laws, Model II forms, GMS modes given). The C rhs_jac's
    derivatives and friction force agree with it to 1e-12 of the terms' magnitudes at 200 random
    states and times (prescribed motion: v_r the input's slope at that time)."""
    make, temperature, modes_kind = RHS_CASES[case]
    model = make()
    rng = np.random.default_rng(zlib.crc32(case.encode()))
    worst = 0.0
    for t in _times(model, temperature, rng, 200):
        ref0 = R.ReferenceSystem(model, temperature)
        y, modes = random_case_state(ref0, t, rng, modes_kind)
        ref = R.ReferenceSystem(model, temperature, gms_mode=modes)
        dy_c, F_c, _ = core_eval(_spec(model, temperature, modes), t, y)
        dy_r = np.array(ref.rhs(t, list(y)))
        F_r = ref.friction(t, y)
        mag, F_mag = term_magnitudes(ref, t, y)
        err = np.abs(dy_c - dy_r) / np.where(mag > 0, mag, 1.0)
        e = max(err.max(initial=0.0), abs(F_c - F_r) / F_mag)
        worst = max(worst, e)
        assert e < 1e-12, (case, t, y, modes, dy_c, dy_r, F_c, F_r)
    print(f"{case}: worst relative difference {worst:.2e}")


def fd_jacobian(ref, t, y, h):
    """Five-point central differences of the reference rhs (error O(h^4)), steps h per state."""
    n = ref.n
    J = np.empty((n, n))
    for j in range(n):
        f = []
        for s in (-2, -1, 1, 2):
            yy = y.copy()
            yy[j] += s * h[j]
            f.append(np.array(ref.rhs(t, list(yy))))
        J[:, j] = (f[0] - 8 * f[1] + 8 * f[2] - f[3]) / (12 * h[j])
    return J


@pytest.mark.parametrize("case", [c for c in RHS_CASES if not (
    c.startswith("prescribed") and any(k in c for k in ("coulomb", "stribeck")))])
def test_jacobian_matches_finite_differences_of_reference(case):
    """Oracle: five-point central finite differences of the independent reference implementation's
    rhs (tests/reference/, GMS modes held). The C analytic Jacobian agrees to 1e-6 of each row's
    scale at 60 random states; steps are 1e-4 of each state's local scale (velocities: the
    smallest of |v_r| and the friction's velocity bands; elasto-plastic z kept 1e-3 of fc/sigma0
    away from alpha's switching deflections)."""
    make, temperature, modes_kind = RHS_CASES[case]
    model = make()
    rng = np.random.default_rng(1 + zlib.crc32(case.encode()))
    worst = 0.0
    for t in _times(model, temperature, rng, 60):
        ref0 = R.ReferenceSystem(model, temperature)
        y, modes = random_case_state(ref0, t, rng, modes_kind, v_min=1e-7, vp_over_v=30.0, margin=1e-3)
        ref = R.ReferenceSystem(model, temperature, gms_mode=modes)
        _, _, J = core_eval(_spec(model, temperature, modes), t, y, jac=True)
        p = ref.params_at_time(t)
        v = ref.velocity(t, y)
        vloc = min([abs(v), *_velocity_bands(p, ref.kind, p.dF_offset != 0.0)])
        sc = ref.scales()
        loc = sc.copy()
        if ref.plant == "stick-slip":
            loc[[1, 3]] = vloc
        elif ref.plant == "mass":
            loc[1] = vloc
        J_fd = fd_jacobian(ref, t, y, 1e-4 * loc)
        # compare the Jacobian scaled to each state's local scale, row by row; the floor is far
        # above the differences' rounding noise (~1e-12 of the row's term magnitudes)
        A_c, A_fd = J * loc, J_fd * loc
        row = np.max(np.abs(A_fd), axis=1) + 1e-3 * term_magnitudes(ref, t, y)[0]
        dev = np.abs(A_c - A_fd) / row[:, None]
        worst = max(worst, dev.max())
        assert np.all(dev <= 1e-6), (case, t, y, modes, J, J_fd, dev)
    print(f"{case}: worst scaled Jacobian difference {worst:.2e}")


# ---------------------------------------------------------------------------------------------
# b. full simulations
# ---------------------------------------------------------------------------------------------

# name: (model factory, temperature, duration [s], sample rate [Hz], reference method, reference max_step [s])
# (LSODA for the smoothed static maps: stiff near v = 0, where DOP853 would take minutes. max_step, for GMS:
#  an adaptive step can jump the short window in which a slipping element's force, exactly constant while
#  |v| >> vs, follows g(v) up before a reversal (mass-force-square-gms: 2e-3 of the range without it); 1 ms
#  on the mass and under prescribed motion, 0.1 ms on the actuator. Checked once: every reference here moves
#  by < 1e-8 of its range at rtol 1e-11 and a fifth of its max_step (or 1 ms where it has none).)
MS_MASS, MS_PRESCRIBED, MS_ACTUATOR = 1e-3, 1e-3, 1e-4
SIM_CASES = {}
for _kind in KINDS:
    _meth = "LSODA" if _kind in ("coulomb", "stribeck") else "DOP853"
    _ms = 1.0 if _kind == "gms" else math.inf
    SIM_CASES[f"mass-canudas-{_kind}"] = (functools.partial(mass_model, _kind), None, 12.0, 1000, _meth,
                                          _ms * MS_MASS)
    SIM_CASES[f"prescribed-sine-20um-{_kind}"] = (functools.partial(prescribed_model, _kind), None, 1.25, 4000, _meth,
                                                  _ms * MS_PRESCRIBED)
    SIM_CASES[f"prescribed-triangle-1mm-{_kind}"] = (
        functools.partial(prescribed_model, _kind, TRIANGLE_1MM), None, 2.0, 4000, _meth, _ms * MS_PRESCRIBED)
    SIM_CASES[f"stick-slip-{_kind}"] = (functools.partial(actuator_model, _kind), None, 0.4, 10_000, _meth,
                                        _ms * MS_ACTUATOR)
SIM_CASES.update({
    # a force-driven mass (no spring): stick-slip under a sine force; GMS under a square force (corners + events)
    "mass-force-sine-lugre": (lambda: tf.Model(tf.MassPlant(1.0), canudas_friction("lugre"), input=tf.Sine(1.6, 0.5)),
                              None, 4.0, 1000, "DOP853", math.inf),
    "mass-force-square-gms": (lambda: tf.Model(tf.MassPlant(1.0), canudas_friction("gms"),
                                               input=tf.Square(2.4, 1.0, slew=0.05, offset=-1.2)), None, 3.0, 1000,
                              "DOP853", MS_MASS),
    "mass-elastoplastic-model-i-ramp": (ep_model_i, RAMP, 12.0, 1000, "DOP853", math.inf),
    "mass-gms-model-i-35C": (gms_model_i, 35.0, 12.0, 1000, "DOP853", MS_MASS),
    "mass-stribeck-model-ii-offset-40C": (lambda: with_model_ii(mass_model("stribeck"), "offset"), 40.0, 12.0, 1000,
                                          "LSODA", math.inf),
    "prescribed-sine-gms-model-ii-scale-ramp": (lambda: with_model_ii(prescribed_model("gms"), "scale"), RAMP, 1.0,
                                                4000, "DOP853", MS_PRESCRIBED),
    "prescribed-triangle-lugre-model-ii-offset-40C": (
        lambda: with_model_ii(prescribed_model("lugre", TRIANGLE_1MM), "offset"), 40.0, 2.0, 4000, "DOP853",
        math.inf),
    "stick-slip-dahl-model-i-35C": (dahl_model_i, 35.0, 0.4, 10_000, "DOP853", math.inf),
    "stick-slip-elastoplastic-model-ii-scale-40C": (
        lambda: with_model_ii(actuator_model("elastoplastic"), "scale"), 40.0, 0.4, 10_000, "DOP853", math.inf),
})
SOLVERS = {"auto": tf.AutoSwitch(), "dopri5": tf.Dopri5(), "rodas4": tf.Rodas4()}
SLOW_CASES: set = set()

# (name, solver): (reason, exception raised or None) -- known misses, marked strict xfail
KNOWN: dict = {}


def _sim_params():
    for name in SIM_CASES:
        for solver in SOLVERS:
            marks = [pytest.mark.slow] if name in SLOW_CASES else []
            if (name, solver) in KNOWN:
                reason, raises = KNOWN[name, solver]
                marks.append(pytest.mark.xfail(reason=reason, strict=True, raises=raises))
            yield pytest.param(name, solver, marks=marks, id=f"{name}-{solver}")


@functools.cache
def sim_reference(name):
    make, T, duration, rate, method, max_step = SIM_CASES[name]
    t = np.arange(int(round(duration * rate)) + 1) / rate
    return R.reference_simulate_system(make(), t, T, method=method, rtol=1e-10, max_step=max_step)


@pytest.mark.parametrize("name, solver", list(_sim_params()))
def test_simulation_matches_tight_reference(name, solver):
    """Oracle: independent reference implementation (tests/reference/, reference_simulate_system)
    integrated by SciPy solve_ivp at rtol 1e-10 (per-state atol), restarted at every corner of the
    input and knot of the temperature and, for GMS, at every stick/slip switch (terminal events).
    At default tolerances every C solver keeps the driven body's displacement (the stage's too on
    the actuator) within 0.1 % of its range, or, under prescribed motion, the friction force within
    0.1 % of its range; the force output is the reference's friction law at the C states."""
    make, T, duration, rate, _, _ = SIM_CASES[name]
    model = make()
    ref = sim_reference(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tf.TemperatureRangeWarning)
        warnings.simplefilter("ignore", tf.PassivityWarning)
        warnings.simplefilter("ignore", tf.ConditioningWarning)
        res = tf.simulate(model, duration, temperature=T, sample_rate=rate, solver=SOLVERS[solver])
    assert res.time.shape == ref.time.shape and np.allclose(res.time, ref.time, rtol=0, atol=1e-12)
    F_range = np.ptp(ref.friction_force)
    F_err = np.max(np.abs(res.friction_force - ref.friction_force)) / F_range
    if model.plant.type == "prescribed":
        # the motion itself is the input: its value and right-hand slope
        np.testing.assert_allclose(res.displacement, ref.displacement, rtol=0,
                                   atol=1e-12 * np.max(np.abs(ref.displacement)))
        np.testing.assert_allclose(res.velocity, ref.velocity, rtol=0, atol=1e-12 * np.max(np.abs(ref.velocity)))
        print(f"{name} [{solver}]: max |F error| / range = {F_err:.2e}, range {F_range:.3g} N, "
              f"{res.stats['steps']} steps, {res.stats['events']} events (reference {ref.events})")
        assert F_range > 0
        assert F_err < 1e-3
        states = res.states
    else:
        x_range = np.ptp(ref.displacement)
        err = np.max(np.abs(res.displacement - ref.displacement)) / x_range
        msg = (f"{name} [{solver}]: max |x error| / range = {err:.2e}, range {x_range:.3e} m, force {F_err:.2e}, "
               f"{res.stats['steps']} steps, {res.stats['events']} events (reference {ref.events})")
        if model.plant.type == "stick-slip":
            xp_err = np.max(np.abs(res.stage_displacement - ref.stage_displacement)) / np.ptp(ref.stage_displacement)
            print(msg + f", stage {xp_err:.2e}")
            assert xp_err < 1e-3
            states = np.column_stack([res.stage_displacement, res.stage_velocity, res.displacement, res.velocity,
                                      res.states])
        else:
            print(msg)
            states = np.column_stack([res.displacement, res.velocity, res.states])
        assert x_range > 0
        assert err < 1e-3
    # the force output is the friction law at the states the solver returned (GMS: F does not
    # depend on the modes)
    sys_ = R.ReferenceSystem(model, T)
    idx = np.arange(0, res.time.size, max(1, res.time.size // 200))
    F_mine = np.array([sys_.friction(res.time[i], states[i]) for i in idx])
    np.testing.assert_allclose(res.friction_force[idx], F_mine, rtol=1e-9, atol=1e-12 * np.max(np.abs(F_mine)))


@pytest.mark.parametrize("solver", ["auto", "dopri5", "rodas4"])
def test_gms_breaks_loose_after_reversing_at_capacity(solver):
    """Oracle: closed form (one GMS element, see test_reference_gms_single_element_closed_form).
    Under a 1 mm triangle the element slips at +fc on the way up, sticks at the corner, is unloaded
    at k V and must break loose at -fc 0.1 s later: F(1 s) = -fc, whatever the solver."""
    k, fc = 1e4, 1.0
    model = tf.Model(tf.PrescribedMotion(), tf.GMS(k=(k,), w=(1.0,), C=200.0, fc=fc), input=TRIANGLE_1MM)
    res = tf.simulate(model, 1.0, sample_rate=1000, solver=SOLVERS[solver])
    print(f"{solver}: F(0.5 s) = {res.friction_force[500]:.6g} N, F(1 s) = {res.friction_force[-1]:.6g} N, "
          f"min {res.friction_force.min():.6g} N, {res.stats['events']} events")
    assert res.friction_force[500] == pytest.approx(fc, abs=1e-6)
    assert res.friction_force.min() >= -fc * (1 + 1e-6)
    assert res.friction_force[-1] == pytest.approx(-fc, abs=1e-6)


# ---------------------------------------------------------------------------------------------
# Forward sensitivities of every friction model (the identification's Jacobian) against central
# differences of whole simulations, on the actuator (the plant identification runs on)
# ---------------------------------------------------------------------------------------------

#: every parameter of the list each model reads (the actuator's levels, sigma2 > 0 so that it counts)
SENSITIVITY_PARAMETERS = {
    "coulomb": ("fc", "sigma2", "v_smooth"),
    "stribeck": ("fc", "fs", "vs", "delta", "sigma2", "v_smooth"),
    "dahl": ("sigma0", "fc"),
    "lugre": ("sigma0", "sigma1", "fc", "fs", "vs", "delta", "vd", "sigma2"),
    "elastoplastic": ("sigma0", "sigma1", "fc", "fs", "vs", "delta", "vd", "z_ba", "sigma2"),
    "gms": ("C", "fc", "fs", "vs", "delta", "sigma2"),
}


def sensitivity_model(kind):
    m = actuator_model(kind)
    extra = {"lugre": dict(fs=1.3 * m.friction.fc, vs=1e-3, vd=5e-3),
             "elastoplastic": dict(fs=1.3 * m.friction.fc, vs=1e-3, vd=5e-3)}.get(kind, {})
    if "sigma2" in SENSITIVITY_PARAMETERS[kind]:
        extra["sigma2"] = 20.0
    return m.with_friction(**extra)


def x_e_and_sensitivities(model, names, t, rtol=1e-10):
    """x_e(t) and dx_e/dtheta by the core's forward sensitivities (as identification/engine.py runs them)."""
    from thermofriction.fitting.parameters import target_of
    spec = _bridge.model_spec(model, 30.0, model.input)
    theta = np.array([model.friction.values()[n] for n in names], float)
    targets = np.array([target_of(model, n) for n in names], dtype=np.int32).reshape(-1, 3)
    atol_y = rtol * _bridge.state_scale(spec)
    atol_s = atol_y[:, None] / np.abs(theta)[None, :]
    out = np.empty((len(t), _bridge.n_outputs(model, False)))
    sens = np.empty((len(t), len(atol_y), len(names)))
    stats = _bridge.run_sensitivities(spec, targets, t, out, sens, rtol=rtol,
                                      atol=np.concatenate([atol_y, atol_s.ravel()]), max_steps=10_000_000)
    i = _bridge.state_index(model, "x_e")
    return out[:, _bridge.OUTPUT_COLUMN["displacement"]], sens[:, i, :], stats


def x_e(model, t, rtol=1e-12):
    spec = _bridge.model_spec(model, 30.0, model.input)
    out = np.empty((len(t), _bridge.n_outputs(model, False)))
    stats = _bridge.run(spec, t, out, method="dopri5", rtol=rtol)
    return out[:, _bridge.OUTPUT_COLUMN["displacement"]], stats


@pytest.mark.parametrize("kind", KINDS)
def test_sensitivities_match_finite_differences_of_simulations(kind):
    """Oracle: central differences (relative step 1e-3) of x_e(t) simulated at rtol 1e-12. The
    forward sensitivities of every parameter each model reads agree to 1e-3 of the largest
    sensitivity times the parameter (the displacement a 100 % change would make, to first order).
    For GMS the record holds stick-slip cycles, so elements break loose and re-stick (events):
    the sensitivities' jump at each switch is part of what is checked."""
    model = sensitivity_model(kind)
    names = SENSITIVITY_PARAMETERS[kind]
    t = np.linspace(0.0, 0.21, 1051)  # through the sawtooth's first flyback (0.1998 s), where it slips
    x, S, _ = x_e_and_sensitivities(model, names, t)
    x_ref, stats = x_e(model, t)
    # the same trajectory as a simulation (a sensitivity run that missed GMS's mode switches would not be)
    np.testing.assert_allclose(x, x_ref, atol=1e-6 * np.ptp(x_ref))
    if kind == "gms":
        assert stats["events"] >= 4, stats  # elements switched modes within the record
    for j, name in enumerate(names):
        v = model.friction.values()[name]
        h = 1e-3 * v  # (smaller steps drown the weakest sensitivities, sigma1's, in the solver's noise)
        xp, _ = x_e(model.with_friction(**{name: v + h}), t)
        xm, _ = x_e(model.with_friction(**{name: v - h}), t)
        fd = (xp - xm) / (2 * h)
        scale = np.max(np.abs(S[:, j])) + np.max(np.abs(fd))
        err = np.max(np.abs(S[:, j] - fd)) / scale
        print(f"{kind} {name}: |S| max {np.max(np.abs(S[:, j])) * v:.3g} m per 100 %, worst {err:.2e}")
        assert scale * v > 1e-6 * np.ptp(x_ref), f"{name} moves nothing here: the test would not see an error"
        assert err < 1e-3, f"{kind} {name}: sensitivity off by {err:.3g} of its scale"
