"""FMI 2.0 co-simulation FMUs (thermofriction.fmu, core/fmu/fmi2_cs.c and fmu_common.c), tested with fmpy -- an FMI
importer no one here wrote -- as the client: it validates each FMU, instantiates it, drives it and reads
its outputs. The reference is ``tf.simulate`` on the same input (the same piecewise-linear signal)."""

from __future__ import annotations

import shutil
import subprocess
import sys

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, defaultCallbacks  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

import thermofriction as tf  # noqa: E402
from thermofriction.fmu import binary_path, export_fmu  # noqa: E402

pytestmark = pytest.mark.skipif(not binary_path().is_file(), reason="no FMU binary (Linux x86-64 only)")


class Run:
    """One FMU instance driven step by step through fmpy's FMI 2 API: the drive (and temperature) set
    at each communication point with its slope over the coming step (fmi2SetRealInputDerivatives), so
    that the FMU sees the same piecewise-linear signal as tf.simulate's Sampled input."""

    def __init__(self, path, tmp_path, start_values=None, tolerance=1e-6):
        self.md = read_model_description(str(path))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.dir = extract(str(path), unzipdir=str(tmp_path / path.stem))
        self.messages = []
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName="test")
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        self.callbacks.allocateMemory = defaultCallbacks.allocateMemory
        self.callbacks.freeMemory = defaultCallbacks.freeMemory
        self.fmu.instantiate(loggingOn=True, callbacks=self.callbacks)
        self.fmu.setupExperiment(tolerance=tolerance, startTime=0.0)
        self.fmu.enterInitializationMode()
        for name, value in (start_values or {}).items():
            self.set(name, value)

    def _log(self, component, instance, status, category, message):
        self.messages.append((status, category.decode(), message.decode()))

    def set(self, name, value):
        self.fmu.setReal([self.vr[name]], [float(value)])

    def get(self, *names):
        return self.fmu.getReal([self.vr[n] for n in names])

    def drive(self, t, inputs, outputs):
        """inputs: name -> values on the grid t; returns name -> values of the outputs on t."""
        for name, values in inputs.items():
            self.set(name, values[0])
        self.fmu.exitInitializationMode()
        out = np.empty((len(t), len(outputs)))
        out[0] = self.get(*outputs)
        for k in range(len(t) - 1):
            h = t[k + 1] - t[k]
            for name, values in inputs.items():
                self.set(name, values[k])
                self.fmu.setRealInputDerivatives([self.vr[name]], [1], [(values[k + 1] - values[k]) / h])
            self.fmu.doStep(currentCommunicationPoint=t[k], communicationStepSize=h)
            out[k + 1] = self.get(*outputs)
        return {name: out[:, i] for i, name in enumerate(outputs)}

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def _export(model, tmp_path, name):
    path = tmp_path / f"{name}.fmu"
    export_fmu(model, path)
    return path


def _assert_close(got, want, what, share=1e-3):
    """Within `share` of the reference's range (0.1 %: the issue's criterion)."""
    scale = np.ptp(want)
    assert scale > 0, what
    err = np.max(np.abs(got - want))
    assert err <= share * scale, f"{what}: max error {err:.3g} is {err / scale:.2%} of the range {scale:.3g}"


def _mass_lugre():
    """A mass under a sine force with LuGre friction: parameters away from every preset."""
    return tf.Model(plant=tf.MassPlant(mass=0.35), name="mass-lugre",
                    friction=tf.LuGre(sigma0=3.0e4, sigma1=0.8, sigma2=0.6, fc=1.3, fs=1.75, vs=4e-3))


def _prescribed_gms():
    return tf.Model(plant=tf.PrescribedMotion(), name="prescribed-gms",
                    friction=tf.GMS(k=(1.2e5, 6.0e4, 4.5e4), w=(0.25, 0.35, 0.4), C=15.0, fc=0.8, fs=1.1,
                                    vs=1.5e-3))


@pytest.mark.parametrize("preset, T", [("li2009-model-i", 35.0), ("li2009-model-ii", 38.2)])
def test_stick_slip_matches_simulate(preset, T, tmp_path):
    """Independent client: fmpy drives the FMU over two sawtooth cycles (stick-slip, Model I and II);
    displacement, velocity, friction force and stage displacement agree with tf.simulate on the same
    input to 0.1 % of their ranges."""
    model = tf.load_model(preset)
    path = _export(model, tmp_path, preset)
    assert validate_fmu(str(path)) == []
    t = np.arange(4001) * 1e-4
    u = tf.Sawtooth(amplitude=30.0, frequency=5.0, rise=0.999)(t)
    run = Run(path, tmp_path, {"temperature": T})
    names = ["displacement", "velocity", "friction_force", "stage_displacement"]
    got = run.drive(t, {"voltage": u}, names)
    run.close()
    ref = tf.simulate(model, input=tf.Sampled(t, u), t_eval=t, temperature=T)
    for name in names:
        _assert_close(got[name], getattr(ref, name), f"{preset} {name}")


def test_mass_lugre_and_prescribed_gms_match_simulate(tmp_path):
    """Independent client: a mass with LuGre under a sine force, and a prescribed sine motion with GMS
    (its stick/slip switches located inside the FMU's steps), agree with tf.simulate to 0.1 % of range."""
    t = np.arange(1001) * 1e-3
    cases = [(_mass_lugre(), "force", 2.2 * np.sin(2 * np.pi * 2.0 * t)),
             (_prescribed_gms(), "motion", 2e-5 * np.sin(2 * np.pi * 1.0 * t))]
    for model, drive, u in cases:
        path = _export(model, tmp_path, model.name)
        assert validate_fmu(str(path)) == []
        run = Run(path, tmp_path)
        got = run.drive(t, {drive: u}, ["displacement", "velocity", "friction_force"])
        run.close()
        ref = tf.simulate(model, input=tf.Sampled(t, u), t_eval=t)
        want = {name: getattr(ref, name) for name in got}
        if drive == "motion":  # after a step the FMU reports the slope of that step, simulate of the next one
            want["velocity"] = np.concatenate([[0.0], ref.velocity[:-1]])
        for name in got:
            _assert_close(got[name], want[name], f"{model.name} {name}")


def test_tunable_parameter_changes_the_result(tmp_path):
    """A tunable parameter (the Coulomb level fc) set between runs: the FMU then matches tf.simulate of
    the model with that value, and no longer the original."""
    model = _mass_lugre()
    path = _export(model, tmp_path, "tunable")
    t = np.arange(501) * 1e-3
    u = 2.2 * np.sin(2 * np.pi * 2.0 * t)
    results = {}
    for fc in (1.3, 1.05):
        run = Run(path, tmp_path, {"friction.fc": fc})
        results[fc] = run.drive(t, {"force": u}, ["displacement"])["displacement"]
        run.close()
    changed = tf.simulate(model.with_friction(fc=1.05), input=tf.Sampled(t, u), t_eval=t).displacement
    _assert_close(results[1.05], changed, "fc = 1.05")
    assert np.max(np.abs(results[1.3] - changed)) > 0.05 * np.ptp(changed)


def test_parameter_changed_during_run_and_refused_values(tmp_path):
    """In step mode a tunable parameter changes the friction from the next step on; a value out of the
    model's domain (fc < 0) is refused with fmi2Error and a logged message, the old value kept."""
    model = _mass_lugre()
    run = Run(_export(model, tmp_path, "midrun"), tmp_path)
    run.set("force", 3.0)
    run.fmu.exitInitializationMode()
    for k in range(300):  # 6 s: ten times the time constant m / sigma2 of the approach to steady sliding
        run.fmu.doStep(k * 0.02, 0.02)
    v0 = run.get("velocity")[0]
    with pytest.raises(Exception, match="fmi2SetReal"):
        run.set("friction.fc", -1.0)
    assert any(status == 3 and "fc" in message for status, _, message in run.messages)
    run.set("friction.sigma2", 6.0)  # ten times the viscous friction: the steady velocity falls
    for k in range(300, 400):
        run.fmu.doStep(k * 0.02, 0.02)
    v1 = run.get("velocity")[0]
    # steady sliding: 3 N = fc + sigma2 v -> v = (3 - 1.3) / sigma2
    assert v0 == pytest.approx((3.0 - 1.3) / 0.6, rel=1e-3)
    assert v1 == pytest.approx((3.0 - 1.3) / 6.0, rel=1e-3)
    run.close()


def test_temperature_ramp(tmp_path):
    """Model I under a temperature ramp 30 -> 41 C fed as the FMU's input (with its slope) agrees with
    tf.simulate given the same temperature signal."""
    model = tf.load_model("li2009-model-i")
    path = _export(model, tmp_path, "ramp")
    t = np.arange(4001) * 1e-4
    u = tf.Sawtooth(amplitude=30.0, frequency=5.0, rise=0.999)(t)
    T = 30.0 + 11.0 * t / t[-1]
    run = Run(path, tmp_path)
    got = run.drive(t, {"voltage": u, "temperature": T}, ["displacement", "friction_force"])
    run.close()
    ref = tf.simulate(model, input=tf.Sampled(t, u), t_eval=t, temperature=tf.Sampled(t, T))
    for name in got:
        _assert_close(got[name], getattr(ref, name), f"ramp {name}")


def test_bad_inputs_give_error_status_not_a_crash(tmp_path):
    """NaN drive or temperature: fmi2Error with a logged message, the state untouched and the instance
    still usable; a temperature outside the laws' range: a logged warning, the step done."""
    run = Run(_export(tf.load_model("li2009-model-i"), tmp_path, "bad"), tmp_path, {"temperature": 35.0})
    run.fmu.exitInitializationMode()
    run.set("voltage", 10.0)
    run.fmu.doStep(0.0, 1e-4)
    before = run.get("displacement", "velocity")
    for name in ("voltage", "temperature"):
        with pytest.raises(Exception):
            run.set(name, float("nan"))
        assert run.messages[-1][0] == 3 and "not finite" in run.messages[-1][2]
    assert run.get("displacement", "velocity") == before
    run.fmu.doStep(1e-4, 1e-4)  # still running
    run.set("temperature", 45.0)
    run.fmu.doStep(2e-4, 1e-4)
    assert run.messages[-1][0] == 1 and "outside the laws' calibrated range" in run.messages[-1][2]
    run.close()


def test_state_save_and_restore(tmp_path):
    """fmi2GetFMUstate / fmi2SetFMUstate: rerunning from a saved state reproduces the run exactly."""
    run = Run(_export(_prescribed_gms(), tmp_path, "state"), tmp_path)
    run.fmu.exitInitializationMode()

    def go(k0, k1):
        out = []
        for k in range(k0, k1):
            t = k * 1e-3
            run.set("motion", 2e-5 * np.sin(2 * np.pi * t))
            run.fmu.setRealInputDerivatives([run.vr["motion"]], [1], [2e-5 * 2 * np.pi * np.cos(2 * np.pi * t)])
            run.fmu.doStep(t, 1e-3)
            out.append(run.get("friction_force")[0])
        return out

    go(0, 300)
    state = run.fmu.getFMUstate()
    first = go(300, 700)
    run.fmu.setFMUstate(state)
    assert go(300, 700) == first
    run.fmu.freeFMUstate(state)
    run.close()


def test_simulate_fmu_end_to_end(tmp_path):
    """fmpy's own simulate_fmu (its master algorithm, inputs held over each step) runs the exported
    Model II FMU; with a fine step it stays within 1 % of range of tf.simulate with the smooth input."""
    model = tf.load_model("li2009-model-ii")
    path = _export(model, tmp_path, "end-to-end")
    t = np.arange(2001) * 1e-4
    wave = tf.Sawtooth(amplitude=30.0, frequency=5.0, rise=0.999)
    signal = np.array(list(zip(t, wave(t))), dtype=[("time", float), ("voltage", float)])
    res = fmpy.simulate_fmu(str(path), stop_time=0.2, output_interval=1e-5, input=signal,
                            start_values={"temperature": 33.0}, output=["displacement"])
    ref = tf.simulate(model, input=wave, t_eval=res["time"], temperature=33.0)
    _assert_close(res["displacement"], ref.displacement, "simulate_fmu displacement", share=1e-2)


def test_binary_needs_only_libc_and_libm(tmp_path):
    """The .so inside an FMU links libc and libm only and exports the fmi2 and fmi3 APIs only."""
    readelf, nm = shutil.which("readelf"), shutil.which("nm")
    if not (readelf and nm):
        pytest.skip("binutils not installed")
    path = _export(tf.load_model("canudas1995"), tmp_path, "deps")
    so = next((tmp_path / "unzipped").glob("*")) if False else None
    import zipfile
    with zipfile.ZipFile(path) as z:
        name = next(n for n in z.namelist() if n.startswith("binaries/linux64/") and n.endswith(".so"))
        so = tmp_path / "fmu.so"
        so.write_bytes(z.read(name))
    needed = subprocess.run([readelf, "-d", str(so)], capture_output=True, text=True, check=True).stdout
    libs = {line.split("[")[1].split("]")[0] for line in needed.splitlines() if "(NEEDED)" in line}
    assert libs <= {"libc.so.6", "libm.so.6"} and "libc.so.6" in libs, libs
    symbols = subprocess.run([nm, "-D", "--defined-only", str(so)], capture_output=True, text=True, check=True).stdout
    exported = {line.split()[-1] for line in symbols.splitlines() if line.split()[1:2] in (["T"], ["D"], ["B"])}
    assert exported and all(s.startswith(("fmi2", "fmi3")) for s in exported), sorted(exported)[:10]


def test_unexportable_model_refused(tmp_path):
    """A heat model with a sampled external heat (samples baked in) is refused with a message naming
    [heat] P_ext, in Python and on the command line (exit 2, no file written)."""
    model = tf.load_model("li2009-self-heating")
    heated = tf.Model(plant=model.plant, friction=model.friction, thermal=model.thermal,
                      heat=tf.Heat(heat_capacity=0.0015, thermal_resistance=2e4, ambient_temperature=30.0,
                                   external_heat=tf.Sampled(np.array([0.0, 1.0]), np.array([0.0, 1e-4]))))
    with pytest.raises(tf.InputError, match=r"\[heat\] P_ext"):
        export_fmu(heated, tmp_path / "x.fmu")
    assert not (tmp_path / "x.fmu").exists()
    model_file = tmp_path / "heated.toml"
    heated.save(model_file)
    out = subprocess.run([sys.executable, "-m", "thermofriction", "fmu", str(model_file), "-o",
                          str(tmp_path / "y.fmu")], capture_output=True, text=True)
    assert out.returncode == 2 and "P_ext" in out.stderr and "Traceback" not in out.stderr
    assert not (tmp_path / "y.fmu").exists()


def test_cli_exports_a_valid_fmu(tmp_path):
    """`thermofriction fmu MODEL -o FILE` writes an FMU that fmpy validates, with a heat model's
    temperature as an output and the ambient temperature as an input."""
    path = tmp_path / "heated.fmu"
    out = subprocess.run([sys.executable, "-m", "thermofriction", "fmu", "li2009-self-heating", "-o", str(path)],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    causality = {v.name: v.causality for v in md.modelVariables}
    assert causality["ambient_temperature"] == "input" and causality["temperature"] == "output"
    assert causality["heat.C_th"] == "parameter"


# ---- the fixed-step real-time integrator (export_fmu(..., solver="realtime", step=...)) ----
#
# Its tolerance: the method is first order (the friction's exponential Euler step with the sliding
# velocity held over a step, the plant's semi-implicit Euler, the drive held at each step's start), so
# its global error is proportional to omega * step, omega the model's fastest mode: the larger of the
# plant's natural frequency and the bristle frequency sqrt(sigma0 / m) of the driven mass. The tests
# ask for an error below omega * step of each output's range (about 0.7 of that is seen for the friction
# force, the output that moves fastest), and that halving the step halves the error (first order,
# converging to tf.simulate's adaptive solution).


def _realtime(model, tmp_path, name, step):
    path = tmp_path / f"{name}.fmu"
    export_fmu(model, path, solver="realtime", step=step)
    return path


def _relative_errors(got, ref):
    return {name: np.max(np.abs(got[name] - getattr(ref, name))) / np.ptp(getattr(ref, name)) for name in got}


def test_realtime_stick_slip_converges_to_simulate(tmp_path):
    """Independent client and reference: fmpy drives the real-time FMU (Model I stick-slip, 35 C) over two
    sawtooth cycles; every output is within omega * step of its range from tf.simulate's adaptive
    solution, omega = max(wn, sqrt(sigma0(T) / m_e)), and at half the step the error halves (first order)."""
    model = tf.load_model("li2009-model-i")
    T = 35.0
    t = np.arange(4001) * 1e-4
    u = tf.Sawtooth(amplitude=30.0, frequency=5.0, rise=0.999)(t)
    ref = tf.simulate(model, input=tf.Sampled(t, u), t_eval=t, temperature=T)
    sigma0 = model.laws["sigma0"](T)
    omega = max(model.plant.modal_parameters()[1], np.sqrt(sigma0 / model.plant.end_effector_mass))
    names = ["displacement", "velocity", "friction_force", "stage_displacement"]
    errors = {}
    for step in (1e-5, 5e-6):
        path = _realtime(model, tmp_path, f"rt{step:g}", step)
        assert validate_fmu(str(path)) == []
        run = Run(path, tmp_path, {"temperature": T})
        errors[step] = _relative_errors(run.drive(t, {"voltage": u}, names), ref)
        run.close()
        for name, err in errors[step].items():
            assert err <= omega * step, f"step {step:g} s, {name}: {err:.3g} of range > omega step = {omega * step:.3g}"
    for name in names:
        ratio = errors[1e-5][name] / errors[5e-6][name]
        assert 1.6 < ratio < 2.5, f"{name}: halving the step divided the error by {ratio:.2f}, not about 2"


def test_realtime_mass_lugre_matches_simulate(tmp_path):
    """Independent reference: a mass with LuGre under a sine force through the real-time FMU, within
    omega * step of range of tf.simulate (omega = sqrt(sigma0 / m), the bristle frequency)."""
    model = _mass_lugre()
    step = 1e-4
    t = np.arange(1001) * 1e-3
    u = 2.2 * np.sin(2 * np.pi * 2.0 * t)
    run = Run(_realtime(model, tmp_path, "rt-mass", step), tmp_path)
    got = run.drive(t, {"force": u}, ["displacement", "velocity", "friction_force"])
    run.close()
    ref = tf.simulate(model, input=tf.Sampled(t, u), t_eval=t)
    omega = np.sqrt(model.friction.sigma0 / model.plant.mass)
    for name, err in _relative_errors(got, ref).items():
        assert err <= omega * step, f"{name}: {err:.3g} of range > omega step = {omega * step:.3g}"


def test_realtime_matches_the_cores_realtime_api(tmp_path):
    """Independent path: a prescribed sine motion with GMS through the real-time FMU (ten fixed steps per
    communication step) gives the friction force that the core's real-time API, driven from Python with
    the same sliding velocities (thermofriction.control.friction_steps, tf_rt_step), gives -- to rounding
    (1e-12 of range)."""
    from thermofriction.control import friction_steps

    model = _prescribed_gms()
    step, per = 1e-4, 10
    t = np.arange(1001) * (step * per)
    u = 2e-5 * np.sin(2 * np.pi * 1.0 * t) + 5e-6 * np.sin(2 * np.pi * 3.7 * t)
    run = Run(_realtime(model, tmp_path, "rt-gms", step), tmp_path)
    got = run.drive(t, {"motion": u}, ["friction_force"])["friction_force"]
    run.close()
    F, _ = friction_steps(model, np.repeat(np.diff(u) / (step * per), per), step)
    want = F[per - 1::per]  # the force after each communication step's last fixed step
    assert np.max(np.abs(got[1:] - want)) <= 1e-12 * np.ptp(want)


def test_realtime_step_not_a_divisor_of_the_communication_step(tmp_path):
    """A communication step that is not a whole number of fixed steps (1 ms with 0.3 ms steps): the last
    step is shortened, the FMU's time lands on each communication point (fmpy's clock check in doStep
    passes) and the result stays within omega * step of tf.simulate (mass with LuGre)."""
    model = _mass_lugre()
    step = 3e-4
    t = np.arange(401) * 1e-3
    u = 2.2 * np.sin(2 * np.pi * 2.0 * t)
    run = Run(_realtime(model, tmp_path, "rt-odd", step), tmp_path)
    got = run.drive(t, {"force": u}, ["displacement", "velocity"])
    assert run.fmu.getRealStatus(2) == pytest.approx(t[-1], abs=1e-12)  # fmi2LastSuccessfulTime
    run.close()
    ref = tf.simulate(model, input=tf.Sampled(t, u), t_eval=t)
    omega = np.sqrt(model.friction.sigma0 / model.plant.mass)
    for name, err in _relative_errors(got, ref).items():
        assert err <= omega * step, f"{name}: {err:.3g} of range > omega step = {omega * step:.3g}"


def test_realtime_choice_in_the_model_description(tmp_path):
    """The real-time FMU declares its step as a fixed parameter integrator.step [s] with the exported
    value, names the integrator in its description and proposes a whole number of steps as default
    communication step; the adaptive FMU has no such parameter."""
    path = _realtime(_mass_lugre(), tmp_path, "rt-md", 2.5e-5)
    md = read_model_description(str(path))
    step = next(v for v in md.modelVariables if v.name == "integrator.step")
    assert (step.causality, step.variability, float(step.start), step.unit) == ("parameter", "fixed", 2.5e-5, "s")
    assert "fixed-step real-time integrator, step 2.5e-05 s" in md.description
    n = float(md.defaultExperiment.stepSize) / 2.5e-5
    assert n == pytest.approx(round(n)) and round(n) >= 1
    adaptive = read_model_description(str(_export(_mass_lugre(), tmp_path, "adaptive-md")))
    assert all(v.name != "integrator.step" for v in adaptive.modelVariables)
    assert "adaptive integrator" in adaptive.description


@pytest.mark.parametrize("kwargs, message", [
    ({"solver": "realtime", "step": 0.0}, "positive"),
    ({"solver": "realtime", "step": -1e-5}, "positive"),
    ({"solver": "realtime", "step": float("nan")}, "positive"),
    ({"solver": "realtime", "step": "fast"}, r"step must be a number \[s\]"),
    ({"solver": "realtime"}, "needs its fixed step"),
    ({"solver": "realtime", "step": 1e-3}, "unstable"),  # li2009: wn = 6686 rad/s, 2 / wn = 0.3 ms
    ({"step": 1e-5}, "realtime solver's fixed step"),
    ({"solver": "euler", "step": 1e-5}, "adaptive, realtime"),
])
def test_bad_step_refused_at_export(kwargs, message, tmp_path):
    """Bad solver or step values: an InputError naming them, no file written."""
    with pytest.raises(tf.InputError, match=message):
        export_fmu(tf.load_model("li2009-model-i"), tmp_path / "bad.fmu", **kwargs)
    assert not (tmp_path / "bad.fmu").exists()


def test_cli_realtime_export_and_bad_steps(tmp_path):
    """`thermofriction fmu ... --solver realtime --step 1e-5` writes a valid FMU; bad steps (0, unstable,
    --step without the realtime integrator) exit with status 2, one message, no file."""
    path = tmp_path / "rt.fmu"
    cmd = [sys.executable, "-m", "thermofriction", "fmu", "li2009-model-ii", "-o"]
    out = subprocess.run(cmd + [str(path), "--solver", "realtime", "--step", "1e-5"], capture_output=True,
                         text=True)
    assert out.returncode == 0, out.stderr
    assert validate_fmu(str(path)) == [] and "fixed step 1e-05 s" in out.stdout
    for extra in (["--solver", "realtime", "--step", "0"], ["--solver", "realtime", "--step", "1e-3"],
                  ["--step", "1e-5"]):
        bad = tmp_path / "bad.fmu"
        out = subprocess.run(cmd + [str(bad)] + extra, capture_output=True, text=True)
        assert out.returncode == 2 and "step" in out.stderr and "Traceback" not in out.stderr, (extra, out.stderr)
        assert not bad.exists()


def test_bad_step_refused_inside_the_fmu(tmp_path):
    """Inside the FMU: integrator.step set to 0, a negative value or NaN before initialisation gives
    fmi2Error with a logged message and keeps the old step; after initialisation the step is fixed. A
    valid new step (half the exported one) is taken: the run then matches an FMU exported with it."""
    model = _mass_lugre()
    path = _realtime(model, tmp_path, "rt-bad", 2e-4)
    run = Run(path, tmp_path)
    for value in (0.0, -1e-4, float("nan")):
        with pytest.raises(Exception):
            run.set("integrator.step", value)
        status, _, message = run.messages[-1]
        assert status == 3 and ("integrator.step" in message or "not finite" in message), message
    assert run.get("integrator.step") == [2e-4]
    run.set("integrator.step", 1e-4)
    t = np.arange(201) * 1e-3
    u = 2.2 * np.sin(2 * np.pi * 2.0 * t)
    got = run.drive(t, {"force": u}, ["displacement"])["displacement"]
    with pytest.raises(Exception, match="fmi2SetReal"):
        run.set("integrator.step", 5e-5)
    assert "fixed" in run.messages[-1][2]
    run.close()
    other = Run(_realtime(model, tmp_path, "rt-1e-4", 1e-4), tmp_path)
    want = other.drive(t, {"force": u}, ["displacement"])["displacement"]
    other.close()
    assert np.array_equal(got, want)


# ---------------------------------------------------------------------------------------------
# Issue 32 (items 3 and 4): entry points that returned fmi2OK for what they could not do, or crashed
# ---------------------------------------------------------------------------------------------

def _refused(run, call, *words):
    """``call`` raises (fmi2Error) and the last logged message is an error naming each of ``words``."""
    with pytest.raises(Exception):
        call()
    status, _, message = run.messages[-1]
    assert status == 3, message
    for word in words:
        assert word in message, message
    return message


def test_realtime_step_count_that_cannot_be_taken_is_refused(tmp_path):
    """The real-time FMU counted its fixed steps as (long)floor(h / step), undefined (it overflowed) for
    doStep(t, 1e300) and for every ordinary step once integrator.step was 1e-300: it answered fmi2OK,
    integrated nothing and moved its clock. Now such a step is refused with fmi2Error and a message, the
    clock and the outputs stay, and an ordinary step afterwards runs."""
    model = _mass_lugre()
    path = _realtime(model, tmp_path, "rt-count", 1e-4)
    run = Run(path, tmp_path)
    run.set("force", 2.0)
    run.fmu.exitInitializationMode()
    _refused(run, lambda: run.fmu.doStep(0.0, 1e300), "1e+300")
    _refused(run, lambda: run.fmu.doStep(0.0, 1e11), "fixed steps", "integrator.step")  # 1e15 steps
    assert run.fmu.getRealStatus(2) == 0.0  # fmi2LastSuccessfulTime: the clock did not move
    run.fmu.doStep(0.0, 1e-3)
    assert run.get("velocity")[0] > 0.0  # 2 N against fs = 1.75 N: the mass moves
    run.close()

    tiny = Run(path, tmp_path, {"integrator.step": 1e-300})
    tiny.set("force", 2.0)
    tiny.fmu.exitInitializationMode()
    _refused(tiny, lambda: tiny.fmu.doStep(0.0, 1e-3), "fixed steps", "integrator.step = 1e-300")
    assert tiny.fmu.getRealStatus(2) == 0.0 and tiny.get("displacement", "velocity") == [0.0, 0.0]
    tiny.close()


def test_undeclared_value_references_and_a_wrong_guid_are_refused(tmp_path):
    """Value references the model description does not declare (7-15 here, an unused parameter number,
    the temperature output of a model without a heat balance) gave fmi2OK for getReal and setReal; a
    wrong GUID was instantiated. Both are refused now, with a message."""
    path = _export(_mass_lugre(), tmp_path, "undeclared")
    run = Run(path, tmp_path)
    declared = {v.valueReference for v in run.md.modelVariables}
    for vr in (1, 5, 6, 7, 9, 15, max(declared) + 1, 2047, 5000):
        assert vr not in declared
        _refused(run, lambda: run.fmu.getReal([vr]), str(vr), "not a variable")
        _refused(run, lambda: run.fmu.setReal([vr], [1.0]), str(vr))
    run.fmu.exitInitializationMode()
    assert len(run.fmu.getReal(sorted(declared))) == len(declared)  # the declared ones still read
    run.close()

    md = read_model_description(str(path))
    unzipped = extract(str(path), unzipdir=str(tmp_path / "guid"))
    messages = []
    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(lambda c, i, s, cat, m: messages.append(m.decode()))
    cb.allocateMemory, cb.freeMemory = defaultCallbacks.allocateMemory, defaultCallbacks.freeMemory
    wrong = "{" + "0" * 8 + "-0000-0000-0000-" + "0" * 12 + "}"
    fmu = FMU2Slave(guid=wrong, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="wrong-guid")
    with pytest.raises(Exception, match="instantiate"):
        fmu.instantiate(callbacks=cb, loggingOn=True)
    assert any("GUID" in m and wrong in m and md.guid in m for m in messages), messages
    fmu.freeLibrary()


def test_start_time_and_temperatures_outside_the_packages_ranges_are_refused(tmp_path):
    """A start time of 1e300 s was accepted (a later step then blamed the sampled input); a temperature of
    -300 C was taken with a warning while the command line refuses anything outside -100 ... 300 C. Now
    fmi2SetupExperiment refuses a start beyond the core's +-1e12 s, fmi2SetReal a temperature outside
    -100 ... 300 C (its ends are taken), and fmi2DoStep a temperature ramp that leaves the range."""
    path = _export(tf.load_model("li2009-model-i"), tmp_path, "ranges")
    md = read_model_description(str(path))
    unzipped = extract(str(path), unzipdir=str(tmp_path / "start"))
    run = Run(path, tmp_path)
    for T in (-300.0, -100.5, 300.5, 1e6):
        _refused(run, lambda: run.set("temperature", T), "not a plausible temperature", "-100 to 300 C")
    for T in (-100.0, 300.0, 35.0):
        run.set("temperature", T)
    run.fmu.exitInitializationMode()
    run.set("voltage", 10.0)
    run.fmu.doStep(0.0, 1e-4)
    run.fmu.setRealInputDerivatives([run.vr["temperature"]], [1], [3e6])  # 35 C + 300 C over the step
    _refused(run, lambda: run.fmu.doStep(1e-4, 1e-4), "335 C", "not a plausible temperature")
    assert run.fmu.getRealStatus(2) == pytest.approx(1e-4)  # the clock did not move
    run.fmu.setRealInputDerivatives([run.vr["temperature"]], [1], [0.0])
    run.fmu.doStep(1e-4, 1e-4)  # held at 35 C: taken
    run.close()

    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="start")
    messages = []
    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(lambda c, i, s, cat, m: messages.append(m.decode()))
    cb.allocateMemory, cb.freeMemory = defaultCallbacks.allocateMemory, defaultCallbacks.freeMemory
    fmu.instantiate(callbacks=cb, loggingOn=True)
    for start in (1e300, -2e12):
        with pytest.raises(Exception):
            fmu.setupExperiment(startTime=start)
        assert "start time" in messages[-1] and "1e+12" in messages[-1], messages
    fmu.setupExperiment(startTime=1e6)  # within the limit: taken
    fmu.freeInstance()


def test_input_derivatives_with_null_arrays_are_refused_not_a_crash(tmp_path):
    """fmi2SetRealInputDerivatives dereferenced NULL arrays (a segmentation fault; the only entry point
    without fmi2SetReal's check). Run in a child process, so that a crash fails this test instead of
    ending the session: every NULL combination gives fmi2Error (3) and the instance still steps."""
    path = _export(_mass_lugre(), tmp_path, "null")
    script = f"""
import ctypes, sys
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
md = read_model_description({str(path)!r})
fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract({str(path)!r}, unzipdir={str(tmp_path / 'null-x')!r}),
                modelIdentifier=md.coSimulation.modelIdentifier, instanceName="null")
fmu.instantiate()
fmu.setupExperiment(startTime=0.0)
fmu.enterInitializationMode()
fmu.exitInitializationMode()
f = fmu.dll.fmi2SetRealInputDerivatives
f.restype = ctypes.c_int
f.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p]
vr, order, value = (ctypes.c_uint * 1)(0), (ctypes.c_int * 1)(1), (ctypes.c_double * 1)(1.0)
codes = [f(fmu.component, a, 1, b, c) for a, b, c in ((None, order, value), (vr, None, value), (vr, order, None),
                                                       (None, None, None))]
codes.append(f(fmu.component, None, 0, None, None))  # nothing to set: fmi2OK
fmu.doStep(0.0, 1e-3)
print(codes)
"""
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.splitlines()[-1] == "[3, 3, 3, 3, 0]", out.stdout
