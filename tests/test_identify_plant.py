"""The plant (xi, wn, K) from a stage response, as the paper obtained it."""

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.identify.plant import fit_plant, step_response, unit_gain_response

XI, WN, K = 0.2488, 6685.5, 0.096e-6


def ramp_response(tau, xi, wn):
    """Analytic response of x'' + 2 xi wn x' + wn^2 x = wn^2 r(t) to the unit ramp r(t) = t."""
    tau = np.clip(tau, 0, None)
    wd = wn * np.sqrt(1 - xi ** 2)
    return (tau - 2 * xi / wn + np.exp(-xi * wn * tau)
            * (2 * xi / wn * np.cos(wd * tau) + (2 * xi ** 2 - 1) / wd * np.sin(wd * tau)))


def test_first_order_hold_is_exact_for_piecewise_linear_input__analytic():
    """A 10 V rise over one sampling interval is two ramps: the response is their analytic
    responses' difference, which the discretisation must reproduce to rounding."""
    t = np.arange(0, 4e-3, 1e-5)
    t1, d = t[100], 1e-5
    u = 10.0 * np.clip((t - t1) / d, 0, 1)
    exact = 10.0 / d * (ramp_response(t - t1, XI, WN) - ramp_response(t - t1 - d, XI, WN))
    assert np.max(np.abs(unit_gain_response(t, u, XI, WN) - exact)) < 1e-9 * 10
    np.testing.assert_allclose(exact[-1], step_response(t[-1:], XI, WN, 1.0, 10.0, t1 + d / 2)[0], rtol=1e-3)


def test_noise_free_response_gives_back_xi_wn_K__analytic():
    t = np.arange(0, 5e-3, 1e-5)
    u = np.clip((t - 1e-3) / 1e-5, 0, 1) * 10.0
    y = K * unit_gain_response(t, u, XI, WN)
    fit = fit_plant(t, u, y)
    assert fit.damping_ratio == pytest.approx(XI, rel=1e-6)
    assert fit.natural_frequency == pytest.approx(WN, rel=1e-6)
    assert fit.gain == pytest.approx(K, rel=1e-6)


def test_noisy_stage_response_from_the_simulator_is_within_the_intervals__synthetic_truth():
    """The stage of the paper's actuator with friction removed, simulated by the C core, under a
    10 V step (ramped over 10 us), with 1 nm sensor noise."""
    base = tf.load_model("li2009-base")
    model = tf.Model(base.plant, tf.LuGre(sigma0=1e-12, sigma1=0.0, fc=1e-12),
                     input=tf.Step(10.0, time=1e-3, slew=1e-5))
    res = tf.simulate(model, 0.006, sample_rate=100_000, controller=tf.StepSizeController(rtol=1e-10))
    y = res.stage_displacement + 1e-9 * np.random.default_rng(0).standard_normal(res.time.size)
    fit = fit_plant(res.time, res.input, y)
    for name, true in (("damping_ratio", XI), ("natural_frequency", WN), ("gain", K)):
        p = fit.parameters[name]
        assert p.ci95[0] <= true <= p.ci95[1], (name, p.value, p.ci95)
    assert fit.rmse == pytest.approx(1e-9, rel=0.1)
