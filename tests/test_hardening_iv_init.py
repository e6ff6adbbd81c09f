"""Hardening IV (issue 41), `init` and the old module names: a temperature's sign in a file name, file names that
are not UTF-8, a manifest checked before it is written (an interrupted or failed init leaves the folder as it was),
and every form of import of the earlier module names (thermofriction.identify, ...) either working or refused with
a message naming the new module."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys

import pytest

import thermofriction as tf
from thermofriction.cli import main
from thermofriction.cli.init import temperature_from_name


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """One short actuator run at 30 C as a CSV file without a temperature column (the attack's `synth ... -o s`)."""
    data = tf.synthesize(tf.load_model("li2009-model-i"), [30.0], duration=0.2, sample_rate=2000, seed=1)
    folder = tmp_path_factory.mktemp("s")
    tf.save_dataset(data, folder / "s")
    return folder / "s" / data.experiments[0].file


def _folder(tmp_path, run, *names):
    folder = tmp_path / "m"
    folder.mkdir()
    for name in names:
        shutil.copy(run, os.path.join(os.fsencode(folder), os.fsencode(name)) if isinstance(name, bytes)
                    else folder / name)
    return folder


def _temperatures(folder):
    return {e.file: e.temperature for e in tf.load_dataset(folder).experiments}


# -- the sign of a temperature in a file name --------------------------------------------------------

@pytest.mark.parametrize("name, T", [
    ("run_-5C.csv", -5.0), ("-5C.csv", -5.0), ("T_-10.csv", -10.0), ("T=-10.csv", -10.0), ("x_-2p5degC.mat", -2.5),
    ("run \u22125C.csv", -5.0), ("run\u22125C.csv", -5.0),          # a minus sign (U+2212) is one anywhere
    ("run-5C.csv", None), ("T-10.csv", None), ("run3-5C.csv", None),  # a hyphen after a letter or digit: either way
    ("oven-150C.csv", 150.0),                                         # -150 C is no plausible temperature
    ("run_-0C.csv", 0.0), ("stage_35p2C.csv", 35.2), ("T33C-validate.csv", 33.0), ("run0-T35C.csv", 35.0)])
def test_the_sign_of_a_temperature_in_a_name(name, T):
    got = temperature_from_name(name)
    assert got == T and (got is None or str(got) == str(T)), (name, got)  # (str: no -0.0)


def test_init_reads_a_negative_temperature_in_a_name(run, tmp_path, capsys):
    """The attack's case: run_-5C.csv was read as +5 C, exit 0."""
    folder = _folder(tmp_path, run, "run_-5C.csv", "run_30C.csv")
    assert main(["init", str(folder)]) == 0
    assert _temperatures(folder) == {"run_-5C.csv": -5.0, "run_30C.csv": 30.0}
    assert "-5 C" in capsys.readouterr().out


def test_init_refuses_a_name_that_reads_two_ways(run, tmp_path, capsys):
    """T-10.csv (read as +10 C) and run-5C.csv: the hyphen may be a separator or a minus sign; init says so in one
    line, writes nothing, and takes the temperature from --temperature."""
    folder = _folder(tmp_path, run, "T-10.csv", "run-5C.csv", "run_30C.csv")
    assert main(["init", str(folder)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "T-10.csv, run-5C.csv" in err[0], err
    assert "T-10.csv: its name reads -10 or 10 C" in err[0] and "run-5C.csv: its name reads -5 or 5 C" in err[0]
    assert "separator or a minus sign" in err[0] and not (folder / "dataset.toml").exists()
    assert main(["init", str(folder), "--temperature", "T-10.csv=-10", "--temperature", "run-5C.csv=5"]) == 0
    assert _temperatures(folder) == {"T-10.csv": -10.0, "run-5C.csv": 5.0, "run_30C.csv": 30.0}


def test_init_on_a_terminal_asks_saying_how_the_name_reads(run, tmp_path, monkeypatch):
    folder = _folder(tmp_path, run, "run-5C.csv")
    prompts = []
    monkeypatch.setattr("sys.stdin.isatty", lambda: True)
    monkeypatch.setattr("builtins.input", lambda prompt: prompts.append(prompt) or "-5")
    assert main(["init", str(folder)]) == 0
    assert prompts == ["temperature of run-5C.csv [C] (its name reads -5 or 5 C): "]
    assert _temperatures(folder) == {"run-5C.csv": -5.0}


# -- file names that are not UTF-8 -------------------------------------------------------------------

def test_init_refuses_a_file_name_that_is_not_utf8(run, tmp_path, capsys):
    """A file named b'\\xff.csv' was a UnicodeEncodeError traceback (writing dataset.toml); now one message naming
    it as bytes, nothing written, and --exclude leaves it out."""
    folder = _folder(tmp_path, run, b"\xff_31C.csv", "run_30C.csv")
    assert main(["init", str(folder)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and r"b'\xff_31C.csv'" in err[0] and "--exclude" in err[0], err
    assert not (folder / "dataset.toml").exists()
    assert main(["init", str(folder), "--exclude", os.fsdecode(b"\xff*")]) == 0
    assert _temperatures(folder) == {"run_30C.csv": 30.0}


def test_init_refuses_a_file_name_with_a_control_character(run, tmp_path, capsys):
    folder = _folder(tmp_path, run, "a\nb_31C.csv", "run_30C.csv")
    assert main(["init", str(folder)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and r"b'a\nb_31C.csv'" in err[0], err
    assert not (folder / "dataset.toml").exists()


def test_init_in_a_folder_whose_name_is_not_utf8(run, tmp_path, capsys):
    """The dataset's name defaults to the folder's: its bytes that are not UTF-8 are replaced; a --name that is not
    UTF-8 is refused."""
    folder = tmp_path / os.fsdecode(b"\xfe-stage")
    folder.mkdir()
    shutil.copy(run, folder / "run_30C.csv")
    assert main(["init", str(folder), "--name", os.fsdecode(b"x\xff")]) == 2
    assert r"--name b'x\xff': not UTF-8 text" in capsys.readouterr().err and not (folder / "dataset.toml").exists()
    assert main(["init", str(folder)]) == 0
    assert tf.load_dataset(folder).name == "\ufffd-stage"


# -- checked before it is written ----------------------------------------------------------------------

@pytest.mark.parametrize("signum, status", [(signal.SIGTERM, 128 + signal.SIGTERM), (signal.SIGINT, 130)])
@pytest.mark.parametrize("old", [b"# the user's manifest\n", None])
def test_an_interrupted_init_leaves_the_folder_as_it_was(run, tmp_path, monkeypatch, capsys, signum, status, old):
    """A signal while the dataset is being checked (the experiment files read): with --force the old manifest is
    still there, byte for byte, without one none is left, and no temporary file either (before, the new, unchecked
    manifest was already written)."""
    folder = _folder(tmp_path, run, "run_30C.csv", "run_35C.csv")
    if old is not None:
        (folder / "dataset.toml").write_bytes(old)
    import thermofriction.data.files as files
    read = files._read_experiment

    def interrupted(*args, **kwargs):
        os.kill(os.getpid(), signum)  # the command line's handler raises it here
        return read(*args, **kwargs)

    monkeypatch.setattr(files, "_read_experiment", interrupted)
    # as a background job (nohup, make test &) the suite runs with SIGINT/SIGHUP ignored, and the command line
    # keeps an ignored signal ignored: this process's disposition set here, as tests/child_signals.py does a child's
    previous = signal.signal(signum, signal.default_int_handler if signum == signal.SIGINT else signal.SIG_DFL)
    try:
        assert main(["init", str(folder), "--force"]) == status
    finally:
        signal.signal(signum, previous)
    assert "no output was written" in capsys.readouterr().err
    assert sorted(os.listdir(folder)) == sorted(["run_30C.csv", "run_35C.csv"] + (["dataset.toml"] if old else []))
    if old is not None:
        assert (folder / "dataset.toml").read_bytes() == old


def test_a_failed_init_with_force_keeps_the_old_manifest(run, tmp_path, capsys):
    folder = _folder(tmp_path, run, "run_30C.csv")
    (folder / "notes_31C.csv").write_text("what,when\n1,2\n")
    (folder / "dataset.toml").write_bytes(b"# mine\n")
    assert main(["init", str(folder), "--force"]) == 2
    assert "notes_31C.csv" in capsys.readouterr().err
    assert (folder / "dataset.toml").read_bytes() == b"# mine\n" and len(os.listdir(folder)) == 3


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs")
def test_init_refuses_a_manifest_that_is_a_fifo(run, tmp_path, capsys):
    """A FIFO named dataset.toml: refused before any work (writing through it would wait for a reader)."""
    folder = _folder(tmp_path, run, "run_30C.csv")
    os.mkfifo(folder / "dataset.toml")
    reader = os.open(folder / "dataset.toml", os.O_RDONLY | os.O_NONBLOCK)  # (so that a regression fails, not hangs)
    try:
        assert main(["init", str(folder), "--force"]) == 2
    finally:
        os.close(reader)
    assert "not a regular file; refusing to replace it" in capsys.readouterr().err


# -- the old module names -----------------------------------------------------------------------------

def _python(*args, code=None):
    """A fresh interpreter (the first import of an old name is the one that warns); with ``code``, its warnings
    are errors."""
    cmd = [sys.executable] + (["-W", "error::DeprecationWarning", "-c", code] if code else list(args))
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("old, new, sub", [("identify", "identification", "procedures"),
                                           ("simulate", "simulation", "solvers"),
                                           ("report", "reporting", "entries")])
def test_old_submodule_names_in_every_import_form(old, new, sub):
    """`import thermofriction.identify.problem as p` was an ImportError ("cannot import name 'problem' from
    'identify'"); the three forms now give the new module, each with a DeprecationWarning naming it, and the
    package's function stays the function."""
    forms = {"import as": f"import thermofriction.{old}.{sub} as m",
             "from import": f"from thermofriction.{old} import {sub} as m",
             "from dotted import": f"from thermofriction.{old}.{sub} import __name__ as n; import sys; "
                                   f"m = sys.modules['thermofriction.{old}.{sub}']"}
    for form, line in forms.items():
        warned = _python(code=line)
        assert warned.returncode == 1 and f"thermofriction.{new}" in warned.stderr, (form, warned.stderr)
        code = "\n".join(["import warnings, types", "warnings.simplefilter('ignore', DeprecationWarning)", line,
                          f"import thermofriction as tf, thermofriction.{new}.{sub} as real",
                          "assert m is real, m",
                          f"assert callable(tf.{old}) and not isinstance(tf.{old}, types.ModuleType)"])
        out = _python(code=code)
        assert out.returncode == 0, (form, out.stderr)


@pytest.mark.parametrize("old, new", [("simulate", "simulation"), ("validate", "validation")])
def test_import_of_an_old_name_as_says_it_is_the_function(old, new):
    """`import thermofriction.simulate as s` binds thermofriction.simulate, which stays the function: it cannot
    be the module, and the warning says so, naming the module's new name."""
    out = _python(code=f"import thermofriction.{old} as s")
    assert out.returncode == 1
    assert f"thermofriction.{new}" in out.stderr and f"'import thermofriction.{old} as ...' gives the function" \
        in out.stderr, out.stderr
    out = _python(code=f"import warnings; warnings.simplefilter('ignore')\nimport thermofriction.{old} as s\n"
                       f"import thermofriction as tf\nassert s is tf.{old} and callable(s)")
    assert out.returncode == 0, out.stderr


@pytest.mark.parametrize("name", ["thermofriction.simulate", "thermofriction.identify", "thermofriction.validate",
                                  "thermofriction.report", "thermofriction.identify.procedures"])
def test_python_m_with_an_old_name_names_the_new_module_and_the_command(name):
    """`python -m thermofriction.simulate --help` was an AttributeError traceback (no get_code); the modules are
    no programs: one line naming the new module and the command line."""
    out = _python("-m", name, "--help")
    new = name.replace("identify", "identification").replace("simulate", "simulation") \
        .replace("validate", "validation").replace("report", "reporting")
    assert out.returncode != 0 and "Traceback" not in out.stderr, out.stderr
    assert f"{name} is now {new}" in out.stderr and "thermofriction --help" in out.stderr, out.stderr
    assert len(out.stderr.strip().splitlines()) == 1 and not out.stdout
