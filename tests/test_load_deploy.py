"""The load where models are deployed (issue 43): the FMU's load input (FMI 2 and 3, Linux and, under Wine, Windows),
the closed loop's and the compensations' loads per control period, and the sweeps' load axis.

Truths: the simulator (``tf.simulate(..., load=...)``, itself matched to the independent reference in
tests/test_load_core.py) for the FMU, driven by fmpy -- an FMI importer no one here wrote; the FMI 2 export for the
FMI 3 one and for the Windows binary; the independent scalar-Python loop (tests/reference/control.py, its laws of the
load written again in tests/reference/laws.py) for the closed loop; single simulations for the sweep's points."""

from __future__ import annotations

import os
import shutil
import subprocess
import warnings
import zipfile

import numpy as np
import pytest

import reference as R
import thermofriction as tf
from thermofriction import control as C
from thermofriction.estimation import TemperatureEstimator
from thermofriction.models import Exp, Linear, LoadLaw, LoadRangeWarning, LoadTerm

fmpy = pytest.importorskip("fmpy")
from fmpy import read_model_description  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402
from test_fmu import Run  # noqa: E402

from thermofriction.fmu import binary_path, export_fmu  # noqa: E402

needs_binary = pytest.mark.skipif(not binary_path().is_file(), reason="no FMU binary (Linux x86-64 only)")

#: |N| 30..150 N: the range the load laws were calibrated on
LOAD_RANGE = (30.0, 150.0)


def preloaded_stage(plant=None, rng=LOAD_RANGE):
    """A 0.8 kg carriage pulled through a 60 N/m spring at 0.05 m/s over a LuGre contact preloaded by a normal force
    N: fc = mu(T) |N| (proportional), fs = fs_0(T) (1 + k S tanh(|N|/S)) + c T s (affine, saturated, interacting),
    sigma0 a law of temperature only. Numbers away from every preset and from tests/test_load_core.py's."""
    fc = LoadLaw(Linear(a=-8e-5, b=0.0125), LoadTerm("proportional", range=rng))
    fs = LoadLaw(Exp(a=1.1, b=-3e-3), LoadTerm("affine", k=0.011, saturation=170.0, interaction=1.5e-5, range=rng))
    friction = tf.LuGre(sigma0=None, sigma1=250.0, sigma2=0.35, fc=None, fs=None, vs=1.2e-3)
    return tf.Model(plant or tf.MassPlant(mass=0.8, spring_stiffness=60.0, pull_velocity=0.05), friction,
                    tf.ModelI({"fc": fc, "fs": fs, "sigma0": Linear(a=-400.0, b=9.0e4)}), name="preloaded_stage")


# ---- the FMU ----------------------------------------------------------------------------------------------------

T_GRID = np.linspace(0.0, 6.0, 601)  # 10 ms communication steps
N_RAMP = np.interp(T_GRID, [0.0, 1.0, 4.5, 6.0], [45.0, 45.0, 135.0, 135.0])  # N
T_RAMP = np.interp(T_GRID, [0.0, 6.0], [25.0, 38.0])  # C


@needs_binary
def test_fmi2_fmu_with_a_load_ramp_matches_the_simulator(tmp_path):
    """Truth: tf.simulate on the same piecewise-linear normal force and temperature (the FMU is given each
    communication step's slope, fmi2SetRealInputDerivatives, so it sees the same signals). Over 6 s of stick-slip
    while N ramps 45 -> 135 N and T 25 -> 38 C, the FMU's friction force and displacement agree to 1e-3 of their
    ranges (test_fmu.py's criterion); the same FMU at a constant 45 N is far from it (the load reaches the FMU)."""
    model = preloaded_stage()
    path = tmp_path / "stage.fmu"
    export_fmu(model, path, temperature=25.0, load=45.0)
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    var = {v.name: v for v in md.modelVariables}
    N = var["normal_force"]
    assert (N.causality, N.variability, N.unit, float(N.start), N.valueReference) == ("input", "continuous", "N",
                                                                                      45.0, 12)
    assert var["thermal.fs.load.k"].unit == "1/N" and var["thermal.fs.load.interaction"].unit == "N/C/N"
    assert "thermal.fc.load.k" not in var  # a proportional term has no k
    outputs = ["friction_force", "displacement"]
    run = Run(path, tmp_path, start_values={"temperature": 25.0, "normal_force": 45.0})
    got = run.drive(T_GRID, {"force": 0 * T_GRID, "temperature": T_RAMP, "normal_force": N_RAMP}, outputs)
    run.close()
    flat = Run(path, tmp_path / "flat", start_values={"temperature": 25.0})
    held = flat.drive(T_GRID, {"force": 0 * T_GRID, "temperature": T_RAMP}, outputs)
    flat.close()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tf.PassivityWarning)
        ref = tf.simulate(model, t_eval=T_GRID, temperature=tf.Sampled(T_GRID, T_RAMP),
                          load=tf.Sampled(T_GRID, N_RAMP), controller=tf.StepSizeController(rtol=1e-9))
    for name in outputs:
        want = getattr(ref, name)
        err = np.max(np.abs(got[name] - want)) / np.ptp(want)
        print(f"FMI 2 {name}: max error / range = {err:.2e}")
        assert err <= 1e-3, (name, err)
        assert np.max(np.abs(held[name] - want)) > 0.05 * np.ptp(want), name


@needs_binary
def test_realtime_fmu_with_a_load_ramp_converges_to_the_simulator_and_the_cli_sets_the_start(tmp_path):
    """Truth: tf.simulate as above. The FMU exported with --solver realtime (the core's tf_rt_step at each fixed step,
    the load read at the step's start) converges to the simulator under the load ramp at first order, as at a
    constant load: from a 1e-4 s to a 1e-5 s step its largest friction-force error falls 10x (seen: 14 % -> 1.5 %
    of the force's range, at the slips' onsets; 16 % -> 1.6 % at a constant 90 N) and its displacement is within
    1e-4 of its range. `thermofriction fmu --load N` sets the load input's start."""
    import subprocess
    import sys
    model = preloaded_stage()
    (tmp_path / "stage.toml").write_text(model.to_toml())
    out = subprocess.run([sys.executable, "-m", "thermofriction", "fmu", "stage.toml", "-o", "rt5.fmu", "--solver",
                          "realtime", "--step", "1e-5", "--load", "45", "--temperature", "25"], cwd=tmp_path,
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    var = {v.name: v for v in read_model_description(str(tmp_path / "rt5.fmu")).modelVariables}
    assert float(var["normal_force"].start) == 45.0 and var["integrator.step"].variability == "fixed"
    export_fmu(model, tmp_path / "rt4.fmu", solver="realtime", step=1e-4, temperature=25.0, load=45.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tf.PassivityWarning)
        ref = tf.simulate(model, t_eval=T_GRID, temperature=tf.Sampled(T_GRID, T_RAMP),
                          load=tf.Sampled(T_GRID, N_RAMP), controller=tf.StepSizeController(rtol=1e-9))
    err = {}
    for name in ("rt4", "rt5"):
        run = Run(tmp_path / f"{name}.fmu", tmp_path / name, start_values={"temperature": 25.0})
        got = run.drive(T_GRID, {"force": 0 * T_GRID, "temperature": T_RAMP, "normal_force": N_RAMP},
                        ["friction_force", "displacement"])
        run.close()
        err[name] = [np.max(np.abs(got[k] - getattr(ref, k))) / np.ptp(getattr(ref, k))
                     for k in ("friction_force", "displacement")]
    print("realtime FMU, max error / range (friction force, displacement) at 1e-4, 1e-5 s:", err)
    assert err["rt5"][0] <= err["rt4"][0] / 5 and err["rt5"][1] <= 1e-4, err


@needs_binary
def test_realtime_fmu_is_the_cores_realtime_api_at_the_same_loads(tmp_path):
    """Independent path: a prescribed sine motion of the preloaded contact through the real-time FMU (ten fixed
    steps of 0.1 ms per communication step; the normal force ramping 50 -> 130 N, held over each communication
    step, so that the force the FMU reports at a communication point is at the load its steps used) gives the
    friction force that the core's real-time API, driven from Python with the same sliding velocities and loads
    (control.friction_steps, tf_rt_step), gives -- to rounding (1e-12 of range); the same steps at a constant
    50 N are far from it."""
    from thermofriction.control import friction_steps

    model = preloaded_stage(tf.PrescribedMotion())
    step, per = 1e-4, 10
    t = np.arange(1001) * (step * per)
    u = 3e-3 * np.sin(2 * np.pi * 1.0 * t) + 8e-4 * np.sin(2 * np.pi * 3.7 * t)
    N = np.interp(t, [0.0, 0.2, 0.8, 1.0], [50.0, 50.0, 130.0, 130.0])
    path = tmp_path / "rt.fmu"
    export_fmu(model, path, solver="realtime", step=step, temperature=30.0, load=50.0)
    run = Run(path, tmp_path, start_values={"temperature": 30.0, "motion": u[0]})
    run.fmu.exitInitializationMode()
    got = np.empty(t.size - 1)
    for k in range(t.size - 1):
        run.set("motion", u[k])
        run.fmu.setRealInputDerivatives([run.vr["motion"]], [1], [(u[k + 1] - u[k]) / (step * per)])
        run.set("normal_force", N[k])  # held over the step: no derivative
        run.fmu.doStep(currentCommunicationPoint=t[k], communicationStepSize=step * per)
        got[k] = run.get("friction_force")[0]
    run.close()
    v = np.repeat(np.diff(u) / (step * per), per)
    F, _ = friction_steps(model, v, step, temperature=30.0, load=np.repeat(N[:-1], per))
    want = F[per - 1::per]  # the force after each communication step's last fixed step
    assert np.max(np.abs(got - want)) <= 1e-12 * np.ptp(want)
    blind, _ = friction_steps(model, v, step, temperature=30.0, load=50.0)
    assert np.max(np.abs(got - blind[per - 1::per])) > 0.1 * np.ptp(want)


@needs_binary
@pytest.mark.parametrize("solver", ["adaptive", "realtime"])
def test_fmi3_fmu_takes_the_load_as_the_fmi2_one(solver, tmp_path):
    """Truth: the FMI 2 export of the same model on the same held inputs (fmpy's own master, simulate_fmu):
    one core, two wrappers, to 1e-9 of each output's range; the load input declared the same way in FMI 3
    (Float64, unit N, start). With the realtime solver the FMU's fixed steps read the load as well."""
    model = preloaded_stage()
    kw = {"solver": "realtime", "step": 1e-4} if solver == "realtime" else {}
    f2, f3 = tmp_path / "s2.fmu", tmp_path / "s3.fmu"
    export_fmu(model, f2, temperature=30.0, **kw)
    export_fmu(model, f3, temperature=30.0, fmi=3, **kw)
    assert validate_fmu(str(f3)) == []
    var = {v.name: v for v in read_model_description(str(f3)).modelVariables}
    N = var["normal_force"]
    assert (N.causality, N.type, N.unit, float(N.start)) == ("input", "Float64", "N", 90.0)  # the range's middle
    t = T_GRID[:201]
    signal = np.array(list(zip(t, 0 * t, 30.0 + 0 * t, N_RAMP[:201] + 40.0 * (t > 1.0))),
                      dtype=[("time", float), ("force", float), ("temperature", float), ("normal_force", float)])
    out = ["friction_force", "displacement", "velocity"]
    r2 = fmpy.simulate_fmu(str(f2), stop_time=t[-1], output_interval=0.01, input=signal, output=out)
    r3 = fmpy.simulate_fmu(str(f3), stop_time=t[-1], output_interval=0.01, input=signal, output=out)
    blind = fmpy.simulate_fmu(str(f2), stop_time=t[-1], output_interval=0.01, input=signal[["time", "force",
                                                                                            "temperature"]],
                              output=out)
    for name in out:
        scale = np.ptp(r2[name])
        assert scale > 0
        np.testing.assert_allclose(r3[name], r2[name], rtol=0, atol=1e-9 * scale, err_msg=name)
        assert np.max(np.abs(blind[name] - r2[name])) > 1e-2 * scale, name  # the load input is read


@needs_binary
def test_a_load_free_model_has_no_load_input_and_a_rotary_joint_a_load_torque(tmp_path):
    """A model without a law of the load exports the FMU it did before: no load variable (value reference 12
    undeclared, refused by fmi2SetReal), no load line in its resources. A rotary joint's laws of the load read a
    load torque: ``load_torque`` [N m]."""
    path = tmp_path / "free.fmu"
    export_fmu("stage-model-i", path, temperature=35.0)
    md = read_model_description(str(path))
    assert not [v for v in md.modelVariables if "load" in v.name or v.valueReference == 12]
    with zipfile.ZipFile(path) as z:
        assert "load" not in z.read("resources/model.tfm").decode().replace("model.toml", "")
    run = Run(path, tmp_path, start_values={"temperature": 35.0})
    with pytest.raises(Exception):
        run.fmu.setReal([12], [50.0])
    assert any("value reference 12 cannot be set" in m for _, _, m in run.messages)
    joint = preloaded_stage(tf.PrescribedMotion(motion="rotary"))
    export_fmu(joint, tmp_path / "joint.fmu", temperature=30.0, load=12.0)
    var = {v.name: v for v in read_model_description(str(tmp_path / "joint.fmu")).modelVariables}
    assert var["load_torque"].unit == "N m" and var["load_torque"].causality == "input"
    assert "normal_force" not in var


@needs_binary
def test_the_fmu_warns_outside_the_load_range_and_refuses_a_bad_load(tmp_path):
    """The load laws' range of |load| (30..150 N) is the FMU's as the temperature's is: a load of 180 N steps with
    fmi2Warning and a logged message naming the range (once per excursion); a NaN load is refused with an error,
    the state unchanged; a load where the model leaves its domain (fc = mu |N| = 0 at N = 0) is refused. A model
    whose laws have no range needs the load's start at export; the temperature estimator exports with a law of the
    load (it steps at the load input)."""
    model = preloaded_stage()
    path = tmp_path / "s.fmu"
    export_fmu(model, path, temperature=30.0)
    run = Run(path, tmp_path, start_values={"temperature": 30.0, "normal_force": 60.0})
    run.fmu.exitInitializationMode()
    run.fmu.doStep(0.0, 0.01)
    run.set("normal_force", 180.0)
    status = run.fmu.fmi2DoStep(run.fmu.component, 0.01, 0.01, 1)
    assert status == 1  # fmi2Warning
    assert any("load 180 is outside" in m and "[30, 150]" in m for _, _, m in run.messages), run.messages
    x = run.get("displacement")[0]
    with pytest.raises(Exception):
        run.set("normal_force", float("nan"))
    assert any("the load input" in m and "not finite" in m for _, _, m in run.messages)
    run.set("normal_force", 0.0)
    with pytest.raises(Exception, match="status 3"):  # fmi2Error
        run.fmu.fmi2DoStep(run.fmu.component, 0.02, 0.01, 1)
    assert any("load 0: the model is outside its domain" in m for _, _, m in run.messages), run.messages[-3:]
    assert run.get("displacement")[0] == x
    run.close()
    with pytest.raises(tf.InputError, match="no load range: give the load input's start"):
        export_fmu(preloaded_stage(rng=None), tmp_path / "n.fmu", temperature=30.0)
    export_fmu(preloaded_stage(rng=None), tmp_path / "n.fmu", temperature=30.0, load=70.0)
    export_fmu(model, tmp_path / "e.fmu", temperature=30.0, estimator=TemperatureEstimator(C_th=5.0, R_th=2.0,
                                                                                            r_F=0.01))
    assert (tmp_path / "e.fmu").exists()  # the estimator steps at the load input (tests/test_estimator_load.py)


DLL = binary_path("win64")
HARNESS = DLL.parent / "fmu_harness.exe"


@needs_binary
@pytest.mark.skipif(not DLL.is_file() and not os.environ.get("CI"),
                    reason="package built without the MinGW-w64 cross compiler (CI installs it)")
def test_the_windows_binary_under_wine_takes_the_load_as_the_linux_one(tmp_path):
    """The win64 DLL, loaded by a Windows program (core/fmu/harness) under Wine and given the drive, the
    temperature and the normal force (value references 0, 1, 12) each communication step, gives the outputs
    fmpy gets from the Linux binary of the same FMU on the same held inputs, to 1e-10 of each output's range."""
    wine = shutil.which("wine") or shutil.which("wine64")
    if not wine and not os.environ.get("CI"):
        pytest.skip("Wine is not installed (Debian: apt-get install wine64 wine; CI installs it)")
    assert wine, "Wine is not installed (Debian: apt-get install wine64 wine)"
    path = tmp_path / "w.fmu"
    export_fmu(preloaded_stage(), path, temperature=30.0)
    unzip = tmp_path / "w"
    with zipfile.ZipFile(path) as z:
        z.extractall(unzip)
    guid = read_model_description(str(path)).guid
    h, n = 0.01, 150
    t = np.arange(n + 1) * h
    N = np.interp(t, [0.0, 0.3, 1.2, 1.5], [45.0, 45.0, 140.0, 140.0])
    rows = "\n".join(f"0 30.0 {v:.17g}" for v in N[:n]) + "\n"
    env = dict(os.environ, WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=",
               WINEPREFIX=os.environ.get("WINEPREFIX", os.path.expanduser("~/.wine-thermofriction")))
    uri = "file:///Z:" + str(unzip / "resources").replace(os.sep, "/")
    out = subprocess.run([wine, str(HARNESS), "Z:" + str(unzip / "binaries" / "win64" / "preloaded_stage.dll"),
                          uri, guid, repr(h), "0,1,12", "2,3,4"], input=rows, capture_output=True, text=True,
                         env=env, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    got = np.loadtxt(out.stdout.splitlines())
    assert got.shape == (n, 4)
    signal = np.array(list(zip(t, 0 * t, 30.0 + 0 * t, N)),
                      dtype=[("time", float), ("force", float), ("temperature", float), ("normal_force", float)])
    ref = fmpy.simulate_fmu(str(path), stop_time=n * h, output_interval=h, input=signal,
                            start_values={"temperature": 30.0, "normal_force": 45.0},
                            output=["displacement", "velocity", "friction_force"])
    for k, name in enumerate(("displacement", "velocity", "friction_force"), start=1):
        scale = np.ptp(ref[name])
        assert scale > 0, name
        np.testing.assert_allclose(got[:, k], ref[name][1:], rtol=0, atol=1e-10 * scale, err_msg=name)


# ---- the closed loop ----------------------------------------------------------------------------------------------

def loop_stage():
    """The preloaded stage's contact on a free 1 kg carriage (the loop's single mass)."""
    return preloaded_stage(tf.MassPlant(mass=1.0))


def _loop_case():
    ref = C.sine_reference(2e-3, 0.5, 2.0)
    N = np.interp(ref.time, [0.0, 0.4, 1.6, 2.0], [45.0, 45.0, 140.0, 140.0])  # one per control period
    T = np.interp(ref.time, [0.0, 2.0], [28.0, 36.0])
    return ref, N, T


def test_closed_loop_with_a_load_ramp_matches_the_plain_python_reference():
    """Oracle: the independent scalar-Python loop (tests/reference/control.py; its laws of the load written again in
    tests/reference/laws.py). Over 2 s of a 2 mm sine at 0.5 Hz while the stage's normal force ramps 45 -> 140 N
    and its temperature 28 -> 36 C, the C loop's positions agree with it to 1e-12 of the amplitude, with the
    observer told the stage's load and temperature (a load sensor) and told a constant 45 N (load-blind); the
    load-blind observer's friction estimate is the worse, by the laws' change over the ramp."""
    stage = loop_stage()
    ref, N, T = _loop_case()
    amplitude = 2e-3
    runs = {}
    for name, told in (("sensor", None), ("blind", 45.0)):
        res = C.simulate_loop(stage, ref, temperature=T, load=N, compensation=C.Observer(stage, 100.0, load=told))
        xs = R.reference_closed_loop(stage, ref, T, C.DEFAULT_PID, gain=100.0, L=N, L_comp=told)
        err = np.max(np.abs(res.position - xs))
        print(f"loop with a load ramp, observer told {name}: max |x - reference| = {err:.2e} m")
        assert err <= 1e-12 * amplitude, (name, err)
        runs[name] = res
    np.testing.assert_array_equal(runs["sensor"].plant_load, N)
    np.testing.assert_array_equal(runs["sensor"].compensation_load, N)
    np.testing.assert_array_equal(runs["blind"].compensation_load, np.full(N.size, 45.0))
    assert "plant_load" in runs["blind"]._frame()
    fe = {k: float(np.sqrt(np.mean(r.friction_error[N > 130.0] ** 2))) for k, r in runs.items()}
    print("RMS friction-estimate error at N > 130 N:", fe)
    assert fe["blind"] > 3 * fe["sensor"], fe


def test_a_load_blind_feed_forward_costs_what_the_load_changes():
    """Truth: the laws' own values. A feed-forward told a constant 45 N on a stage at 135 N compensates the sliding
    friction of 45 N: in steady sliding of the sine's middle (|v_ref| > 3 vs) its estimate falls short of the
    stage's friction by fc(T, 135 N) - fc(T, 45 N) (the LuGre's level, fc plus sigma2 v alike in both), to 2 % of
    that gap; told the load, it is within 2 % of the gap of the friction. The tracking error says what the blind
    compensation costs: its RMS error is larger."""
    stage = loop_stage()
    ref = C.sine_reference(2e-3, 0.5, 2.0)
    T = 32.0
    out = {}
    for name, told in (("told", None), ("blind", 45.0)):
        out[name] = C.simulate_loop(stage, ref, temperature=T, load=135.0,
                                    compensation=C.FeedForward(stage, load=told), inertia_feedforward=True)
    fc = stage.thermal.laws["fc"]
    gap = fc.value(T, 135.0) - fc.value(T, 45.0)
    sliding = np.abs(ref.velocity) > 3 * 1.2e-3
    mid = sliding & (ref.time > 0.5)
    blind_short = -out["blind"].friction_error[mid] * np.sign(ref.velocity[mid])
    assert abs(np.median(blind_short) - gap) <= 0.02 * gap, (np.median(blind_short), gap)
    assert np.median(np.abs(out["told"].friction_error[mid])) <= 0.02 * gap
    print(f"feed-forward at 135 N: RMS error told {out['told'].rms_error:.3g} m, blind {out['blind'].rms_error:.3g} m")
    assert out["blind"].rms_error > 1.5 * out["told"].rms_error


def test_the_loop_needs_a_load_for_a_law_of_the_load_and_checks_it():
    """The loop names the law that needs a load; a load series of the wrong length, a NaN load or a load where the
    model leaves its domain is refused naming it; a temperature estimator steps a law of the load at the
    compensation's load (and needs one); a load-free stage ignores the load."""
    stage = loop_stage()
    ref = C.sine_reference(1e-3, 1.0, 0.05)
    with pytest.raises(tf.InputError, match=r"the stage: \[thermal\] fc: a law of the load.*give the run's load"):
        C.simulate_loop(stage, ref, temperature=30.0)
    with pytest.raises(tf.InputError, match=r"simulate_loop: load must be one-dimensional with 501 values"):
        C.simulate_loop(stage, ref, temperature=30.0, load=np.full(7, 50.0))
    bad = np.full(ref.time.size, 50.0)
    bad[3] = np.nan
    with pytest.raises(tf.InputError, match=r"load\[3\] is nan"):
        C.simulate_loop(stage, ref, temperature=30.0, load=bad)
    with pytest.raises(tf.InputError, match=r"compensation's model: Model I at 30 C and load 0: 'fc' must be positive"), \
            pytest.warns(LoadRangeWarning):
        C.simulate_loop(stage, ref, temperature=30.0, load=50.0, compensation=C.FeedForward(stage, load=0.0))
    with pytest.raises(tf.InputError, match=r"Observer: load must be"):
        C.Observer(stage, load="heavy")
    est = TemperatureEstimator(C_th=50.0, R_th=2.0, r_F=0.01)
    with pytest.raises(tf.InputError, match=r"compensation's model has a law of the load \(fc, fs\) and its "
                                            r"estimator is told no load"):
        C.simulate_loop(tf.load_model("stage-model-i"), ref, temperature=30.0,
                        compensation=C.FeedForward(stage, temperature=est))
    told = C.simulate_loop(stage, ref, temperature=30.0, load=50.0, compensation=C.FeedForward(stage, temperature=est))
    assert np.all(np.isfinite(told.compensation_temperature)) and np.all(told.compensation_load == 50.0)
    free = tf.load_model("stage-model-i")
    a = C.simulate_loop(free, ref, temperature=35.0, compensation=C.Observer(free))
    b = C.simulate_loop(free, ref, temperature=35.0, load=80.0, compensation=C.Observer(free, load=20.0))
    np.testing.assert_array_equal(a.position, b.position)
    assert b.plant_load is None and b.compensation_load is None


# ---- the sweeps ---------------------------------------------------------------------------------------------------

SWEEP_METRICS = ["final_displacement", "displacement_range", "peak_friction_force"]


def swept_stage():
    import dataclasses
    return dataclasses.replace(preloaded_stage(), input=tf.Sine(amplitude=0.6, frequency=2.0))


def test_sweep_load_axis_equals_simulate_point_by_point():
    """Truth: tf.simulate run point by point at each (load, temperature) (an independent path through the library);
    the load axis' unit is N; the points differ with the load (the axis reaches the laws)."""
    model = swept_stage()
    grid = {"load": [40.0, 95.0, 140.0], "temperature": [26.0, 37.0]}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tf.PassivityWarning)
        res = tf.sweep(model, grid, duration=0.5, sample_rate=1000, metrics=SWEEP_METRICS, scheduler="sequential",
                       batch_size=4)
        assert len(res) == 6 and res.failed == 0 and res.units["load"] == "N"
        for i in range(len(res)):
            r = tf.simulate(model, 0.5, sample_rate=1000, temperature=res["temperature"][i], load=res["load"][i])
            assert res["final_displacement"][i] == r.displacement[-1]
            assert res["displacement_range"][i] == np.ptp(r.displacement)
            assert res["peak_friction_force"][i] == np.max(np.abs(r.friction_force))
        one = tf.sweep(model, {"temperature": [26.0]}, load=140.0, duration=0.5, sample_rate=1000,
                       metrics=SWEEP_METRICS, scheduler="sequential")
    assert one["peak_friction_force"][0] == res["peak_friction_force"][4]
    assert len(set(res["peak_friction_force"][::2])) == 3


def test_cli_sweep_load_axis_on_the_local_cluster_equals_the_sequential_run(tmp_path):
    """`--grid load=...` on the command line, on the local Dask cluster (two worker processes) and sequentially:
    the same table, its load column in N; a load axis for a model without a law of the load and a model with one
    given no load are usage errors (exit 2) naming what to do."""
    from test_sweep import run
    (tmp_path / "stage.toml").write_text(swept_stage().to_toml())
    grid = ["--grid", "load=40:140:50", "--grid", "temperature=26,37", "--metrics", ",".join(SWEEP_METRICS)]
    common = ["--duration", "0.3", "--sample-rate", "1000"]
    seq = run("sweep", "stage.toml", *grid, *common, "--scheduler", "sequential", "-o", "seq.csv", cwd=tmp_path)
    assert seq.returncode == 0, seq.stderr
    loc = run("sweep", "stage.toml", *grid, *common, "--scheduler", "processes", "--workers", "2", "-o", "local.csv",
              cwd=tmp_path)
    assert loc.returncode == 0, loc.stderr
    assert "a local Dask cluster (2 workers)" in loc.stdout and "6 points (0 failed)" in loc.stdout
    table = (tmp_path / "local.csv").read_text()
    assert table == (tmp_path / "seq.csv").read_text() and table.startswith("load[N],temperature[C],")
    free = run("sweep", "li2009-model-i", "--grid", "load=40,80", "--temperature", "35", *common, "-o", "f.csv",
               cwd=tmp_path)
    assert free.returncode == 2 and "grid 'load': the model has no law of the load" in free.stderr
    none = run("sweep", "stage.toml", "--grid", "temperature=26,37", *common, "-o", "n.csv", cwd=tmp_path)
    assert none.returncode == 2 and "give a load axis in the grid (load=20:100:20)" in none.stderr, none.stderr
    assert not (tmp_path / "f.csv").exists() and not (tmp_path / "n.csv").exists()
