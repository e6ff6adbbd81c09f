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
    """tests/coverage_study.py over 8 truths each (measured: masses freed 76/80 = 0.95, every fit adequate -- 70/80
    before the law kinds were checked on all experiments, when one fit ended in a wrong optimum with a linear
    sigma0 law, flagged not adequate; Stribeck with fs fitted from laws 2-3x off 121/128 = 0.95; before the held
    laws' range reached the intervals 0.83 and 0.79; Stribeck with the end-effector mass twice the start's, freed:
    122/128 = 0.95, 120/128 before the kinds' check, 0.83 before the freed mass was profiled)."""
    from coverage_study import masses_freed, stribeck
    rows = [masses_freed(s) for s in range(8)]
    assert all(r["adequate"] for r in rows), rows
    assert sum(r["covered"] for r in rows) >= 0.9 * sum(r["points"] for r in rows), rows
    rows = [stribeck(s) for s in range(8)]
    assert sum(r["covered"] for r in rows) >= 0.9 * sum(r["points"] for r in rows), rows
    rows = [stribeck(s, heavy=True) for s in range(8)]
    assert sum(r["covered"] for r in rows) >= 0.9 * sum(r["points"] for r in rows), rows


def test_coverage_with_vs_fitted_on_records_that_hardly_determine_it():
    """tests/coverage_study.py's stribeck_vs on 0.4 s records over 6 data seeds (measured: 88/96 = 0.92 with vs's
    range from the profile of the per-temperature fits with sigma1 -- held for lack of information in 4 of the 6 --
    free at each temperature, widened to the linearized interval, reaching the others through refits at its ends;
    81/96 = 0.84 with sigma1 held at the start's law, 2x off, in that profile: its range then excluded the truth's
    vs in 2 of 6; 69/96 = 0.72 with the linearized sensitivities alone; every fit called adequate at residuals
    0.99-1.01 times the noise. Seeds 6-11: 96/96, 92/96 before; they showed why the search itself keeps sigma1
    held: free there too, 2 of them stopped at the start's vs, 2.5x off)."""
    from coverage_study import stribeck_vs
    rows = [stribeck_vs(s) for s in range(6)]
    assert all(r["adequate"] for r in rows), rows
    assert sum(r["covered"] for r in rows) >= 0.9 * sum(r["points"] for r in rows), rows


def test_vs_recovered_where_the_records_determine_it():
    """stribeck_vs on 2 s records (4 data seeds), vs started 2.5x off and the laws 2-3x off (measured: vs within
    4-15 % and inside the range the fit gives it in 4 of 4, fc within 0.8-2.5 % and fs within 1.8-6.7 % at every
    fit temperature, 64/64 intervals covering the truth; before the profile over vs the joint refinement stopped
    at vs 2.3x off with fc 47 % off and 8 of 16 intervals covering)."""
    from coverage_study import stribeck_vs
    rows = [stribeck_vs(s, duration=2.0) for s in range(4)]
    assert all(r["vs_covered"] and abs(r["vs_error"]) < 0.2 for r in rows), rows
    assert all(r["fc_error"] < 0.05 and r["fs_error"] < 0.1 for r in rows), rows
    assert sum(r["covered"] for r in rows) >= 0.9 * sum(r["points"] for r in rows), rows


def test_friction_level_within_5_percent_with_a_wrong_mass_freed_on_2_s_records():
    """The Stribeck truths with the end-effector mass twice the start's, freed (8 truths, 2 s records): fc and fs
    within 5 % at every fit temperature (measured: fc 0.1-1.2 %, fs 0.1-0.9 %, m_e within 1.0 %, coverage 128/128;
    before the law kinds were checked on all experiments fc up to 3.1 %, 118/128: truth 6's fs law was exponential,
    468 in chi-square worse than the truth's linear kind. On 0.4 s records 4 of 8 are at 5.2-11 %, each within 4
    in chi-square of the fit started from the truth's values, as far off -- m_e 4-9 % off in a flat valley those
    short records leave)."""
    from coverage_study import stribeck
    rows = [stribeck(s, heavy=True, duration=2.0) for s in range(8)]
    assert all(r["fc_error"] < 0.05 and r["fs_error"] < 0.05 for r in rows), rows
    assert sum(r["covered"] for r in rows) >= 0.9 * sum(r["points"] for r in rows), rows
