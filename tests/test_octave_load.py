"""The MATLAB/Octave friction loop with a law of the load (matlab/thermofriction_mex.c: friction and observer's
optional trailing load; +thermofriction/friction_step.m, observer_step.m), under Octave: held against
``control.friction_steps`` (tf_rt_step on the model the package builds itself) bit for bit, as tests/test_octave.py
holds the load-free loop. Skipped where Octave is not installed (a failure on CI, as there)."""
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.control import friction_steps
from thermofriction.fmu import NoWindowsBinaryWarning

sys.path.insert(0, str(Path(__file__).parent))
from test_estimator_load import HIGH, LOW, joint_model  # noqa: E402
from test_octave import _octave_doubles, fmu, octave  # noqa: E402,F401  (fixtures)


@pytest.fixture(scope="module")
def joint_fmu(tmp_path_factory):
    path = tmp_path_factory.mktemp("octave_load") / "joint.fmu"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NoWindowsBinaryWarning)
        tf.export_fmu(joint_model(), path, temperature=35.0, load=LOW)
    return path


def test_octave_friction_loop_at_a_switching_load_is_python_friction_steps_bit_for_bit(octave, joint_fmu, tmp_path):
    """A joint whose fc and fs follow laws of temperature and load torque (tests/test_estimator_load.py), its load
    switching between 10 and 40 N m every 50 steps: thermofriction.friction_step called once per period with that
    load gives the bits of control.friction_steps at the same loads; called with the whole vectors, the same; the
    observer at gain 0 is the model's own friction at the load (to 1e-12 of its range, as without a load); and
    the load changes the force (the steps at a constant 10 N m differ by over a tenth of the range)."""
    model = joint_model()
    dt, n = 1e-4, 400
    v = 0.5 * np.sin(2 * np.pi * 25 * np.arange(n) * dt)
    load = np.where((np.arange(n) // 50) % 2, HIGH, LOW)
    np.column_stack([v, load]).tofile(tmp_path / "in.bin")  # interleaved: (v, load) per sample
    Y = _octave_doubles(octave, f"x = reshape(fread(fopen('{tmp_path / 'in.bin'}'), Inf, 'double'), 2, []).'; "
                        "v = x(:, 1); L = x(:, 2); "
                        f"m = thermofriction.load_model('{joint_fmu}'); F = zeros(size(v)); "
                        f"for k = 1:numel(v), F(k) = thermofriction.friction_step(m, v(k), 35.0, {dt!r}, L(k)); end; "
                        "thermofriction.reset_friction(m); "
                        f"W = thermofriction.friction_step(m, v, 35.0, {dt!r}, L); "
                        "thermofriction.reset_friction(m); "
                        f"G = thermofriction.observer_step(m, v, 1e-6, 0, 35.0, {dt!r}, L); Y = [F, W, G]; "
                        "thermofriction.close_model(m)", tmp_path / "Y.bin", tmp_path)
    expected, _ = friction_steps(model, v, dt, temperature=35.0, load=load)
    blind, _ = friction_steps(model, v, dt, temperature=35.0, load=LOW)
    scale = np.ptp(expected)
    assert np.max(np.abs(blind - expected)) > 0.1 * scale
    assert np.array_equal(Y[:, 0], expected) and np.array_equal(Y[:, 1], expected)
    np.testing.assert_allclose(Y[:, 2], expected, rtol=0, atol=1e-12 * scale)


def test_octave_needs_the_load_of_a_law_of_the_load_and_a_load_free_model_ignores_it(octave, joint_fmu, fmu,
                                                                                     tmp_path):
    """Without a load, the joint's step is refused naming the load; a load of the wrong length is refused naming
    it; the load-free li2009 model gives the same bits with or without a load."""
    out = octave(f"m = thermofriction.load_model('{joint_fmu}'); "
                 "try, thermofriction.friction_step(m, 1e-3, 35.0, 1e-4); catch e, disp(e.message); end; "
                 "try, thermofriction.friction_step(m, [1e-3 2e-3 3e-3], 35.0, 1e-4, [10 20]); "
                 "catch e, disp(e.message); end; thermofriction.close_model(m); "
                 f"m = thermofriction.load_model('{fmu}'); a = thermofriction.friction_step(m, [1e-3 2e-3], 35.7, "
                 "1e-4); thermofriction.reset_friction(m); b = thermofriction.friction_step(m, [1e-3 2e-3], 35.7, "
                 "1e-4, 80); disp(isequal(a, b)); thermofriction.close_model(m)", tmp_path)
    lines = out.strip().splitlines()
    assert len(lines) == 3, out
    assert "step 1" in lines[0] and "load (not finite: the model has a law of the load)" in lines[0], lines[0]
    assert "load must have one value per sample (3) or one, got 2" in lines[1], lines[1]
    assert lines[2].strip() == "1"
