"""A freed plant parameter profiled after Model I's joint refinement (identification/profile.py), on a truth
simulated by the independent SciPy reference (tests/stribeck_truths.py): a Stribeck effect, sigma1 rising with
temperature, the end-effector mass twice the start's, every law 2-3x off. Without the profile step (and without the
law kinds' check, identification/law_kinds.py, which came later) this fit stopped where the falling sigma1 law met
zero at the range's end, with m_e 9 % low, its interval missing the truth and fc 11 % off, called adequate."""

import pytest

import thermofriction as tf
import thermofriction.identification.model_i as model_i
from coverage_study import stribeck, stribeck_fit
from stribeck_truths import reference_experiments

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")


def _without_the_kinds_check(monkeypatch):
    monkeypatch.setattr(model_i, "checked_kinds", lambda refined, *a, **k: refined)


def test_the_freed_mass_is_recovered_inside_its_interval(monkeypatch):
    """The profile step alone (the kinds' check off): held at 2 standard errors, the mass no longer asks the blocked
    law to cross zero, and the refit leaves the blocked point."""
    _without_the_kinds_check(monkeypatch)
    row = stribeck(5, heavy=True)
    assert row["m_e_covered"] and abs(row["m_e_error"]) < 0.05, row
    assert row["fc_error"] < 0.05 and row["covered"] >= 14, row


def test_without_the_profile_step_the_same_fit_misses(monkeypatch):
    """The check above can fail: the joint refinement alone ends at the blocked point."""
    _without_the_kinds_check(monkeypatch)
    monkeypatch.setattr(model_i, "profiled", lambda model, params, outcome, traces, *a, **k:
                        model_i.Profiled(model, params, outcome, traces))
    row = stribeck(5, heavy=True)
    assert not row["m_e_covered"] and row["fc_error"] > 0.08, row


def test_with_both_steps_the_fit_lands_where_the_fit_from_the_truth_does():
    """With the kinds' check too, sigma1's law turns exponential (the profile step's optimum is 128 in chi-square
    worse) and the fit lands where the same fit started from the truth's values does: m_e 5 % low and fc 7 % off
    there -- what 0.4 s records say -- with every interval covering the truth."""
    fit, truth = stribeck_fit(5, heavy=True)
    data = reference_experiments(truth, seed=5, duration=0.4)
    from_truth = tf.identify(data, "model-i", init=truth, parameters=["sigma0", "sigma1", "fc", "fs"], free=["m_e"])
    n = sum(e.time.size for e in data)
    assert abs(fit.cost - from_truth.cost) / (from_truth.cost / n) < 1.0
    assert fit.details["laws"]["sigma1"].get("switched_from") == "linear"
    lo, hi = fit.parameters["m_e"].ci95
    assert lo <= truth.plant.end_effector_mass <= hi
    assert all(r["covered"] for r in fit.recovery(truth, (31.0, 34.0, 37.0, 40.0)))


def test_a_flat_profile_widens_the_freed_mass_interval(monkeypatch):
    """Truth 4: the data fit as well at the true mass as at the optimum 9 % above it (a flat valley); the
    held fits at 2 standard errors rise less than a quadratic profile's 4, and the interval says so."""
    from coverage_study import stribeck_fit
    fit, _ = stribeck_fit(4, heavy=True)
    factor = fit.details.get("profiled", {}).get("m_e")
    assert factor is not None and factor > 1.05, fit.details.get("profiled")
    assert any("'m_e': the fit changes less" in w for w in fit.warnings)
    monkeypatch.setattr(model_i, "widened", lambda res, factors: None)
    narrow, _ = stribeck_fit(4, heavy=True)
    lo, hi = fit.parameters["m_e"].ci95
    nlo, nhi = narrow.parameters["m_e"].ci95
    assert hi - lo > 1.05 * (nhi - nlo)
