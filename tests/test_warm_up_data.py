"""Warm-up records in files (docs/formats.md#warm-up-records): the ambient and proxy columns, the manifest's
ambient_temperature and continues keys, and the refusals, each naming the file."""

from __future__ import annotations

import numpy as np
import pytest

import thermofriction as tf

HEADER = "time[s],position[rad],velocity[rad/s],friction_torque[N*m]"


def _write(path, extra_header="", extra=()):
    t = np.arange(0.0, 20.0, 0.05)
    v = np.sin(t)
    x = 1 - np.cos(t)
    F = 0.8 * np.tanh(v / 1e-2) + 0.1 * v + 0.01 * np.random.default_rng(0).normal(size=t.size)
    cols = [t, x, v, F] + [np.full(t.size, e) for e in extra]
    np.savetxt(path, np.column_stack(cols), delimiter=",", comments="", header=HEADER + extra_header)


def _manifest(folder, entries):
    folder.joinpath("dataset.toml").write_text("".join(f"[[experiment]]\n{e}\n" for e in entries))


def test_ambient_and_proxy_columns_make_a_warm_up_record(tmp_path):
    """An ambient_temperature[C] column and no contact temperature: a warm-up record with its columns in C; the
    experiment's temperature is the ambient's mean (a label)."""
    _write(tmp_path / "w.csv", ",ambient_temperature[C],proxy_temperature[C]", (24.5, 30.0))
    _manifest(tmp_path, ['file = "w.csv"'])
    e = tf.load_dataset(tmp_path).experiments[0]
    assert e.warm_up and e.temperature == pytest.approx(24.5)
    assert np.all(e.ambient_temperature == 24.5) and np.all(e.proxy_temperature == 30.0) and e.continues is None


def test_the_manifest_gives_a_constant_ambient_and_what_a_record_continues(tmp_path):
    _write(tmp_path / "a.csv")
    _write(tmp_path / "b.csv")
    _manifest(tmp_path, ['file = "a.csv"\nambient_temperature = 22.0',
                         'file = "b.csv"\nambient_temperature = 22.0\ncontinues = "a.csv"'])
    a, b = tf.load_dataset(tmp_path).experiments
    assert a.warm_up and b.warm_up and b.continues == "a.csv"
    assert np.all(a.ambient_temperature == 22.0)


@pytest.mark.parametrize("header, extra, entry, message", [
    (",ambient_temperature[C]", (25.0,), 'file = "w.csv"\ntemperature = 30.0', "an ambient temperature beside"),
    (",ambient_temperature[C]", (25.0,), 'file = "w.csv"\nambient_temperature = 25.0', "both an ambient"),
    (",proxy_temperature[C]", (25.0,), 'file = "w.csv"\ntemperature = 30.0', "needs the ambient temperature"),
    ("", (), 'file = "w.csv"\nambient_temperature = 25.0\ncontinues = "x.csv"', "'continues' must name"),
    (",ambient_temperature[C]", (400.0,), 'file = "w.csv"', "not a plausible temperature"),
])
def test_bad_warm_up_records_are_refused_by_name(tmp_path, header, extra, entry, message):
    _write(tmp_path / "w.csv", header, extra)
    _manifest(tmp_path, [entry])
    with pytest.raises(tf.InputError, match=message) as e:
        tf.load_dataset(tmp_path)
    assert "w.csv" in str(e.value) or "dataset.toml" in str(e.value)


def test_actuator_files_refuse_the_warm_up_keys(tmp_path):
    t = np.arange(0, 1, 0.01)
    np.savetxt(tmp_path / "s.csv", np.column_stack([t, np.sin(t), 1e-6 * t]), delimiter=",", comments="",
               header="time[s],voltage[V],displacement[m]")
    _manifest(tmp_path, ['file = "s.csv"\ntemperature = 30.0\nambient_temperature = 25.0'])
    with pytest.raises(tf.InputError, match="'ambient_temperature' applies to force experiments only"):
        tf.load_dataset(tmp_path)


def test_the_command_line_fits_a_warm_up_and_writes_the_model_and_the_results(tmp_path):
    """``thermofriction identify DATA --method warm-up --init MODEL``: exit 0, the fitted Model I file and the
    results JSON with the heat path and the temperature trajectory (five minutes of the independent truth, with a
    proxy)."""
    import json
    import subprocess
    import sys

    from warmup_truth import Truth, initial_model, measured, proxy_record, warm_up
    truth = Truth()
    rng = np.random.default_rng(9)
    t, v, x, T1, _, Tp, _ = warm_up(truth, duration=300.0)
    cols = np.column_stack([t, x, v, measured(truth, rng, t, v, T1, 0.03), np.full(t.size, 25.0),
                            proxy_record(rng, Tp)])
    np.savetxt(tmp_path / "w.csv", cols, delimiter=",", comments="",
               header=HEADER + ",ambient_temperature[C],proxy_temperature[C]")
    _manifest(tmp_path, ['file = "w.csv"'])
    initial_model(truth).save(tmp_path / "init.toml")
    run = subprocess.run([sys.executable, "-m", "thermofriction", "identify", str(tmp_path), "--method", "warm-up",
                          "--init", str(tmp_path / "init.toml"), "-o", str(tmp_path / "fit.toml"), "--json",
                          str(tmp_path / "fit.json")], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    d = json.loads((tmp_path / "fit.json").read_text())
    assert d["method"] == "warm-up" and d["details"]["heat_path"]["scale"] == "proxy"
    assert len(d["details"]["temperature"]["w.csv"]["contact"]) > 100
    assert tf.load_model(tmp_path / "fit.toml").laws.keys() == {"fc", "fs"}
