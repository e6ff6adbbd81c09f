"""Issue 45's warm-up follow-ups: validation refuses warm-up records (no contact temperature to score a model at),
by name, exit 2 and no output (docs/self-heating.md#warm-up-without-a-contact-temperature)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import thermofriction as tf

from warmup_truth import Truth, initial_model

HEADER = "time[s],position[rad],velocity[rad/s],friction_torque[N*m]"


def _dataset(folder, warm=True):
    """A force dataset of one run: a warm-up record (an ambient column, no contact temperature) or, with
    ``warm=False``, the same run at a known contact temperature."""
    folder.mkdir(parents=True, exist_ok=True)
    t = np.arange(0.0, 20.0, 0.05)
    v = np.sin(t)
    cols = [t, 1 - np.cos(t), v, 0.8 * np.tanh(v / 1e-2) + 0.1 * v]
    header = HEADER
    if warm:
        cols.append(np.full(t.size, 25.0))
        header += ",ambient_temperature[C]"
    np.savetxt(folder / "w.csv", np.column_stack(cols), delimiter=",", comments="", header=header)
    folder.joinpath("dataset.toml").write_text('[[experiment]]\nfile = "w.csv"\n' +
                                               ("" if warm else "temperature = 30.0\n"))
    return folder


def test_validate_refuses_a_warm_up_record_by_name(tmp_path):
    """A warm-up record's temperature is the ambient's mean only as a label: scoring a model there would be a
    silently wrong number, so validate raises InputError naming the file; the same run with a contact
    temperature is scored (the refusal is the record's, not the model's)."""
    model = initial_model(Truth())
    data = tf.load_dataset(_dataset(tmp_path / "warm"))
    with pytest.raises(tf.InputError, match=r"^w\.csv: a warm-up record .* cannot be scored"):
        tf.validate(model, data)
    v = tf.validate(model, tf.load_dataset(_dataset(tmp_path / "soak", warm=False)))
    assert len(v.predictions) == 1 and v.predictions[0].temperature == pytest.approx(30.0)


@pytest.mark.parametrize("command", ["validate", "report"])
def test_the_command_line_refuses_a_warm_up_record_with_exit_2_and_writes_nothing(tmp_path, command):
    """``thermofriction validate`` and ``report`` on a warm-up record: exit 2, one line naming the file, no
    traceback, no output file."""
    data = _dataset(tmp_path / "data")
    initial_model(Truth()).save(tmp_path / "m.toml")
    out = tmp_path / ("metrics.json" if command == "validate" else "report.html")
    args = [str(tmp_path / "m.toml"), str(data)] + (["--json", str(out)] if command == "validate" else
                                                    ["-o", str(out)])
    run = subprocess.run([sys.executable, "-m", "thermofriction", command, *args], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 2, run.stderr
    assert "w.csv: a warm-up record" in run.stderr and "Traceback" not in run.stderr
    assert not out.exists()


def _warm_up_pair(folder):
    """Two warm-up records: a.csv with ambient and proxy columns, b.csv with the manifest's ambient and
    ``continues = "a.csv"``."""
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(4)
    t = np.arange(0.0, 20.0, 0.05)
    v = np.sin(t)
    F = 0.8 * np.tanh(v / 1e-2) + 0.1 * v + 0.01 * rng.normal(size=t.size)
    amb, proxy = 24.0 + 0.01 * t, 30.0 + 0.1 * np.round(10 * rng.normal(size=t.size)) / 10
    np.savetxt(folder / "a.csv", np.column_stack([t, 1 - np.cos(t), v, F, amb, proxy]), delimiter=",",
               comments="", header=HEADER + ",ambient_temperature[C],proxy_temperature[C]")
    np.savetxt(folder / "b.csv", np.column_stack([t, 1 - np.cos(t), v, F]), delimiter=",", comments="",
               header=HEADER)
    folder.joinpath("dataset.toml").write_text('[[experiment]]\nfile = "a.csv"\n\n[[experiment]]\nfile = "b.csv"\n'
                                               'ambient_temperature = 22.5\ncontinues = "a.csv"\n')
    return tf.load_dataset(folder)


def _same_warm_up(a, b):
    """Every warm-up field of two loaded records equal (the values read back bit for bit: every digit written)."""
    assert b.warm_up and a.continues == b.continues
    np.testing.assert_array_equal(a.ambient_temperature, b.ambient_temperature)
    if a.proxy_temperature is None:
        assert b.proxy_temperature is None
    else:
        np.testing.assert_array_equal(a.proxy_temperature, b.proxy_temperature)
    np.testing.assert_array_equal(a.force, b.force)
    assert a.temperature == b.temperature  # the ambient's mean, a label (no contact temperature)


@pytest.mark.parametrize("suffix", [".csv", ".mat"])
def test_save_dataset_keeps_the_warm_up_columns_and_continues(tmp_path, suffix):
    """save_dataset then load_dataset (CSV files, and MATLAB files: data/matlab.py) gives back the ambient and
    proxy records, the constant ambient of the manifest (as a column), and ``continues``: compared with the
    records as first loaded from hand-written files."""
    import dataclasses
    data = _warm_up_pair(tmp_path / "in")
    if suffix == ".mat":
        renamed = {e.file: e.file.replace(".csv", ".mat") for e in data.experiments}
        data.experiments = [dataclasses.replace(e, file=renamed[e.file],
                                                continues=renamed.get(e.continues)) for e in data.experiments]
    tf.save_dataset(data, tmp_path / "out")
    back = tf.load_dataset(tmp_path / "out")
    assert [e.file for e in back.experiments] == [f"a{suffix}", f"b{suffix}"]
    for a, b in zip(data.experiments, back.experiments):
        _same_warm_up(a, b)
    assert back.experiments[1].continues == f"a{suffix}"
