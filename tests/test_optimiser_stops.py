"""The optimiser's stops of issue 42's third round, against the same fit without them (the reference: the optimiser
as it was, run apart from the change by switching the stops off): a start of the multi-start that lands within
LANDED standard errors of the first run's optimum stops there, and a fine stage whose cost stalls (STALL_COST of
the misfit's variance in STALL_EVALUATIONS steps) stops at its best point. On look-alike force data (the cost
study's force truths, benchmarks/study_cost.py, drawn there from tests/lookalike.py: no model reaches the noise, so
the multi-start always runs) the fit must end where the reference ends, to a small fraction of each parameter's
standard error, at the same cost, and spend fewer evaluations. (The third change, the small-step stop measured in
the intervals' standard errors above the noise, is in both: the study compares it with main, docs/performance.md.)"""

import sys
from pathlib import Path

import pytest

import thermofriction as tf
from thermofriction.fitting import optimiser

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import study_cost as S  # noqa: E402


@pytest.mark.parametrize("kind, seed", [("force", 0), ("force", 5)])
def test_the_stops_end_where_the_fit_without_them_ends(kind, seed, monkeypatch):
    data, _, start, opts = S.force_case(kind, seed, False)
    fit = tf.identify(data, init=start, **opts)
    assert fit.starts > 1  # the multi-start ran (look-alike data never reach the noise)
    monkeypatch.setattr(optimiser, "LANDED", 0.0)
    monkeypatch.setattr(optimiser, "STALL_COST", 0.0)
    reference = tf.identify(data, init=start, **opts)
    for n in opts["parameters"]:
        p, q = fit.parameters[n], reference.parameters[n]
        assert abs(p.value - q.value) <= 0.05 * q.stderr, (n, p.value, q.value, q.stderr)
    assert fit.cost == pytest.approx(reference.cost, rel=1e-5)
    assert fit.nfev < reference.nfev  # (the stops were taken)
