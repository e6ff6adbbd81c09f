"""Fleet identification (tf.identify_fleet, `thermofriction identify DATASET DATASET ...`) and
uncertainty propagation (tf.propagate). The datasets are small and simulated from truths away
from the presets; runs here are sequential (the cluster runs are in test_dask_cluster.py)."""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.errors import InputError
from thermofriction.scale.fleet import fleet_datasets

FC_FACTORS = (0.8, 0.83, 0.78, 1.25)   # the last actuator's Coulomb level stands out
NOISE = 20e-9


def _truth(fc_factor, k):
    base = tf.load_model("li2009-base")
    fr = base.friction
    return dataclasses.replace(base, friction=dataclasses.replace(fr, fc=fr.fc * fc_factor,
                                                                  sigma0=fr.sigma0 * (1.2 + 0.03 * k)))


@pytest.fixture(scope="module")
def fleet_dir(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fleet")
    for k, f in enumerate(FC_FACTORS):
        data = tf.synthesize(_truth(f, k), [35.0], duration=0.4, sample_rate=2500, noise=NOISE, seed=10 + k)
        tf.save_dataset(data, folder / f"unit-{k}")
    (folder / "unit-9").mkdir()
    (folder / "unit-9" / "dataset.toml").write_text("[[experiment]]\nfile = 'gone.csv'\ntemperature = 35.0\n")
    return folder


@pytest.fixture(scope="module")
def fleet(fleet_dir):
    return tf.identify_fleet(fleet_dir, "base", starts=2, scheduler="sequential")


def test_fleet_paths_are_several_datasets_or_a_folder_of_them(fleet_dir):
    assert fleet_datasets([fleet_dir / "unit-0"]) is None  # one dataset: the single path
    assert fleet_datasets(str(fleet_dir / "unit-0")) is None
    assert fleet_datasets([fleet_dir / "unit-0", fleet_dir / "unit-1"]) == [fleet_dir / "unit-0",
                                                                             fleet_dir / "unit-1"]
    assert [p.name for p in fleet_datasets([fleet_dir])] == ["unit-0", "unit-1", "unit-2", "unit-3", "unit-9"]
    assert fleet_datasets(["no-such-folder"]) is None


def test_every_actuator_is_fitted_near_its_truth_and_the_failure_has_its_reason(fleet):
    assert fleet.names == ["unit-0", "unit-1", "unit-2", "unit-3", "unit-9"]
    assert list(fleet.failures) == ["unit-9"] and "gone.csv" in fleet.failures["unit-9"]
    for k, f in enumerate(FC_FACTORS):
        fit = fleet.fits[f"unit-{k}"]
        truth = _truth(f, k).friction.fc
        p = fit.parameters["fc"]
        # within 5 standard errors (set by the 20 nm noise), and the errors are small against the spread
        assert abs(p.value - truth) < 5 * p.stderr, (k, p.value, truth, p.stderr)
        assert p.stderr < 0.01 * truth


def test_summary_names_the_outlier_and_describes_each_parameter(fleet):
    s = fleet.summary()
    assert (s["datasets"], s["identified"], s["failed"]) == (5, 4, 1)
    fc = s["parameters"]["fc"]
    assert [o["dataset"] for o in fc["outliers"]] == ["unit-3"] and fc["outliers"][0]["z"] > 3.5
    values = [fleet.fits[f"unit-{k}"].parameters["fc"].value for k in range(4)]
    assert fc["median"] == pytest.approx(np.median(values), rel=1e-12)
    assert (fc["min"], fc["max"]) == (min(values), max(values)) and fc["unit"] == "N"
    assert s["failures"] == [{"dataset": "unit-9", "reason": fleet.failures["unit-9"]}]
    text = fleet.report()
    assert "outlier: unit-3: fc" in text and "FAILED: unit-9" in text


def test_write_publishes_every_model_result_and_the_summary(fleet, tmp_path):
    out = fleet.write(tmp_path / "out")
    names = sorted(os.listdir(out))
    assert names == sorted([f"unit-{k}.{e}" for k in range(4) for e in ("toml", "json")] + ["fleet.csv",
                                                                                              "fleet.json"])
    for k in range(4):
        loaded = tf.load_model(out / f"unit-{k}.toml")
        assert loaded.friction.fc == pytest.approx(fleet.fits[f"unit-{k}"].model.friction.fc, rel=1e-12)
        assert json.loads((out / f"unit-{k}.json").read_text())["method"] == "base"
    rows = (out / "fleet.csv").read_text().splitlines()
    assert rows[0] == "dataset,status,rmse[m],sigma0[N/m],sigma1[N s/m],fc[N],error"
    assert rows[4].startswith("unit-3,ok,") and rows[5].startswith("unit-9,failed,,,,,")
    # the rmse is at the noise each dataset was made with (these fits are adequate)
    rmse = [float(r.split(",")[2]) for r in rows[1:5]]
    assert all(0.8 * NOISE < x < 1.25 * NOISE for x in rmse)


def test_cli_fleet_and_its_usage_errors(fleet_dir, tmp_path, monkeypatch, capsys):
    r = subprocess.run([sys.executable, "-m", "thermofriction", "identify", fleet_dir / "unit-0", fleet_dir / "unit-9",
                        "--method", "base", "--starts", "2", "--scheduler", "sequential", "-o", "out"], cwd=tmp_path,
                       capture_output=True, text=True, timeout=240)
    assert r.returncode == 1 and "unit-9: not identified" in r.stderr and "Traceback" not in r.stderr
    assert sorted(os.listdir(tmp_path / "out")) == ["fleet.csv", "fleet.json", "unit-0.json", "unit-0.toml"]
    from thermofriction.cli import main
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile").write_text("")
    for args, words in ((["--scheduler", "sequential"], "give -o DIR"),
                        (["-o", "x", "--json", "r.json"], "--json applies to one dataset"),
                        (["-o", "afile"], "not a folder")):
        assert main(["identify", str(fleet_dir / "unit-0"), str(fleet_dir / "unit-1"), *args]) == 2
        assert words in capsys.readouterr().err
    assert sorted(os.listdir(tmp_path)) == ["afile", "out"]


# -- uncertainty propagation ------------------------------------------------------------------

@pytest.fixture(scope="module")
def fit_two():
    """A fit of sigma0 and fc only (both well determined), on data from a truth away from the preset."""
    data = tf.synthesize(_truth(0.85, 3), [35.0], duration=0.6, sample_rate=5000, noise=NOISE, seed=3)
    return tf.identify(data, "base", init="li2009-base", starts=2, parameters=["sigma0", "fc"])


def test_monte_carlo_spread_equals_the_delta_method(fit_two):
    """For small uncertainties the Monte Carlo standard deviation of a prediction equals the first-order
    (delta-method) one, sqrt(g' C g), g the prediction's gradient by central differences: an
    independent computation. Tolerance: the Monte Carlo error of a standard deviation from 300 draws
    (1/sqrt(2 x 300) = 4.1 %), times 3."""
    from thermofriction.fitting.parameters import with_values

    T, draws = 38.0, 300
    tight = tf.StepSizeController(rtol=1e-10)  # the differences below must not see the integration error
    res = tf.propagate(fit_two, [T], draws=draws, seed=5, duration=0.6, controller=tight, scheduler="sequential")
    assert res.failures == {} and res.parameters.shape == (draws, 2)
    names = res.names
    theta = np.array([fit_two.parameters[n].value for n in names])
    se = np.array([fit_two.parameters[n].stderr for n in names])
    cov = fit_two.correlation * np.outer(se, se)

    def final(th):
        return tf.simulate(with_values(fit_two.model, dict(zip(names, th))), 0.6, temperature=T,
                           sample_rate=1000, controller=tight).displacement[-1]
    g = np.empty(len(names))
    for i in range(len(names)):
        h = 1e-3 * se[i]
        up, down = theta.copy(), theta.copy()
        up[i] += h
        down[i] -= h
        g[i] = (final(up) - final(down)) / (2 * h)
    delta = np.sqrt(g @ cov @ g)
    mc = np.std(res.final_displacement[:, 0], ddof=1)
    print(f"Monte Carlo {mc:.4g} m, delta method {delta:.4g} m")
    assert mc == pytest.approx(delta, rel=3 * 0.041)
    # the band holds the nominal prediction and is about 2 x 1.96 standard deviations wide
    assert res.lower[0, -1] < res.nominal[0, -1] < res.upper[0, -1]
    assert res.upper[0, -1] - res.lower[0, -1] == pytest.approx(2 * 1.96 * delta, rel=0.2)
    assert np.all(res.prediction_upper - res.prediction_lower >= res.upper - res.lower - 1e-15)
    assert res.noise == pytest.approx(NOISE, rel=0.2)


def test_draws_are_seeded_and_follow_the_covariance(fit_two):
    from thermofriction.scale.propagate import draw_parameters
    names, a = draw_parameters(fit_two, 4000, seed=1)
    _, b = draw_parameters(fit_two, 4000, seed=1)
    _, c = draw_parameters(fit_two, 4000, seed=2)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    se = np.array([fit_two.parameters[n].stderr for n in names])
    np.testing.assert_allclose(a.std(axis=0), se, rtol=0.1)
    assert np.corrcoef(a.T)[0, 1] == pytest.approx(fit_two.correlation[0, 1], abs=0.05)


def test_propagation_writes_bands_and_refuses_what_it_cannot_draw(fit_two, tmp_path):
    res = tf.propagate(fit_two, [33.0, 40.0], draws=20, seed=0, duration=0.2, sample_rate=500,
                       scheduler="sequential", batch_size=6)
    res.to_csv(tmp_path / "bands.csv")
    table = np.genfromtxt(tmp_path / "bands.csv", delimiter=",", names=True)
    assert table.size == 2 * res.time.size
    assert set(np.unique(table[table.dtype.names[0]])) == {33.0, 40.0}
    assert "40 C: step per cycle" in res.report()
    from xml.etree import ElementTree

    from thermofriction.scale.figures import save_bands_figure
    save_bands_figure(res, tmp_path / "bands.svg")
    save_bands_figure(res, tmp_path / "bands.png")
    svg = (tmp_path / "bands.svg").read_text()
    ElementTree.fromstring(svg)  # well-formed
    assert "33 °C" in svg and "mean step per cycle" in svg
    assert (tmp_path / "bands.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the report shows the same bands (one figure implementation)
    fig = res.plot()
    assert len(fig.axes) == 2 and fig.axes[0].collections  # a filled band per temperature
    data = tf.synthesize(tf.load_model("li2009-base"), [35.0], validate=[36.0], duration=0.2, sample_rate=2000,
                         noise=NOISE, seed=1)
    page = tf.report([fit_two], data, tmp_path / "report.html", bands=res)
    section = page[page.index("<h2>Prediction bands</h2>"):]
    assert "<svg" in section[:section.index("</section>")] and "20 parameter sets" in section
    params = tf.Parameters({name: dataclasses.replace(p) for name, p in fit_two.parameters.items()})
    broken = dataclasses.replace(fit_two, parameters=params)
    broken.parameters["fc"].stderr = float("inf")
    with pytest.raises(InputError, match="'fc' has no finite standard error"):
        tf.propagate(broken, [35.0], scheduler="sequential")
    with pytest.raises(InputError, match="draws must be"):
        tf.propagate(fit_two, [35.0], draws=1, scheduler="sequential")
