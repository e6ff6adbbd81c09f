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


def test_gms_on_a_coulomb_level_holds_c_and_says_so(tmp_path):
    """Issue 40 item 7: a GMS fit on force data whose friction is a plain Coulomb level (a static map written
    here with NumPy, 0.3 tanh(v / 2 mrad/s) plus 3 mN m noise). With fs = fc a slipping element sits at its
    capacity and C changes nothing (GMS's slip law C (sgn(v) w_i - F_i / g) is zero there), so C is held with
    a warning naming it, and fc is reported determined (a finite interval within a few % of its value). Before:
    C fitted, running off to 3e-4 with a standard error of 5e13."""
    import tomli_w

    import thermofriction as tf

    t = np.arange(0.0, 4.0, DT)
    x, v = A * np.sin(W * t), A * W * np.cos(W * t)
    F = 0.3 * np.tanh(v / 0.002) + np.random.default_rng(0).normal(0.0, 0.003, t.size)
    np.savetxt(tmp_path / "run0.csv", np.column_stack([t, x, v, F]), delimiter=",", comments="", fmt="%.12g",
               header="time[s],position[rad],velocity[rad/s],friction_torque[N*m]")
    (tmp_path / "dataset.toml").write_text(tomli_w.dumps({"name": "c", "experiment": [
        {"file": "run0.csv", "temperature": 25.0}]}))
    res = tf.identify(tf.load_dataset(tmp_path), method="base", friction="gms", starts=1)
    assert "C" not in [p.name for p in res.parameters.varying]
    said = [w for w in res.warnings if w.startswith("'C'")]
    assert len(said) == 1 and "fs = fc" in said[0] and "held" in said[0], res.warnings
    fc = res.parameters["fc"]
    assert math.isfinite(fc.stderr) and fc.stderr < 0.05 * fc.value and fc.ci95[1] - fc.ci95[0] < 0.2 * fc.value
