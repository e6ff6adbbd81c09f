"""The plant (xi, wn, K) from a stage response, as the paper obtained it (Eqs. 3-4).

Oracles: the analytic step and ramp responses of x'' + 2 xi wn x' + wn^2 x = K wn^2 u(t) from rest
(closed forms, independent of the fitter's discretisation), SciPy's matrix exponential for the
discretisation, and the C core's simulation of the paper's stage with friction removed."""

import json
import math

import numpy as np
import pytest
from scipy import linalg

import thermofriction as tf
from thermofriction.identification.plant import PlantFit, fit_plant, step_response, unit_gain_response

XI, WN, K = 0.2488, 6685.5, 0.096e-6   # the paper's plant
TRUE = {"damping_ratio": XI, "natural_frequency": WN, "gain": K}


def ramp_response(tau, xi, wn):
    """Analytic response of x'' + 2 xi wn x' + wn^2 x = wn^2 r(t) to the unit ramp r(t) = t (xi < 1)."""
    tau = np.clip(tau, 0, None)
    wd = wn * np.sqrt(1 - xi ** 2)
    return (tau - 2 * xi / wn + np.exp(-xi * wn * tau)
            * (2 * xi / wn * np.cos(wd * tau) + (2 * xi ** 2 - 1) / wd * np.sin(wd * tau)))


def expm_response(t, u, xi, wn, hold):
    """Reference: the sampled system from SciPy's matrix exponential of the augmented matrix,
    stepped sample by sample (slow, obviously correct)."""
    h = t[1] - t[0]
    A = np.array([[0.0, 1.0], [-wn * wn, -2 * xi * wn]])
    M = np.zeros((4, 4))
    M[:2, :2], M[1, 2], M[2, 3] = A * h, wn * wn * h, 1.0
    E = linalg.expm(M)
    Phi, G0, G1 = E[:2, :2], E[:2, 2], E[:2, 3]
    x, y = np.zeros(2), np.zeros(t.size)
    for k in range(t.size - 1):
        du = u[k + 1] - u[k] if hold == "foh" else 0.0
        x = Phi @ x + G0 * u[k] + G1 * du
        y[k + 1] = x[0]
    return y


def test_first_order_hold_is_exact_for_piecewise_linear_input__analytic():
    """A 10 V rise over one sampling interval is two ramps: the response is the difference of their
    analytic responses, which the first-order hold must reproduce to rounding."""
    t = np.arange(0, 4e-3, 1e-5)
    t1, d = t[100], 1e-5
    u = 10.0 * np.clip((t - t1) / d, 0, 1)
    exact = 10.0 / d * (ramp_response(t - t1, XI, WN) - ramp_response(t - t1 - d, XI, WN))
    assert np.max(np.abs(unit_gain_response(t, u, XI, WN) - exact)) < 1e-12 * 10


@pytest.mark.parametrize("xi", [0.05, XI, 0.9999, 1.0, 1.7])
def test_zero_order_hold_is_exact_for_a_step__analytic(xi):
    """An ideal step at a sample instant, under- to overdamped (including the double pole)."""
    t = np.arange(0, 5e-3, 1e-5)
    u = np.where(t >= t[37], 10.0, 0.0)
    exact = step_response(t, xi, WN, 1.0, 10.0, t[37])
    assert np.max(np.abs(unit_gain_response(t, u, xi, WN, hold="zoh") - exact)) < 1e-12 * 10


@pytest.mark.parametrize("hold", ["foh", "zoh"])
@pytest.mark.parametrize("xi,wn,h", [(XI, WN, 1e-5), (0.02, 300.0, 1e-5), (1.4, 2e4, 1e-4), (1.0, WN, 1e-5)])
def test_discretisation_matches_the_matrix_exponential(hold, xi, wn, h):
    """The closed-form discretisation against SciPy's expm, with an input that does not start at
    zero (the stage still starts at rest at zero, as in tf.simulate). The filter form loses about
    eps / (wn h)^2 when the record is heavily oversampled (poles near z = 1)."""
    t = np.arange(300) * h
    u = 3.0 + 20.0 * np.sin(2 * math.pi * 50 * t) + np.where(t > 100 * h, 5.0, 0.0)
    ref = expm_response(t, u, xi, wn, hold)
    tol = max(1e-12, 1e-14 / (wn * h) ** 2)
    assert np.max(np.abs(unit_gain_response(t, u, xi, wn, hold) - ref)) < tol * np.max(np.abs(ref))


def test_noise_free_step_response_gives_back_xi_wn_K__analytic():
    """Data: the analytic step response (10 V at 1 ms, from rest); no initial guess given."""
    t = np.arange(0, 5e-3, 1e-5)
    u = np.where(t >= 1e-3, 10.0, 0.0)
    fit = fit_plant(t, u, step_response(t, XI, WN, K, 10.0, t[100]), hold="zoh")
    assert isinstance(fit, PlantFit) and fit.success
    assert fit.damping_ratio == pytest.approx(XI, rel=1e-6)
    assert fit.natural_frequency == pytest.approx(WN, rel=1e-6)
    assert fit.gain == pytest.approx(K, rel=1e-6)
    assert fit.rmse < 1e-6 * K * 10


def test_noise_free_ramped_step_gives_back_xi_wn_K__analytic():
    """Data: the analytic response to a 10 V step ramped over 50 us (two ramps), first-order hold."""
    t = np.arange(0, 5e-3, 1e-5)
    t1, d = 1e-3, 5e-5
    u = 10.0 * np.clip((t - t1) / d, 0, 1)
    y = K * 10.0 / d * (ramp_response(t - t1, XI, WN) - ramp_response(t - t1 - d, XI, WN))
    fit = fit_plant(t, u, y)
    for name, true in TRUE.items():
        assert getattr(fit, name) == pytest.approx(true, rel=1e-6), name


def test_overdamped_stage_and_an_initial_guess__analytic():
    xi, wn, k = 1.6, 2.0e4, 2e-7
    t = np.arange(0, 2e-3, 2e-6)
    u = np.where(t >= t[50], 5.0, 0.0)
    y = step_response(t, xi, wn, k, 5.0, t[50]) + 3e-9   # plus a sensor offset
    for initial in (None, (1.0, 1.0e4), {"damping_ratio": 3.0, "natural_frequency": 5e4}):
        fit = fit_plant(t, u, y, hold="zoh", initial=initial)
        assert fit.modal_parameters() == pytest.approx((xi, wn, k), rel=1e-6), initial
        assert fit.offset == pytest.approx(3e-9, rel=1e-6)


@pytest.fixture(scope="module")
def frictionless():
    """The paper's stage with the end effector's friction removed."""
    base = tf.load_model("li2009-base")
    assert base.plant.modal_parameters() == pytest.approx((XI, WN, K))
    return lambda inp: tf.Model(base.plant, tf.LuGre(sigma0=1e-12, sigma1=0.0, fc=1e-12), input=inp)


@pytest.mark.parametrize("step,hold", [(tf.Step(10.0, time=1e-4), "zoh"),
                                       (tf.Step(10.0, time=1e-3, slew=1e-5), "foh")], ids=["ideal", "slewed"])
def test_noisy_stage_step_response_from_the_simulator_is_within_the_intervals__synthetic_truth(frictionless,
                                                                                               step, hold):
    """A 10 V step simulated by the C core at 100 kHz, plus 1 nm sensor noise: the true xi, wn, K
    lie within the 95 % intervals, the errors are about the stated standard errors, and the
    residual is the noise."""
    res = tf.simulate(frictionless(step), 0.005, sample_rate=100_000, controller=tf.StepSizeController(rtol=1e-10))
    y = res.stage_displacement + 1e-9 * np.random.default_rng(0).standard_normal(res.time.size)
    fit = fit_plant(res.time, res.input, y, hold=hold)
    for name, true in TRUE.items():
        p = fit.parameters[name]
        assert p.ci95[0] <= true <= p.ci95[1], (name, p.value, p.ci95)
        assert 0 < p.stderr < 1e-3 * true
    assert fit.rmse == pytest.approx(1e-9, rel=0.1)
    assert not fit.warnings


def test_sawtooth_input_with_an_offset__synthetic_truth(frictionless):
    """Any input that moves the stage will do: the paper's sawtooth, starting at 2 V (the stage
    starting at rest at zero, as in tf.simulate), noise-free."""
    inp = tf.Sawtooth(amplitude=30.0, frequency=50.0, rise=0.9, offset=2.0)
    res = tf.simulate(frictionless(inp), 0.04, sample_rate=50_000, controller=tf.StepSizeController(rtol=1e-11))
    fit = fit_plant(res.time, res.input, res.stage_displacement)
    for name, true in TRUE.items():
        assert getattr(fit, name) == pytest.approx(true, rel=1e-5), name


def test_report_and_json(frictionless):
    res = tf.simulate(frictionless(tf.Step(10.0, time=1e-4)), 0.004, sample_rate=100_000)
    y = res.stage_displacement + 1e-9 * np.random.default_rng(1).standard_normal(res.time.size)
    fit = fit_plant(res.time, res.input, y, hold="zoh")
    text = fit.report()
    for word in ("[[Plant fit]]", "damping_ratio", "natural_frequency", "gain", "rad/s", "m/V", "95 % interval"):
        assert word in text
    d = json.loads(json.dumps(fit.to_dict()))
    for name in TRUE:
        p = d["parameters"][name]
        assert set(p) >= {"value", "stderr", "ci95"} and p["ci95"][0] < p["value"] < p["ci95"][1]
    assert np.asarray(d["correlation"]["matrix"]).shape == (3, 3)
    assert fit.stderr["gain"] == d["parameters"]["gain"]["stderr"]
    plant = fit.plant(0.05, 0.05)
    assert plant.modal_parameters() == pytest.approx(fit.modal_parameters())


@pytest.mark.parametrize("args,words", [
    ((np.arange(30.0), np.ones(30), np.arange(30.0)), "voltage is constant"),
    ((np.arange(30.0), np.arange(30.0), np.arange(29.0)), "equal length"),
    ((np.arange(10.0), np.arange(10.0), np.arange(10.0)), ">= 20 samples"),
    ((np.r_[np.arange(29.0), 3.0], np.arange(30.0), np.arange(30.0)), "increasing"),
    ((np.arange(30.0), np.r_[np.arange(29.0), np.nan], np.arange(30.0)), "finite"),
])
def test_bad_records_are_input_errors(args, words):
    with pytest.raises(tf.InputError, match=words):
        fit_plant(*args)


@pytest.mark.slow
def test_intervals_cover_the_truth_at_their_nominal_rate__synthetic_truth(frictionless):
    """Over 100 noise realisations, each 95 % interval contains the truth about 95 % of the time
    (binomial sd 2.2 %: between 88 % and 100 %)."""
    res = tf.simulate(frictionless(tf.Step(10.0, time=1e-4)), 0.005, sample_rate=100_000,
                      controller=tf.StepSizeController(rtol=1e-10))
    hits = np.zeros(3)
    for seed in range(100):
        y = res.stage_displacement + 1e-9 * np.random.default_rng(seed).standard_normal(res.time.size)
        fit = fit_plant(res.time, res.input, y, hold="zoh")
        hits += [fit.ci95[name][0] <= true <= fit.ci95[name][1] for name, true in TRUE.items()]
    assert np.all((hits >= 88) & (hits <= 100)), hits
