"""Fits of the 10 ms-lag look-alike joint over many noise seeds (issue 40 item 1: "within 3 % of the truth from the
data's own start, intervals covering at >= 90 %"): tests/lookalike_laws.py makes the data outside the package (LuGre
with a Stribeck curve and viscous friction integrated by SciPy's LSODA under an analytic motion, a 17-bit encoder, a
firmware velocity 10 ms late and quantised, a sensor re-zeroed per run, AR(1) noise 0.02 N m with rho 0.5); the fits
start from a plant-only file. Every interval is checked against that truth, over eight seeds.

What the data can give (the Jacobian at the truth with a fit's own noise estimate, its AR(1) inflation included):
three runs at 40 C determine fs to 2.7-3.4 % and vs to 6-7.4 % (one standard error), so fs "within 3 %" is not a
promise the data can keep on every seed: there the requirement is met by intervals that cover. Model I's single run
per temperature, the fastest at 60 C, determines fs(60 C) to 15 % and vs to 32 % alone, and through linear laws on all
five runs to 9-10 % and 17-20 %."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.data.experiments import Dataset
from thermofriction.data.force import force_experiment
from thermofriction.data.motion import SUBSTEPS, MotionWarning, motion_waveform
from thermofriction.fitting.problem import Problem
from thermofriction.measurements import Force, make_traces

import lookalike_laws as L

PLANT_ONLY = '[plant]\ntype = "prescribed"\nmotion = "rotary"\n\n[friction]\nmodel = "lugre"\n'
NAMES = ("sigma0", "sigma1", "fc", "fs", "vs", "sigma2")
SEEDS = range(8)


@pytest.fixture(scope="module")
def plant_only(tmp_path_factory):
    path = tmp_path_factory.mktemp("coverage") / "joint.toml"
    path.write_text(PLANT_ONLY)
    return str(path)


def _dataset(runs, *, true_force=False, true_position=False):
    """The runs as a thermofriction Dataset, as tests/lookalike_laws.py loads them; optionally with the truth's force
    (no offset noise, no quantisation) and its unquantised position driving."""
    exps = []
    with warnings.catch_warnings():  # (the late column's MotionWarning: tests/test_starts_land.py checks it)
        warnings.simplefilter("ignore", MotionWarning)
        for k, r in enumerate(runs):
            exps.append(_experiment(k, r, true_force, true_position))
    return Dataset(name="joint", experiments=exps)


def _experiment(k, r, true_force, true_position):
    """Run ``k`` as a force experiment (see :func:`_dataset`)."""
    columns = {"time": r.time, "position": r.true_position if true_position else r.position,
               "velocity": r.velocity, "force": r.true_force + r.offset if true_force else r.force,
               "rotary": True, "headers": {"time": "time[s]", "position": "position[rad]",
                                           "velocity": "velocity[rad/s]", "force": "friction_torque[N*m]"}}
    return force_experiment(f"joint run{k}", f"run{k}.csv", temperature=r.temperature, role=r.role,
                            description="look-alike", from_zero=lambda t, i: (t, i),
                            motion="position" if true_position else "auto", flip_sign=False, columns=columns)


def _runs(seed, temperatures):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MotionWarning)
        return L.law_runs(seed=seed, temperatures=temperatures)


def _fit(data, method, plant_only):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return tf.identify(data, method, init=plant_only, offset="per-experiment")


def test_the_motion_is_linear_in_velocity_between_samples():
    """Analytic: the driving waveform's slope at a point between two samples is the linear interpolation of their
    velocities at its step's middle (SUBSTEPS steps per interval), the sample's own velocity around each sample,
    and its positions at the samples are the trapezoidal rule's (jittered samples, a velocity with noise)."""
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.5e-2, 1.5e-2, 300))
    v = np.sin(3 * t) + 0.2 * rng.normal(size=t.size)
    w = motion_waveform(t, v, start=0.4)
    dt = np.diff(t)
    h = 1e-3 * dt.min() / SUBSTEPS
    for j in range(SUBSTEPS):
        at = t[:-1] + dt * (j + 0.3) / SUBSTEPS  # inside the step whose middle is j / SUBSTEPS of the interval
        slope = (w(at + h) - w(at - h)) / (2 * h)
        expected = v[:-1] + (v[1:] - v[:-1]) * j / SUBSTEPS
        np.testing.assert_allclose(slope, expected, rtol=0, atol=1e-7 * np.ptp(v))
    trapezoid = 0.4 + np.concatenate([[0.0], np.cumsum(0.5 * dt * (v[1:] + v[:-1]))])
    np.testing.assert_allclose(w(t), trapezoid, rtol=0, atol=1e-12 * np.ptp(trapezoid))


@pytest.mark.parametrize("seed, late", [(2, 60.0), (4, 50.0)])
def test_a_fast_run_beside_a_fine_encoder_is_driven_by_its_position(seed, late):
    """The fastest runs (0.96 rad at 0.35 Hz) move many encoder counts between samples even at their reversals, so
    their least move between samples is coarser than the late column's step, but their positions still resolve a
    count: every run is driven by its position. Before, the run at ``late`` C was driven by the column 10 ms late,
    and Model I's fs was +193 % (seed 2) at 60 C."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MotionWarning)
        data, _ = L.law_experiments(seed=seed)
    assert [e.motion_source for e in data.experiments] == ["position"] * 5, \
        {e.temperature: e.motion_source for e in data.experiments}


def test_a_noise_free_stribeck_fit_is_not_biased_by_the_motions_steps(plant_only):
    """The truth's own force (no noise, no offset noise, no quantisation) and unquantised position, three runs at
    40 C sampled at 66.7 Hz: the fit's fs and vs within 1.5 % of the truth (half their standard error on noisy data).
    Before, the velocity held constant to the midpoints between samples put fs +5.9 % and vs -4.9 % off (seed 0):
    the Stribeck curve is crossed in two or three samples at the reversals."""
    truth = L.true_values(40.0)
    fit = _fit(_dataset(_runs(0, (40.0,) * 3), true_force=True, true_position=True), "base", plant_only)
    for n in ("fs", "vs", "fc", "sigma0", "sigma2"):
        assert abs(fit.parameters[n].value / truth[n] - 1) < 0.015, (n, fit.parameters[n].value, truth[n])


def _covers(fit, name, T, truth) -> bool:
    """Whether Model I's own 95 % interval of ``name`` at ``T`` (FitResult.law_interval: the delta method on its
    law's coefficients) holds ``truth``."""
    _, lo, hi = fit.law_interval(name, [T])
    return bool(lo[0] <= truth <= hi[0])


def test_base_fits_land_and_cover_over_eight_seeds(plant_only):
    """Three runs at 40 C, eight noise seeds, from the plant-only file: fc, sigma2 and sigma0 within 3 % of the truth;
    fs within 3 % or inside its 95 % interval on every seed; the 95 % intervals of all six parameters cover the
    truth in at least 90 % of the 48 cases (measured 47 of 48: sigma0 +2.6 % on one seed); and the standard errors of
    fs and vs agree with the Jacobian's at the truth with the fit's noise (its AR(1) inflation included) within a
    factor 1.5 (measured 0.79-1.19): the intervals are neither shrunk nor padded. Before (three seeds): fs +9.8 %,
    +9.2 %, +8.3 % on three of six seeds, outside its interval each time."""
    truth = L.true_values(40.0)
    covered = []
    for seed in SEEDS:
        data = _dataset(_runs(seed, (40.0,) * 3))
        fit = _fit(data, "base", plant_only)
        for n in ("fc", "sigma2", "sigma0"):
            assert abs(fit.parameters[n].value / truth[n] - 1) < 0.03, (seed, n, fit.parameters[n].value)
        p = fit.parameters["fs"]
        assert abs(p.value / truth["fs"] - 1) < 0.03 or p.ci95[0] <= truth["fs"] <= p.ci95[1], (seed, p)
        covered += [fit.parameters[n].ci95[0] <= truth[n] <= fit.parameters[n].ci95[1] for n in NAMES]
        model = tf.Model(tf.PrescribedMotion(motion="rotary"), tf.LuGre(**truth))
        problem = Problem(model, list(NAMES), make_traces(data.experiments, model, Force("per-experiment")),
                          rtol=1e-8)
        _, J = problem.evaluate(np.array([truth[n] for n in NAMES]), jac=True)
        noise = fit.statistics["residual_std"] ** 2 * fit.statistics["variance_inflation"]
        at_truth = np.sqrt(np.diag(np.linalg.inv(J.T @ J)) * noise)
        for n in ("fs", "vs"):
            ratio = fit.parameters[n].stderr / at_truth[NAMES.index(n)]
            assert 1 / 1.5 < ratio < 1.5, (seed, n, ratio)
    assert np.mean(covered) >= 0.9, (np.mean(covered), covered)


def test_model_i_lands_and_covers_over_eight_seeds(plant_only):
    """Model I on five temperatures, eight noise seeds, from the plant-only file: every parameter's value at every
    temperature against the truth's laws, with the 95 % interval Model I gives it there (FitResult.law_interval,
    which `recovery` uses: the delta method on the law's coefficients). Measured: fc within 0.9 %, sigma0 within
    2.8 % everywhere; fs +24 % at 60 C on seed 7, whose vs estimates chose a sloped law; the intervals cover in 229
    of 240 cases (fc 37/40, fs 38/40, vs 38/40, sigma2 37/40; a constant law is a candidate for vs alone: for every
    parameter without a law it covered 234 of 240 here but cost displacement truths their slopes,
    tests/test_identify_coverage.py). Before: fs up to +29 % (+193 % on seed 2, whose 60 C run the 10 ms-late column drove) and
    sigma0 +36 % at 60 C; with the motion fixed but no constant law, fs up to +32 %, covering in 224 of 240 (fs
    36/40, vs 31/40: each parameter's intervals must cover in 90 % of its 40 cases). With the truth's own law
    kinds the data determine fs(T) to 2.8-4.7 % and vs to 5.7-6.6 % (the Jacobian at the truth), so fs within 3 %
    at 60 C is beyond them: there the interval is the answer."""
    covered, fs_ok = {n: [] for n in NAMES}, []
    for seed in SEEDS:
        fit = _fit(_dataset(_runs(seed, L.TEMPERATURES)), "model-i", plant_only)
        for T in L.TEMPERATURES:
            truth = L.true_values(T)
            at = fit.model.parameters_at(T)
            for n in ("fc", "sigma0"):
                assert abs(at[n] / truth[n] - 1) < 0.03, (seed, T, n, at[n], truth[n])
            fs_ok.append(abs(at["fs"] / truth["fs"] - 1) < 0.03 or _covers(fit, "fs", T, truth["fs"]))
            for n in NAMES:
                covered[n].append(_covers(fit, n, T, truth[n]))
    assert np.mean(fs_ok) >= 0.9, fs_ok
    for n in NAMES:  # each parameter's intervals, not only all of them together
        assert np.mean(covered[n]) >= 0.9, (n, np.mean(covered[n]))
