"""The joint fit of laws of temperature and load (identification/load_fit.py) and the load-blind check
(identification/load_blind.py), on an independent truth (tests/load_truth.py: LuGre with interacting laws written
there, integrated by SciPy, per-run offsets, AR(1) noise): 3 loads x 3 temperatures fitted, two loads held out (one
outside the fitted range)."""

from __future__ import annotations

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.identification.load_blind import LoadBlindWarning, check_load_blind, load_findings
from thermofriction.identification.load_fit import fit_load_laws, held_out_rmse
from thermofriction.models import LoadLaw, LoadRangeWarning, LoadTerm, Linear, LuGre, Model, ModelI, PrescribedMotion

import load_truth as lt

GRID = [(T, L) for T in (20.0, 35.0, 50.0) for L in (5.0, 15.0, 25.0)]
HELD = [(35.0, 35.0), (27.0, 10.0)]  # a load beyond the fitted range, one inside it at a new temperature
TRUE = {"fc.a": -0.003, "fc.b": 0.40, "fc.load.k": 0.02, "fc.load.interaction": 1e-4, "fs.a": -0.004, "fs.b": 0.55,
        "fs.load.k": 0.012, "sigma2": lt.SIGMA2}


def friction():
    """The held parameters at the truth's, sigma2 started 20 % off (fitted), the levels from laws."""
    return LuGre(sigma0=lt.SIGMA0, sigma1=lt.SIGMA1, sigma2=0.08, vs=lt.VS, fc=None, fs=None)


def start_model():
    """Laws of the truth's forms, started away from it (slopes a third or half of the truth's, levels 10 % low)."""
    laws = {"fc": LoadLaw(Linear(a=-0.002, b=0.35), LoadTerm("affine", k=0.01, interaction=0.0)),
            "fs": LoadLaw(Linear(a=-0.002, b=0.5), LoadTerm("affine", k=0.005, combine="sum"))}
    return Model(PrescribedMotion(motion="rotary"), friction(), ModelI(laws))


def blind_model():
    return Model(PrescribedMotion(motion="rotary"), friction(),
                 ModelI({"fc": Linear(a=-0.002, b=0.5), "fs": Linear(a=-0.002, b=0.7)}))


@pytest.fixture(scope="module")
def data():
    ds, _ = lt.runs(GRID + HELD, seed=3, roles=["fit"] * len(GRID) + ["validate"] * len(HELD), rate=250.0)
    return ds


@pytest.fixture(scope="module")
def fitted(data):
    return fit_load_laws(start_model(), data, free=("sigma2",))


def test_laws_within_3_percent_at_every_condition(fitted):
    """Against the truth's formulas at every fitted and held-out condition."""
    for T, L in GRID + HELD:
        for name, true in (("fc", lt.fc_true), ("fs", lt.fs_true)):
            value = fitted.model.laws[name].value(T, L, warn=False)
            assert abs(value / true(T, L) - 1) < 0.03, (name, T, L, value, true(T, L))
    assert fitted.values[fitted.names.index("sigma2")] == pytest.approx(lt.SIGMA2, rel=0.03)


def test_held_out_loads_are_predicted_at_the_noise(fitted, data):
    """The held-out runs' RMSE (each run's offset removed) within 15 % of the noise's standard deviation, the fit
    runs' too: nothing but the noise is left."""
    held = held_out_rmse(fitted.model, data.validate)
    assert set(held) == {"run9.csv", "run10.csv"}
    for rmse in [*held.values(), *fitted.rmse.values()]:
        assert rmse == pytest.approx(lt.NOISE, rel=0.15)


def test_validate_predicts_each_run_at_its_load(fitted, data):
    """validate: a run at its load; the held-out run beyond the fitted load range warned about; no load-blind note
    for a model with the laws."""
    assert fitted.model.laws["fc"].load.range == pytest.approx((5.0, 25.0), abs=0.01)
    assert fitted.model.laws["fc"].range == (20.0, 50.0)
    res = tf.validate(fitted.model, data, offset="per-experiment")
    rmse = {p.file: p.rmse for p in res.predictions}
    assert rmse["run9.csv"] == pytest.approx(lt.NOISE, rel=0.15)
    outside = [f.message for f in res.findings if issubclass(f.category, LoadRangeWarning)]
    assert len(outside) == 1 and outside[0].startswith("run9.csv: load 35 is outside") and "'fs' (5..25)" in outside[0]
    assert not any(f.category is LoadBlindWarning for f in res.findings)


def test_intervals_cover_over_seeds():
    """The coefficients' 95 % intervals (correlated noise accounted for) cover the truth in >= 90 % of 6 seeds x 8
    coefficients; without the correlation's correction they would be about half as wide."""
    hits = []
    for seed in range(10, 16):
        ds, _ = lt.runs(GRID, seed=seed)
        fit = fit_load_laws(start_model(), ds, free=("sigma2",))
        assert fit.correlation_time > 2.0  # AR(1) with rho = 0.6 (1 + 2 rho / (1 - rho) = 4 at the sampling)
        hits += [abs(v - TRUE[n]) < 1.96 * s for n, v, s in zip(fit.names, fit.values, fit.stderr)]
    assert np.mean(hits) >= 0.9


def test_a_load_blind_model_is_told_and_the_law_tried(data):
    """The load-blind fit is >= 5x worse on the held-out runs than the same model with the load term the check
    adds and fits; the check says so; validate says it too."""
    found = check_load_blind(blind_model(), data, free=("sigma2",))
    assert found.load_blind and found.scored_on == "held-out runs"
    assert found.rmse_blind >= 5 * found.rmse_loaded
    assert found.rmse_loaded == pytest.approx(lt.NOISE, rel=0.5)
    assert "the model is load-blind" in found.message() and f"{found.gain:.3g}x" in found.message()
    res = tf.validate(found.blind.model, data, offset="per-experiment")
    notes = [f.message for f in res.findings if f.category is LoadBlindWarning]
    assert len(notes) == 1 and "load-blind" in notes[0]


def test_no_load_dependence_is_not_called_load_blind():
    """A truth whose levels do not depend on the load: the check tries the law and says the model needs none."""
    ds, _ = lt.runs([(T, L) for T in (20.0, 50.0) for L in (5.0, 25.0)], seed=5, load_free=True)
    found = check_load_blind(blind_model(), ds, free=("sigma2",))
    assert not found.load_blind and "needs none" in found.message()


def test_a_run_without_its_load_is_named(data):
    exp = data.experiments[0]
    bare = type(exp)(**{**{k: getattr(exp, k) for k in exp.__dataclass_fields__}, "load": None})
    with pytest.raises(tf.InputError, match=r"run0\.csv: the model's laws depend on the load but the run has none"):
        fit_load_laws(start_model(), [bare])


def test_a_model_ii_is_not_checked_as_if_it_were_model_i(data):
    """A Model II model is not fitted by dropping its term: the check says it could not be tried, and why."""
    m = Model(PrescribedMotion(motion="rotary"), LuGre(sigma0=100.0, sigma1=0.5, sigma2=0.1, vs=0.08, fc=0.4, fs=0.5),
              tf.ModelII(Linear(a=-0.001, b=0.03)))
    with pytest.raises(tf.InputError, match="Model II"):
        fit_load_laws(m, data)
    notes = load_findings(m, data.experiments)
    assert len(notes) == 1 and "could not be tried" in notes[0].message and "Model II" in notes[0].message
