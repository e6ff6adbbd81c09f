"""FMI 3.0 export, the win64 binary and the default experiment (thermofriction.fmu, core/fmu/fmi3_cs.c,
core/fmu/harness/fmu_harness.c; docs/fmu.md). The references: fmpy (an FMI importer no one here wrote)
running the FMI 2 export of the same model on the same held input, and the waveform's own numbers for
the default experiment."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zipfile

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy import read_model_description  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

import thermofriction as tf  # noqa: E402
from thermofriction import fmu as fmu_module  # noqa: E402
from thermofriction.fmu import NoWindowsBinaryWarning, binary_path, default_experiment, export_fmu  # noqa: E402

pytestmark = pytest.mark.skipif(not binary_path().is_file(), reason="no FMU binary (Linux x86-64 only)")

SAW = tf.Sawtooth(amplitude=30.0, frequency=5.0, rise=0.999)  # the paper's drive: a 0.2 ms fall each 0.2 s


def _signal(t, temperature=None):
    cols = [("time", float), ("voltage", float)] + ([("temperature", float)] if temperature is not None else [])
    rows = [(a, b) + ((c,) if temperature is not None else ()) for a, b, c in
            zip(t, SAW(t), temperature if temperature is not None else t)]
    return np.array(rows, dtype=cols)


def _run(path, stop, h, temperature=35.0):
    """fmpy's simulate_fmu with the inputs held over each communication step h (its own master)."""
    t = np.arange(int(round(stop / h)) + 1) * h
    return fmpy.simulate_fmu(str(path), stop_time=stop, output_interval=h, input=_signal(t, 35.0 + 0 * t),
                             start_values={"temperature": temperature},
                             output=["displacement", "velocity", "friction_force"])


def test_fmi3_export_is_valid_and_agrees_with_fmi2(tmp_path):
    """fmpy validates the FMI 3.0 export and runs it; on the same held input (a sawtooth fall of the
    paper's actuator in 20 us steps) it gives the FMI 2 export's outputs: one core, two wrappers."""
    fmu2, fmu3 = tmp_path / "m2.fmu", tmp_path / "m3.fmu"
    export_fmu("li2009-model-i", fmu2, temperature=35.0)
    export_fmu("li2009-model-i", fmu3, temperature=35.0, fmi=3)
    assert validate_fmu(str(fmu3)) == []
    md = read_model_description(str(fmu3))
    assert md.fmiVersion == "3.0" and md.coSimulation is not None
    causality = {v.name: v.causality for v in md.modelVariables}
    assert causality["time"] == "independent" and causality["voltage"] == "input"
    assert causality["friction_force"] == "output" and causality["thermal.fc.a"] == "parameter"
    r2, r3 = _run(fmu2, 0.21, 2e-5), _run(fmu3, 0.21, 2e-5)
    assert len(r3) == len(r2) == 10501
    for name in ("displacement", "velocity", "friction_force"):
        scale = np.ptp(r2[name])
        assert scale > 0
        np.testing.assert_allclose(r3[name], r2[name], rtol=0, atol=1e-9 * scale, err_msg=name)
    with zipfile.ZipFile(fmu3) as z:
        names = z.namelist()
    assert "binaries/x86_64-linux/li2009_model_i.so" in names
    assert "documentation/licenses/fmi3-headers.txt" in names


@pytest.mark.parametrize("preset, kwargs", [("li2009-self-heating", {}), ("li2009-model-ii", {}),
                                            ("li2009-model-i", {"integrator": "realtime", "step": 1e-5})])
def test_fmi3_heat_model_ii_and_realtime_agree_with_fmi2(preset, kwargs, tmp_path):
    """A heat model (temperature an output), Model II and the real-time integrator: the FMI 3.0 export
    validates and gives the FMI 2 export's outputs over 2 ms of its default step with a 30 V drive."""
    paths = {}
    for fmi in (2, 3):
        paths[fmi] = tmp_path / f"{preset}-{fmi}.fmu"
        export_fmu(preset, paths[fmi], fmi=fmi, **kwargs)
    assert validate_fmu(str(paths[3])) == []
    h = float(read_model_description(str(paths[3])).defaultExperiment.stepSize)
    runs = [fmpy.simulate_fmu(str(paths[fmi]), stop_time=2e-3, output_interval=h, start_values={"voltage": 30.0})
            for fmi in (2, 3)]
    names = [n for n in runs[0].dtype.names if n != "time"]
    assert names == [n for n in runs[1].dtype.names if n != "time"] and "friction_force" in names
    assert np.ptp(runs[0]["displacement"]) > 0
    for name in names:
        np.testing.assert_allclose(runs[1][name], runs[0][name], rtol=1e-12, atol=1e-300, err_msg=name)


def test_fmi3_refuses_bad_input_with_an_error_not_a_crash(tmp_path):
    """The shared checks hold in FMI 3: a NaN input is refused by fmi3SetFloat64 with fmi3Error (fmpy
    raises), and a model description of another FMU (a wrong instantiation token) gives no instance."""
    path = tmp_path / "m3.fmu"
    export_fmu("li2009-model-i", path, fmi=3)
    t = np.array([0.0, 1e-4, 2e-4])
    bad = np.array(list(zip(t, [0.0, np.nan, 0.0], [35.0] * 3)),
                   dtype=[("time", float), ("voltage", float), ("temperature", float)])
    with pytest.raises(Exception, match="fmi3SetFloat64|Error"):
        fmpy.simulate_fmu(str(path), stop_time=2e-4, output_interval=1e-4, input=bad)


def test_default_experiment_resolves_the_input(tmp_path):
    """Every FMU states a default experiment whose step resolves the model's [input]: for the paper's
    5 Hz sawtooth with rise 0.999 the fall lasts 0.2 ms, so 1/20 of it, 10 us (1/200 of the period would
    be 1 ms), over two periods; with the realtime integrator a whole number of its fixed steps."""
    model = tf.load_model("li2009-model-i")
    fall = (1 - SAW.rise) / SAW.frequency
    assert model.input == SAW  # the preset's drive
    stop, h, why = default_experiment(model)
    for fmi in (2, 3):
        path = tmp_path / f"d{fmi}.fmu"
        export_fmu(model, path, fmi=fmi)
        exp = read_model_description(str(path)).defaultExperiment
        assert float(exp.stepSize) == pytest.approx(fall / 20, rel=0.05), fmi
        assert float(exp.stopTime) == pytest.approx(2 / SAW.frequency)
    assert "fall" in why and h == pytest.approx(1e-5)
    _, h_rt, _ = default_experiment(model, step=3e-6)
    assert h_rt == pytest.approx(9e-6)  # 3 fixed steps: the nearest whole number to 10 us
    bare = tf.Model(plant=model.plant, friction=model.friction, thermal=model.thermal)
    assert default_experiment(bare)[:2] == (1.0, 1e-4)


def test_without_the_windows_binary_the_fmu_says_so(tmp_path, monkeypatch):
    """A package built without MinGW-w64: the export warns and the FMU carries linux64 only."""
    real = fmu_module.binary_path
    monkeypatch.setattr(fmu_module, "binary_path",
                        lambda p="linux64": tmp_path / "none.dll" if p == "win64" else real(p))
    with pytest.warns(NoWindowsBinaryWarning, match="linux64 only"):
        export_fmu("canudas1995", tmp_path / "l.fmu")
    with zipfile.ZipFile(tmp_path / "l.fmu") as z:
        assert not any(n.startswith("binaries/win64") for n in z.namelist())


def test_cli_fmi3(tmp_path):
    """`thermofriction fmu MODEL -o FILE --fmi 3` writes an FMI 3.0 FMU fmpy validates."""
    path = tmp_path / "c3.fmu"
    out = subprocess.run([sys.executable, "-m", "thermofriction", "fmu", "canudas1995", "-o", str(path), "--fmi", "3"],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "FMI 3.0" in out.stdout
    assert validate_fmu(str(path)) == [] and read_model_description(str(path)).fmiVersion == "3.0"


# ---- the win64 binary ----

DLL = binary_path("win64")
HARNESS = DLL.parent / "fmu_harness.exe"
needs_dll = pytest.mark.skipif(not DLL.is_file() and not os.environ.get("CI"),
                               reason="package built without the MinGW-w64 cross compiler (CI installs it)")


@needs_dll
def test_dll_imports_windows_system_libraries_only(tmp_path):
    """The FMU's win64 DLL imports KERNEL32 and the C runtime only (libgcc linked in) and is in every
    export, FMI 2 and 3."""
    objdump = shutil.which("x86_64-w64-mingw32-objdump") or shutil.which("objdump")
    out = subprocess.run([objdump, "-p", str(DLL)], capture_output=True, text=True, check=True).stdout
    dlls = {line.split(":")[1].strip().lower() for line in out.splitlines() if "DLL Name:" in line}
    assert dlls and dlls <= {"kernel32.dll", "msvcrt.dll"}, dlls
    for fmi, folder in ((2, "win64"), (3, "x86_64-windows")):
        export_fmu("canudas1995", tmp_path / f"w{fmi}.fmu", fmi=fmi)
        with zipfile.ZipFile(tmp_path / f"w{fmi}.fmu") as z:
            assert f"binaries/{folder}/canudas1995.dll" in z.namelist(), z.namelist()


@needs_dll
def test_dll_runs_under_wine_as_the_linux_binary(tmp_path):
    """The win64 DLL, loaded by a Windows program (core/fmu/harness) under Wine, runs a co-simulation
    of the paper's actuator through a sawtooth fall (held inputs, 20 us steps) and gives the outputs
    fmpy gets from the Linux binary of the same FMU, to 1e-10 of each output's range (seen: 7e-15, the
    rounding of two compilers and C libraries)."""
    wine = shutil.which("wine") or shutil.which("wine64")
    if not wine and not os.environ.get("CI"):
        pytest.skip("Wine is not installed (Debian: apt-get install wine64 wine; CI installs it)")
    assert wine, "Wine is not installed (Debian: apt-get install wine64 wine)"
    path = tmp_path / "w.fmu"
    export_fmu("li2009-model-i", path, temperature=35.0)
    unzip = tmp_path / "w"
    with zipfile.ZipFile(path) as z:
        z.extractall(unzip)
    guid = read_model_description(str(path)).guid
    # 1.2 ms of held samples of the sawtooth from 0.4 ms before its first fall (at 0.1998 s): the drive
    # jumps to 30 V, falls to 0 V and starts to rise again, so the end effector sticks and slips
    h, n = 2e-5, 60
    t = np.arange(n + 1) * h
    u = SAW(t + 0.1994)
    rows = "\n".join(f"{v:.17g} 35.0" for v in u[:n]) + "\n"
    env = dict(os.environ, WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=",
               WINEPREFIX=os.environ.get("WINEPREFIX", os.path.expanduser("~/.wine-thermofriction")))
    uri = "file:///Z:" + str(unzip / "resources").replace(os.sep, "/")
    out = subprocess.run([wine, str(HARNESS), "Z:" + str(unzip / "binaries" / "win64" / "li2009_model_i.dll"),
                          uri, guid, repr(h)], input=rows, capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    got = np.loadtxt(out.stdout.splitlines())
    assert got.shape == (n, 4)
    signal = np.array(list(zip(t, u, [35.0] * (n + 1))),
                      dtype=[("time", float), ("voltage", float), ("temperature", float)])
    ref = fmpy.simulate_fmu(str(path), stop_time=n * h, output_interval=h, input=signal,
                            start_values={"temperature": 35.0}, output=["displacement", "velocity", "friction_force"])
    np.testing.assert_allclose(got[:, 0], ref["time"][1:], rtol=1e-12)
    for k, name in enumerate(("displacement", "velocity", "friction_force"), start=1):
        scale = np.ptp(ref[name])
        assert scale > 0, name
        np.testing.assert_allclose(got[:, k], ref[name][1:], rtol=0, atol=1e-10 * scale, err_msg=name)
