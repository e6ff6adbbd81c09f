"""A position ripple the residuals hold, found and tried before it is said (identification/ripple_advice.py).

Truths from tests/lookalike.py (LuGre with direction-dependent levels integrated by SciPy, per-run offsets, AR(1)
noise, a velocity column 40 ms late): a cogging joint (a ripple of 50 periods a turn as large as the Coulomb level,
as the FAIRINO logs of benchmarks/bench_public_logs.py hold), and the same joint without a ripple."""

import math
import warnings

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.identification.ripple_advice import strongest_period

import lookalike as L

PERIOD = 2 * math.pi / 50


def _data(ripple, seed):
    truth = L.Truth(ripple=ripple, ripple_period=PERIOD)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return L.lookalike_experiments(truth=truth, offsets=(0.02, -0.015, 0.03), lag=0.04, rho=0.5, noise=0.02,
                                       start_angles=(0.3, 2.1, 4.0), seed=seed)


def _fit(data, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return tf.identify(data, "base", offset="per-experiment", **kw)


def test_the_periodogram_finds_a_known_period():
    """Analytic: a sine of known period in the angle, sampled irregularly over three runs with different phases and
    noise, is found within 0.5 % (the summed Lomb-Scargle power of the runs)."""
    rng = np.random.default_rng(0)
    runs = []
    for k in range(3):
        x = np.sort(rng.uniform(0.5 * k, 0.5 * k + 1.0, 4000))
        runs.append((x, 0.3 * np.sin(2 * math.pi * x / 0.037 + k) + rng.normal(0, 0.1, x.size)))
    assert abs(strongest_period(runs) / 0.037 - 1) < 5e-3


@pytest.mark.parametrize("seed", [5, 6])
def test_a_ripple_in_the_residuals_is_said_with_gains_a_refit_bears_out(seed):
    """Fitted without a ripple, the cogging joint's fit says its residuals hold one, names the period within 1 % of
    the truth's, and calls the fit not adequate; the held-out RMSE it says the refit reaches is what a user's own
    fit with that period (tf.identify with the ripple's amplitudes fitted) reaches on the held-out run, within 15 %."""
    data, runs = _data(0.36, seed)
    fit = _fit(data)
    found = fit.fit_quality["ripple"]
    assert found["said"] and abs(found["period"] / PERIOD - 1) < 0.01, found
    assert fit.adequate is False and fit.fit_quality["verdict_basis"] == "ripple"
    assert fit.warnings[0].startswith("the fit is not adequate: the residuals hold a position ripple")
    assert "NOT ADEQUATE: the residuals hold a position ripple" in fit.report()
    init = fit.model.with_friction(ripple_period=found["period"])
    followed = _fit(data, init=init, parameters=[p.name for p in fit.parameters.varying] + ["ripple_cos1",
                                                                                               "ripple_sin1"])
    v = tf.validate(followed.model, data, offset="per-experiment")
    held = float(np.sqrt(np.mean([p.rmse ** 2 for p in v.predictions if p.role == "validate"])))
    assert found["heldout_after"] < 0.5 * found["heldout_before"]
    assert abs(found["heldout_after"] / held - 1) < 0.15, (found, held)


@pytest.mark.parametrize("seed", [5, 6])
def test_no_ripple_no_advice(seed):
    """The same joint without a ripple: nothing is said about one (no false advice), and the verdict is not the
    ripple's."""
    data, _ = _data(0.0, seed)
    fit = _fit(data)
    found = fit.fit_quality.get("ripple")
    assert found is None or not found["said"], found
    assert not any("position ripple" in w for w in fit.warnings)
    assert fit.fit_quality.get("verdict_basis") != "ripple"
