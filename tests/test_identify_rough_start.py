"""What makes a fit from a rough start cheaper (issue 31; benchmarks/bench_rough_start.py measures the cost): the
step budget of trial runs, the coarse stage's evaluations for a fit at the coarse tolerance, and, with freed plant
parameters, the per-temperature estimates moved to the shared value before Model I's laws are drawn through them."""

import math
import types

import numpy as np

import thermofriction as tf
from thermofriction import _bridge
from thermofriction.fitting import optimiser, problem
from thermofriction.identification import laws
from thermofriction.measurements import make_traces
from thermofriction.fitting.parameters import Parameters
from thermofriction.identification.procedures import fit_friction


def _data(model, T=35.0):
    return tf.synthesize(model, [T], duration=0.2, sample_rate=5000, noise=20e-9, seed=4)


def test_a_trial_run_gets_twenty_times_the_steps_of_its_first_run(monkeypatch, model_i):
    """The budget each run with sensitivities is given (captured at the bridge): the first run of a trace the full
    MAX_STEPS, every later one STEP_FACTOR times the first's steps (at least STEP_FLOOR)."""
    base = tf.Model(model_i.plant, tf.LuGre(**{n: model_i.parameters_at(35.0)[n] for n in ("sigma0", "sigma1", "fc")}),
                    input=model_i.input)
    traces = make_traces(list(_data(base).fit), base)
    seen = []
    real = _bridge.run_sensitivities

    def spy(*args, **kwargs):
        stats = real(*args, **kwargs)
        seen.append((kwargs["max_steps"], stats["steps"]))
        return stats

    monkeypatch.setattr(_bridge, "run_sensitivities", spy)
    p = problem.Problem(base, ["sigma0", "sigma1", "fc"], traces, rtol=1e-6)
    theta = np.array([base.friction.sigma0, base.friction.sigma1, base.friction.fc])
    p.evaluate(theta, jac=True)
    p.evaluate(theta * 1.1, jac=True)
    assert seen[0][0] == problem.MAX_STEPS
    first = seen[0][1]
    assert seen[1][0] == min(problem.MAX_STEPS, max(problem.STEP_FLOOR, problem.STEP_FACTOR * first))


def test_a_fit_at_the_coarse_tolerance_has_the_coarse_stages_evaluations(monkeypatch, model_i):
    """rtol 1e-6: one stage, with 40 evaluations (the coarse stage's); rtol 1e-8: 40 then 15."""
    limits = []
    real = optimiser._least_squares

    def spy(problem_, transform, phi0, bounds, max_nfev, *args, **kwargs):
        limits.append((problem_.rtol, max_nfev))
        return real(problem_, transform, phi0, bounds, max_nfev, *args, **kwargs)

    monkeypatch.setattr(optimiser, "_least_squares", spy)
    base = tf.Model(model_i.plant, tf.LuGre(**{n: model_i.parameters_at(35.0)[n] for n in ("sigma0", "sigma1", "fc")}),
                    input=model_i.input)
    exps = list(_data(base).fit)
    fit_friction(exps, base, rtol=1e-6, starts=1)
    assert limits == [(1e-6, 40)]
    limits.clear()
    fit_friction(exps, base, rtol=1e-8, starts=1)
    assert limits == [(1e-6, 40), (1e-8, 15)]


def test_estimates_moved_to_the_shared_mass_are_the_conditional_mean():
    """Independent reference: the conditional mean of a Gaussian from its precision matrix (the minimiser of the
    quadratic form with the mass fixed), x_o = mu_o - P_oo^-1 P_of (x_f - mu_f), in the coordinates the fits use
    (log for the well-determined sigma0, fc and m_e; sigma1, with a standard error above 30 % of its value, in its
    own)."""
    params = Parameters()
    values = {"sigma0": 2e6, "sigma1": 10.0, "fc": 0.3, "m_e": 0.08}
    se = {"sigma0": 2e4, "sigma1": 5.0, "fc": 3e-3, "m_e": 1e-3}
    for n, v in values.items():
        params.add(n, v, min=0.0)
        params[n].stderr = se[n]
    corr = np.array([[1.0, 0.2, -0.6, 0.7], [0.2, 1.0, 0.1, 0.3], [-0.6, 0.1, 1.0, -0.5], [0.7, 0.3, -0.5, 1.0]])
    res = types.SimpleNamespace(parameters=params, correlation=corr)
    shared = {"m_e": 0.082}
    (T, moved), = laws.at_shared([(35.0, res)], ["m_e"], shared)

    log = np.array([True, False, True, True])
    v = np.array(list(values.values()))
    s = np.array(list(se.values())) / np.where(log, v, 1.0)
    P = np.linalg.inv(corr * np.outer(s, s))
    y = np.where(log, np.log(v), v)
    o, f = [0, 1, 2], [3]
    x = y[o] - np.linalg.solve(P[np.ix_(o, o)], P[np.ix_(o, f)] @ (np.log([0.082]) - y[f]))
    expect = np.where(log[o], np.exp(x), x)
    got = [moved.parameters[n].value for n in ("sigma0", "sigma1", "fc")]
    np.testing.assert_allclose(got, expect, rtol=1e-10)
    assert moved.parameters["m_e"].value == 0.082
    # the conditional covariance: the inverse of P_oo
    cond = np.linalg.inv(P[np.ix_(o, o)])
    se_expect = np.sqrt(np.diag(cond)) * np.where(log[o], expect, 1.0)
    np.testing.assert_allclose([moved.parameters[n].stderr for n in ("sigma0", "sigma1", "fc")], se_expect, rtol=1e-10)
    # the original is untouched, and a mass already at the shared value moves nothing
    assert params["sigma0"].value == 2e6
    (_, same), = laws.at_shared([(35.0, res)], ["m_e"], {"m_e": 0.08})
    assert all(math.isclose(same.parameters[n].value, values[n], rel_tol=1e-12) for n in values)
