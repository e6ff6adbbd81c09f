"""Accuracy follows the tolerance, and the default settings are accurate.

Oracle (self-convergence against a tight run, itself checked against the independent reference):
each case is integrated once at rtol 1e-12 with Dopri5; that run agrees with SciPy's DOP853 on the
plain-Python right-hand side (tests/reference/, rtol 1e-10) far below every error measured here. Errors
are maxima over the output grid as a fraction of the quantity's range in the run.

- For every method and the default, the error falls as rtol tightens from 1e-4 to 1e-9 (each decade
  more accurate than the one before), on the paper's workload and on the Canudas de Wit stick-slip case.
- At default settings, the Canudas de Wit experiments (stick-slip, presliding, break-away, frictional
  lag) stay within 0.1 % of range of the tight run, in displacement and in friction force.
- At default settings, parameter sets of the paper's range that exceeded 2e-4 % of range before
  Dormand-Prince's steps ended at velocity reversals are within it (issue 31's accuracy target), and
  AutoSwitch still takes Rodas4 on the ramps.
"""

import dataclasses
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples"))
import canudas1995 as ex  # noqa: E402
import reference as R  # noqa: E402

RTOLS = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)
TIGHT = tf.StepSizeController(rtol=1e-12)
SOLVERS = {"default": None, "dopri5": tf.Dopri5(), "rodas4": tf.Rodas4()}


def _run(model, solver=None, rtol=None, **kw):
    if solver is not None:
        kw["solver"] = solver
    if rtol is not None:
        kw["controller"] = tf.StepSizeController(rtol=rtol)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=tf.PassivityWarning)  # the 1995 set: known, see the example
        return tf.simulate(model, **kw)


def _cdw_mass(**plant):
    return tf.Model(tf.MassPlant(ex.MASS, **plant), ex.lugre())


CASES = {
    "li2009-workload": (lambda: tf.load_model("li2009-model-i"), dict(duration=2.0, temperature=35.7,
                                                                        sample_rate=10_000)),
    "canudas-stick-slip": (lambda: _cdw_mass(spring_stiffness=ex.K_SPRING, pull_velocity=ex.V_PULL),
                           dict(duration=20.0, sample_rate=1000)),
}


@pytest.fixture(scope="module", params=list(CASES))
def case(request):
    make, kw = CASES[request.param]
    model = make()
    tight = _run(model, tf.Dopri5(), **kw, controller=TIGHT)
    return request.param, model, kw, tight


def _errors(res, tight):
    """Max |error| of displacement and friction force, each as a fraction of its range."""
    return (np.max(np.abs(res.displacement - tight.displacement)) / np.ptp(tight.displacement),
            np.max(np.abs(res.friction_force - tight.friction_force)) / np.ptp(tight.friction_force))


def test_tight_run_agrees_with_the_independent_reference():
    """Independent reference (SciPy DOP853, rtol 1e-10, piecewise between the input's corners) for the
    tight run the tolerance sweep measures against: agreement to 5e-8 of the range, the reference's own
    accuracy. It shows that the tight run solves the same equations; its own accuracy, below the sweep's
    smallest error (~1e-9 of the range at rtol 1e-9), rests on the three decades of tolerance between."""
    make, kw = CASES["li2009-workload"]  # (the mass plant's runs against the reference: test_differential.py)
    model = make()
    tight = _run(model, tf.Dopri5(), **kw, controller=TIGHT)
    ref = R.reference_simulate(model, tight.time, kw["temperature"], method="DOP853", rtol=1e-10)
    assert np.max(np.abs(ref.y[:, 2] - tight.displacement)) < 5e-8 * np.ptp(tight.displacement)


@pytest.mark.parametrize("solver", list(SOLVERS))
def test_error_falls_as_the_tolerance_tightens(case, solver):
    """Self-convergence: from rtol 1e-4 to 1e-9 every decade gives a smaller displacement error and a
    smaller friction-force error than the decade before, and 1e-9 is at least 1000x better than 1e-4."""
    name, model, kw, tight = case
    errs = [_errors(_run(model, SOLVERS[solver], rtol, **kw), tight) for rtol in RTOLS]
    for what, k in (("displacement", 0), ("friction force", 1)):
        e = [x[k] for x in errs]
        assert all(b < a for a, b in zip(e, e[1:])), (what, dict(zip(RTOLS, e)))
        assert e[-1] < 1e-3 * e[0], (what, dict(zip(RTOLS, e)))


# --- the Canudas de Wit experiments at default settings -----------------------------------------------

def _stick_slip(**kw):
    r = ex.run_stick_slip(**kw)
    return r.displacement, r.friction_force


def _presliding(**kw):
    r = ex.run_presliding(**kw)
    return r.displacement, r.friction_force


def _break_away(**kw):
    r = ex.run_break_away(0.3, **kw)
    return r.displacement, r.friction_force


def _frictional_lag(**kw):
    r = ex.simulate_frictional_lag(10.0, **kw)
    return r.displacement, r.friction_force


@pytest.mark.parametrize("experiment", [_stick_slip, _presliding, _break_away, _frictional_lag],
                         ids=["stick-slip", "presliding", "break-away", "frictional-lag"])
def test_canudas_experiments_at_default_settings_within_0p1_percent(experiment):
    """Self-convergence: the example's run (examples/canudas1995.py) with the default solver and tolerance
    against the same run with Dopri5 at rtol 1e-12, within 0.1 % of range in displacement and in friction
    force (under prescribed motion the displacement is the input itself)."""
    (x, F), (x_tight, F_tight) = experiment(), experiment(solver=tf.Dopri5(), controller=TIGHT)
    dF = np.max(np.abs(F - F_tight)) / np.ptp(F_tight)
    dx = np.max(np.abs(x - x_tight)) / np.ptp(x_tight)
    assert dx < 1e-3 and dF < 1e-3, (dx, dF)


# --- random parameter sets of the paper's range at default settings (benchmarks/bench_accuracy.py) -----

# (temperature [degC], sigma0 [N/m], sigma1 [N s/m], fc [N]) of three sets of bench_accuracy.py
ACCURACY_SETS = {
    # seed 11, set 39: the worst of the 100 sets (5.2e-4 % while steps crossed reversals of v_r unchecked)
    "seed11-set39": (33.36604894289319, 1458910.581905387, 1.5100454987254297, 0.7290328157269454),
    # seed 3, set 3: 4.4e-4 % then
    "seed3-set3": (35.4077198184317, 1051730.0703170875, 2.167528467482736, 0.7164188140778436),
    # seed 3, set 34: ringing through the whole ramp; with the reversals handled but AUTO free to switch
    # to Rodas4 in the ringing, 1.9e-3 % (docs/performance.md)
    "seed3-set34": (38.361180798774114, 352560.9776742372, 0.7274908538710414, 0.24216218691808158),
}


@pytest.mark.parametrize("name", list(ACCURACY_SETS))
def test_random_parameter_sets_at_default_settings_within_2e_4_percent(name):
    """Self-convergence (the tight run checked against the independent reference above): the
    li2009-model-i preset's friction with sigma0, sigma1 and fc of a random set of the paper's range, 2 s
    of the sawtooth at 10 kHz output, default solver and tolerance, against Dopri5 at rtol 1e-12: the
    displacement within 2e-4 % of its range."""
    T, sigma0, sigma1, fc = ACCURACY_SETS[name]
    preset = tf.load_model("li2009-model-i")
    friction = dataclasses.replace(preset.friction, sigma0=sigma0, sigma1=sigma1, fc=fc)
    model = dataclasses.replace(preset, thermal=None, friction=friction)
    kw = dict(duration=2.0, temperature=T, sample_rate=10_000)
    res = _run(model, **kw)
    tight = _run(model, tf.Dopri5(), **kw, controller=TIGHT)
    err = np.max(np.abs(res.displacement - tight.displacement)) / np.ptp(tight.displacement)
    assert err < 2e-6, f"{err * 100:.2e} % of range"


@pytest.mark.parametrize("preset", ["li2009-base", "li2009-model-i", "li2009-model-ii"])
def test_default_solver_still_takes_rodas4_on_the_ramps(preset):
    """The default's reversal handling leaves AutoSwitch's choice of Rodas4 for the ramps (a regression
    test: when the steps were cut at Dormand-Prince's own oscillation of v_r, the stiffness test never
    fired on li2009-base and li2009-model-ii, which then took 2.4x the evaluations in Dopri5): every
    period's ramp takes Rodas4 steps, and the run takes fewer evaluations than Dopri5 alone."""
    kw = dict(duration=2.0, temperature=35.7)
    auto = _run(tf.load_model(preset), **kw)
    dopri = _run(tf.load_model(preset), tf.Dopri5(), **kw)
    assert auto.stats["jac_evals"] >= 10 * 5, auto.stats  # 10 periods, a few Rodas4 steps in each ramp
    assert auto.stats["rhs_evals"] < dopri.stats["rhs_evals"], (auto.stats, dopri.stats)
