"""benchmarks/study_cost.py (issue 42): its quick mode counts what it says. Checked against counts made apart from
the study's per-stage ledger (bench_rough_start.py's own counter of C core calls, a plain counter of the fitting
engine's evaluations), against the fit's own clock, against NumPy's quantiles on a known sample, and the study's
truth data (integrated by SciPy through tests/reference) against the C core's simulation of the same truth."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.fitting import problem

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
sys.path.insert(0, str(BENCH))
import study_cost as S  # noqa: E402
from bench_rough_start import core_calls  # noqa: E402


@pytest.fixture(scope="module")
def quick_rows():
    """One quick truth of Model I and of Model II, each with the evaluations counted apart from the ledger."""
    plain = S.Plain(S.model_i_truth(np.random.default_rng(0)), 35.0)
    rows = []
    evaluate = problem.Problem.evaluate
    for kind in ("model-i", "model-ii"):
        seen = [0]

        def counting(self, theta, jac=False):
            seen[0] += 1
            return evaluate(self, theta, jac)

        problem.Problem.evaluate = counting
        try:
            with core_calls() as calls:
                row = S.run_case(kind, 1, True, plain)
        finally:
            problem.Problem.evaluate = evaluate
        rows.append((row, seen[0], sum(c for c, _ in calls.values())))
    return rows


def test_every_evaluation_and_core_call_is_in_one_stage(quick_rows):
    """The per-stage evaluations and C core calls add up to the counts made apart (none lost, none twice), and the
    fit's own nfev and njev are those counts: every evaluation it made, its Jacobians too (Model II's base fit at
    the reference temperature, its dF scans and fits, Model I's heads, the held tests)."""
    for row, evaluations, core in quick_rows:
        stages = row["stages"]
        assert sum(s["evaluations"] for s in stages.values()) == evaluations == row["evaluations"]
        assert sum(s["core_calls"] for s in stages.values()) == core > 0
        assert row["nfev"] == evaluations
        assert row["njev"] == sum(s["jacobians"] for s in stages.values())
        assert set(stages) <= {stage for _, _, stage in S.STAGES} | {"other"}


def test_the_stages_cover_the_fit_and_its_cost_is_in_units_of_the_plain_simulation(quick_rows):
    """The stages' own wall times add up to the fit's wall time (measured by run_case's clock around identify,
    within 2 % and 50 ms: the ledger starts just before it); the cost is that time over the unit; the fit's
    simulations (all with sensitivities, each run at least once) take longer than one plain simulation of its
    runs; Model I spends evaluations in its per-temperature fits and its joint refinement."""
    for row, _, _ in quick_rows:
        stage_wall = sum(s["wall"] for s in row["stages"].values())
        assert row["wall"] <= stage_wall <= row["wall"] * 1.02 + 0.05
        assert row["cost"] == pytest.approx(row["wall"] / row["unit_wall"], rel=1e-12)
        assert sum(s["core_time"] for s in row["stages"].values()) > row["unit_wall"] > 0
        assert row["cost"] > 1
    model_i = quick_rows[0][0]["stages"]
    assert model_i["per-temperature fits"]["evaluations"] > 0 and model_i["joint refinement"]["evaluations"] > 0
    assert all(r["evaluations"] <= r["limit"] + 1 for r in quick_rows[0][0]["runs"])


def test_percentiles_against_numpys_definition_and_ordered(quick_rows):
    """percentiles of 1..10: median 5.5, 90th percentile 9.1 (linear interpolation), worst 10; on the study's rows
    median <= p90 <= worst."""
    assert S.percentiles(range(1, 11)) == pytest.approx((5.5, 9.1, 10.0), rel=1e-12)
    med, p90, worst = S.percentiles([r["cost"] for r, _, _ in quick_rows])
    assert med <= p90 <= worst == max(r["cost"] for r, _, _ in quick_rows)


def test_the_truth_data_are_the_truths_own_within_the_noise():
    """The study's data (SciPy's solve_ivp on the reference equations, 20 nm noise) against the C core's
    simulation of the same truth: their difference is the noise (RMS 20 nm within 15 %), not a model error."""
    truth, temps, _, _ = S.case("model-i", 2, True)
    data = S.dataset(truth, temps[:1], 0.4, 5000.0, 2)
    exp = data.fit[0]
    sim = tf.simulate(truth, 0.4, temperature=exp.temperature, sample_rate=5000.0)
    rms = math.sqrt(np.mean((exp.displacement - sim.displacement) ** 2))
    assert rms == pytest.approx(20e-9, rel=0.15)


def test_a_force_truth_is_fitted_and_costed_in_its_own_exact_stepping():
    """A quick force truth with a ripple (tests/lookalike.py's integration, drawn in the study): the fit's nfev and
    njev are the evaluations the study counts apart; the cost is the fit's time over the exact stepping of its fit
    runs (two of three: one is held out); the rough start's fit lands where the same fit from the truth's values
    does (the look-alike's logger can leave the truth itself outside the intervals)."""
    row = S.run_case("force-ripple", 1, True, None)
    stages = row["stages"]
    assert row["nfev"] == row["evaluations"] == sum(s["evaluations"] for s in stages.values()) > 0
    assert row["njev"] == sum(s["jacobians"] for s in stages.values())
    assert row["cost"] == pytest.approx(row["wall"] / row["unit_wall"], rel=1e-12) and row["cost"] > 1
    assert stages["force fit"]["evaluations"] > 0
    assert row["same_optimum"] < 1.0
    assert set(row["values"]) == set(S.FORCE_NAMES) | {"ripple_cos1", "ripple_sin1"}
