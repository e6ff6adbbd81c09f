"""The friction model library (docs/models.md: #mass-plant, #prescribed-motion, #friction-models,
#thermal-extensions) against analytic solutions and known properties.

Every test names its oracle in its docstring: a closed-form solution of the model's equations, a
linearisation, or a structural property of the model (no drift, return-point memory, Masing's
rule). None of them compares the library with itself, except where the property *is* an equality
between two runs (thermal extensions, return-point memory).
"""

import math
import warnings
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import thermofriction as tf
from conftest import run_cli

FC = 1.0
SIGMA0 = 1e5  # N/m: presliding deflection fc/sigma0 = 10 um


def stribeck_g(v, fc, fs, vs, delta=2.0):
    """docs/models.md#friction-models: g(v) = fc + (fs - fc) exp(-|v/vs|^delta)."""
    return fc + (fs - fc) * np.exp(-np.abs(np.asarray(v, float) / vs) ** delta)


def prescribed(friction, **kw):
    return tf.Model(tf.PrescribedMotion(), friction, **kw)


def tight(rtol=1e-9, **kw):
    return tf.StepSizeController(rtol=rtol, **kw)


# ---------------------------------------------------------------------------------------------
# 1. Dahl: closed form along the displacement, through reversals
# ---------------------------------------------------------------------------------------------

def dahl_closed_form(x, t, t_rev, x_rev, sigma0, fc):
    """Dahl's model is rate independent: with u = sgn(v) fixed between reversals, dF/dx =
    sigma0 (1 - u F / fc), so from a reversal at (x0, F0)
        F = u fc - (u fc - F0) exp(-sigma0 |x - x0| / fc).
    ``t_rev``/``x_rev`` are the start (0, 0) and the reversal points, in order."""
    F = np.empty_like(x)
    F0 = 0.0
    for k in range(len(t_rev)):
        t_end = t_rev[k + 1] if k + 1 < len(t_rev) else np.inf
        x_end = x_rev[k + 1] if k + 1 < len(t_rev) else None
        seg = (t >= t_rev[k]) & (t <= t_end)
        u = np.sign((x_end if x_end is not None else x[-1]) - x_rev[k])
        F[seg] = u * fc - (u * fc - F0) * np.exp(-sigma0 * np.abs(x[seg] - x_rev[k]) / fc)
        if x_end is not None:
            F0 = u * fc - (u * fc - F0) * math.exp(-sigma0 * abs(x_end - x_rev[k]) / fc)
    return F


def test_dahl_follows_its_closed_form_through_reversals__piecewise_linear_motion():
    """Analytic (Dahl 1968, integrated in x): F = u fc - (u fc - F0) exp(-sigma0 |x - x0|/fc)
    after each reversal (x0, F0), u the sign of the motion. The motion has minor and major
    reversals, travelling 0.5 to 4 presliding lengths fc/sigma0 between them."""
    model = prescribed(tf.Dahl(sigma0=SIGMA0, fc=FC))
    t_k = np.array([0.0, 1.0, 2.2, 3.2, 3.5, 4.5])
    x_k = np.array([0.0, 30e-6, -5e-6, 20e-6, 15e-6, 40e-6])
    res = tf.simulate(model, t_k[-1], input=tf.Sampled(t_k, x_k), sample_rate=1000, controller=tight(1e-8))
    assert np.allclose(res.displacement, np.interp(res.time, t_k, x_k), rtol=0, atol=1e-15)
    expected = dahl_closed_form(res.displacement, res.time, t_k[:-1], x_k[:-1], SIGMA0, FC)
    assert np.max(np.abs(res.friction_force - expected)) < 1e-6 * FC  # measured 8e-9
    # the bristle state is F / sigma0
    assert np.allclose(res.states[:, 0] * SIGMA0, res.friction_force, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("waveform, t_rev", [
    # triangle 0 -> 25 um -> 0 ... (reversals at the peaks and troughs)
    (tf.Sawtooth(amplitude=25e-6, frequency=2.0, rise=0.5), [0.0, 0.25, 0.5, 0.75, 1.0, 1.25]),
    # sine: the velocity varies continuously, the force must not (rate independence)
    (tf.Sine(amplitude=18e-6, frequency=2.0, offset=3e-6), [0.0, 0.125, 0.375, 0.625, 0.875, 1.125]),
])
def test_dahl_closed_form_under_periodic_motion(waveform, t_rev):
    """Analytic: Dahl's closed form in x (above), chained from reversal to reversal of a
    triangle (sawtooth, rise 0.5) and of a sine; the force depends on the path of x only."""
    fc, sigma0 = 0.7, 2e5
    model = prescribed(tf.Dahl(sigma0=sigma0, fc=fc))
    # (the sine's reversals are no corners of the input: the solver steps across the kink of |v|
    # there, so the error is a few hundred times rtol; rtol 1e-10 gives 7e-9 fc)
    res = tf.simulate(model, 1.25, input=waveform, sample_rate=4000, controller=tight(1e-10))
    x_rev = np.array([float(waveform(np.array([t]))[0]) for t in t_rev])
    # the sine starts at its offset: the model starts from rest there, so measure x from it
    x = res.displacement - x_rev[0]
    expected = dahl_closed_form(x, res.time, t_rev, x_rev - x_rev[0], sigma0, fc)
    assert np.max(np.abs(res.friction_force - expected)) < 1e-7 * fc
    # and the loop saturates towards +-fc on the long strokes without ever exceeding it
    assert np.max(np.abs(res.friction_force)) < fc


# ---------------------------------------------------------------------------------------------
# 2. LuGre and elasto-plastic steady sliding: the Stribeck curve plus viscous friction
# ---------------------------------------------------------------------------------------------

STEADY = dict(sigma0=SIGMA0, sigma1=30.0, fc=1.0, fs=1.5, vs=1e-3, sigma2=50.0)


@pytest.mark.parametrize("friction, delta", [
    (tf.LuGre(**STEADY), 2.0),
    (tf.ElastoPlastic(**STEADY, z_ba=5e-6), 2.0),
    (tf.LuGre(**STEADY, delta=1.0, vd=1e-3), 1.0),
    (tf.ElastoPlastic(**STEADY, z_ba=2e-6, delta=0.5), 0.5),
], ids=["lugre", "elastoplastic", "lugre-delta1-vd", "elastoplastic-delta0.5"])
def test_steady_sliding_force_is_stribeck_curve_plus_viscous__analytic(friction, delta):
    """Analytic: at constant v, z' = 0 gives z = g(v) sgn(v)/sigma0 (alpha = 1 there for the
    elasto-plastic model) and F = g(v) sgn(v) + sigma2 v, g(v) = fc + (fs-fc) exp(-|v/vs|^delta).
    Velocities from 0.1 vs (almost fs) through the Stribeck drop to 20 vs (fc), both signs."""
    model = prescribed(friction)
    for v in (1e-4, -3e-4, 1e-3, 2e-3, -5e-3, 2e-2):
        # z relaxes over the distance g/sigma0: sample after 40 of them, on a ramp that goes on
        T = 40 * STEADY["fs"] / STEADY["sigma0"] / abs(v)
        res = tf.simulate(model, input=tf.Sampled([0.0, 2 * T], [0.0, 2 * v * T]), t_eval=np.array([0.0, T]),
                          controller=tight(1e-9))
        assert res.relative_velocity[-1] == pytest.approx(v, rel=1e-12)
        g = stribeck_g(v, STEADY["fc"], STEADY["fs"], STEADY["vs"], delta)
        expected = g * np.sign(v) + STEADY["sigma2"] * v
        assert res.friction_force[-1] == pytest.approx(expected, rel=1e-6), v  # measured < 1e-8
        assert res.states[-1, 0] == pytest.approx(g * np.sign(v) / STEADY["sigma0"], rel=1e-6), v


# ---------------------------------------------------------------------------------------------
# 3. Presliding: a mass on LuGre bristles rings like a linear spring-damper
# ---------------------------------------------------------------------------------------------

def ringing(t, x, v):
    """Damped natural frequency and damping ratio from the extrema of x (zero crossings of v):
    the half period is pi/wd, the log decrement of successive half swings pi zeta/sqrt(1-zeta^2)."""
    i = np.nonzero(((v[:-1] > 0) & (v[1:] <= 0)) | ((v[:-1] < 0) & (v[1:] >= 0)))[0]
    i = i[i > 0]
    tz = t[i] - v[i] * (t[i + 1] - t[i]) / (v[i + 1] - v[i])
    xz = np.interp(tz, t, x)
    half = np.diff(tz)
    swings = np.abs(np.diff(xz))
    d = np.mean(np.log(swings[:-1] / swings[1:])[:20])
    zeta = d / math.hypot(math.pi, d)
    wd = math.pi / np.mean(half[:20])
    return wd / math.sqrt(1 - zeta ** 2), zeta, len(tz)


def test_presliding_ringing_of_a_mass_on_lugre__linearisation():
    """Linearisation (Canudas de Wit et al. 1995): for |z| << fc/sigma0, z' ~ v and
    m x'' + (sigma1 + sigma2) x' + sigma0 x = f, so a small step of force rings at
    wn = sqrt(sigma0/m) with damping ratio (sigma1 + sigma2) / (2 sqrt(sigma0 m))."""
    m, s0, s1, s2 = 1.0, SIGMA0, 20.0, 5.0
    model = tf.Model(tf.MassPlant(m), tf.LuGre(sigma0=s0, sigma1=s1, sigma2=s2, fc=FC))
    res = tf.simulate(model, 0.5, input=tf.Step(amplitude=1e-3 * FC, slew=1e-4), sample_rate=200_000,
                      controller=tight(1e-9))
    wn, zeta, n = ringing(res.time, res.displacement, res.velocity)
    assert n > 40
    assert wn == pytest.approx(math.sqrt(s0 / m), rel=1e-3)  # measured 6e-6
    assert zeta == pytest.approx((s1 + s2) / (2 * math.sqrt(s0 * m)), rel=1e-2)  # measured 1.7e-3
    # it settles at the bristle deflection f/sigma0 (LuGre creeps a little beyond it)
    assert res.displacement[-1] == pytest.approx(1e-3 * FC / s0, rel=0.05)


# ---------------------------------------------------------------------------------------------
# 4. Elasto-plastic: no drift under small oscillating forces (where LuGre drifts)
# ---------------------------------------------------------------------------------------------

def test_elastoplastic_does_not_drift_under_small_oscillating_force_where_lugre_does():
    """Property (Dupont et al. 2002): below the break-away deflection z_ba the elasto-plastic
    model is a pure spring-damper (alpha = 0, z' = v), so a biased oscillating force that keeps
    |z| < z_ba moves the mass periodically about f_mean/sigma0 with no drift; LuGre with the
    same sigma0, sigma1, fc relaxes z on every push and ratchets in the direction of the bias."""
    m, s0 = 0.01, SIGMA0
    s1 = math.sqrt(s0 * m)  # damping ratio 0.5
    z_ba = 0.8 * FC / s0
    f_mean, f_amp, freq, ncyc = 0.35 * FC, 0.35 * FC, 20.0, 20
    force = tf.Sine(amplitude=f_amp, frequency=freq, offset=f_mean)
    per = 400
    means = {}
    for fr in (tf.ElastoPlastic(sigma0=s0, sigma1=s1, fc=FC, z_ba=z_ba), tf.LuGre(sigma0=s0, sigma1=s1, fc=FC)):
        res = tf.simulate(tf.Model(tf.MassPlant(m), fr), ncyc / freq, input=force, sample_rate=freq * per,
                          controller=tight(1e-9))
        x = res.displacement[: ncyc * per].reshape(ncyc, per).mean(axis=1)
        means[fr.model] = x
        if fr.model == "elastoplastic":
            assert np.max(np.abs(res.states[:, 0])) < z_ba  # the premise: always below break-away
            assert np.max(np.abs(res.displacement - res.states[:, 0])) < 1e-12 * z_ba  # x = z: no slip
    ep, lg = means["elastoplastic"], means["lugre"]
    drift_ep = ep[-3:].mean() - ep[1:4].mean()
    drift_lg = lg[-3:].mean() - lg[1:4].mean()
    assert abs(drift_ep) < 1e-6 * z_ba  # measured 0
    assert ep[-1] == pytest.approx(f_mean / s0, rel=1e-6)
    assert drift_lg > 10 * FC / s0  # LuGre: ~0.7 fc/sigma0 per cycle


# ---------------------------------------------------------------------------------------------
# 5. GMS: virgin curve, Masing's rule and return-point memory (elastic/Coulomb limit)
# ---------------------------------------------------------------------------------------------

GMS_K = np.array([4e5, 2e5, 1e5, 5e4])
GMS_W = np.array([0.1, 0.2, 0.3, 0.4])  # break-away displacements 0.25, 1, 3, 8 um


def gms_elastic_coulomb():
    """fs = fc: capacities w_i fc are constant; C large: a slipping element stays at capacity."""
    return tf.GMS(k=tuple(GMS_K), w=tuple(GMS_W), C=1e6, fc=FC)


def maxwell_slip_virgin(x):
    """Virgin curve of N elasto-plastic (Maxwell-slip) elements from rest: sum min(k_i |x|, w_i fc) sgn x."""
    x = np.asarray(x, float)
    return np.sign(x) * np.minimum(GMS_K[:, None] * np.abs(x)[None, :], (GMS_W * FC)[:, None]).sum(axis=0)


def masing_curves(t, x, t_rev, x_rev):
    """Masing's rule for Maxwell-slip elements: the virgin curve until the first reversal, then
    from each reversal (x_r, F_r) the branch F_r + 2 u F_v(|x - x_r|/2), u the new direction
    (valid here because every reversal lies on the outer loop, beyond the last break-away)."""
    F = maxwell_slip_virgin(x)
    F_r = float(maxwell_slip_virgin([x_rev[0]])[0])
    for k, (tr, xr) in enumerate(zip(t_rev, x_rev)):
        u = -np.sign(xr - (x_rev[k - 1] if k else 0.0))
        seg = (t > tr) & (t <= (t_rev[k + 1] if k + 1 < len(t_rev) else np.inf))
        F[seg] = F_r + 2 * u * maxwell_slip_virgin(np.abs(x[seg] - xr) / 2)
        if k + 1 < len(t_rev):
            F_r = F_r + 2 * u * float(maxwell_slip_virgin([abs(x_rev[k + 1] - xr) / 2])[0])
    return F


A_GMS = 10e-6  # beyond the last break-away (8 um): full loops


@pytest.mark.parametrize("motion, duration, t_rev, x_rev", [
    # triangle: its reversals are corners of the input
    (tf.Sampled([0.0, 1.0, 3.0, 5.0], [0.0, A_GMS, -A_GMS, A_GMS]), 5.0, [1.0, 3.0], [A_GMS, -A_GMS]),
    # a sine through the same reversal points: smooth reversals
    (tf.Sine(amplitude=A_GMS, frequency=0.25), 5.0, [1.0, 3.0], [A_GMS, -A_GMS]),
    # five cycles of a sine 5x beyond the last break-away: long phases with every element slipping
    (tf.Sine(amplitude=4 * A_GMS, frequency=5.0), 1.0, [0.05 + 0.1 * k for k in range(10)],
     [4 * A_GMS * (-1) ** k for k in range(10)]),
], ids=["triangle", "sine", "sine-5-cycles"])
def test_gms_virgin_curve_and_masing_reversal_curves__analytic(motion, duration, t_rev, x_rev):
    """Analytic (Maxwell-slip model = Iwan model; Al-Bender et al. 2005): the virgin curve is
    F_v(x) = sum_i min(k_i x, w_i fc); a reversal curve from (x_r, F_r) obeys Masing's rule
    F = F_r - 2 F_v((x_r - x)/2) (downwards), F_r + 2 F_v((x - x_r)/2) (upwards). With fs = fc
    the model is rate independent: a triangle and a sine through the same reversal points give
    the same curves."""
    res = tf.simulate(prescribed(gms_elastic_coulomb()), duration, input=motion, sample_rate=1000,
                      controller=tight(1e-10))
    t, x, F = res.time, res.displacement, res.friction_force
    expected = masing_curves(t, x, t_rev, x_rev)
    first = t <= t_rev[0]
    err_virgin = np.max(np.abs(F[first] - expected[first]))
    err_reversals = np.max(np.abs(F[~first] - expected[~first]))
    # every element force stays within its capacity w_i fc
    over = np.max(np.abs(res.states) / (GMS_W * FC)) - 1
    assert (err_virgin, err_reversals, over) == pytest.approx((0, 0, 0), abs=1e-8)  # fc = 1 N


def test_gms_return_point_memory_after_a_closed_minor_loop__property():
    """Property (return-point / non-local memory of Maxwell-slip, Al-Bender et al. 2005): after
    a closed minor loop B -> C -> B inside a major loop, the force continues on the branch it
    left, i.e. at every x it equals the force of the same motion without the minor loop."""
    A, B, C = 10e-6, 3e-6, -2e-6
    with_loop = tf.Sampled([0.0, 1.0, 3.0, 3.65, 4.15, 4.65, 5.0], [0.0, A, -A, B, C, B, A])
    without = tf.Sampled([0.0, 1.0, 3.0, 3.65, 4.0], [0.0, A, -A, B, A])
    model = prescribed(gms_elastic_coulomb())
    r1 = tf.simulate(model, 5.0, input=with_loop, sample_rate=2000)
    r0 = tf.simulate(model, 4.0, input=without, sample_rate=2000)
    at_B1 = np.searchsorted(r1.time, 3.65)
    at_B2 = np.searchsorted(r1.time, 4.65)
    # the minor loop closes: back at B, the same force
    assert r1.friction_force[at_B2] == pytest.approx(r1.friction_force[at_B1], abs=1e-9)
    # and the branch after B is the one without the minor loop, point by point in x
    after1 = r1.time >= 4.65
    after0 = r0.time >= 3.65
    F0_at_x = np.interp(r1.displacement[after1], r0.displacement[after0], r0.friction_force[after0])
    assert np.max(np.abs(r1.friction_force[after1] - F0_at_x)) < 1e-9
    # and both agree with Masing's rule from the reversal at -A (the major loop's branch)
    expected = masing_curves(r0.time, r0.displacement, [1.0, 3.0], [A, -A])
    assert np.max(np.abs(r0.friction_force[after0] - expected[after0])) < 1e-9


# ---------------------------------------------------------------------------------------------
# 6. Static maps
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("friction, G", [
    (tf.Coulomb(fc=0.8, sigma2=30.0, v_smooth=1e-4), lambda v: 0.8),
    (tf.Coulomb(fc=2.0, v_smooth=5e-4), lambda v: 2.0),
    (tf.Stribeck(fc=1.0, fs=1.6, vs=1e-3, sigma2=30.0, v_smooth=1e-4), lambda v: stribeck_g(v, 1.0, 1.6, 1e-3)),
    (tf.Stribeck(fc=1.0, fs=1.3, vs=5e-4, delta=1.0, v_smooth=2e-5), lambda v: stribeck_g(v, 1.0, 1.3, 5e-4, 1.0)),
], ids=["coulomb-viscous", "coulomb-wide-band", "stribeck", "stribeck-delta1"])
def test_static_maps_match_their_formulas__analytic(friction, G):
    """Definition (docs/models.md#friction-models): F = fc tanh(v/v_smooth) + sigma2 v (Coulomb), F = g(v)
    tanh(v/v_smooth) + sigma2 v (Stribeck), at the prescribed velocity v = dx/dt of a sine."""
    X, f = 1e-3, 1.0  # peak velocity 6.3 mm/s, through the smoothing band and the Stribeck drop
    res = tf.simulate(prescribed(friction), 1.0, input=tf.Sine(amplitude=X, frequency=f), sample_rate=5000)
    v_exact = 2 * math.pi * f * X * np.cos(2 * math.pi * f * res.time)
    assert np.allclose(res.relative_velocity, v_exact, rtol=1e-9, atol=1e-15)
    v = res.relative_velocity
    expected = G(v) * np.tanh(v / friction.v_smooth) + friction.sigma2 * v
    assert np.max(np.abs(res.friction_force - expected)) < 1e-12
    assert res.states.shape == (len(res.time), 0)


# ---------------------------------------------------------------------------------------------
# 7. Thermal extensions for every model
# ---------------------------------------------------------------------------------------------

BASE = {
    "coulomb": tf.Coulomb(fc=1.0, sigma2=20.0, v_smooth=1e-4),
    "stribeck": tf.Stribeck(fc=1.0, fs=1.5, vs=1e-3, sigma2=20.0, v_smooth=1e-4),
    "dahl": tf.Dahl(sigma0=1e5, fc=1.0),
    "lugre": tf.LuGre(sigma0=1e5, sigma1=30.0, fc=1.0, fs=1.5, vs=1e-3, sigma2=20.0),
    "elastoplastic": tf.ElastoPlastic(sigma0=1e5, sigma1=30.0, fc=1.0, z_ba=5e-6, fs=1.5, vs=1e-3, sigma2=20.0),
    "gms": tf.GMS(k=(4e5, 1e5, 3e4), w=(0.2, 0.3, 0.5), C=50.0, fc=1.0, fs=1.5, vs=1e-3, sigma2=20.0),
}

# one or more Model I laws per model; at 35 C they give the values noted
LAWS = {
    "coulomb": {"fc": tf.Linear(-0.02, 2.0)},                                            # 1.3 N
    "stribeck": {"fs": tf.Exp(1.0, 0.012)},                                              # 1.52 N
    "dahl": {"sigma0": tf.Exp(2e5, -0.02)},                                              # 9.9e4 N/m
    "lugre": {"sigma0": tf.Exp(2e5, -0.02), "sigma1": tf.Linear(-0.5, 40.0), "fc": tf.Exp(1.2, -0.005)},
    "elastoplastic": {"z_ba": tf.PWL([20.0, 50.0], [6e-6, 2e-6])},                       # 4e-6 m
    "gms": {"C": tf.Exp(100.0, -0.02)},                                                  # 49.7 N/s
}

T_TEST = 35.0


def thermal_input(plant):
    if isinstance(plant, tf.PrescribedMotion):
        return tf.Sine(amplitude=2e-5, frequency=5.0)  # peak 0.63 mm/s: presliding, Stribeck drop, reversals
    return tf.Sine(amplitude=1.6, frequency=5.0)  # force on a 0.1 kg mass: stick and slip


@pytest.mark.parametrize("plant", [tf.PrescribedMotion(), tf.MassPlant(0.1)], ids=["prescribed", "mass"])
@pytest.mark.parametrize("name", list(BASE))
def test_model_i_law_equals_base_model_with_the_laws_value(name, plant):
    """Definition (docs/models.md#model-i): a Model I law on a parameter gives exactly the base model with the
    law's value at that temperature; and the parameter matters (another value differs)."""
    base = BASE[name]
    laws = LAWS[name]
    with_laws = base.with_values(**{p: None for p in laws})
    thermal = tf.Model(plant, with_laws, tf.ModelI(laws))
    at_T = {p: law(T_TEST) for p, law in laws.items()}
    # the law's value, by hand (independent of the C law evaluator)
    for p, law in laws.items():
        by_hand = {"linear": lambda l: l.a * T_TEST + l.b, "exp": lambda l: l.a * math.exp(l.b * T_TEST),
                   "pwl": lambda l: float(np.interp(T_TEST, l.T, l.values))}[law.kind](law)
        assert at_T[p] == pytest.approx(by_hand, rel=1e-14)
    plain = tf.Model(plant, base.with_values(**at_T))
    inp = thermal_input(plant)
    kw = dict(input=inp, sample_rate=2000, controller=tight(1e-9))
    r_th = tf.simulate(thermal, 0.4, temperature=T_TEST, **kw)
    r_pl = tf.simulate(plain, 0.4, **kw)
    scale = np.max(np.abs(r_pl.friction_force))
    np.testing.assert_allclose(r_th.friction_force, r_pl.friction_force, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(r_th.displacement, r_pl.displacement, rtol=0,
                               atol=1e-9 * np.max(np.abs(r_pl.displacement)))
    assert np.all(r_th.temperature == T_TEST)
    # the parameter matters: the base model with the laws' values off by 30 % differs clearly
    other = tf.simulate(tf.Model(plant, base.with_values(**{p: 1.3 * v for p, v in at_T.items()})), 0.4, **kw)
    assert np.max(np.abs(other.friction_force - r_pl.friction_force)) > 1e-3 * scale


@pytest.mark.parametrize("name", list(BASE))
def test_model_ii_scale_form_scales_every_base_model_by_1_plus_dF_over_fc(name):
    """Definition (docs/models.md#model-ii): F' = (1 + dF(T)/F_ref) F_base with F_ref = fc; under prescribed
    motion the base model's state does not see the thermal factor, so the whole force record is
    scaled, pointwise, by lambda = 1 + (a T + b)/fc."""
    base = BASE[name]
    dF = tf.Linear(-0.02, 0.3)  # -0.4 N at 35 C
    lam = 1.0 + (-0.02 * T_TEST + 0.3) / base.fc
    inp = tf.Sine(amplitude=2e-5, frequency=5.0)
    kw = dict(input=inp, sample_rate=2000, controller=tight(1e-9))
    r_base = tf.simulate(prescribed(base), 0.4, **kw)
    r_ii = tf.simulate(prescribed(base, thermal=tf.ModelII(dF)), 0.4, temperature=T_TEST, **kw)
    scale = np.max(np.abs(r_base.friction_force))
    np.testing.assert_allclose(r_ii.friction_force, lam * r_base.friction_force, rtol=0, atol=1e-9 * scale)
    if base.nstate:  # the internal states are the base model's
        np.testing.assert_allclose(r_ii.states, r_base.states, rtol=0, atol=1e-9 * np.max(np.abs(r_base.states)))


@pytest.mark.parametrize("friction, dF, warns, damping", [
    (tf.Dahl(sigma0=SIGMA0, fc=FC), -0.3, True, 0.0),  # no damping of its own at v = 0
    (tf.GMS(k=(1e5,), w=(1.0,), C=20.0, fc=FC, sigma2=0.4), -0.3, True, 0.4),
    (tf.Coulomb(fc=FC, sigma2=0.4), -0.3, False, 0.4 + 1e6),  # its smoothed sign: fs/v_smooth
    (tf.Stribeck(fc=FC, fs=1.5, vs=1e-3), -0.3, False, 1.5e6),
    (tf.Coulomb(fc=FC), -1.2, True, 1e6),  # |dF| beyond fs: anti-damped even so
], ids=["dahl", "gms", "coulomb", "stribeck", "coulomb-dF>fs"])
def test_model_ii_offset_form_conditioning_check_counts_each_models_own_damping(friction, dF, warns, damping):
    """Linearisation at v = 0 (docs/models.md#model-ii, offset form): F' = F_base + dF tanh(v/v_smooth) has the
    slope dF/v_smooth there; with dF < 0 it is anti-damped where that outweighs the base model's
    own damping (sigma1 + sigma2; fs/v_smooth + sigma2 for a static map's smoothed sign). The check
    must hold for models without sigma1 (it raised KeyError for them) and name the damping."""
    model = tf.Model(tf.MassPlant(1.0), friction, thermal=tf.ModelII(tf.Const(dF), form="offset"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tf.simulate(model, 0.01, temperature=35.0, sample_rate=1000)
    cond = [w for w in caught if issubclass(w.category, tf.ConditioningWarning)]
    assert bool(cond) == warns
    if warns:
        assert f"= {damping:.3g} N s/m" in str(cond[0].message)


# ---------------------------------------------------------------------------------------------
# 8. Parameter checks
# ---------------------------------------------------------------------------------------------

P = tf.PrescribedMotion()


@pytest.mark.parametrize("build, match", [
    (lambda: tf.Model(P, tf.Stribeck(fc=1.0, fs=0.8, vs=1e-3)), r"'fs' \(0.8\) must be at least 'fc'"),
    (lambda: tf.Model(P, tf.LuGre(sigma0=1e5, sigma1=1.0, fc=1.0, fs=0.9, vs=1e-3)), "'fs'"),
    (lambda: tf.Model(P, tf.ElastoPlastic(sigma0=1e5, sigma1=1.0, fc=1.0, fs=0.5, vs=1e-3, z_ba=1e-6)), "'fs'"),
    (lambda: tf.Model(P, tf.GMS(k=(1e5,), w=(1.0,), C=10.0, fc=1.0, fs=0.99, vs=1e-3)), "'fs'"),
    (lambda: tf.GMS(k=(1e5, 2e5), w=(0.5, 0.4), C=10.0, fc=1.0), "'w' must sum to one"),
    (lambda: tf.GMS(k=(1e5, 2e5), w=(0.7, 0.4), C=10.0, fc=1.0), "'w' must sum to one"),
    (lambda: tf.Model(P, tf.ElastoPlastic(sigma0=1e5, sigma1=1.0, fc=1.0, z_ba=1e-5)), "'z_ba'"),
    (lambda: tf.Model(P, tf.ElastoPlastic(sigma0=1e5, sigma1=1.0, fc=1.0, z_ba=3e-5)), "'z_ba'"),
    (lambda: tf.Model(P, tf.LuGre(sigma0=0.0, sigma1=1.0, fc=1.0)), "'sigma0' must be positive"),
    (lambda: tf.Model(P, tf.Dahl(sigma0=-1e5, fc=1.0)), "'sigma0' must be positive"),
    (lambda: tf.Model(P, tf.ElastoPlastic(sigma0=-1e5, sigma1=1.0, fc=1.0, z_ba=1e-6)), "'sigma0'"),
    (lambda: tf.GMS(k=(1e5, 0.0), w=(0.5, 0.5), C=10.0, fc=1.0), r"'k\[1\]' must be positive"),
    (lambda: tf.GMS(k=(-1e5,), w=(1.0,), C=10.0, fc=1.0), r"'k\[0\]' must be positive"),
    (lambda: tf.StickSlipPlant(mass=0.05, end_effector_mass=0.02, damping=1.0, stiffness=0.0, transducer_ratio=1.0),
     "'k' must be positive"),
    (lambda: tf.MassPlant(1.0, spring_stiffness=-2.0, pull_velocity=0.1), "'k_s'"),
], ids=["stribeck-fs<fc", "lugre-fs<fc", "elastoplastic-fs<fc", "gms-fs<fc", "gms-w-0.9", "gms-w-1.1",
        "z_ba=fc/sigma0", "z_ba>fc/sigma0", "lugre-sigma0=0", "dahl-sigma0<0", "ep-sigma0<0", "gms-k=0",
        "gms-k<0", "stage-k=0", "mass-k_s<0"])
def test_bad_parameters_raise_input_error_naming_the_parameter(build, match):
    """Physical domain (docs/models.md#friction-models): fs >= fc, GMS weights sum to one, z_ba < fc/sigma0, positive
    stiffnesses; each violation is an InputError that names the parameter."""
    with pytest.raises(tf.InputError, match=match):
        build()


@pytest.mark.parametrize("friction, laws, match", [
    (tf.Stribeck(fc=1.0, fs=None, vs=1e-3), {"fs": tf.Linear(-0.02, 1.5)}, "'fs'"),  # 0.8 < fc at 35 C
    (tf.ElastoPlastic(sigma0=1e5, sigma1=1.0, fc=1.0, z_ba=None), {"z_ba": tf.Linear(1e-6, -2e-5)}, "'z_ba'"),
    (tf.Dahl(sigma0=None, fc=1.0), {"sigma0": tf.Linear(-1e4, 3e5)}, "'sigma0'"),  # -5e4 at 35 C
    (tf.GMS(k=(1e5,), w=(1.0,), C=None, fc=1.0), {"C": tf.Linear(-1.0, 20.0)}, "'C'"),  # -15 at 35 C
], ids=["fs-law", "z_ba-law", "sigma0-law", "C-law"])
def test_model_i_law_outside_the_physical_domain_at_the_temperature_is_an_input_error(friction, laws, match):
    """Physical domain at the simulated temperature: a Model I law that takes a parameter out of
    its domain there (fs < fc, z_ba >= fc/sigma0, sigma0 <= 0, C <= 0) is an InputError naming it."""
    model = prescribed(friction, thermal=tf.ModelI(laws))
    with pytest.raises(tf.InputError, match=match):
        tf.simulate(model, 0.1, temperature=T_TEST, input=tf.Sine(1e-5, 5.0))


# ---------------------------------------------------------------------------------------------
# 9. Every friction model on every plant, from a model file, through the command line
# ---------------------------------------------------------------------------------------------

FRICTION_TOML = {
    "coulomb": 'fc = 1.0\nsigma2 = 20.0\nv_smooth = 1e-4\n',
    "stribeck": 'fc = 1.0\nfs = 1.5\nvs = 1e-3\nsigma2 = 20.0\nv_smooth = 1e-4\n',
    "dahl": 'sigma0 = 1e5\nfc = 1.0\n',
    "lugre": 'sigma0 = 1e5\nsigma1 = 30.0\nsigma2 = 20.0\nfc = 1.0\nfs = 1.5\nvs = 1e-3\n',
    "elastoplastic": 'sigma0 = 1e5\nsigma1 = 30.0\nsigma2 = 20.0\nfc = 1.0\nfs = 1.5\nvs = 1e-3\nz_ba = 5e-6\n',
    "gms": 'k = [4e5, 1e5, 3e4]\nw = [0.2, 0.3, 0.5]\nC = 50.0\nfc = 1.0\nfs = 1.5\nvs = 1e-3\nsigma2 = 20.0\n',
}
PLANT_TOML = {
    "stick-slip": 'type = "stick-slip"\nxi = 0.2488\nwn = 6685.5\nK = 0.096e-6\nm = 0.05\nm_e = 0.05\n',
    "mass": 'type = "mass"\nm = 0.1\nk_s = 2000.0\nv_0 = 1e-3\n',
    "prescribed": 'type = "prescribed"\n',
}
PLANT_INPUT = {
    "stick-slip": ("sawtooth:amplitude=30,frequency=50,rise=0.9", "V"),
    "mass": ("sine:amplitude=0.5,frequency=20", "N"),
    "prescribed": ("sine:amplitude=2e-5,frequency=20", "m"),
}
STATE_COLUMNS = {"coulomb": [], "stribeck": [], "dahl": ["z[m]"], "lugre": ["z[m]"], "elastoplastic": ["z[m]"],
                 "gms": ["F_1[N]", "F_2[N]", "F_3[N]"]}


def cli_simulate(model_name, plant, tmp_path):
    folder = tmp_path / f"{model_name}-{plant}"
    folder.mkdir()
    (folder / "model.toml").write_text(f'[plant]\n{PLANT_TOML[plant]}\n[friction]\nmodel = "{model_name}"\n'
                                       f'{FRICTION_TOML[model_name]}\n[thermal]\nmodel = "none"\n')
    spec, _ = PLANT_INPUT[plant]
    out = run_cli("simulate", "model.toml", "--duration", "0.1", "--sample-rate", "2000", "--input", spec,
                  "-o", "out.csv", cwd=folder)
    return folder, out


def check_cli_result(model_name, plant, folder, out):
    assert out.returncode == 0, f"{model_name} on {plant}: {out.stderr}"
    assert "Traceback" not in out.stderr
    header = (folder / "out.csv").read_text().splitlines()[0].split(",")
    unit = PLANT_INPUT[plant][1]
    expected = ["time[s]", f"input[{unit}]"] + (["stage_displacement[m]"] if plant == "stick-slip" else []) + \
        ["displacement[m]", "velocity[m/s]", "friction_force[N]", "temperature[C]"] + STATE_COLUMNS[model_name]
    assert header == expected, f"{model_name} on {plant}"
    data = np.genfromtxt(folder / "out.csv", delimiter=",", skip_header=1)
    assert data.shape == (201, len(expected))
    cols = dict(zip(header, data.T))
    assert np.all(np.isfinite(cols["friction_force[N]"])) and np.all(np.isfinite(cols["displacement[m]"]))
    assert np.max(np.abs(cols["friction_force[N]"])) > 0
    if plant == "prescribed":  # the driven body follows the prescribed motion exactly
        t = cols["time[s]"]
        np.testing.assert_allclose(cols["displacement[m]"], 2e-5 * np.sin(2 * np.pi * 20 * t), rtol=0, atol=1e-15)
        np.testing.assert_allclose(cols[f"input[{unit}]"], cols["displacement[m]"], rtol=0, atol=1e-15)


def run_matrix(pairs, tmp_path):
    # each run is a fresh interpreter (~1 s of imports): two at a time
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(lambda p: cli_simulate(*p, tmp_path), pairs))
    for (model_name, plant), (folder, out) in zip(pairs, results):
        check_cli_result(model_name, plant, folder, out)


PLANTS = list(PLANT_TOML)
MODELS = list(FRICTION_TOML)


def test_cli_simulates_each_friction_model_and_each_plant(tmp_path):
    """Interface (docs/formats.md#model-files, docs/cli.md): a model file of each friction model,
    on the plants in turn (every plant twice), simulates from the command line with exit status 0
    and the columns of docs/formats.md#simulation-output: stage_displacement[m] only for the
    stick-slip plant, input[V]/[N]/[m] by plant, the model's internal states last."""
    run_matrix([(m, PLANTS[i % 3]) for i, m in enumerate(MODELS)], tmp_path)


@pytest.mark.slow
def test_cli_simulates_every_friction_model_on_every_plant(tmp_path):
    """Interface (docs/formats.md#model-files, docs/cli.md): the full matrix, 6 friction models x
    3 plants (18 interpreters)."""
    run_matrix([(m, p) for m in MODELS for p in PLANTS], tmp_path)


# ---------------------------------------------------------------------------------------------
# One description per friction model (issue 39): what the model file, the checks, the FMU and the
# reports derive from; the domain rules, one per parameter
# ---------------------------------------------------------------------------------------------

_RIPPLE = dict(ripple_period=2e-3, ripple_cos1=0.01, ripple_sin2=-0.02)
#: one friction model of each kind with every kind of parameter it takes (sides, ripple, arrays)
EXAMPLES = {
    "lugre": tf.LuGre(sigma0=1e5, sigma1=300.0, fc=0.5, fs=0.7, vs=1e-3, sigma2=2.0, vd=1e-3, fc_neg=0.45,
                      fs_neg=0.8, vs_neg=2e-3, sigma2_neg=1.0, **_RIPPLE),
    "coulomb": tf.Coulomb(fc=0.5, sigma2=1.0, fc_neg=0.6, **_RIPPLE),
    "stribeck": tf.Stribeck(fc=0.5, fs=0.8, vs=1e-3, delta=1.5, sigma2=1.0, sigma2_neg=0.0),
    "dahl": tf.Dahl(sigma0=1e5, fc=0.5, fc_neg=0.4),
    "elastoplastic": tf.ElastoPlastic(sigma0=1e5, sigma1=300.0, fc=0.5, z_ba=2e-6, fs=0.6, vs=1e-3),
    "gms": tf.GMS(k=(1e5, 5e4, 2e4), w=(0.5, 0.3, 0.2), C=1e4, fc=0.5, fs=0.6, vs=1e-3, sigma2=0.5),
}
#: sha256 (first 16 hex digits) of each kind's model files, FMU resource files and modelDescription.xml (FMI 2
#: and 3; date and version masked) over two plants and three thermal extensions, as written before the friction
#: models were described once (commit 582d816): derived now, byte for byte the same
WRITTEN_BEFORE = {"lugre": "cc4199da46602808", "coulomb": "e2a73172a23053c5", "stribeck": "9be385da8a6f97dd",
                  "dahl": "15fa678faf505eba", "elastoplastic": "a01dd627627029ff", "gms": "59d7c11b73133054"}


def _written(name):
    import hashlib
    import re
    import tomllib
    from thermofriction import _bridge
    from thermofriction.fmu_description import description_xml2, description_xml3, resource_text, variables_of
    out = {}
    for plant in (tf.MassPlant(mass=1.0), tf.PrescribedMotion()):
        for thermal in (None, "I", "II"):
            friction, th = EXAMPLES[name], None
            if thermal == "I":
                th, friction = tf.ModelI({"fc": tf.Linear(a=0.5, b=-0.001, range=(20.0, 60.0))}), friction.with_values(fc=None)
            elif thermal == "II":
                th = tf.ModelII(tf.PWL(T=(20.0, 40.0, 60.0), values=(0.0, 0.01, 0.03)))
            m = tf.Model(plant, friction, th, tf.Sine(amplitude=1.0, frequency=2.0), name=f"{name}-{plant.type}-{thermal}")
            assert tf.models.model_from_dict(tomllib.loads(m.to_toml())) == m  # the file round trip
            spec = _bridge.model_spec(m)
            v = variables_of(m, spec, 30.0 if thermal else None)
            key = f"{name}/{plant.type}/{thermal}"
            out.update({f"{key}/toml": m.to_toml(), f"{key}/res": resource_text(m, spec, v),
                        f"{key}/xml2": description_xml2(m, v, "id", "guid", "src", sources=("a.c",)),
                        f"{key}/xml3": description_xml3(m, v, "id", "guid", "src")})
    text = "\n".join(re.sub(r'generationDateAndTime="[^"]*"', "", out[k]).replace(tf.__version__, "VERSION")
                     for k in sorted(out))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def test_every_friction_model_has_an_example_here():
    assert set(EXAMPLES) == set(tf.models.FRICTION_MODELS) == set(WRITTEN_BEFORE)


@pytest.mark.parametrize("name", list(WRITTEN_BEFORE))
def test_model_files_and_fmu_descriptions_are_written_as_before(name):
    """Byte for byte: the model file (TOML), the FMU's resource file and modelDescription.xml (FMI 2.0 and 3.0) of
    each friction model, its sides, ripple and arrays included, on two plants, without a thermal extension, with a
    Model I law and with Model II -- as the code wrote them before each friction model was described once."""
    assert _written(name) == WRITTEN_BEFORE[name]


@pytest.mark.parametrize("name", list(EXAMPLES))
def test_a_friction_models_facts_come_from_its_description(name):
    """The class's name, required parameters (the fields without a default), arrays, states, law targets, sides and
    domains are its description's and the domain table's; its id is the core's."""
    import dataclasses
    from thermofriction import _bridge
    from thermofriction.models.domains import NEGATIVE_SIDE, PARAMETER_DOMAIN
    cls = tf.models.FRICTION_MODELS[name]
    d = cls.description
    assert cls.model == d.name == name and d.c_id in _bridge.FRICTION_CODES
    fields = [f.name for f in dataclasses.fields(cls)]
    assert cls.required == tuple(f.name for f in dataclasses.fields(cls) if f.default is dataclasses.MISSING)
    assert cls.arrays == tuple(d.arrays) and set(cls.law_targets) == set(fields) - set(d.arrays)
    assert set(cls.law_targets) <= set(_bridge.PARAMETERS)
    assert cls.sides == tuple(n for n in cls.law_targets if n in NEGATIVE_SIDE)
    assert cls.domains == {n: PARAMETER_DOMAIN[n] for n in cls.law_targets}
    if d.states:
        assert EXAMPLES[name].state_names == tuple(n for n, _ in d.states) == cls.state_names
    assert EXAMPLES[name].nstate == len(EXAMPLES[name].state_names) == len(EXAMPLES[name].state_units)
    for fitted in d.fitted.values():
        assert set(fitted) <= set(cls.law_targets)


def test_the_measurements_default_fits_are_the_descriptions():
    """What each measurement fits by default per friction model (its FIT_PARAMETERS) is the description's."""
    from thermofriction.measurements import displacement, force
    for module, measurement in ((displacement, "displacement"), (force, "force")):
        assert module.FIT_PARAMETERS == {n: c.description.fitted[measurement]
                                         for n, c in tf.models.FRICTION_MODELS.items()}


def test_one_domain_rule_per_parameter_of_a_small_vocabulary():
    """Every core parameter has one rule, of RULES (a table a test compares with the core's at merge); the sides
    and static levels are the rules'."""
    from thermofriction import _bridge
    from thermofriction.models import domains
    assert list(domains.PARAMETER_DOMAIN) == list(_bridge.PARAMETERS)
    assert {r.partition(":")[0] for r in domains.PARAMETER_DOMAIN.values()} <= set(domains.RULES)
    assert domains.STATIC_LEVELS == (("fs", "fc"), ("fs_neg", "fc_neg"))
    assert domains.NEGATIVE_SIDE == {"fc_neg": "fc", "fs_neg": "fs", "vs_neg": "vs", "sigma2_neg": "sigma2"}
    assert domains.in_domain("vd", [0.0, 1e-3]).tolist() == [False, True]  # Python refuses vd = 0 (C: sigma1 constant)
    assert domains.in_domain("z_ba", [-1e-9, 0.0]).tolist() == [False, True]
    assert domains.in_domain("fs", [-1.0, np.inf]).tolist() == [True, False]  # fs: relative to fc, checked with it


@pytest.mark.parametrize("values, message", [
    (dict(sigma0=1e5, sigma1=1.0, fc=1.0, vd=0.0), "[friction]: 'vd' must be positive and finite, got 0.0"),
    (dict(sigma0=1e5, sigma1=1.0, fc=1.0, fs=1.5), "[friction]: 'vs' must be positive when fs != fc (the Stribeck "
     "velocity), got None"),
    (dict(sigma0=1e5, sigma1=1.0, fc=1.0, fs=0.5), "[friction]: 'fs' (0.5) must be at least 'fc' (1.0)"),
    (dict(sigma0=1e5, sigma1=1.0, fc=1.0, z_ba=1e-4), "[friction]: 'z_ba' (0.0001 m) must be below the steady "
     "deflection fc/sigma0 (1e-05 m): the elasto-plastic model breaks away before it"),
    (dict(sigma0=1e5, sigma1=1.0, fc=1.0, fs=2.0, vs=1.0, fc_neg=0.5, vs_neg=-1.0), "[friction]: 'vs_neg' must be "
     "positive and finite, got -1.0"),
    (dict(sigma0=1e5, sigma1=1.0, fc=1.0, fs_neg=0.5), "[friction]: the negative side's static level fs_neg (0.5; fs "
     "where not given) must be at least its Coulomb level fc_neg (1.0)"),
    (dict(sigma0=1e5, sigma1=1.0, fc=1.0, fs=2.0, vs=1.0, fc_neg=1.5, fs_neg=1.5, vs_neg=1.0, sigma2_neg=1.0,
          delta=-1.0), "[friction]: 'delta' must be positive and finite, got -1.0"),
])
def test_the_checks_from_the_rules_say_what_they_said(values, message):
    with pytest.raises(tf.InputError) as e:
        tf.models.check_friction_values(values, "[friction]")
    assert str(e.value) == message


def test_the_descriptions_say_what_the_lists_elsewhere_say():
    """Until each is derived from the descriptions, the lists of friction models written elsewhere agree with them:
    the observer's models (bristle), the static maps through a smoothed sign, the passivity test's, the models with
    a Stribeck curve (fs among their parameters), the command line's choices."""
    from thermofriction import control
    from thermofriction.cli import build_parser
    models = tf.models.FRICTION_MODELS

    def having(flag):
        return tuple(n for n, c in models.items() if getattr(c.description, flag))
    assert control.OBSERVED_MODELS == having("bristle") == ("lugre", "dahl", "elastoplastic")
    assert having("smoothed_sign") == ("coulomb", "stribeck") and having("dissipativity") == ("lugre", "elastoplastic")
    assert {n for n, c in models.items() if "fs" in c.law_targets} == {"stribeck", "gms", "lugre", "elastoplastic"}
    identify = next(a for a in build_parser()._subparsers._group_actions[0].choices["identify"]._actions
                    if "--friction" in a.option_strings)
    assert set(identify.choices) == set(models)
    assert [c.description.title for c in models.values()] == ["LuGre", "Coulomb", "Stribeck", "Dahl",
                                                              "elasto-plastic", "GMS"]
