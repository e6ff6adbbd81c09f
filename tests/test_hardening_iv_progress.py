"""Issue 41 (hardening IV): progress where nobody watches a terminal, and the tests that send signals run as
a background job (``nohup make test &``)."""

from __future__ import annotations

import ast
import io
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import thermofriction as tf
from child_signals import SENT

TESTS = Path(__file__).resolve().parent


# -- the tests that send signals, run as a background job ----------------------------------------

def _ignoring_parent():
    """What ``nohup CMD &`` in a non-interactive shell does to CMD: SIGINT and SIGHUP ignored."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)


def test_a_child_started_with_default_signals_under_nohup_handles_each_signal_again():
    """Under nohup and & the child inherits the ignored signals; default_signals gives them back (the
    program itself keeps an ignored signal ignored, as nohup asks)."""
    report = ("import signal; print(' '.join(str(signal.getsignal(s) is signal.SIG_IGN) for s in "
              f"{[int(s) for s in SENT]}))")
    parent = ("import subprocess, sys; from child_signals import default_signals\n"
              f"plain = subprocess.run([sys.executable, '-c', {report!r}], capture_output=True, text=True)\n"
              f"reset = subprocess.run([sys.executable, '-c', {report!r}], capture_output=True, text=True, "
              "preexec_fn=default_signals)\n"
              "print(plain.stdout.strip()); print(reset.stdout.strip())\n")
    r = subprocess.run([sys.executable, "-c", parent], capture_output=True, text=True, cwd=TESTS,
                       preexec_fn=_ignoring_parent, timeout=60)
    plain, reset = r.stdout.splitlines()
    assert plain == "True False True", r  # the inherited dispositions: SIGINT and SIGHUP ignored
    assert reset == "False False False", r


def _signalled_scopes(tree):
    """(name, sends a catchable signal, its Popen calls) per top-level function or class of a test file."""
    for scope in tree.body:
        if not isinstance(scope, (ast.FunctionDef, ast.ClassDef)):
            continue
        sends, popens = False, []
        for node in ast.walk(scope):
            if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Attribute):
                continue
            name = node.func.attr
            if name in ("send_signal", "kill", "killpg") and node.args:
                sent = ast.unparse(node.args[-1])
                sends |= "SIGKILL" not in sent and (name == "send_signal" or "SIG" in sent)
            elif name == "Popen":
                popens.append(node)
        yield scope.name, sends, popens


def test_every_test_that_signals_a_child_sets_the_childs_dispositions():
    """A test that sends SIGINT, SIGTERM or SIGHUP to a child starts it with preexec_fn=default_signals:
    otherwise it fails when the suite runs as a background job (an ignored signal is inherited)."""
    missing, checked = [], 0
    for path in sorted(TESTS.glob("test_*.py")):
        for name, sends, popens in _signalled_scopes(ast.parse(path.read_text(encoding="utf-8"))):
            if not sends:
                continue
            checked += 1
            for call in popens:
                if not any(k.arg == "preexec_fn" and ast.unparse(k.value) == "default_signals" for k in call.keywords):
                    missing.append(f"{path.name}:{call.lineno} ({name})")
    assert checked >= 7, checked  # the rule sees the tests it is about
    assert not missing, missing


# -- progress in a pipe or a log -------------------------------------------------------------------

INTERVAL_ENV = "THERMOFRICTION_PROGRESS_INTERVAL"  # the documented name (docs/cli.md#environment)

ANSI = re.compile(r"\x1b|\r")  # a terminal's escapes and carriage returns: none in a log
#: [s] the interval the tests set: the commands below run for several of it
SHORT = 0.2


def _cli(*args, interval=SHORT, cwd=None):
    """The command line as a job under a scheduler runs it: stdout and stderr are pipes."""
    env = {**os.environ, INTERVAL_ENV: str(interval)}
    return subprocess.run([sys.executable, "-m", "thermofriction", *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=300)


def _progress_lines(stderr, label):
    return [line for line in stderr.splitlines() if line.startswith(f"thermofriction: {label}: ")]


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """A base fit (identify -o --json) of synthesised data, identify's stderr kept."""
    folder = tmp_path_factory.mktemp("progress")
    tf.save_dataset(tf.synthesize(tf.load_model("li2009-model-i"), [31.0, 41.0], duration=0.4, sample_rate=2000,
                                  seed=2), folder / "data")
    r = _cli("identify", folder / "data", "--method", "base", "--starts", "1", "-o", folder / "fit.toml",
             "--json", folder / "fit.json", interval=0.05)
    assert r.returncode == 0, r.stderr
    return folder, r


def test_propagate_in_a_pipe_prints_plain_lines_with_the_time_left(fitted):
    """Before: 1,000 draws printed nothing in 100 s when stderr was not a terminal."""
    folder, _ = fitted
    t0 = time.monotonic()
    # draws in tasks of 5 at a 0.02 s interval: on an idle machine 200 draws in tasks of 100 were done before the
    # first line, whose count was then 100 % with no time left to estimate
    r = _cli("propagate", folder / "fit.json", "--temperatures", "33,38", "--draws", "400", "--duration", "0.1",
             "--workers", "1", "--batch-size", "5", interval=0.02)
    took = time.monotonic() - t0
    assert r.returncode == 0, r.stderr
    lines = _progress_lines(r.stderr, "propagate")
    assert took > 0.12 and len(lines) >= 2, (took, r.stderr)
    assert not ANSI.search(r.stderr), repr(r.stderr)
    counted = [re.fullmatch(r"thermofriction: propagate: (\d+) of 400 draws \((\d+) %\) in .+", x) for x in lines]
    assert all(counted), lines
    assert [int(m.group(1)) for m in counted] == sorted(int(m.group(1)) for m in counted)
    assert any(re.search(r", (under 1 s|about \d+ s|about \d+ min \d+ s) left$", x) for x in lines), lines
    assert len(lines) <= took / 0.02 + 1  # at most one an interval


def test_identify_in_a_pipe_says_what_it_is_doing(fitted):
    """Before: identify on a pipe printed each stage as it began (none while a stage or the reading of a large
    file lasted): now a line every interval, naming the stage, with the time so far."""
    _, r = fitted
    lines = _progress_lines(r.stderr, "identify")
    assert lines and all(re.search(r"; (under 1 s|\d+ s) so far$", x) for x in lines), r.stderr
    assert not ANSI.search(r.stderr) and "Traceback" not in r.stderr


def test_quick_work_and_quiet_print_no_progress(tmp_path):
    """Work shorter than the interval prints no line; --quiet none however long."""
    grid = ("--grid", "temperature=30:41.5:0.1", "--duration", "0.5")  # ~0.5 s of work
    quick = _cli("sweep", "li2009-model-i", *grid, "-o", tmp_path / "a.csv", interval=30)
    assert quick.returncode == 0 and quick.stderr == "", quick.stderr
    quiet = _cli("sweep", "li2009-model-i", *grid, "-q", "-o", tmp_path / "b.csv", interval=0.01)
    assert quiet.returncode == 0 and quiet.stderr == "", quiet.stderr
    shown = _cli("sweep", "li2009-model-i", *grid, "-o", tmp_path / "c.csv", interval=0.01)
    assert _progress_lines(shown.stderr, "sweep"), shown.stderr  # the same work, with lines: the two above count


def test_synth_in_a_pipe_counts_experiments(tmp_path):
    r = _cli("synth", "li2009-model-i", "--temperatures", "30,32,34,36,38,40", "--duration", "1",
             "--sample-rate", "20000", "-o", tmp_path / "d", interval=0.05)
    assert r.returncode == 0, r.stderr
    lines = _progress_lines(r.stderr, "synth")
    assert lines and all(re.search(r"(\d+) of 6 experiments", x) for x in lines), r.stderr
    assert not ANSI.search(r.stderr)


@pytest.mark.parametrize("value", ["0", "-1", "soon", "nan", "inf"])
def test_a_bad_interval_is_one_message_naming_the_variable(tmp_path, value):
    r = _cli("sweep", "li2009-model-i", "--grid", "temperature=30:31:1", "--duration", "0.1", "-o",
             tmp_path / "s.csv", interval=value)
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert len(r.stderr.splitlines()) == 1 and INTERVAL_ENV in r.stderr and repr(value) in r.stderr, r.stderr
    assert not (tmp_path / "s.csv").exists()


def test_the_plain_line_and_its_estimate(monkeypatch):
    """The line's arithmetic: what, how far, the time so far and the time left from the rate so far."""
    from thermofriction import _progress
    from thermofriction._progress import Progress
    monkeypatch.setenv(INTERVAL_ENV, "1000")  # no line from the clock during this test
    p = Progress("propagate", 1000, "draws", stream=io.StringIO(), terminal=False)
    try:
        t0 = p._t0
        assert p.line(t0 + 3) == "thermofriction: propagate: 0 of 1,000 draws (0 %) in 3 s, time left not known yet"
        p.count(250)
        assert p.line(t0 + 100) == ("thermofriction: propagate: 250 of 1,000 draws (25 %) in 1 min 40 s, "
                                    "about 5 min 0 s left")
        p.stage("reading big.csv")
        assert p.line(t0 + 7300).startswith("thermofriction: propagate: reading big.csv; 250 of 1,000 draws (25 %) "
                                             "in 2 h 1 min, about 6 h 5 min left")
    finally:
        p.stop()
    assert p._stream.getvalue() == ""
    assert _progress.duration(0.4) == "under 1 s"


def test_lines_come_from_the_clock_while_a_stage_lasts_and_stop_with_the_work(monkeypatch):
    """A stage that lasts several intervals without a call gets a line per interval; none after stop()."""
    from thermofriction._progress import Progress
    monkeypatch.setenv(INTERVAL_ENV, "0.05")
    out = io.StringIO()
    with Progress("identify", stream=out, terminal=False) as p:
        p.stage("Model I: per-temperature fits")
        time.sleep(0.5)
    n = len(out.getvalue().splitlines())
    time.sleep(0.2)
    assert len(out.getvalue().splitlines()) == n and 3 <= n <= 11, out.getvalue()
    assert out.getvalue().splitlines()[0].startswith("thermofriction: identify: Model I: per-temperature fits; ")
