"""Issue 44: `thermofriction init` on a MATLAB file with one struct per run (docs/your-data.md section 8) writes
one [[experiment]] per struct, and every table and JSON names a struct's run `runs.mat:run1`, not `runs.mat` on
every row."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest
import scipy.io

import thermofriction as tf
from thermofriction.cli import main

MODEL = "li2009-model-i"


@pytest.fixture(scope="module")
def synthesized():
    """Two short runs at 30.5 and 34.0 C, simulated by the package (the data only; the checks below compare
    names and the temperatures the runs recorded, not the simulation)."""
    return tf.synthesize(tf.load_model(MODEL), [30.5, 34.0], duration=0.2)


def _runs_mat(folder, data, temperature_field=True, names=("run1", "run2")):
    """runs.mat as section 8 of docs/your-data.md makes it: one struct per run with time, voltage,
    displacement_um and (``temperature_field``) temperature."""
    folder.mkdir()
    runs = {}
    for name, e in zip(names, data.experiments):
        run = {"time": e.time, "voltage": e.voltage, "displacement_um": e.displacement * 1e6}
        if temperature_field:
            sig = e.temperature_signal
            run["temperature"] = np.full_like(e.time, e.temperature) if sig is None else sig
        runs[name] = run
    scipy.io.savemat(folder / "runs.mat", runs)
    return folder


def test_init_writes_one_experiment_per_struct(tmp_path, synthesized, capsys):
    """The manifest lists runs.mat once per struct, each with its struct, the temperature left to the struct's
    own field (its mean is the run's recorded temperature, 30.5 and 34.0 C to 1e-9 C)."""
    folder = _runs_mat(tmp_path / "my-stage-mat", synthesized)
    assert main(["init", str(folder)]) == 0
    out = capsys.readouterr().out
    assert "runs.mat:run1" in out and "runs.mat:run2" in out and "temperature field" in out
    manifest = tomllib.loads((folder / "dataset.toml").read_text())
    assert [(e["file"], e["struct"]) for e in manifest["experiment"]] == [("runs.mat", "run1"), ("runs.mat", "run2")]
    assert all("temperature" not in e for e in manifest["experiment"])
    data = tf.load_dataset(folder)
    assert [e.label for e in data.experiments] == ["runs.mat:run1", "runs.mat:run2"]
    want = [float(np.mean(e.temperature_signal)) if e.temperature_signal is not None else e.temperature
            for e in synthesized.experiments]
    assert [e.temperature for e in data.experiments] == pytest.approx(want, abs=1e-9)


def test_validate_names_each_struct(tmp_path, synthesized, capsys):
    """validate's table and JSON (and the Python API's predictions) name each struct's run, one distinct name
    per row."""
    folder = _runs_mat(tmp_path / "m", synthesized)
    assert main(["init", str(folder)]) == 0
    result = tf.validate(tf.load_model(MODEL), tf.load_dataset(folder))
    assert [p.file for p in result.predictions] == ["runs.mat:run1", "runs.mat:run2"]
    capsys.readouterr()
    assert main(["validate", MODEL, str(folder), "--json", str(tmp_path / "v.json")]) == 0
    table = capsys.readouterr().out
    rows = [line for line in table.splitlines() if "runs.mat" in line]
    assert len(rows) == 2 and "runs.mat:run1" in rows[0] and "runs.mat:run2" in rows[1], table
    text = (tmp_path / "v.json").read_text()
    assert "runs.mat:run1" in text and "runs.mat:run2" in text and '"runs.mat"' not in text
    json.loads(text)


def test_struct_temperature_from_its_name(tmp_path, synthesized, capsys):
    """Structs without a temperature field take the temperature their names state (T30p5C, T34C), as files do."""
    folder = _runs_mat(tmp_path / "n", synthesized, temperature_field=False, names=("T30p5C", "T34C"))
    assert main(["init", str(folder)]) == 0
    assert "from the struct's name" in capsys.readouterr().out
    manifest = tomllib.loads((folder / "dataset.toml").read_text())
    assert [(e["struct"], e["temperature"]) for e in manifest["experiment"]] == [("T30p5C", 30.5), ("T34C", 34.0)]


def test_struct_without_temperature_is_refused_by_name(tmp_path, synthesized, capsys):
    """No temperature field and no temperature in the struct's or the file's name: one message naming each run
    as FILE:STRUCT and the option to give, exit 2, no manifest; the advice it gives then works."""
    folder = _runs_mat(tmp_path / "r", synthesized, temperature_field=False)
    assert main(["init", str(folder)]) == 2
    err = capsys.readouterr().err
    assert "runs.mat:run1, runs.mat:run2" in err and "--temperature runs.mat:run1=35.2" in err
    assert "Traceback" not in err and not (folder / "dataset.toml").exists()
    assert main(["init", str(folder), "--temperature", "runs.mat:run1=30.5", "--temperature",
                 "runs.mat:run2=34"]) == 0
    assert [e.temperature for e in tf.load_dataset(folder).experiments] == [30.5, 34.0]


def test_plain_variables_stay_one_experiment(tmp_path, synthesized):
    """A .mat of plain variables (one run) stays one [[experiment]] without 'struct'."""
    folder = tmp_path / "p"
    folder.mkdir()
    e = synthesized.experiments[0]
    scipy.io.savemat(folder / "T30p5C.mat", {"time": e.time, "voltage": e.voltage,
                                             "displacement_um": e.displacement * 1e6})
    assert main(["init", str(folder)]) == 0
    manifest = tomllib.loads((folder / "dataset.toml").read_text())
    assert manifest["experiment"] == [{"file": "T30p5C.mat", "temperature": 30.5, "role": "fit"}]
