"""The adequacy verdict's false alarms and detections, and the intervals' coverage, on random truths (issue 30,
items 2-4), simulated by the independent SciPy reference (tests/adequacy_study.py, tests/coverage_study.py). Slow:
32 identifications (~1-50 s each)."""

import pytest

from adequacy_study import study

pytestmark = [pytest.mark.slow, pytest.mark.filterwarnings("ignore::UserWarning")]


def test_right_models_are_not_flagged_and_a_wrong_held_mass_is():
    right = study(range(8))
    assert sum(r["adequate"] is False for r in right) == 0, right  # measured: 0 of 8 (ratios 0.991-1.005)
    wrong = study(range(8), wrong_mass=True)
    assert sum(r["adequate"] is False for r in wrong) >= 7, wrong  # measured: 8 of 8


def test_coverage_of_the_95_percent_intervals_on_random_truths():
    """tests/coverage_study.py over 8 truths each (measured: masses freed 69/80 = 0.86, 66/70 = 0.94 over the fits
    called adequate -- the one fit flagged not adequate ended in a wrong optimum; Stribeck with fs fitted from laws
    2-3x off 121/128 = 0.95; before the held laws' range reached the intervals 0.83 and 0.79; Stribeck with the
    end-effector mass twice the start's, freed: 120/128 = 0.94, 0.83 before the freed mass was profiled)."""
    from coverage_study import masses_freed, stribeck
    rows = [masses_freed(s) for s in range(8)]
    good = [r for r in rows if r["adequate"]]
    assert sum(r["covered"] for r in good) >= 0.9 * sum(r["points"] for r in good), rows
    rows = [stribeck(s) for s in range(8)]
    assert sum(r["covered"] for r in rows) >= 0.9 * sum(r["points"] for r in rows), rows
    rows = [stribeck(s, heavy=True) for s in range(8)]
    assert sum(r["covered"] for r in rows) >= 0.9 * sum(r["points"] for r in rows), rows


def test_coverage_with_vs_fitted_on_records_that_do_not_determine_it():
    """tests/coverage_study.py's stribeck_vs over 6 data seeds (measured: 86/96 = 0.90 with vs's range reaching the
    others through refits at its ends; 69/96 = 0.72 with the linearized sensitivities; every fit called adequate at
    residuals 0.99-1.01 times the noise, vs 0.0066-0.0158 m/s against the truth's 0.006)."""
    from coverage_study import stribeck_vs
    rows = [stribeck_vs(s) for s in range(6)]
    assert all(r["adequate"] for r in rows), rows
    assert sum(r["covered"] for r in rows) >= 0.85 * sum(r["points"] for r in rows), rows
