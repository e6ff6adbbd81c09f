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
from thermofriction.models import Exp, Linear, LoadLaw, LoadTerm

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
    whose laws have no range needs the load's start at export."""
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
