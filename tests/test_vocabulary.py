"""One meaning per option name and one way to give tolerances (issue: architecture III): ``method`` is the
identification method only -- the integrator is ``solver`` (simulate, sweep, simulate_heating, the CLI's
--solver) -- and tolerances are given by a StepSizeController (``controller=``). The earlier spellings still
work, each with a DeprecationWarning (Python) or a note (command line), and give the same result."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.heating import Full, TwoTimeScale, simulate_heating

from conftest import run_cli


def test_heating_solver_and_its_earlier_name_method():
    model = tf.load_model("li2009-self-heating")
    new = simulate_heating(model, 0.5, solver=Full(), samples=10)
    with pytest.warns(DeprecationWarning, match="solver="):
        old = simulate_heating(model, 0.5, method=Full(), samples=10)
    assert np.array_equal(new.temperature, old.temperature) and new.method == "full"
    with pytest.raises(tf.InputError, match="not both"):
        simulate_heating(model, 0.5, solver=Full(), method=Full())


def test_two_time_scale_tolerance_by_controller():
    assert TwoTimeScale().tolerance == 1e-8
    assert TwoTimeScale(controller=tf.StepSizeController(rtol=1e-6)).tolerance == 1e-6
    with pytest.warns(DeprecationWarning, match="controller="):
        assert TwoTimeScale(rtol=1e-5).tolerance == 1e-5


def test_identify_tolerance_by_controller():
    data = tf.synthesize(tf.load_model("li2009-base"), [35.0], duration=0.05, seed=4)
    new = tf.identify(data, "base", starts=1, controller=tf.StepSizeController(rtol=1e-7))
    with pytest.warns(DeprecationWarning, match="controller=StepSizeController"):
        old = tf.identify(data, "base", starts=1, rtol=1e-7)
    assert [p.value for p in new.parameters.values()] == [p.value for p in old.parameters.values()]
    with pytest.raises(tf.InputError, match="controller"):
        tf.identify(data, "base", controller=1e-7)


def test_cli_solver_and_its_earlier_name(tmp_path):
    a = run_cli("simulate", "li2009-base", "--temperature", "35", "--duration", "0.01", "--solver", "rodas4",
                "-o", tmp_path / "a.csv")
    b = run_cli("simulate", "li2009-base", "--temperature", "35", "--duration", "0.01", "--method", "rodas4",
                "-o", tmp_path / "b.csv")
    assert a.returncode == 0 and b.returncode == 0, (a.stderr, b.stderr)
    assert "--method is now --solver" in b.stderr and "--method" not in a.stderr
    assert (tmp_path / "a.csv").read_text() == (tmp_path / "b.csv").read_text()
    c = run_cli("simulate", "li2009-base", "--temperature", "35", "--duration", "0.01", "--method", "rodas4",
                "--solver", "dopri5")
    assert c.returncode == 2 and "contradict" in c.stderr
