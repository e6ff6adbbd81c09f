"""Statistics that stay honest when the noise is not white (issue: real measurements). The noise estimate says
when it cannot be trusted; adequacy is then unknown, not "check the units"; intervals take the residuals'
autocorrelation in (the integrated autocorrelation time: an effective sample size), and their coverage is
measured on correlated-noise truths (a Stribeck map in closed form, AR(1) noise)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from lookalike import ar1  # noqa: E402

import thermofriction as tf  # noqa: E402
from thermofriction.data.experiments import Dataset  # noqa: E402
from thermofriction.data.force import force_experiment  # noqa: E402
from thermofriction.fitting.uncertainty import integrated_autocorrelation  # noqa: E402
from thermofriction.fitting.quality import fit_quality, noise_check, noise_level  # noqa: E402

TRUE = dict(fc=0.4, fs=0.55, vs=0.1, sigma2=0.12)


def joint_data(friction, seed, n=800, noise=lambda n, rng: np.zeros(n), offset=0.0, name="joint"):
    """Two runs of a joint under sine motions; torque ``friction(v)`` in closed form (independent of the
    package's models) plus an offset and ``noise(n, rng)``."""
    rng = np.random.default_rng(seed)
    exps = []
    for k in range(2):
        t = np.linspace(0.0, 8.0, n)
        A, f = 0.6 * (1 + 0.2 * k), 0.25 * (1 + 0.1 * k)
        x, v = A * np.sin(2 * np.pi * f * t), A * 2 * np.pi * f * np.cos(2 * np.pi * f * t)
        cols = {"time": t, "position": x, "velocity": v, "force": friction(v) + offset + noise(n, rng),
                "rotary": True, "headers": {"time": "time[s]", "position": "position[rad]",
                                            "velocity": "velocity[rad/s]", "force": "friction_torque[N*m]"}}
        exps.append(force_experiment(f"run{k}", f"run{k}.csv", temperature=25.0, role="fit", description="",
                                     from_zero=lambda t, i: (t, i), motion="velocity", flip_sign=False, columns=cols))
    return Dataset(name=name, experiments=exps)


def stribeck_data(seed, rho, n=800, noise=0.02, offset=0.03):
    """The Stribeck map of TRUE, an offset and AR(1) noise of stationary standard deviation ``noise``."""
    def stribeck(v):
        return np.sign(v) * (TRUE["fc"] + (TRUE["fs"] - TRUE["fc"]) * np.exp(-(v / TRUE["vs"]) ** 2)) + \
            TRUE["sigma2"] * v
    return joint_data(stribeck, seed, n, lambda m, rng: ar1(m, rho, noise, rng), offset, "stribeck")


def start():
    return tf.Model(tf.PrescribedMotion(motion="rotary"), tf.Stribeck(fc=0.5, fs=0.7, vs=0.15, sigma2=0.1))


@pytest.mark.parametrize("phi", [0.0, 0.5, 0.9])
def test_integrated_autocorrelation_of_an_ar1_series_analytic(phi):
    """Analytic: an AR(1) series' integrated autocorrelation time is (1 + phi)/(1 - phi)."""
    x = ar1(200_000, phi, 1.0, np.random.default_rng(1))
    assert integrated_autocorrelation(x) == pytest.approx((1 + phi) / (1 - phi), rel=0.1)


def test_noise_estimate_says_when_it_cannot_be_trusted():
    """White noise on a smooth signal: trusted and right. AR(1) noise (an estimator's output), a signal with no
    visible noise, a quantised one: not trusted, with the reason. A stick-slip record with white noise and 5 nm
    quantisation (the your-data guide's): trusted."""
    rng = np.random.default_rng(2)
    t = np.linspace(0, 10, 20_000)
    white = np.sin(t) + 0.01 * rng.standard_normal(t.size)
    assert noise_check(white) == (True, "") and noise_level(white) == pytest.approx(0.01, rel=0.05)
    coloured = np.sin(t) + ar1(t.size, 0.7, 0.01, rng)
    ok, why = noise_check(coloured)
    assert not ok and "not white" in why
    assert noise_level(coloured) < 0.6 * 0.01  # what the check guards against: the estimate is far too low
    assert not noise_check(np.sin(t))[0]
    ok, why = noise_check(np.round(np.sin(t) * 20) / 20)
    assert not ok and ("quantised" in why or "not white" in why)
    data = tf.synthesize(tf.load_model("li2009-model-i"), [30.5, 41.0], duration=0.4, sample_rate=5000,
                         noise=20e-9, quantization=5e-9, seed=12)
    assert all(noise_check(e.displacement)[0] for e in data.experiments)


def test_adequacy_is_unknown_not_a_false_alarm_on_a_smooth_estimator_output():
    """Torque with AR(1) noise (lag-1 0.9, like an estimator's output): the second-difference noise estimate is a
    quarter of the real noise, so 'residuals 4x the noise: check the units' would be a false alarm. The fit says
    its adequacy is unknown and why, and advises held-out error, not the units."""
    fit = tf.identify(stribeck_data(0, 0.9), "base", init=start(), friction="stribeck", starts=1)
    q = fit.fit_quality
    assert q["adequate"] is None and fit.adequate is None and not q["noise_reliable"]
    assert q["ratio"] > 2.0  # the old test would have called it not adequate
    text = fit.report()
    assert "NOT ADEQUATE" not in text and "adequacy unknown" in text and "check the units" not in text
    assert any("held-out" in w for w in fit.warnings)
    white = tf.identify(stribeck_data(0, 0.0), "base", init=start(), friction="stribeck", starts=1)
    assert white.adequate is True and white.fit_quality["noise_reliable"]


def test_interval_coverage_on_correlated_noise_truths():
    """Coverage (measured): 95 % intervals of fc, fs, vs, sigma2 over 40 truths with AR(1) noise (lag-1 0.8)
    cover the truth in at least 90 % of cases; the same intervals without the autocorrelation's inflation
    (what independent residuals would give) cover far less -- the check can fail."""
    covered = naive = total = 0
    for seed in range(40):
        fit = tf.identify(stribeck_data(100 + seed, 0.8), "base", init=start(), friction="stribeck", starts=1)
        shrink = math.sqrt(fit.statistics["variance_inflation"])
        assert shrink > 2.0
        for name, p in fit.parameters.items():
            if not p.vary:
                continue
            total += 1
            covered += p.ci95[0] <= TRUE[name] <= p.ci95[1]
            lo, hi = (math.log(c) for c in p.ci95)
            mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo) / shrink
            naive += math.exp(mid - half) <= TRUE[name] <= math.exp(mid + half)
    assert covered / total >= 0.90, covered / total
    assert naive / total < 0.75, naive / total


def test_fit_quality_of_white_residuals_is_unchanged():
    """White residuals at the noise on a smooth record: adequate, the ratio ~1, the noise trusted."""
    rng = np.random.default_rng(3)
    t = np.linspace(0, 10, 5000)
    measured = np.sin(t) + 0.01 * rng.standard_normal(t.size)
    q = fit_quality(measured - np.sin(t), measured)
    assert q["adequate"] is True and q["noise_reliable"] and q["ratio"] == pytest.approx(1.0, abs=0.1)


def test_presliding_reversals_are_real_reversals_not_velocity_noise():
    """The report's presliding panels: turning points of the position by excursion. A sine's turning points are
    found where they are (analytic: t = 1, 3, 5, ... s at 0.25 Hz); a hold with velocity noise at rest (sign
    flips at every sample) adds none."""
    from thermofriction.reporting.force import reversals
    t = np.linspace(0, 10, 2001)
    x = np.sin(2 * np.pi * 0.25 * t)
    assert [round(float(t[i]), 2) for i in reversals(x, 10)] == [1.0, 3.0, 5.0, 7.0, 9.0]
    held = np.concatenate([x[:300], np.full(500, x[300]) + 1e-9 * np.random.default_rng(0).standard_normal(500)])
    v = np.gradient(held, t[:800])
    assert np.sum(np.sign(v[1:]) * np.sign(v[:-1]) < 0) > 100  # what velocity sign flips would have picked
    assert [round(float(t[i]), 2) for i in reversals(held, 10)] == [1.0]


def coulomb_data(seed=0, n=800):
    """A Coulomb-viscous map (no Stribeck excess), white noise."""
    return joint_data(lambda v: 0.4 * np.sign(v) + 0.12 * v, seed, n, lambda m, rng: 0.02 * rng.standard_normal(m),
                      name="coulomb")


def test_a_stribeck_excess_the_data_do_not_show_is_said():
    """--friction stribeck on Coulomb-viscous data: from a start without an excess (fs = fc) the fit says fs and
    vs were not fitted; from one with an excess it says the data show none (fs - fc within two standard errors)."""
    data = coulomb_data()
    flat = tf.Model(tf.PrescribedMotion(motion="rotary"), tf.Stribeck(fc=0.5, fs=0.5, vs=0.1, sigma2=0.1))
    fit = tf.identify(data, "base", init=flat, starts=1)
    assert "fs" not in fit.parameters and any("fs and vs were not fitted" in w for w in fit.warnings)
    fit = tf.identify(data, "base", init=start(), starts=1)
    assert any("no Stribeck excess" in w for w in fit.warnings), fit.warnings
    with_excess = tf.identify(stribeck_data(0, 0.0), "base", init=start(), starts=1)
    assert not any("Stribeck" in w for w in with_excess.warnings)


def test_a_parameter_at_its_bound_is_shown_at_bound_with_a_one_sided_interval():
    """fc held below its true value by a bound (max 0.3 N m, truth 0.4): it ends at the bound, shown "at upper
    bound" with a one-sided interval from the bound, not a two-sided one around it."""
    from thermofriction.identification import Parameters, fit_friction
    model = start()
    params = Parameters()
    params.add("fc", 0.25, min=0.0, max=0.3, unit="N m")
    params.add("sigma2", 0.1, min=0.0, unit="N m s/rad")
    fit = fit_friction(stribeck_data(0, 0.0).experiments, model, params, starts=1)
    fc = fit.parameters["fc"]
    assert fc.at_bound == "upper" and fc.ci95[1] == pytest.approx(0.3) and fc.ci95[0] < 0.3
    assert fit.parameters["sigma2"].at_bound is None
    assert "at upper bound" in fit.report() and "(one-sided)" in fit.report()
    assert fit.parameters.to_dict()["fc"]["at_bound"] == "upper"


def test_the_evaluation_limit_can_be_raised_and_is_named_when_reached():
    data = stribeck_data(0, 0.0)
    short = tf.identify(data, "base", init=start(), starts=1, max_evaluations=2)
    assert not short.success and "max-evaluations" in short.message
    assert tf.identify(data, "base", init=start(), starts=1, max_evaluations=200).success
    with pytest.raises(tf.InputError, match="max_evaluations"):
        tf.identify(data, "base", init=start(), max_evaluations=0)
