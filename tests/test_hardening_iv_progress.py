"""Issue 41 (hardening IV): progress where nobody watches a terminal, and the tests that send signals run as
a background job (``nohup make test &``)."""

from __future__ import annotations

import ast
import signal
import subprocess
import sys
from pathlib import Path

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
