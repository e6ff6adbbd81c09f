"""Issue 32 (hardening III): the command line with zero tracebacks and no wrong statuses or partial
outputs -- standard output that cannot encode a model's name, SIGTERM during `demo`, implausible
inputs, `synth`'s limit, damaged Dask schedulers, repeated grid axes, a fleet writing over its input,
and force data from a stuck load cell. Each test failed before its fix (said where it is not obvious)."""

import dataclasses
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import thermofriction as tf
from child_signals import default_signals
from conftest import run_cli


def _one_line(err):
    err = err.strip()
    assert "Traceback" not in err and len(err.splitlines()) == 1 and err.startswith("thermofriction: error:"), err
    return err


# -- standard output that cannot encode a character ----------------------------------------------

@pytest.mark.parametrize("env", [{"PYTHONIOENCODING": "ascii"}, {"PYTHONIOENCODING": "latin-1"},
                                 {"LANG": "C", "LC_ALL": "C", "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0"}],
                         ids=["ascii", "latin-1", "C-locale"])
def test_a_model_name_with_degree_and_micro_signs_on_a_narrow_stdout(tmp_path, env):
    """Before: UnicodeEncodeError traceback at cli/commands.py:59 after the simulation ran."""
    model = dataclasses.replace(tf.load_model("li2009-model-i"), name="stage at 35 °C, 5 µm — ✓")
    model.save(tmp_path / "m.toml")
    r = subprocess.run([sys.executable, "-m", "thermofriction", "simulate", tmp_path / "m.toml", "--temperature",
                        "35", "--duration", "0.05"], capture_output=True, env={**os.environ, **env}, timeout=120)
    assert r.returncode == 0, r.stderr
    assert b"Traceback" not in r.stderr
    first = r.stdout.splitlines()[0]
    assert first.startswith(b"stage at 35 ") and b"samples" in first  # the name, escaped where it cannot be encoded
    r = subprocess.run([sys.executable, "-m", "thermofriction", "simulate", tmp_path / "nö-such-°.toml"],
                       capture_output=True, env={**os.environ, **env}, timeout=120)
    assert r.returncode == 2 and b"Traceback" not in r.stderr and len(r.stderr.splitlines()) == 1, r.stderr


# -- SIGTERM during demo -------------------------------------------------------------------------

def test_sigterm_during_demo_leaves_no_folders(tmp_path):
    """Before: `demo/` and `demo/data/` stayed (empty) while the message said no output was written."""
    out = tmp_path / "new" / "demo"
    proc = subprocess.Popen([sys.executable, "-m", "thermofriction", "demo", "-o", out], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=default_signals,
                            env={**os.environ, "THERMOFRICTION_PROGRESS_INTERVAL": "0.05"})
    lines = []
    try:
        for line in proc.stderr:  # progress lines (stderr is a pipe), one every 0.05 s: wait until it identifies
            lines.append(line)
            if line.startswith("thermofriction: demo: ") and "synthesising" not in line:
                break
        time.sleep(0.5)
        assert out.is_dir()  # the run is working in it
        proc.send_signal(signal.SIGTERM)
        rest = proc.stderr.read()
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 128 + signal.SIGTERM, (lines, rest)
    assert "no output was written" in rest and "Traceback" not in rest, rest
    assert not (tmp_path / "new").exists(), list(tmp_path.rglob("*"))


def test_remove_empty_keeps_a_folder_that_holds_anything(tmp_path):
    from thermofriction.cli.commands import _missing_folders, _remove_empty
    target = tmp_path / "a" / "b"
    missing = _missing_folders(target, "data")
    assert missing == [target / "data", target, tmp_path / "a"]
    (target / "data").mkdir(parents=True)
    (target / "user-file").write_text("mine")
    _remove_empty(missing)
    assert not (target / "data").exists() and (target / "user-file").read_text() == "mine"


# -- implausible voltages ----------------------------------------------------------------------

@pytest.fixture(scope="module")
def small_dataset(tmp_path_factory):
    data = tf.synthesize(tf.load_model("li2009-model-i"), [35.0], duration=0.1, sample_rate=2000, seed=3)
    return tf.save_dataset(data, tmp_path_factory.mktemp("small") / "ds")


def _copy(folder, to):
    import shutil
    shutil.copytree(folder, to)
    return to


def test_a_voltage_of_9e18_in_a_dataset_is_refused_naming_file_sample_and_value(small_dataset, tmp_path):
    """Before: 9.2e18 V passed every check (the values are limited to 1e100 only) and identify ran."""
    ds = _copy(small_dataset, tmp_path / "ds")
    f = next(ds.glob("*.csv"))
    lines = f.read_text().splitlines()
    head = lines[0].split(",")
    k = next(i for i, h in enumerate(head) if h.startswith("voltage"))
    cells = lines[21].split(",")
    cells[k] = "9.2e18"
    lines[21] = ",".join(cells)
    f.write_text("\n".join(lines) + "\n")
    with pytest.raises(tf.InputError) as info:
        tf.load_dataset(ds)
    msg = str(info.value)
    for text in (f.name, "voltage", "sample 21", "9.2e+18 V", "not a plausible actuator voltage", "10000 V"):
        assert text in msg, (text, msg)
    r = run_cli("identify", ds, "--method", "base", "-q")
    assert r.returncode == 2 and "9.2e+18 V" in _one_line(r.stderr)


def test_a_plausible_high_voltage_and_a_millivolt_record_still_load(small_dataset, tmp_path):
    """The bound is physical, not tight: 1 kV (a high-voltage piezo stack) and 9.2e6 mV = 9.2 kV load."""
    ds = _copy(small_dataset, tmp_path / "ds")
    f = next(ds.glob("*.csv"))
    text = f.read_text()
    head, *rows = text.splitlines()
    k = next(i for i, h in enumerate(head.split(",")) if h.startswith("voltage"))
    new = []
    for j, row in enumerate(rows):
        cells = row.split(",")
        cells[k] = repr(9.2e6 if j == 5 else 1000.0 * (j % 2))
        new.append(",".join(cells))
    hcells = head.split(",")
    hcells[k] = "voltage[mV]"
    f.write_text(",".join(hcells) + "\n" + "\n".join(new) + "\n")
    data = tf.load_dataset(ds)
    assert np.max(data.experiments[0].voltage) == pytest.approx(9200.0)


def test_manifest_and_synth_inputs_of_9e18_volts_are_refused(small_dataset, tmp_path):
    ds = _copy(small_dataset, tmp_path / "ds")
    man = ds / "dataset.toml"
    man.write_text(man.read_text().replace("amplitude=30.0", "amplitude=9.2e18"))
    assert "9.2e18" in man.read_text()
    with pytest.raises(tf.InputError, match=r"\[\[experiment\]\] 1: 'input': 9.2e\+18 V \(its peak\)"):
        tf.load_dataset(ds)
    with pytest.raises(tf.InputError, match="9.2e\\+18 V"):
        tf.synthesize(tf.load_model("li2009-model-i"), [35.0], input=tf.Sine(amplitude=9.2e18, frequency=5.0))
    r = run_cli("synth", "li2009-model-i", "--temperatures", "35", "--input", "sine:amplitude=9.2e18,frequency=5",
                "-o", tmp_path / "out")
    assert r.returncode == 2 and "9.2e+18 V" in _one_line(r.stderr) and not (tmp_path / "out").exists()


# -- synth: a limit and progress ---------------------------------------------------------------

def test_synth_refuses_30000_temperatures_before_any_work(tmp_path):
    """Before: accepted, and ran for hours with no progress shown."""
    from thermofriction.data.synth import MAX_EXPERIMENTS
    temps = ",".join(str(30 + k % 12) for k in range(30000))  # (one argument is at most 128 KiB)
    t0 = time.perf_counter()
    r = run_cli("synth", "li2009-model-i", "--temperatures", temps, "-o", tmp_path / "out")
    assert r.returncode == 2 and time.perf_counter() - t0 < 30
    err = _one_line(r.stderr)
    assert "30000 temperatures" in err and f"limit of {MAX_EXPERIMENTS}" in err and "docs/limits.md" in err
    assert not (tmp_path / "out").exists()
    with pytest.raises(tf.InputError, match="30000 temperatures"):
        tf.synthesize(tf.load_model("li2009-model-i"), np.linspace(30, 40, 30000))


def test_synthesize_reports_progress_after_each_experiment():
    seen = []
    tf.synthesize(tf.load_model("li2009-model-i"), [33.0, 35.0], validate=[34.0], duration=0.05,
                  sample_rate=1000, progress=lambda done, total: seen.append((done, total)))
    assert seen == [(1, 3), (2, 3), (3, 3)]


# -- force data from a stuck load cell ------------------------------------------------------------

def _force_dataset(folder, force, header="friction_force[N]", position="position[m]"):
    folder.mkdir()
    t = np.arange(2000) / 1000.0
    x = 1e-5 * np.sin(2 * np.pi * 2 * t)
    f = np.broadcast_to(np.asarray(force, float), t.shape)
    rows = "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(t.tolist(), x.tolist(), f.tolist()))
    (folder / "run.csv").write_text(f"time[s],{position},{header}\n" + rows)
    (folder / "dataset.toml").write_text('name = "stuck"\n[[experiment]]\nfile = "run.csv"\ntemperature = 35.0\n')
    return folder


@pytest.mark.parametrize("force,header", [(1.0, "friction_force[N]"), (0.0, "friction_force[N]"),
                                          (-2.5e-3, "friction_torque[N*m]")], ids=["1 N", "0 N", "torque"])
def test_a_constant_force_is_refused_when_the_data_are_loaded(tmp_path, force, header):
    """Before: identify ended in SciPy's `ValueError: Residuals are not finite in the initial point`
    (the noise estimated from a constant record is 0), a traceback with exit 1."""
    ds = _force_dataset(tmp_path / "ds", force, header, "position[rad]" if "torque" in header else "position[m]")
    with pytest.raises(tf.InputError) as info:
        tf.load_dataset(ds)
    msg = str(info.value)
    assert "run.csv" in msg and "does not vary" in msg and "stuck load cell" in msg, msg
    r = run_cli("identify", ds, "--method", "base")
    assert r.returncode == 2 and "does not vary" in _one_line(r.stderr)


def test_a_varying_force_still_loads(tmp_path):
    t = np.arange(2000) / 1000.0
    ds = _force_dataset(tmp_path / "ds", np.sign(np.cos(2 * np.pi * 2 * t)))
    assert np.ptp(tf.load_dataset(ds).experiments[0].force) == 2.0


# -- Dask: damaged scheduler files, something else at the address, repeated axes, a fleet over its input --

SWEEP = ["sweep", "li2009-model-i", "--grid", "temperature=30,35", "--duration", "0.05", "--sample-rate", "1000"]


@pytest.mark.parametrize("content,words", [
    (bytes(range(256)) * 2, ["not a Dask scheduler file", "not UTF-8"]),
    (b"", ["not a Dask scheduler file"]),
    (b"hello", ["not a Dask scheduler file"]),
    (b'{"foo": 1}', ["no \"address\""]),
    (b"[1, 2]", ["no \"address\""]),
    (b'{"address": 42}', ["no \"address\""]),
], ids=["binary", "empty", "text", "no address", "a list", "a number"])
def test_a_damaged_scheduler_file_is_one_message(tmp_path, content, words):
    """Before: an AssertionError (or KeyError, TypeError) traceback from inside Dask."""
    f = tmp_path / "scheduler.json"
    f.write_bytes(content)
    r = run_cli(*SWEEP, "--scheduler", f, "-o", tmp_path / "x.csv")
    err = _one_line(r.stderr)
    assert r.returncode == 2 and "scheduler.json" in err, err
    for w in words:
        assert w in err, (w, err)
    assert not (tmp_path / "x.csv").exists()


def _server(reply, tmp_path):
    """A TCP server on a free port that answers every connection with ``reply`` (b"": says nothing)."""
    code = ("import socket, sys, time\n"
            "s = socket.socket(); s.bind(('127.0.0.1', 0)); s.listen(8)\n"
            "print(s.getsockname()[1], flush=True)\n"
            "conns = []\n"
            "while True:\n"
            "    c, _ = s.accept(); conns.append(c)\n"
            f"    c.sendall({reply!r}) if {reply!r} else None\n")
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    port = int(proc.stdout.readline())
    return proc, port


@pytest.mark.parametrize("reply", [b"SSH-2.0-OpenSSH_9.6\r\n", b"HTTP/1.0 400 Bad Request\r\n\r\n", b""],
                         ids=["ssh banner", "http reply", "silent"])
def test_something_else_than_a_scheduler_at_the_address_is_named(tmp_path, reply):
    """Before: Dask read the first 8 bytes of the text as a message length (3 EiB) and the command said
    "out of memory" (exit 1); a silent server made it wait for ever."""
    proc, port = _server(reply, tmp_path)
    try:
        env = dict(os.environ, DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT="2s")
        t0 = time.perf_counter()
        r = subprocess.run([sys.executable, "-m", "thermofriction", *SWEEP, "--scheduler", f"tcp://127.0.0.1:{port}",
                            "-o", tmp_path / "x.csv"], capture_output=True, text=True, env=env, timeout=120)
        took = time.perf_counter() - t0
    finally:
        proc.kill()
        proc.wait()
    err = _one_line(r.stderr)
    assert r.returncode == 2 and f"tcp://127.0.0.1:{port}: not a Dask scheduler" in err, err
    assert "out of memory" not in err and took < 60
    assert not (tmp_path / "x.csv").exists()


def test_scheduler_file_is_read_and_its_address_probed(tmp_path):
    from thermofriction.scale.cluster import read_scheduler_file
    f = tmp_path / "s.json"
    f.write_text('{"type": "Scheduler", "address": " tcp://10.0.0.1:8786 ", "id": "x"}')
    assert read_scheduler_file(f) == "tcp://10.0.0.1:8786"
    proc, port = _server(b"SSH-2.0-x\r\n", tmp_path)
    try:
        f.write_text(f'{{"address": "tcp://127.0.0.1:{port}"}}')
        with pytest.raises(tf.InputError, match="not a Dask scheduler"):
            tf.sweep("li2009-model-i", {"temperature": [35.0]}, duration=0.05, scheduler=str(f))
    finally:
        proc.kill()
        proc.wait()


def test_a_repeated_grid_axis_is_refused(tmp_path):
    """Before: the first `--grid temperature=...` was dropped without a word (exit 0, one row)."""
    r = run_cli("sweep", "li2009-model-i", "--grid", "temperature=30,35", "--grid", "temperature=40",
                "--duration", "0.05", "--scheduler", "sequential", "-o", tmp_path / "x.csv")
    err = _one_line(r.stderr)
    assert r.returncode == 2 and "'temperature' is given twice" in err and "temperature=30,35" in err, err
    assert not (tmp_path / "x.csv").exists()
    with pytest.raises(tf.InputError, match="given twice"):
        tf.sweep("li2009-model-i", ["temperature=30", "amplitude=20", "temperature=31"], duration=0.05,
                 scheduler="sequential")


def test_a_fleet_writing_over_its_input_is_refused_before_any_identification(tmp_path, monkeypatch):
    """A dataset folder named `dataset` and `-o` that folder: the fleet's `dataset.toml` output is the
    dataset's manifest. Before: refused only when writing, after every identification ran (16 s)."""
    from thermofriction.cli import main
    from thermofriction.scale import fleet
    data = tf.synthesize(tf.load_model("li2009-base"), [35.0], duration=0.05, sample_rate=1000, seed=1)
    a = tf.save_dataset(data, tmp_path / "dataset")
    b = tf.save_dataset(data, tmp_path / "unit-2")
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}

    def never(*args, **kwargs):
        raise AssertionError("identification started")
    monkeypatch.setattr(fleet, "identify_fleet", never)
    assert main(["identify", str(a), str(b), "--method", "base", "-q", "-o", str(a)]) == 2
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before
    assert set(fleet.output_files(a, [a, b])) >= {str(a / "dataset.toml"), str(a / "fleet.json")}
    assert str(a / "T35C.csv") in fleet.input_files([a, b])
