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
                            stderr=subprocess.PIPE, text=True)
    lines = []
    try:
        for line in proc.stderr:  # progress lines (stderr is a pipe): wait until identification runs
            lines.append(line)
            if "identifying" in line:
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
