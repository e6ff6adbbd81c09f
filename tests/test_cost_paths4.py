"""The cheaper paths of issue 42's fourth round, each against an independent reference: the ripple advice's
periodogram on the bins' grid against SciPy's ``lombscargle`` at the bins' centres; the ripple at a shifted angle
from the harmonics at the unshifted one against the ripple evaluated at the shifted angle; the tall QR's R factor by
blocks against numpy's one QR; and a held value tried by a Gauss-Newton step against the refit it replaces."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.signal

import thermofriction as tf
from thermofriction.fitting import optimiser
from thermofriction.identification import advice
from thermofriction.identification.ripple_advice import grid_lombscargle
from thermofriction.measurements import ripple
from thermofriction.models.sides import RIPPLE_AMPLITUDES

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import study_cost as S  # noqa: E402


def test_the_periodogram_on_the_bins_grid_is_scipys():
    """grid_lombscargle (bins k of a width, the sums as products of a coarse and a fine exponential) against SciPy's
    ``lombscargle`` at the bins' centres (shifted by an arbitrary origin, which the periodogram does not see), on
    bins visited unevenly with a periodic part, over 1,500 frequencies (several blocks): equal to 1e-9 of the peak,
    the same peak."""
    rng = np.random.default_rng(11)
    k = np.unique(rng.integers(0, 2500, 1800))
    width = 0.0011
    x = 1.37 + width * (k + 0.5)
    y = 0.4 * np.sin(2 * np.pi * x / 0.061 + 0.3) + rng.normal(size=k.size)
    y -= y.mean()
    omega = 2 * np.pi / np.geomspace(4 * width, 1.3, 1500)
    ours, theirs = grid_lombscargle(k, y, width, omega), scipy.signal.lombscargle(x, y, omega)
    assert np.max(np.abs(ours - theirs)) < 1e-9 * theirs.max()
    assert np.argmax(ours) == np.argmax(theirs)


@pytest.mark.parametrize("phi", [0.0, 0.0123, 0.0871])
def test_the_ripple_at_a_shifted_angle_from_the_harmonics(phi):
    """ripple.shifted (the harmonics at x, the amplitudes rotated by k w phi) against ripple.evaluate at x + phi
    (three harmonics, every amplitude's column, dR/dx), over 40 rad at a 0.1 rad period: equal to 1e-10 of the
    ripple's size (evaluate's own rounding of x + phi, times k w, is ~1e-12 there)."""
    model = tf.Model(tf.PrescribedMotion(motion="rotary"),
                     tf.LuGre(sigma0=100.0, sigma1=0.5, fc=0.3, ripple_period=0.1, ripple_cos1=0.02,
                              ripple_sin1=-0.01, ripple_cos2=0.005, ripple_sin3=0.002))
    x = np.cumsum(np.random.default_rng(4).uniform(0.0, 0.008, 5000))
    names = ("sigma0",) + RIPPLE_AMPLITUDES
    R, J, dx = ripple.shifted(model, ripple.harmonics(x, 0.1), phi, names)
    R0, J0, dx0 = ripple.evaluate(model, x + phi, names)
    size = 0.03
    assert np.max(np.abs(R - R0)) < 1e-10 * size
    assert np.max(np.abs(J - J0)) < 1e-10
    assert np.max(np.abs(dx - dx0)) < 1e-10 * size * 2 * math.pi / 0.1 * 3


def test_the_harmonics_are_kept_per_angle_array_and_period():
    """The cache of a trace's harmonics: the same array object for the same angle array and period; recomputed (and
    right) for another period or another array with the same values."""
    x = np.linspace(0.0, 3.0, 1000)
    a = ripple._harmonics_of(x, 0.2)
    assert ripple._harmonics_of(x, 0.2) is a
    b = ripple._harmonics_of(x, 0.3)
    np.testing.assert_array_equal(b, ripple.harmonics(x, 0.3))
    np.testing.assert_array_equal(ripple._harmonics_of(x.copy(), 0.2), a)


def test_the_kept_harmonics_stay_within_their_budget(monkeypatch):
    """The cache keeps at most _HARMONICS_BYTES (harmonics and angles, counted here from the arrays themselves), drops
    the oldest first, and does not keep a record larger than a quarter of it (computed each time, still right)."""
    monkeypatch.setattr(ripple, "_HARMONICS", {})
    monkeypatch.setattr(ripple, "_HARMONICS_BYTES", 4 * 56_000)  # four runs of 1,000: 8 + 48 kB each
    runs = [np.linspace(0.0, 1.0 + k, 1000) for k in range(6)]
    for x in runs:
        ripple._harmonics_of(x, 0.1)
        assert sum(a.nbytes + H.nbytes for a, _, H in ripple._HARMONICS.values()) <= ripple._HARMONICS_BYTES
    assert len(ripple._HARMONICS) == 4  # the last four
    assert runs[-1] is next(reversed(ripple._HARMONICS.values()))[0] and runs[0] is not next(iter(
        ripple._HARMONICS.values()))[0]
    long = np.linspace(0.0, 9.0, 5000)
    np.testing.assert_array_equal(ripple._harmonics_of(long, 0.1), ripple.harmonics(long, 0.1))
    assert all(a is not long for a, _, _ in ripple._HARMONICS.values())


@pytest.mark.parametrize("rows", [20_000, 9_000])
def test_the_blocked_r_factor_is_the_qr(rows):
    """optimiser._r_factor (R factors of blocks, stacked and factored again) against numpy's QR of the whole: R^T R
    and the rows' absolute values equal to rounding (a row's sign is free)."""
    rng = np.random.default_rng(rows)
    A = rng.normal(size=(rows, 11)) * np.geomspace(1e-3, 1e3, 11)
    R, R0 = optimiser._r_factor(A), np.linalg.qr(A, mode="r")
    np.testing.assert_allclose(R.T @ R, R0.T @ R0, rtol=1e-10, atol=1e-10 * np.abs(R0.T @ R0).max())
    np.testing.assert_allclose(np.abs(R), np.abs(R0), rtol=1e-9, atol=1e-12 * np.abs(R0).max())


@pytest.fixture(scope="module")
def force7():
    """The cost study's force truth 7 (benchmarks/study_cost.py, drawn there from tests/lookalike.py): a look-alike
    joint whose fit is not adequate (no model reaches the noise), so its held delta is tried whatever its score."""
    return S.force_case("force", 7, False)


def test_a_small_held_value_tried_by_a_step_says_what_the_refit_said(force7, monkeypatch):
    """A held value whose linearized gain is below STEP_BELOW of MATERIAL is tried by a Gauss-Newton step measured by
    an exact run, against the 12-evaluation refit it replaces (STEP_BELOW 0): the same verdict (not contradicted, a
    gain below MATERIAL, not worth a parameter), the gains within STEP_AGREES of MATERIAL, the same fitted values,
    fewer evaluations."""
    data, _, start, opts = force7
    fit = tf.identify(data, init=start, **opts)
    monkeypatch.setattr(advice, "STEP_BELOW", 0.0)
    reference = tf.identify(data, init=start, **opts)
    step = next(h for h in fit.fit_quality["held"] if h["name"] == "delta")
    refit = next(h for h in reference.fit_quality["held"] if h["name"] == "delta")
    assert step["refit_basis"] == advice.STEPPED and refit["refit_basis"] != advice.STEPPED
    assert step["contradicted"] == refit["contradicted"] is False
    assert step["refit_holds"] == refit["refit_holds"] is False
    assert max(step["refit_gain"], refit["refit_gain"]) < advice.MATERIAL
    assert abs(step["refit_gain"] - refit["refit_gain"]) <= advice.STEP_AGREES * advice.MATERIAL
    assert all(fit.parameters[n].value == reference.parameters[n].value for n in opts["parameters"])
    assert fit.nfev < reference.nfev - 8
    assert any("Gauss-Newton step" in w for w in fit.warnings)
