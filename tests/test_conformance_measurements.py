"""Conformance of every measurement (issue 39, item 6), parametrized over ``thermofriction.measurements.REGISTRY``:
a measured quantity registered there is tested here once it has a case in tests/conformance_cases.py
(MEASUREMENT_CASES: a model, a few short experiments it recognises, and where their record is).

- its own simulation gives zero residuals: the model's prediction made by the measurement's own validation path
  (``predict``), put in place of the record, held against the same model by the fit's path (``make_trace``, the
  fitting engine's ``Problem``, the measurement's ``residuals``) leaves residuals zero to the signal's scale, under
  every offset policy the measurement takes;
- its Jacobian matches central finite differences of the same residuals, in the parameters it fits by default;
- its offset policy's degrees of freedom are what ``offsets_in`` says: the residuals are linear in the record,
  ``r = P (s - y)``, and the directions of the record the offsets (and any other nuisance the measurement profiles
  out) absorb are the null space of P; its dimension is counted from P itself, probed one sample at a time.
"""

from __future__ import annotations

import copy
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from conformance_cases import MEASUREMENT_CASES, case_of, problem_api  # noqa: E402

from thermofriction.errors import InputError  # noqa: E402
from thermofriction.measurements import OFFSETS, REGISTRY, measurement_of  # noqa: E402

#: samples per run: the residual and Jacobian checks, and the degrees-of-freedom probe (one residual evaluation
#: per sample of every run)
SAMPLES, PROBE_SAMPLES = 400, 40


def _policies():
    """(measurement, offset policy) for every registered measurement and every policy it takes."""
    for name, cls in REGISTRY.items():
        for policy in OFFSETS:
            try:
                cls(policy)
            except InputError:
                continue
            yield pytest.param(name, policy, id=f"{name}-{policy}")


POLICIES = list(_policies())


def _case(name):
    return case_of(MEASUREMENT_CASES, name, "measurement")


@pytest.fixture(scope="module")
def experiments(tmp_path_factory):
    """name -> (model, experiments of SAMPLES, experiments of PROBE_SAMPLES), made once per measurement."""
    made = {}

    def get(name):
        if name not in made:
            case = _case(name)
            folder = tmp_path_factory.mktemp(name)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # (the reader's notes on the synthetic records)
                made[name] = (case.model(), case.experiments(folder / "long", SAMPLES),
                              case.experiments(folder / "short", PROBE_SAMPLES))
        return made[name]
    return get


#: the tolerance the model's own prediction is made at
OWN_RTOL = 1e-10


def _own(measurement, model, exps, record):
    """The experiments with their record replaced by ``model``'s own prediction through ``measurement``'s
    validation path (no noise), at rtol OWN_RTOL."""
    out = []
    for exp in exps:
        p = measurement.predict(model, exp, OWN_RTOL)
        own = copy.copy(exp)
        setattr(own, record, np.asarray(p.predicted, float).copy())
        out.append(own)
    return out


def _measurement(name, policy, exps):
    """The experiments' measurement with offset policy ``policy``, as identify and validate ask it (measurement_of),
    checked to be the registered one the case is of."""
    measurement = measurement_of(exps, offset=policy)
    assert measurement.name == name and type(measurement) is REGISTRY[name], (
        f"the case of {name!r} is recognised as {measurement.name!r}")
    return measurement


def _own_problem(name, policy, experiments, which=1, rtol=OWN_RTOL):
    """(the fitting engine's problem, the parameters' values, the record's range, the measurement): ``model``
    held against its own prediction (which=1: SAMPLES per run; 2: PROBE_SAMPLES) in the parameters the measurement
    fits by default."""
    model, long, short = experiments(name)
    exps = (long, short)[which - 1]
    measurement = _measurement(name, policy, exps)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        exps = _own(measurement, model, exps, _case(name).record)
    traces = [measurement.make_trace(e, model) for e in exps]
    names = list(measurement.fit_parameters[model.friction.model])
    theta = np.array([getattr(model.friction, n) for n in names], float)
    scale = float(np.ptp(np.concatenate([getattr(e, _case(name).record) for e in exps])))
    return problem_api()(model, names, traces, rtol=rtol), theta, scale, measurement


@pytest.mark.parametrize("name", list(REGISTRY))
def test_every_registered_measurement_has_a_case(name):
    """A measurement registered without a case in tests/conformance_cases.py fails here, by name."""
    case = _case(name)
    assert callable(case.model) and callable(case.experiments) and case.record


@pytest.mark.parametrize("name, policy", POLICIES)
def test_own_simulation_gives_zero_residuals(name, policy, experiments):
    """Oracle: analytic zero. The model's own prediction (the measurement's predict at rtol OWN_RTOL = 1e-10),
    held against the same model through the fit's path (at the same rtol), leaves residuals below 1e-6 of the
    record's range: two integrations of the actuator differ by about 2e-8 of it (most at the sawtooth's flyback),
    a prescribed motion integrated and stepped exactly by about 1e-11; a residual that mislays an offset, a unit,
    a sample or a sign is of the order of the signal (against the cases' own placeholder records: 0.4-0.8)."""
    problem, theta, scale, _ = _own_problem(name, policy, experiments)
    assert scale > 0
    r, J = problem.evaluate(theta, jac=False)
    assert r is not None, "the fit's path failed on the model's own prediction"
    assert r.size == sum(tr.n_residuals for tr in problem.traces)
    worst = float(np.max(np.abs(r))) / scale
    assert worst < 1e-6, f"{name} ({policy}): max |r| = {worst:.2e} of the record's range {scale:.3g}"


#: central differences' relative step (of each parameter's value), and the tolerance the runs are integrated at
FD_STEP = 1e-3
FD_RTOL = 1e-12
#: each column's error allowed, relative to the Jacobian's largest column (both in log coordinates)
JAC_TOL = 1e-4


@pytest.mark.parametrize("name, policy", POLICIES)
def test_jacobian_matches_central_finite_differences(name, policy, experiments):
    """Oracle: central finite differences of the same residuals (problem.evaluate), each parameter stepped by
    FD_STEP of its value, the runs integrated at rtol FD_RTOL. The Jacobian compared in log coordinates (each
    column times its parameter's value: what the optimiser steps in), each column's error within JAC_TOL of the
    largest column: the differences' truncation error is about FD_STEP^2 = 1e-6 of a column, their integration
    error about FD_RTOL / FD_STEP = 1e-9 (a weak column -- the actuator's damping sigma1 -- carries the
    sensitivities' own error at 1e-4 of itself, 1e-6 of the largest); the exact stepping of a prescribed motion
    has no integration error. A column of a wrong sign, scale, chain rule or projection is off by its own size,
    which in these cases is at least 1e-2 of the largest."""
    problem, theta, _, _ = _own_problem(name, policy, experiments, rtol=FD_RTOL)
    r, J = problem.evaluate(theta, jac=True)
    assert r is not None and J is not None and J.shape == (r.size, theta.size)
    D = np.empty_like(J)
    for k in range(theta.size):
        h = FD_STEP * abs(theta[k])
        up, down = theta.copy(), theta.copy()
        up[k] += h
        down[k] -= h
        r_up, _ = problem.evaluate(up)
        r_down, _ = problem.evaluate(down)
        assert r_up is not None and r_down is not None, f"a run failed at {problem.names[k]} +- {h:.3g}"
        D[:, k] = (r_up - r_down) / (2 * h)
    scaled = np.linalg.norm(D * np.abs(theta), axis=0)
    largest = float(np.max(scaled))
    assert largest > 0
    for k, n in enumerate(problem.names):
        err = abs(theta[k]) * float(np.linalg.norm(J[:, k] - D[:, k])) / largest
        assert err < JAC_TOL, (f"{name} ({policy}): d r / d {n} off the central differences by {err:.2e} of the "
                               f"largest column ({scaled[k] / largest:.2e} its own size)")


@pytest.mark.parametrize("name, policy", POLICIES)
def test_offsets_take_the_degrees_of_freedom_offsets_in_says(name, policy, experiments):
    """Oracle: the residuals' own linear map of the record. r = P (s - y): each sample of the record moved by one
    unit moves the residuals by a column of -P; the record's directions that do not move them (the null space of
    P: what the offsets and any other profiled-out nuisance absorb) number ``offsets_in(traces)``. P is probed
    exactly (it is linear in the record), its rank taken from its singular values (1 or 0 for a projection:
    threshold 1e-6)."""
    problem, theta, _, measurement = _own_problem(name, policy, experiments, which=2)
    r0, _ = problem.evaluate(theta)
    assert r0 is not None
    n = r0.size
    columns = []
    offsets = np.cumsum([0] + [len(tr.measured) for tr in problem.traces])
    for i, tr in enumerate(problem.traces):
        for j in range(len(tr.measured)):
            saved = tr.measured[j]
            tr.measured[j] = saved + 1.0
            try:
                r, _ = problem.evaluate(theta)
            finally:
                tr.measured[j] = saved
            columns.append(r0 - r)
    assert len(columns) == offsets[-1] == n, "the residuals are not one per recorded sample"
    P = np.column_stack(columns)
    sv = np.linalg.svd(P, compute_uv=False)
    rank = int(np.sum(sv > 1e-6 * sv[0]))
    assert n - rank == measurement.offsets_in(problem.traces), (
        f"{name} ({policy}): the record's {n - rank} directions the residuals do not see, offsets_in says "
        f"{measurement.offsets_in(problem.traces)}")
