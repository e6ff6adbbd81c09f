"""The MATLAB/Octave interface (matlab/, docs/matlab.md) under Octave: the MEX built with mkoctfile from
the C sources, the examples run, and its results held against the Python package's.

The same C runs on both sides (the MEX is compiled from the core's sources and core/fmu/fmu_common.c, the
package's FMU binary and its _core from the same sources), so the comparisons are bit for bit: a
simulation against the package's FMU stepped by fmpy with the same calls, and the friction loop against
`control.friction_steps` (tf_rt_step). Skipped where Octave is not installed; on CI (CI=true) its
absence is a failure (.ci/run installs octave and liboctave-dev)."""
import os
import shutil
import subprocess
import types
import warnings
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.control import friction_steps
from thermofriction.fmu import NoWindowsBinaryWarning

ROOT = Path(__file__).resolve().parents[1]
MATLAB = ROOT / "matlab"
OCTAVE = shutil.which("octave-cli") or shutil.which("octave")


@pytest.fixture(scope="module")
def octave():
    """Runs Octave code with matlab/ on the path; returns its standard output (fails on an error)."""
    if OCTAVE is None or shutil.which("mkoctfile") is None:
        if os.environ.get("CI") == "true":
            pytest.fail("octave or mkoctfile is missing: CI must install octave and liboctave-dev (.ci/run)")
        pytest.skip("Octave (octave, liboctave-dev) is not installed")

    def run(code, cwd):
        done = subprocess.run([OCTAVE, "--no-gui", "--norc", "--eval", f"addpath('{MATLAB}'); {code}"],
                              capture_output=True, text=True, cwd=cwd, timeout=300)
        # Octave 7.3 prints this at exit whenever a MEX file was loaded (an Octave bug, fixed in 8): not ours
        errors = [line for line in done.stderr.splitlines() if "ignoring const execution_exception" not in line]
        assert done.returncode == 0 and not [e for e in errors if e.startswith("error")], done.stderr
        return done.stdout

    run("thermofriction.build();", ROOT)
    return run


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    path = tmp_path_factory.mktemp("octave") / "li2009-model-i.fmu"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NoWindowsBinaryWarning)  # a package built without MinGW-w64
        tf.export_fmu("li2009-model-i", path)
    return path


def _octave_doubles(octave, code, out, cwd):
    """Runs code that leaves a matrix in Y, written as raw doubles: the bits, not a printed rounding."""
    octave(f"{code}; f = fopen('{out}', 'w'); fwrite(f, size(Y), 'double'); fwrite(f, Y, 'double'); fclose(f);",
           cwd)
    raw = np.fromfile(out, dtype="<f8")
    rows, cols = int(raw[0]), int(raw[1])
    return raw[2:].reshape(cols, rows).T


def test_octave_simulation_is_the_fmus_bit_for_bit(octave, fmu, tmp_path):
    """thermofriction.simulate in Octave and the package's FMU binary stepped from Python by fmpy with the
    same calls (inputs set at each sample, their slopes to the next one as input derivatives) give the same
    bits: the same C (fmu_common.c over tf_solve) reads the same resource file."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    t = np.arange(0, 201) * 1e-4
    u = 50 * np.sin(2 * np.pi * 100 * t)
    T = 30.0 + 200.0 * t  # a temperature ramp 30 -> 34 C: the temperature's derivative is followed too
    for name, x in (("t", t), ("u", u), ("T", T)):
        x.tofile(tmp_path / f"{name}.bin")
    load = ";".join(f"{n} = fread(fopen('{tmp_path / (n + '.bin')}'), Inf, 'double')" for n in "tuT")
    Y = _octave_doubles(octave, f"{load}; m = thermofriction.load_model('{fmu}'); "
                        "r = thermofriction.simulate(m, t, u, T); "
                        "Y = [r.displacement, r.velocity, r.friction_force, r.stage_displacement]; "
                        "thermofriction.close_model(m)", tmp_path / "Y.bin", tmp_path)

    folder = extract(str(fmu))
    md = read_model_description(folder)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="python")
    slave.instantiate()
    slave.setupExperiment(tolerance=1e-6, startTime=t[0], stopTime=t[-1])
    slave.enterInitializationMode()
    slave.setReal([0, 1], [u[0], T[0]])
    slave.exitInitializationMode()
    outputs = [2, 3, 4, 6]  # displacement, velocity, friction force, stage displacement
    rows = [slave.getReal(outputs)]
    for k in range(1, t.size):
        h = t[k] - t[k - 1]
        slave.setReal([0, 1], [u[k - 1], T[k - 1]])
        slave.setRealInputDerivatives([0, 1], [1, 1], [(u[k] - u[k - 1]) / h, (T[k] - T[k - 1]) / h])
        slave.doStep(t[k - 1], h)
        rows.append(slave.getReal(outputs))
    slave.terminate()
    slave.freeInstance()
    expected = np.array(rows)
    assert np.ptp(expected[:, 0]) > 1e-7  # the actuator moved (~um): the comparison is not of zeros
    assert np.array_equal(Y, expected)


def test_octave_simulation_agrees_with_python_simulate(octave, fmu, tmp_path):
    """Against the package's own tf.simulate (the whole run by one tf_solve, the sine input exact): agreement
    to 1e-3 of the displacement's range. Not bit for bit: Octave's run restarts the integrator at every
    sample and follows the sine by straight lines between samples 1e-5 s apart (100 Hz: a chord error
    of (2 pi 100 * 1e-5)^2 / 8 ~ 5e-6 of the amplitude), and both integrate to rtol 1e-6."""
    model = tf.load_model("li2009-model-i")
    ref = tf.simulate(model, 0.02, temperature=35.7, sample_rate=1e5)
    np.asarray(ref.time).tofile(tmp_path / "t.bin")
    np.asarray(ref.input).tofile(tmp_path / "u.bin")
    load = ";".join(f"{n} = fread(fopen('{tmp_path / (n + '.bin')}'), Inf, 'double')" for n in "tu")
    Y = _octave_doubles(octave, f"{load}; m = thermofriction.load_model('{fmu}'); "
                        "r = thermofriction.simulate(m, t, u, 35.7); Y = [r.displacement, r.friction_force]; "
                        "thermofriction.close_model(m)", tmp_path / "Y.bin", tmp_path)
    x = np.asarray(ref.displacement)
    assert np.ptp(x) > 1e-7
    assert np.max(np.abs(Y[:, 0] - x)) < 1e-3 * np.ptp(x)
    F = np.asarray(ref.friction_force)
    assert np.max(np.abs(Y[:, 1] - F)) < 1e-2 * np.ptp(F)


def test_octave_friction_loop_is_python_friction_steps_bit_for_bit(octave, fmu, tmp_path):
    """thermofriction.friction_step called once per control period in an Octave loop gives the bits of
    control.friction_steps (tf_rt_step on the model the package builds itself, not from the FMU's file):
    the parameters reach the MEX through the resource file's text without losing a bit. The observer with
    gain 0 is the model's own friction (control.h: no correction), stepped by the same exponential Euler."""
    model = tf.load_model("li2009-model-i")
    dt, n = 1e-4, 500
    v = 2e-3 * np.sin(2 * np.pi * 20 * np.arange(n) * dt)
    v.tofile(tmp_path / "v.bin")
    Y = _octave_doubles(octave, f"v = fread(fopen('{tmp_path / 'v.bin'}'), Inf, 'double'); "
                        f"m = thermofriction.load_model('{fmu}'); F = zeros(size(v)); "
                        f"for k = 1:numel(v), F(k) = thermofriction.friction_step(m, v(k), 35.7, {dt!r}); end; "
                        "thermofriction.reset_friction(m); "
                        f"G = thermofriction.observer_step(m, v, 1e-6, 0, 35.7, {dt!r}); Y = [F, G]; "
                        "thermofriction.close_model(m)", tmp_path / "Y.bin", tmp_path)
    expected, _ = friction_steps(model, v, dt, temperature=35.7)
    assert np.ptp(expected) > 0.1  # friction swings both ways (~0.4 N)
    assert np.array_equal(Y[:, 0], expected)
    np.testing.assert_allclose(Y[:, 1], expected, rtol=0, atol=1e-12 * np.ptp(expected))


def test_octave_refuses_bad_input_with_one_message(octave, fmu, tmp_path):
    """A temperature outside the model's domain, a temperature given to the wrong model, a closed handle:
    an Octave error naming the argument, not a crash."""
    out = octave(f"m = thermofriction.load_model('{fmu}'); "
                 "try, thermofriction.friction_step(m, [1e-3 NaN], 35.7, 1e-4); catch e, disp(e.message); end; "
                 "try, thermofriction.simulate(m, [0 1e-4], [0 1], []); catch e, disp(e.message); end; "
                 "thermofriction.close_model(m); "
                 "try, thermofriction.friction_step(m, 1e-3, 35.7, 1e-4); catch e, disp(e.message); end",
                 tmp_path)
    lines = out.strip().splitlines()
    assert len(lines) == 3, out
    assert "step 2" in lines[0] and "v = nan" in lines[0].lower()
    assert "takes a temperature" in lines[1]
    assert "not an open model" in lines[2]


def test_octave_runs_the_matlab_examples(octave, fmu, tmp_path):
    """Every script in matlab/examples runs under Octave and prints what it says."""
    model = tf.load_model("li2009-base")
    res = tf.simulate(model, 0.05, temperature=30.0, sample_rate=5000.0)
    exp = types.SimpleNamespace(file="T30.csv", time=res.time, voltage=res.input, temperature=30.0, role="fit",
                                displacement=res.displacement)
    fit = tf.identify([exp], method="base", init=model)
    fit.to_mat(tmp_path / "fit.mat")
    scripts = sorted((MATLAB / "examples").glob("*.m"))
    assert {s.stem for s in scripts} == {"simulate_model", "friction_loop", "read_fit_results"}
    out = {s.stem: octave(f"fmu_file = '{fmu}'; fit_file = '{tmp_path / 'fit.mat'}'; run('{s}');", tmp_path)
           for s in scripts}
    assert out["simulate_model"].count("displacement after 2 cycles") == 2
    assert "largest difference 0 N" in out["friction_loop"]
    assert "method base" in out["read_fit_results"] and "sigma0" in out["read_fit_results"]
