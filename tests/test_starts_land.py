"""Starts that land (issue 40 item 1): on look-alike joint logs (tests/lookalike_laws.py: a LuGre truth with a Stribeck
curve and viscous friction, integrated by SciPy's LSODA outside the package, fc(T), fs(T), sigma2(T) linear over five
temperatures, a 17-bit encoder, a firmware velocity 10 ms late and quantised, a sensor re-zeroed per run, AR(1) noise)
a fit from a plant-only file lands within 3 % of the truth on what the data determine, its intervals cover the truth,
and a Model I per-temperature fit that cannot start fails as a computation naming the temperature."""

from __future__ import annotations

import time
import warnings

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.data.motion import MotionWarning
from thermofriction.errors import ComputationError
from thermofriction.fitting.parameters import EXCESS
from thermofriction.fitting.problem import Problem
from thermofriction.measurements import make_traces
from thermofriction.measurements.force import force_start
from thermofriction.measurements import Force

import lookalike_laws as L

PLANT_ONLY = '[plant]\ntype = "prescribed"\nmotion = "rotary"\n\n[friction]\nmodel = "lugre"\n'


def _joint(seed=0, temperatures=L.TEMPERATURES):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MotionWarning)
        data, _ = L.law_experiments(seed=seed, temperatures=temperatures)
    return data


@pytest.fixture(scope="module")
def plant_only(tmp_path_factory):
    path = tmp_path_factory.mktemp("starts") / "joint.toml"
    path.write_text(PLANT_ONLY)
    return str(path)


def test_a_fine_encoder_drives_the_model_where_the_velocity_column_lags():
    """A column 10 ms late (0.66 of the 66.7 Hz interval) beside a 17-bit encoder, whose least change over an interval
    (0.0032 rad/s) is finer than the column's step (0.0098 rad/s): the position drives the model, a warning says why
    (before: the column, within the 1-interval limit, drove it, and the fit's sigma0 was 50 % high)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        data, _ = L.law_experiments(temperatures=(40.0,))
    e = data.experiments[0]
    assert e.motion_source == "position"
    assert abs(e.motion_check.lag - 0.010) < 0.001
    said = [str(w.message) for w in caught if issubclass(w.category, MotionWarning)]
    assert len(said) == 1 and "lags the position's derivative by" in said[0] and "the position drives" in said[0]


def test_the_start_reads_each_run_with_its_own_offset_and_levels():
    """Five temperatures, each run its own offset: the start's Coulomb level and viscous coefficient are near the
    truth's at the middle temperature (0.8 N m, 0.25 N m s/rad), and it has a Stribeck excess (fs > fc). Before, one
    map pooled over the temperatures gave fc 0.97, sigma2 0.086 and no Stribeck excess, so Model I held fs at fc."""
    start = force_start(_joint().experiments)
    truth = L.true_values(40.0)
    assert abs(start["fc"] / truth["fc"] - 1) < 0.1
    assert abs(start["sigma2"] / truth["sigma2"] - 1) < 0.15
    assert start.get("fs", 0.0) > start["fc"]


def test_a_fitted_stribeck_excess_is_stepped_exactly():
    """fs fitted as its excess over fc (Model I's per-temperature fits) goes through the core's exact stepping, and
    its Jacobian equals central differences of the residuals (before: integrated runs and forward differences, twice
    the time)."""
    data = _joint(temperatures=(40.0,))
    model = tf.Model(tf.PrescribedMotion(motion="rotary"),
                     tf.LuGre(sigma0=300.0, sigma1=0.6, fc=0.8, fs=1.1, vs=0.1, sigma2=0.25))
    names = ["sigma0", "fc", EXCESS, "vs"]
    problem = Problem(model, names, make_traces(data.experiments, model, Force("per-experiment")), rtol=1e-10)
    assert Force.exact_names(problem, model) == ["sigma0", "fc", "fs", "vs"]
    theta = np.array([300.0, 0.8, 0.3, 0.1])
    r, J = problem.evaluate(theta, jac=True)
    for k in range(len(names)):
        h = 1e-5 * theta[k]
        up, down = theta.copy(), theta.copy()
        up[k] += h
        down[k] -= h
        fd = (problem.evaluate(up)[0] - problem.evaluate(down)[0]) / (2 * h)
        assert np.max(np.abs(J[:, k] - fd)) < 1e-4 * np.max(np.abs(fd)), names[k]


def _base_fit(seed, plant_only):
    data = _joint(seed=seed, temperatures=(40.0, 40.0, 40.0))
    t0 = time.perf_counter()
    fit = tf.identify(data, "base", init=plant_only, offset="per-experiment")
    return fit, time.perf_counter() - t0


def test_a_base_fit_from_the_data_start_lands(plant_only):
    """Three runs at 40 C from a plant-only file, three noise seeds: fc, sigma2 and sigma0 within 3 % of the truth,
    the 95 % intervals of all six parameters cover the truth in at least 90 % of cases (18 of 18 measured; fs +3.9,
    -0.9, -0.1 %); before, driven by the late column: sigma0 +50 %, fs -20 %, 8 of 18 covered; then with the
    velocity held to the midpoints between samples, 17 of 18, fs +9.8 % (eight seeds: tests/test_joint_coverage.py)."""
    truth = L.true_values(40.0)
    covered = []
    for seed in (0, 1, 2):
        fit, _ = _base_fit(seed, plant_only)
        for n in ("fc", "sigma2", "sigma0"):
            assert abs(fit.parameters[n].value / truth[n] - 1) < 0.03, (seed, n, fit.parameters[n].value)
        for n, v in truth.items():
            p = fit.parameters[n]
            covered.append(abs(p.value - v) <= 1.96 * p.stderr)
    assert np.mean(covered) >= 0.9, covered


def _model_i_errors(fit):
    return {T: {n: fit.model.parameters_at(T)[n] / L.true_values(T)[n] - 1 for n in ("fc", "sigma2", "sigma0")}
            for T in L.TEMPERATURES}


def test_model_i_on_five_temperatures_lands_in_seconds(plant_only):
    """Model I from the plant-only file on five temperatures of the joint (offsets per run): fc(T), sigma2(T) and
    sigma0(T) within 3 % of the truth at every temperature, in under 60 s (measured 0.3-1 s on the shared machine).
    Before (driven by the late column, fs held at fc: the pooled start had no Stribeck excess): at 20 C fc +2.2 %,
    sigma2 -5.6 %, sigma0 +24 %, fs -29 %."""
    data = _joint(seed=0)
    t0 = time.perf_counter()
    fit = tf.identify(data, "model-i", init=plant_only, offset="per-experiment")
    assert time.perf_counter() - t0 < 60.0
    for T, errors in _model_i_errors(fit).items():
        for n, e in errors.items():
            assert abs(e) < 0.03, (T, n, e)


@pytest.mark.slow
def test_model_i_lands_on_three_seeds(plant_only):
    """The same on three noise seeds: fc(T), sigma2(T) and sigma0(T) within 3 % everywhere (measured 0.7 %, 1.8 %,
    0.5 %; before, on seed 2 the 60 C run was driven by the 10 ms-late column and sigma0 was 36 % off there, fs
    193 %: tests/test_joint_coverage.py measures eight seeds with the intervals)."""
    for seed in (0, 1, 2):
        fit = tf.identify(_joint(seed=seed), "model-i", init=plant_only, offset="per-experiment")
        for T, errors in _model_i_errors(fit).items():
            assert all(abs(e) < 0.03 for e in errors.values()), (seed, T, errors)


def test_a_per_temperature_fit_that_cannot_start_names_its_temperature(plant_only, monkeypatch):
    """A relation broken in the values a temperature's fit continues from (fs below a fitted fc: the issue's
    "[friction]: 'fs' (0.8655...) must be at least 'fc' (0.8988...)", exit 2 after 16 min) is a failed computation
    naming the temperature and the parameters, not an error about a section of the user's file."""
    from thermofriction.errors import InputError
    from thermofriction.identification import model_i

    def broken(self, T, previous):
        if previous is not None:
            raise InputError("[friction]: 'fs' (0.8655) must be at least 'fc' (0.8988)")
        return original(self, T, previous)

    original = model_i._PerTemperature.start_at
    monkeypatch.setattr(model_i._PerTemperature, "start_at", broken)
    with pytest.raises(ComputationError) as err:
        tf.identify(_joint(temperatures=(20.0, 40.0, 60.0)), "model-i", init=plant_only, offset="per-experiment")
    message = str(err.value)
    assert any(f"at {T:g} C" in message for T in (40.0, 60.0)) and "'fs' (0.8655) must be at least 'fc' (0.8988)" in message
    assert not message.startswith("[friction]") and "not in the initial model" in message


def test_progress_reports_a_long_model_i_fit(plant_only):
    """Every per-temperature fit and the joint refinement say what they do through ``progress`` (the command line's
    clock prints the current one at most every 5 s)."""
    said = []
    tf.identify(_joint(temperatures=(20.0, 40.0, 60.0)), "model-i", init=plant_only, offset="per-experiment",
                progress=said.append)
    for T in (20, 40, 60):
        assert any(f"at {T} C" in s for s in said), said
    assert any("joint refinement" in s for s in said)


def test_the_screening_keeps_the_start_whose_short_fit_ends_lowest():
    """Of two starts, the issue's wrong basin (fc half the truth's, sigma2 twice, vs ten times) and the data's own
    reading, the screening keeps the one whose short fit ends lowest, whichever comes first: sigma2 within 5 % of the
    truth's (0.25 N m s/rad at 40 C) and vs within a factor 3 of its 0.1 rad/s (the wrong start's short fit reaches
    fc but ends with vs 57 rad/s and sigma2 0.215)."""
    from thermofriction.measurements.force import screened
    from thermofriction.measurements.force_start import read_start

    exps = _joint(temperatures=(40.0, 40.0)).experiments
    good = read_start(exps)[0]
    wrong = {**good, "fc": 0.5 * good["fc"], "fs": 0.5 * good["fc"] + (good["fs"] - good["fc"]),
             "sigma2": 2 * good["sigma2"], "vs": 10 * good["vs"]}
    for candidates in ([wrong, good], [good, wrong]):
        chosen = screened(exps, candidates, tf.PrescribedMotion(motion="rotary"))
        assert abs(chosen["sigma2"] / 0.25 - 1) < 0.05 and 1 / 3 < chosen["vs"] / 0.1 < 3, chosen
