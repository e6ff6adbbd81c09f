"""The cheaper paths of issue 42's second round, each against an independent reference: the compressed residuals
(one QR of [J r]) against their definition computed directly; the ripple advice's periodogram against SciPy's
``lombscargle``; the profile's linearized start against the exact conditional minimum of a linear least-squares
problem; and a fit's ``nfev`` / ``njev`` against a count of every model evaluation made apart from the package."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.signal

import thermofriction as tf
from thermofriction.fitting import problem
from thermofriction.fitting.optimiser import Transform, compressed
from thermofriction.fitting.parameters import Parameters
from thermofriction.identification.profile import conditional_step
from thermofriction.identification.ripple_advice import lombscargle

sys.path.insert(0, str(Path(__file__).resolve().parent))
from lookalike import lookalike_experiments  # noqa: E402


@pytest.mark.parametrize("rows", [5000, 3])
def test_compressed_residuals_keep_the_norm_gradient_and_normal_matrix(rows):
    """|f| = |r|, G^T f = J^T r and G^T G = J^T J (r and J in the noise's units and the fitted coordinates),
    computed directly from their definitions, to rounding; also with fewer samples than parameters + 1."""
    rng = np.random.default_rng(3)
    p = 4
    J = rng.normal(size=(rows, p)) * np.array([1.0, 1e3, 1e-3, 5.0])
    r = rng.normal(size=rows) + J @ rng.normal(size=p)
    theta = np.array([2.0, 0.5, -1.5, 3.0])
    transform = Transform(np.array([True, True, False, False]), np.array([1.0, 1.0, 1.5, 3.0]))
    f, G = compressed(r, J, transform, theta, 0.7)
    rs, Js = r / 0.7, J * transform.dtheta_dphi(theta)[None, :] / 0.7
    assert f @ f == pytest.approx(rs @ rs, rel=1e-12)
    np.testing.assert_allclose(G.T @ f, Js.T @ rs, rtol=1e-9, atol=1e-9 * np.abs(Js.T @ rs).max())
    np.testing.assert_allclose(G.T @ G, Js.T @ Js, rtol=1e-9, atol=1e-9 * np.abs(Js.T @ Js).max())


def test_the_periodogram_is_scipys():
    """The ripple advice's Lomb-Scargle periodogram against SciPy's (its "power" normalisation) on unevenly
    sampled noise with a periodic part, over 700 frequencies (more than one block): equal to 1e-10 of the peak, and
    the same peak."""
    rng = np.random.default_rng(5)
    x = np.sort(rng.uniform(0.0, 3.0, 900))
    y = 0.3 * np.sin(2 * np.pi * x / 0.07 + 0.4) + rng.normal(size=x.size)
    y -= y.mean()
    omega = 2 * np.pi / np.geomspace(0.01, 1.5, 700)
    ours, theirs = lombscargle(x, y, omega), scipy.signal.lombscargle(x, y, omega)
    assert np.max(np.abs(ours - theirs)) < 1e-10 * theirs.max()
    assert np.argmax(ours) == np.argmax(theirs)


def test_the_profiles_start_is_the_conditional_minimum_of_the_linearization():
    """On a linear model r = J theta - y the conditional step of the others with one parameter moved by d is the
    exact minimum over them (numpy's lstsq of the reduced problem); a positive parameter is moved by its log, the
    same to first order."""
    rng = np.random.default_rng(7)
    J = rng.normal(size=(200, 3))
    J[:, 2] += 0.8 * J[:, 0]  # correlated with the moved one
    theta = np.array([1.0, -2.0, 0.5])

    class Outcome:
        pass

    outcome = Outcome()
    outcome.theta, outcome.J = theta, J
    params = Parameters()
    params.add("a", 1.0)
    params.add("b", -2.0)
    params.add("c", 0.5)
    step = 0.01
    shift = conditional_step(outcome, ["a", "b", "c"], "a", step, params)
    exact = np.linalg.lstsq(J[:, 1:], -J[:, 0] * step, rcond=None)[0]
    assert shift["b"] == pytest.approx(theta[1] + exact[0], rel=1e-12)
    assert shift["c"] == pytest.approx(theta[2] + exact[1], rel=1e-12)
    positive = Parameters()
    positive.add("b", -2.0)
    positive.add("c", 0.5, min=0.0)
    shift = conditional_step(outcome, ["a", "b", "c"], "a", step, positive)
    assert shift["c"] == pytest.approx(theta[2] * math.exp(exact[1] / theta[2]), rel=1e-12)
    assert shift["c"] - theta[2] == pytest.approx(exact[1], rel=0.05)


def test_nfev_is_every_evaluation_of_a_force_fit_its_tests_and_advice():
    """A force fit from the start read off the data (the screening's short fits), with the held values' tests and
    the ripple advice (the look-alike holds a ripple): its nfev and njev equal the model evaluations counted by a
    wrapper of Problem.evaluate made here, outside the package's own counting."""
    data, _ = lookalike_experiments(motion="position", offsets=(0.02,), roles=["fit"], duration=30.0, rate=100.0,
                                    seed=1)
    seen = [0, 0]
    evaluate = problem.Problem.evaluate

    def counting(self, theta, jac=False):
        seen[0] += 1
        seen[1] += int(jac)
        return evaluate(self, theta, jac)

    problem.Problem.evaluate = counting
    try:
        fit = tf.identify(data, "base", friction="lugre")
    finally:
        problem.Problem.evaluate = evaluate
    assert fit.fit_quality.get("ripple") is not None  # the advice ran a refit: its evaluations are in the count
    assert (fit.nfev, fit.njev) == tuple(seen)
    assert fit.nfev > fit.fit_quality["ripple"]["evaluations"] > 0


@pytest.mark.parametrize("centred", [True, False])
def test_the_phase_cost_is_the_ripple_evaluated_at_the_shifted_angle(centred):
    """measurements/ripple.py's cost of a run's angle offset (the harmonics rotated, a quadratic form) against the
    ripple evaluated on the whole run at the shifted angle and summed directly, at phases over its period: equal
    to 1e-12 of the cost (three harmonics, an uneven travel, an offset in the residuals)."""
    from thermofriction.measurements import ripple

    model = tf.Model(tf.PrescribedMotion(motion="rotary"),
                     tf.LuGre(sigma0=100.0, sigma1=0.5, fc=0.3, fs=0.4, vs=0.08, sigma2=0.1, ripple_period=0.1,
                              ripple_cos1=0.02, ripple_sin1=-0.01, ripple_cos2=0.005, ripple_sin3=0.002))
    rng = np.random.default_rng(2)
    x = np.cumsum(rng.uniform(0.0, 0.003, 4000))
    r0 = rng.normal(0.0, 0.01, x.size) + 0.3
    cost = ripple._phase_cost(model, x, r0, centred)
    for phi in np.linspace(0.0, 0.1, 7):
        e = r0 + ripple.evaluate(model, x + phi)[0]
        direct = float(np.sum((e - e.mean()) ** 2 if centred else e ** 2))
        assert cost(phi) == pytest.approx(direct, rel=1e-12)
