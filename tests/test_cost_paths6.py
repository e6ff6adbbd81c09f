"""The cheaper path of issue 42's sixth round, against the package's own reference: a multi-start given the optimum
of its first run (``fit(first=)``, what Model I's fallback from the initial model is given: the heads' fit refined
on the whole records) ends where the same multi-start that makes its first run itself ends, with the same answer
and without that run's evaluations. The data: study_cost.py's freed-mass truth (tests/reference/'s integration,
not the package's), its first temperature, its start 2-3x off."""

import copy
import sys
from pathlib import Path

import numpy as np
import pytest

from thermofriction.fitting.optimiser import fit
from thermofriction.fitting.parameters import friction_parameters
from thermofriction.measurements import make_traces
from thermofriction.models.transforms import base_model

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import study_cost as S  # noqa: E402


@pytest.fixture(scope="module")
def one_temperature():
    truth, temps, start, opts = S.case("free-me", 6, False)
    temps = temps[:1]  # 2 s at 10 kHz, where the first run's optimum (m_e 0.028 kg) is 1.10 times the noise
    data = S.dataset(truth, temps, 2.0, 10_000.0, 6)
    group = [e for e in data.fit if e.temperature == temps[0]]
    model = base_model(start, float(temps[0]))
    params = friction_parameters(model, ["sigma0", "sigma1", "fc", "m_e"])
    return model, params, make_traces(group, model, None)


def test_a_multi_start_given_its_first_runs_optimum_ends_as_the_one_that_runs_it(one_temperature):
    """fit(first=) with the optimum of the first run from the initial values (a fit of one start, which hands it on
    through ``found``) makes the same screened starts, stops them where they land on it, and ends at the same
    optimum, to rounding, as the multi-start that runs its first run itself: with that run's evaluations fewer."""
    model, params, traces = one_temperature
    found = []
    alone = fit(model, copy.deepcopy(params), traces, starts=1, found=found)
    assert len(found) == 1 and found[0][0] == [p.name for p in params.varying]
    np.testing.assert_array_equal(found[0][1], alone.theta)
    reference = fit(model, copy.deepcopy(params), traces, starts=8)
    given = fit(model, copy.deepcopy(params), traces, starts=8, first=found[0])
    assert reference.starts > 1  # the first run was not at the noise: the multi-start ran after it
    np.testing.assert_allclose(given.theta, reference.theta, rtol=1e-12)
    assert float(given.r @ given.r) == pytest.approx(float(reference.r @ reference.r), rel=1e-12)
    assert given.nfev == reference.nfev - alone.nfev and given.njev == reference.njev - alone.njev


def test_a_first_optimum_of_other_parameters_is_not_taken(one_temperature):
    """An optimum given for other parameters (m_e held) does not stand for the first run: the fit is the plain one."""
    model, params, traces = one_temperature
    found = []
    held = copy.deepcopy(params)
    held["m_e"].vary = False
    fit(model, held, traces, starts=1, found=found)
    reference = fit(model, copy.deepcopy(params), traces, starts=1)
    given = fit(model, copy.deepcopy(params), traces, starts=1, first=found[0])
    np.testing.assert_array_equal(given.theta, reference.theta)
    assert given.nfev == reference.nfev
