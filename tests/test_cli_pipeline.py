"""The whole workflow from the command line: synth, identify, validate, report, and demo."""

import json
from pathlib import Path

import pytest

import thermofriction as tf

from conftest import run_cli


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cli") / "data"
    out = run_cli("synth", "li2009-model-i", "--temperatures", "31,34,37,40", "--validate", "35.5",
                  "--duration", "0.6", "--noise", "2e-8", "--seed", "3", "-o", folder)
    assert out.returncode == 0, out.stderr
    return folder


def test_identify_validate_report_from_the_command_line(dataset, tmp_path):
    out = run_cli("identify", dataset, "--method", "model-i", "--init", "li2009-model-i", "--starts", "2",
                  "-o", tmp_path / "mi.toml", "--json", tmp_path / "mi.json")
    assert out.returncode == 0, out.stderr
    assert "[[Parameters]]" in out.stdout and "sigma0.a" in out.stdout
    res = json.loads((tmp_path / "mi.json").read_text())
    assert res["parameters"]["fc.b"]["ci95"][0] < -0.159 < res["parameters"]["fc.b"]["ci95"][1]
    out = run_cli("validate", tmp_path / "mi.toml", dataset, "--json", tmp_path / "v.json")
    assert out.returncode == 0, out.stderr
    v = json.loads((tmp_path / "v.json").read_text())
    assert max(e["max_error_pct"] for e in v["experiments"]) < 5
    out = run_cli("report", tmp_path / "mi.toml", "li2009-base", dataset, "-o", tmp_path / "r.html",
                  "--figures", tmp_path / "figs")
    assert out.returncode == 0, out.stderr
    text = (tmp_path / "r.html").read_text()
    assert "Model I" in text and 'id="fig-model-i-parameters"' in text  # the fit's JSON was found beside it
    assert (tmp_path / "figs" / "displacement.png").exists()


def test_identify_bad_dataset_is_a_data_error(tmp_path):
    (tmp_path / "d").mkdir()
    out = run_cli("identify", tmp_path / "d", "-o", tmp_path / "m.toml")
    assert out.returncode == 2 and "no dataset.toml" in out.stderr and "Traceback" not in out.stderr
    assert not (tmp_path / "m.toml").exists()


def test_report_without_held_out_experiments_is_refused(tmp_path):
    folder = tmp_path / "d"
    assert run_cli("synth", "li2009-model-i", "--temperatures", "31,40", "--duration", "0.2", "-o", folder).returncode == 0
    out = run_cli("report", "li2009-model-i", folder, "-o", tmp_path / "r.html")
    assert out.returncode == 2 and "validate" in out.stderr
    assert not (tmp_path / "r.html").exists()


def test_demo_runs_the_main_job(tmp_path):
    out = run_cli("demo", "-o", tmp_path / "demo")
    assert out.returncode == 0, out.stderr
    for name in ("report.html", "model-i.toml", "model-i.json", "model-ii.toml", "model-ii.json", "validation.json",
                 "data/dataset.toml"):
        assert (tmp_path / "demo" / name).exists(), name
    assert (tmp_path / "demo" / "report.html").stat().st_size < 1_000_000  # issue 19: the whole report under 1 MB
    v = json.loads((tmp_path / "demo" / "validation.json").read_text())
    held = {k: v[k]["summary"]["validate"]["max_error_pct"] for k in v}
    assert held["model-i"] < held["base"] and held["model-ii"] < held["base"]
    assert "report:" in out.stdout
    # the demo knows its truth (the Model I preset): Model I's intervals cover it, Model II says why it
    # cannot be compared
    rec = json.loads((tmp_path / "demo" / "recovery.json").read_text())
    assert rec["model-i"]["points"] == 24 and rec["model-i"]["covered"] >= 0.9 * 24, rec["model-i"]["missed"]
    assert rec["model-ii"]["covered"] is None and "not comparable" in rec["model-ii"]["summary"]
    assert "against the truth" in out.stdout


def test_identify_plant_from_a_recorded_stage(tmp_path):
    """xi, wn, K from the stage record of a synthetic experiment: the stage alone (the end effector's
    friction negligible, as when the paper measured its step responses); the preset's plant is the truth."""
    folder = tmp_path / "d"
    stage = tmp_path / "stage.toml"
    stage.write_text((Path(tf.models.preset_path("li2009-base"))).read_text()
                     .replace("sigma0 = 1945575.887588102", "sigma0 = 1e-9").replace("fc = 0.8992595121614437", "fc = 1e-12")
                     .replace("sigma1 = 2.305", "sigma1 = 0.0"))
    assert run_cli("synth", stage, "--temperatures", "30", "--duration", "0.05", "--sample-rate",
                   "100000", "--noise", "1e-9", "--record-stage", "-o", folder).returncode == 0
    out = run_cli("identify", folder, "--method", "plant", "--json", tmp_path / "p.json")
    assert out.returncode == 0, out.stderr
    p = json.loads((tmp_path / "p.json").read_text())["parameters"]
    for name, true in (("damping_ratio", 0.2488), ("natural_frequency", 6685.5), ("gain", 0.096e-6)):
        lo, hi = p[name]["ci95"]
        assert lo <= true <= hi, (name, p[name])
