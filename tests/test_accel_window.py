"""The acceleration's window of a drive-command fit chosen from the record (issue 40 item 6;
measurements/command.py accel_window, docs/force-data.md#drives-without-a-torque-sensor): the narrowest
Savitzky-Golay window whose noise biases J by at most ACCEL_BIAS (the noise's variance over the acceleration's).

Checked against the analytic noise gain of a quadratic Savitzky-Golay slope over 2m + 1 samples (the least
squares slope: h_k = k / (dt sum k^2), so sum h^2 = 1 / (dt^2 m (m + 1) (2m + 1) / 3)) and a sine's acceleration
variance (A w^2)^2 / 2, written here, not taken from the package."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from thermofriction.measurements.command import ACCEL_BIAS, accel_window, velocity_noise

DT, A, W = 1e-3, 0.5, 2 * math.pi * 0.5


def record(sigma, seed=0, n=4000):
    t = DT * np.arange(n)
    v = A * W * np.cos(W * t) + np.random.default_rng(seed).normal(0.0, sigma, n)
    return SimpleNamespace(time=t, drive_velocity=v, velocity_resolution=None)


def noise_ratio(sigma, w):
    m = (w - 1) // 2
    return sigma ** 2 / (DT ** 2 * m * (m + 1) * (2 * m + 1) / 3) / ((A * W ** 2) ** 2 / 2)


def test_a_clean_velocity_takes_the_narrowest_window():
    """A noise-free velocity (as the servo truth of test_delay logs it): 3 samples, which the fixed 9 blurred."""
    assert accel_window(record(0.0)) == 3


@pytest.mark.parametrize("sigma", [1e-4, 1e-3, 3e-3])
def test_the_window_is_the_narrowest_within_the_bias(sigma):
    """White velocity noise sigma: its estimate within 10 %, and the window chosen is the narrowest whose
    analytic noise-to-signal ratio is within ACCEL_BIAS (the next narrower one exceeds it, allowing the noise
    estimate's 10 %)."""
    rec = record(sigma, seed=1)
    assert velocity_noise(rec.drive_velocity) == pytest.approx(sigma, rel=0.1)
    w = accel_window(rec)
    assert noise_ratio(sigma, w) <= 1.25 * ACCEL_BIAS, (w, noise_ratio(sigma, w))
    assert w == 3 or noise_ratio(sigma, w - 2) > 0.8 * ACCEL_BIAS, (w, noise_ratio(sigma, w - 2))
    assert (w > 3) == (sigma > 1e-4)


def test_a_quantised_velocity_counts_its_step():
    """A quantised velocity's noise is at least its step over sqrt(12), however its differences fall."""
    assert velocity_noise(np.zeros(100), resolution=0.012) == pytest.approx(0.012 / math.sqrt(12))
