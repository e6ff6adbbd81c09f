"""identify on force runs at several loads and temperatures (identification/load_identify.py): per-condition fits,
laws through them with the load form chosen by AICc, the joint refinement with the leading forms compared on all
runs. Checked against independent truths written outside the package (tests/load_truth.py: a preloaded linear
stage and a joint, LuGre with interacting laws of temperature and load, integrated by SciPy's LSODA, per-run
offsets, AR(1) noise, quantised positions, a load cell's noise): 4 normal forces x 3 temperatures fitted, a load
beyond the fitted range and a new (temperature, load) inside it held out."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.identification.load_blind import LoadBlindWarning, check_load_blind
from thermofriction.identification.load_result import law_band
from thermofriction.models import LoadLaw, LoadTerm, Linear, LuGre, Model, ModelI, PrescribedMotion

import load_truth as lt

GRID = [(T, N) for T in (20.0, 35.0, 50.0) for N in (20.0, 45.0, 70.0, 95.0)]
HELD = [(35.0, 120.0), (42.0, 55.0)]  # a normal force beyond the fitted 20-95 N, a new condition inside it
TRUE = {"fc": lt.stage_fc, "fs": lt.stage_fs}
#: the seeds of the coverage test (each: 12 runs of 6 s at 250 Hz integrated, one identify; about 2.5 s a seed):
#: CI-affordable. At 100 Hz the sampling's discretisation of the breakaways biases fs by about 2 standard errors
#: (coverage 69 % on these seeds): the intervals hold where the record resolves the Stribeck peak
COVERAGE_SEEDS = range(20, 26)


def stage_start(fc_form=("affine", "product"), fs_form="proportional") -> Model:
    """The stage's model started away from the truth in value and in form: fc affine in the load as a product
    without an interaction (the truth: a sum with one), fs proportional (the truth: affine, a product); sigma2
    25 % low (fitted); the other LuGre constants at the truth's."""
    fr = LuGre(sigma0=lt.STAGE_SIGMA0, sigma1=lt.STAGE_SIGMA1, sigma2=30.0, vs=lt.STAGE_VS, fc=None, fs=None)
    fc_term = LoadTerm(fc_form[0], k=0.03, combine=fc_form[1]) if fc_form[0] == "affine" else LoadTerm("proportional")
    laws = {"fc": LoadLaw(Linear(a=-0.005, b=1.2), fc_term),
            "fs": LoadLaw(Linear(a=-0.0002, b=0.1), LoadTerm(fs_form) if fs_form == "proportional" else
                          LoadTerm("affine", k=0.01))}
    return Model(PrescribedMotion(motion="linear"), fr, ModelI(laws))


@pytest.fixture(scope="module")
def data():
    ds, _ = lt.stage_runs(GRID + HELD, seed=1, roles=["fit"] * len(GRID) + ["validate"] * len(HELD))
    return ds


@pytest.fixture(scope="module")
def fit(data):
    return tf.identify(data, init=stage_start(), parameters=["sigma2"], offset="per-experiment")


def test_stage_laws_within_3_percent_at_every_condition(fit):
    """Against the truth's formulas at every fitted and held-out condition; sigma2 too."""
    for T, N in GRID + HELD:
        for name, true in TRUE.items():
            value = fit.model.laws[name].value(T, N, warn=False)
            assert abs(value / true(T, N) - 1) < 0.03, (name, T, N, value, true(T, N))
    assert fit.parameters["sigma2"].value == pytest.approx(lt.STAGE_SIGMA2, rel=0.03)


def test_the_forms_are_chosen_and_said(fit):
    """The truth's forms recovered from wrong given ones: fc with an interaction (a sum, or the product with an
    interaction, the same functions over a linear temperature law), fs affine, not proportional; by per-condition
    fits (determined here), and said in the result."""
    load = fit.details["load"]
    assert load["procedure"].startswith("per-condition fits") and not load["why_joint"]
    assert len(load["conditions"]) == len(GRID)
    fc, fs = fit.model.laws["fc"].load, fit.model.laws["fs"].load
    assert fc.kind == "affine" and fc.interaction is not None
    assert fs.kind == "affine" and fs.interaction is None
    said = [w for w in fit.warnings if "law of load" in w]
    assert any(w.startswith("fs's law of load: affine, product, chosen by AICc") for w in said), said
    kept = [r for r in load["forms"]["fs"] if r["kept"]]
    assert len(kept) == 1 and all(r["aicc_all"] >= kept[0]["aicc_all"] for r in load["forms"]["fs"])


def test_held_out_loads_and_temperatures_at_the_noise(fit, data):
    """identify's generalisation and validate: the held-out runs (one at 120 N, beyond the fitted 20-95 N) within
    15 % of the noise's standard deviation, each run's offset removed; the run beyond the range warned about; the
    validation table carries each run's load."""
    gen = fit.fit_quality["generalisation"]
    assert gen["heldout_rmse"] == pytest.approx(lt.STAGE_NOISE, rel=0.15)
    v = tf.validate(fit.model, data)  # scored as the fit record says (per-experiment offsets)
    rmse = {p.file: p.rmse for p in v.predictions}
    for f in ("stage12.csv", "stage13.csv"):
        assert rmse[f] == pytest.approx(lt.STAGE_NOISE, rel=0.15)
    assert any(w.startswith("stage12.csv: load 120 is outside") for w in v.warnings)
    assert not any(w.startswith("stage13.csv") for w in v.warnings)
    rows = {r["file"]: r for r in v.experiments}
    assert rows["stage12.csv"]["load"] == pytest.approx(120.0, rel=0.01)
    assert "load [N]" in v.report().splitlines()[1]


def test_the_fitted_model_file_carries_its_laws_and_how_it_was_fitted(fit, tmp_path):
    """The TOML read back gives the same laws (forms, coefficients, ranges) and the fit record; the results JSON
    has the load details; the report names the laws' forms."""
    path = tmp_path / "fitted.toml"
    fit.model.save(path)
    back = tf.load_model(path)
    for name in ("fc", "fs"):
        assert back.laws[name].to_dict() == fit.model.laws[name].to_dict()
        assert back.laws[name].load.range == pytest.approx((20.0, 95.0), rel=0.01)
    assert back.provenance["fit_record"]["offset"] == "per-experiment"
    d = json.loads(fit.to_json())
    assert d["details"]["load"]["laws"]["fc"]["load"]["law"] == "affine"
    assert "fs's law of load" in fit.report()


def test_intervals_cover_over_seeds():
    """The laws' 95 % intervals (delta method on the coefficients' covariance, correlated noise accounted for)
    cover the truth at >= 90 % of the fitted conditions over COVERAGE_SEEDS (6 seeds x 12 conditions x 2 laws,
    250 Hz)."""
    hits = []
    for seed in COVERAGE_SEEDS:
        ds, _ = lt.stage_runs(GRID, seed=seed, rate=250.0)
        res = tf.identify(ds, init=stage_start(), parameters=["sigma2"], offset="per-experiment")
        T, N = np.array(GRID).T
        for name, true in TRUE.items():
            _, lo, hi = law_band(res, name, T, N)
            truth = np.array([true(t, n) for t, n in GRID])
            hits += list((lo <= truth) & (truth <= hi))
    assert np.mean(hits) >= 0.9, np.mean(hits)


def test_the_load_blind_model_is_5x_worse_held_out_and_told(data):
    """A stage model without laws of load: the check fits it and the load terms, and the held-out error of the
    load-blind fit is >= 5x the other's; validate says it is load-blind."""
    fr = LuGre(sigma0=lt.STAGE_SIGMA0, sigma1=lt.STAGE_SIGMA1, sigma2=30.0, vs=lt.STAGE_VS, fc=None, fs=None)
    blind = Model(PrescribedMotion(motion="linear"), fr,
                  ModelI({"fc": Linear(a=-0.01, b=4.0), "fs": Linear(a=-0.01, b=5.0)}))
    found = check_load_blind(blind, data, free=("sigma2",))
    assert found.load_blind and found.scored_on == "held-out runs"
    assert found.rmse_blind >= 5 * found.rmse_loaded
    notes = [f.message for f in tf.validate(found.blind.model, data, offset="per-experiment").findings
             if f.category is LoadBlindWarning]
    assert len(notes) == 1 and "the model is load-blind" in notes[0]
    gain = float(re.search(r"\(([0-9.]+)x\)", notes[0]).group(1))  # validate's own fits, from the fitted model
    assert gain >= 5


def test_the_joint_by_identify():
    """The joint truth (a product with an interaction for fc, a sum for fs), 3 loads x 3 temperatures at 250 Hz:
    identify's laws within 3 % at every condition, held-out included."""
    grid = [(T, L) for T in (20.0, 35.0, 50.0) for L in (5.0, 15.0, 25.0)]
    held = [(35.0, 35.0), (27.0, 10.0)]
    ds, _ = lt.runs(grid + held, seed=3, roles=["fit"] * 9 + ["validate"] * 2, rate=250.0)
    laws = {"fc": LoadLaw(Linear(a=-0.002, b=0.35), LoadTerm("affine", k=0.01)),
            "fs": LoadLaw(Linear(a=-0.002, b=0.5), LoadTerm("affine", k=0.005, combine="sum"))}
    init = Model(PrescribedMotion(motion="rotary"), LuGre(sigma0=lt.SIGMA0, sigma1=lt.SIGMA1, sigma2=0.08, vs=lt.VS,
                                                           fc=None, fs=None), ModelI(laws))
    res = tf.identify(ds, init=init, parameters=["sigma2"], offset="per-experiment")
    for T, L in grid + held:
        assert res.model.laws["fc"].value(T, L, warn=False) == pytest.approx(lt.fc_true(T, L), rel=0.03)
        assert res.model.laws["fs"].value(T, L, warn=False) == pytest.approx(lt.fs_true(T, L), rel=0.03)
    assert res.model.laws["fc"].load.interaction is not None
    assert res.fit_quality["generalisation"]["heldout_rmse"] == pytest.approx(lt.NOISE, rel=0.15)


def test_too_few_conditions_fall_back_to_the_joint_fit():
    """2 loads x 2 temperatures cannot choose among forms of 4 coefficients by per-condition AICc: the joint fit
    from the given laws, and the result says why."""
    ds, _ = lt.stage_runs([(20.0, 20.0), (20.0, 95.0), (50.0, 20.0), (50.0, 95.0)], seed=4, rate=100.0)
    res = tf.identify(ds, init=stage_start(fc_form=("affine", "sum")), parameters=["sigma2"],
                      offset="per-experiment")
    load = res.details["load"]
    assert load["procedure"].startswith("joint fit from the given laws") and "4 conditions" in load["why_joint"]
    assert any(w.startswith("laws of load: joint fit") for w in res.warnings)


def test_options_that_do_not_apply_are_named(data):
    """Options of other fits given to a fit with laws of the load: each refused by name, before any work."""
    with pytest.raises(tf.InputError, match="laws: a law of load keeps"):
        tf.identify(data, init=stage_start(), laws={"fc": "linear"})
    with pytest.raises(tf.InputError, match="method 'model-i'"):
        tf.identify(data, method="model-ii", init=stage_start())
    with pytest.raises(tf.InputError, match="parameters: 'delta_x' is neither a law"):
        tf.identify(data, init=stage_start(), parameters=["delta_x"])
    # the multi-start's options are refused by name, not silently ignored (the load fit has no multi-start)
    with pytest.raises(tf.InputError, match="starts, max_evaluations: not an option of a fit with laws of the load"):
        tf.identify(data, init=stage_start(), starts=3, max_evaluations=50)


def test_the_report_shows_the_laws_over_load(fit, data, tmp_path):
    """The force report on runs at several loads: the map per load (a panel per load, the held-out ones said), the
    laws over load with their bands, the table of the laws with the fitted equation, a load column in the errors;
    FitResult.plot draws the laws over load with a panel per law."""
    html = tf.report([fit], data, tmp_path / "report.html", figures_dir=tmp_path / "figs")
    assert 'id="fig-velocity-map-load"' in html and 'id="fig-load-laws"' in html
    assert "Laws of temperature and load" in html and "load 120 N (held out)" in html
    assert "<th>load [N]</th>" in html
    law = fit.model.laws["fc"]
    assert f"{law.base.a:.4g} T + {law.base.b:.4g}" in html  # the fitted equation, not a placeholder
    assert (tmp_path / "figs" / "load-laws.png").stat().st_size > 0
    fig = fit.plot()
    titles = [a.get_title() for a in fig.axes]
    assert len(titles) == 2 and titles[0].startswith("fc: affine") and titles[1].startswith("fs: affine")


def test_the_command_line_identifies_validates_and_reports(tmp_path, capsys):
    """thermofriction identify on a dataset folder with a normal_force[N] column and a model file with load tables,
    then validate and report on the fitted file: exit 0, the fitted file's laws of load, the table's load column."""
    from thermofriction.cli import main
    ds, _ = lt.stage_runs(GRID + HELD, seed=2, roles=["fit"] * len(GRID) + ["validate"] * len(HELD), rate=100.0)
    folder = lt.write_stage(tmp_path / "stage", ds)
    (tmp_path / "start.toml").write_text(lt.STAGE_MODEL)
    fitted = tmp_path / "fitted.toml"
    assert main(["identify", folder, "--init", str(tmp_path / "start.toml"), "--parameters", "sigma2", "--offset",
                 "per-experiment", "-o", str(fitted), "--json", str(tmp_path / "fitted.json"), "-q"]) == 0
    model = tf.load_model(fitted)
    for name, true in TRUE.items():
        assert model.laws[name].value(42.0, 55.0, warn=False) == pytest.approx(true(42.0, 55.0), rel=0.03)
    capsys.readouterr()
    assert main(["validate", str(fitted), folder]) == 0
    assert "load [N]" in capsys.readouterr().out
    assert main(["report", str(fitted), folder, "-o", str(tmp_path / "r.html")]) == 0
    assert 'id="fig-load-laws"' in (tmp_path / "r.html").read_text()


def test_identify_tells_a_load_blind_fit(data):
    """identify without laws of load (method base, LuGre for all runs) on runs spanning 20-120 N: its warnings say
    the model is load-blind, with the held-out gain of the load terms tried (>= 5x)."""
    m = Model(PrescribedMotion(motion="linear"), LuGre(sigma0=lt.STAGE_SIGMA0, sigma1=lt.STAGE_SIGMA1, sigma2=30.0,
                                                       vs=lt.STAGE_VS, fc=3.0, fs=4.0))
    res = tf.identify(data, method="base", init=m, parameters=["fc", "fs", "sigma2"], offset="per-experiment")
    said = [w for w in res.warnings if w.startswith("the model is load-blind")]
    assert len(said) == 1 and "held-out runs" in said[0]
    assert float(re.search(r"\(([0-9.]+)x\)", said[0]).group(1)) >= 5


def test_model_i_without_laws_of_load_on_runs_spanning_loads_completes_and_is_told(data):
    """Regression (was a raw InputError, fs below fc, inside the profile of the constant fitted on all runs): Model
    I from LuGre fc 3, fs 4 N (the truth: fc 2.2-4.8 N, fs 2.9-6.2 N over these runs) on
    the stage's runs at 20-95 N completes; being load-blind it is not adequate, and its warnings say it is
    load-blind with the held-out gain of a load law."""
    m = Model(PrescribedMotion(motion="linear"), LuGre(sigma0=lt.STAGE_SIGMA0, sigma1=lt.STAGE_SIGMA1, sigma2=30.0,
                                                       vs=lt.STAGE_VS, fc=3.0, fs=4.0))
    res = tf.identify(data, method="model-i", init=m, parameters=["fc", "fs", "sigma2"], offset="per-experiment")
    assert res.fit_quality["adequate"] is False
    assert any(w.startswith("the model is load-blind") for w in res.warnings)
