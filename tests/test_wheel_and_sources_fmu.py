"""FMUs that carry their C sources, binaries built at export time (``platforms=``, ``--platforms``), the Makefile's
rebuild when the cross compiler appears, and the wheel and sdist installed in a clean venv (thermofriction.fmu,
fmu_sources.py, CMakeLists.txt, Makefile; docs/fmu.md#sources, README.md). The references: the FMU's own
prebuilt binary (the package's CMake build) against binaries compiled from the FMU's ``sources/`` by
someone else (fmpy's CMake project for FMI 2; a plain ``cc`` call written here from buildDescription.xml for
FMI 3), run by fmpy on the same held inputs."""

from __future__ import annotations

import os
import shutil
import stat
import subprocess
import sys
import textwrap
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy.validation import validate_fmu  # noqa: E402

import thermofriction as tf  # noqa: E402
from thermofriction import fmu_sources  # noqa: E402
from thermofriction.errors import ComputationError, InputError  # noqa: E402
from thermofriction.fmu import binary_path, export_fmu  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
HAS_BINARY = binary_path().is_file()
needs_binary = pytest.mark.skipif(not HAS_BINARY, reason="no FMU binary (Linux x86-64 only)")
SAW = tf.Sawtooth(amplitude=30.0, frequency=5.0, rise=0.999)  # the paper's drive: a 0.2 ms fall each 0.2 s
OUTPUTS = ("displacement", "velocity", "friction_force")


def _run(path, stop=0.2012, h=2e-5):
    """fmpy's simulate_fmu on li2009-model-i at 35 C through the sawtooth's fall at 0.2 s, inputs held over h."""
    t = np.arange(int(round(stop / h)) + 1) * h
    signal = np.array(list(zip(t, SAW(t), 35.0 + 0 * t)),
                      dtype=[("time", float), ("voltage", float), ("temperature", float)])
    return fmpy.simulate_fmu(str(path), stop_time=stop, output_interval=h, input=signal, output=list(OUTPUTS))


def _assert_same(got, ref, tol=1e-12):
    """Equal to ``tol`` of each output's range (a slip included: the ranges are the run's own)."""
    assert len(got) == len(ref) > 10000
    for name in OUTPUTS:
        scale = np.ptp(ref[name])
        assert scale > 0
        np.testing.assert_allclose(got[name], ref[name], rtol=0, atol=tol * scale, err_msg=name)


def _unzip(path, where):
    with zipfile.ZipFile(path) as z:
        z.extractall(where)
    return where


# ---- FMUs with their sources ----

@needs_binary
@pytest.mark.parametrize("fmi", [2, 3])
def test_every_fmu_carries_its_sources_and_fmpy_validates_it(fmi, tmp_path):
    """The default export carries the prebuilt binary and ``sources/``: the C files the model description (FMI 2:
    ``<SourceFiles>``) or buildDescription.xml (FMI 3) lists, each present, the other standard's wrapper left
    out; fmpy's validator finds nothing to object to."""
    path = tmp_path / f"m{fmi}.fmu"
    export_fmu("li2009-model-i", path, fmi=fmi)
    assert validate_fmu(str(path)) == []
    with zipfile.ZipFile(path) as z:
        names = set(z.namelist())
        md = ET.fromstring(z.read("modelDescription.xml"))
        listed = ([f.get("name") for f in md.iter("File")] if fmi == 2 else
                  [f.get("name") for f in ET.fromstring(z.read("sources/buildDescription.xml")).iter("SourceFile")])
    assert f"sources/fmi{fmi}_cs.c" in names and f"sources/fmi{5 - fmi}_cs.c" not in names
    assert {f"fmi{fmi}_cs.c", "fmu_common.c", "solve.c", "rodas4.c"} <= set(listed)
    assert all(f"sources/{name}" in names for name in listed)
    assert "sources/thermofriction/plant.h" in names and "sources/thermofriction.h" in names


@needs_binary
@pytest.mark.slow
def test_sources_only_fmi2_fmu_compiled_by_fmpy_matches_the_binary_fmu(tmp_path):
    """``platforms=[]``: an FMU with no binary, its sources only. ``fmpy compile`` builds it on its own (fmpy's
    CMake project, from the model description's <SourceFiles>, into the FMU), and run by fmpy through the
    paper's sawtooth fall it gives the prebuilt binary FMU's outputs to 1e-12 of each output's range."""
    src, ref = tmp_path / "src.fmu", tmp_path / "bin.fmu"
    export_fmu("li2009-model-i", src, temperature=35.0, platforms=[])
    export_fmu("li2009-model-i", ref, temperature=35.0)
    with zipfile.ZipFile(src) as z:
        assert not any(n.startswith("binaries/") for n in z.namelist())
    assert validate_fmu(str(src)) == []
    out = subprocess.run([sys.executable, "-m", "fmpy", "compile", str(src)], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-2000:]
    with zipfile.ZipFile(src) as z:
        assert "binaries/linux64/li2009_model_i.so" in z.namelist()
    _assert_same(_run(src), _run(ref))


@needs_binary
@pytest.mark.slow
def test_sources_only_fmi3_fmu_compiled_with_cc_matches_the_binary_fmu(tmp_path):
    """FMI 3: the test compiles the sources-only FMU itself with ``cc``, as buildDescription.xml says (its
    source files and libraries, none: not even libm, which the importer's process has; -O2 where the package
    uses -O3), and the result matches the binary FMU to 1e-12 of each output's range."""
    src, ref = tmp_path / "src.fmu", tmp_path / "bin.fmu"
    export_fmu("li2009-model-i", src, temperature=35.0, platforms=[], fmi=3)
    export_fmu("li2009-model-i", ref, temperature=35.0, fmi=3)
    unzipped = _unzip(src, tmp_path / "unzipped")
    build = ET.parse(unzipped / "sources" / "buildDescription.xml").getroot()
    config = build.find("BuildConfiguration")
    files = [f.get("name") for f in config.iter("SourceFile")]
    libs = [f"-l{lib.get('name')}" for lib in config.iter("Library")]
    out = unzipped / "binaries" / "x86_64-linux" / f"{config.get('modelIdentifier')}.so"
    out.parent.mkdir(parents=True)
    run = subprocess.run(["cc", "-std=c99", "-O2", "-shared", "-fPIC", "-o", str(out), *files, *libs],
                         cwd=unzipped / "sources", capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    _assert_same(_run(unzipped), _run(ref))


# ---- platforms built at export time ----

@needs_binary
@pytest.mark.slow
@pytest.mark.skipif(shutil.which("x86_64-w64-mingw32-gcc") is None, reason="no MinGW-w64 cross compiler")
def test_platforms_are_built_at_export_time(tmp_path, monkeypatch):
    """``platforms=["linux64", "win64"]`` builds both from the sources now, whatever was built with the package
    (here: as if no binary had been installed): the FMU carries a Linux shared object that fmpy runs as the
    prebuilt one (to 1e-12 of range) and a Windows DLL (a PE file importing KERNEL32 and msvcrt only)."""
    ref = tmp_path / "bin.fmu"
    export_fmu("li2009-model-i", ref, temperature=35.0)
    monkeypatch.setattr(tf.fmu, "binary_path", lambda p="linux64": tmp_path / "not-installed")
    path = tmp_path / "built.fmu"
    export_fmu("li2009-model-i", path, temperature=35.0, platforms=["linux64", "win64"])
    with zipfile.ZipFile(path) as z:
        dll = z.read("binaries/win64/li2009_model_i.dll")
        so = z.read("binaries/linux64/li2009_model_i.so")
    assert dll[:2] == b"MZ" and so[:4] == b"\x7fELF"
    (tmp_path / "x.dll").write_bytes(dll)
    objdump = shutil.which("x86_64-w64-mingw32-objdump")
    if objdump:
        dump = subprocess.run([objdump, "-p", str(tmp_path / "x.dll")], capture_output=True, text=True).stdout
        imports = {line.split(":")[1].strip().lower() for line in dump.splitlines() if "DLL Name:" in line}
        assert imports == {"kernel32.dll", "msvcrt.dll"}
    _assert_same(_run(path), _run(ref))


@needs_binary
def test_a_platform_that_cannot_be_built_is_named_with_why_and_nothing_is_written(tmp_path, monkeypatch):
    """A missing compiler and a compiler that fails: one ComputationError names each platform and why (the
    compiler and the package that has it; the compiler's own error line), and no FMU is written."""
    fake = tmp_path / "fake-cc"
    fake.write_text("#!/bin/sh\necho 'plant.c:1: error: something the compiler refused' >&2\nexit 1\n")
    fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
    monkeypatch.setitem(fmu_sources.COMPILERS, "linux64", str(fake))
    monkeypatch.setitem(fmu_sources.COMPILERS, "win64", "no-such-mingw-gcc")
    path = tmp_path / "m.fmu"
    with pytest.raises(ComputationError) as err:
        export_fmu("li2009-model-i", path, platforms=["linux64", "win64"])
    message = str(err.value)
    assert "linux64" in message and "something the compiler refused" in message and "exit status 1" in message
    assert "win64: no no-such-mingw-gcc on PATH" in message and "gcc-mingw-w64-x86-64" in message
    assert not path.exists() and list(tmp_path.iterdir()) == [fake]


@needs_binary
def test_cli_platforms_option(tmp_path):
    """``--platforms none`` writes the sources-only FMU and says so; an unknown platform exits 2 naming it and the
    platforms there are, with no traceback and no file."""
    path = tmp_path / "s.fmu"
    out = subprocess.run([sys.executable, "-m", "thermofriction", "fmu", "canudas1995", "-o", str(path),
                          "--platforms", "none"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "(FMI 2.0 co-simulation, C sources, adaptive integrator)" in out.stdout
    with zipfile.ZipFile(path) as z:
        assert not any(n.startswith("binaries/") for n in z.namelist())
    bad = tmp_path / "b.fmu"
    out = subprocess.run([sys.executable, "-m", "thermofriction", "fmu", "canudas1995", "-o", str(bad),
                          "--platforms", "linux64,darwin64"], capture_output=True, text=True)
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert "'darwin64'" in out.stderr and "linux64, win64" in out.stderr and not bad.exists()
    with pytest.raises(InputError, match="platforms must be a name or a list of names"):
        export_fmu("canudas1995", tmp_path / "c.fmu", platforms=3)
    export_fmu("canudas1995", tmp_path / "n.fmu", platforms="none")  # the command line's word, in Python too
    with zipfile.ZipFile(tmp_path / "n.fmu") as z:
        assert not any(n.startswith("binaries/") for n in z.namelist()) and "sources/solve.c" in z.namelist()


# ---- make install and the cross compiler ----

@pytest.mark.skipif(shutil.which("make") is None, reason="no make")
def test_make_install_rebuilds_when_the_cross_compiler_appears_or_goes(tmp_path):
    """The Makefile's install target (a stand-in venv whose python records each install) runs again when
    ``x86_64-w64-mingw32-gcc`` (here the MINGW variable, a file made executable later) appears or goes, and
    not otherwise: the win64 DLL is built with the package only if the compiler was there (docs/fmu.md)."""
    shutil.copy(ROOT / "Makefile", tmp_path / "Makefile")
    for name in ("core/a.c", "src/b.py", "pyproject.toml", "CMakeLists.txt"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("")
    python = tmp_path / ".venv" / "bin" / "python"
    python.parent.mkdir(parents=True)
    python.write_text(f"#!/bin/sh\necho \"$*\" >> {tmp_path / 'installs.log'}\n")
    python.chmod(0o755)
    mingw = tmp_path / "mingw-gcc"

    def installs():
        subprocess.run(["make", "-s", "install", f"MINGW={mingw}"], cwd=tmp_path, check=True, capture_output=True)
        log = tmp_path / "installs.log"
        return log.read_text().count("pip install") if log.exists() else 0

    assert installs() == 1
    assert installs() == 1  # nothing changed: nothing to do
    mingw.write_text("#!/bin/sh\n")
    mingw.chmod(0o755)
    assert installs() == 2  # the cross compiler appeared
    assert installs() == 2
    mingw.unlink()
    assert installs() == 3  # and went


# ---- the wheel and the sdist ----

@pytest.mark.slow
def test_wheel_built_from_the_sdist_installs_and_runs_in_a_clean_venv(tmp_path):
    """``python -m build`` makes the sdist and, from it, the wheel (so the sdist holds all the wheel needs); the
    wheel, pip-installed into a fresh venv (dependencies from pip's cache) and run from a folder outside the
    source tree, imports from that venv, simulates a preset and exports an FMU carrying its sources."""
    pytest.importorskip("build")
    dist = tmp_path / "dist"
    out = subprocess.run([sys.executable, "-m", "build", "--outdir", str(dist), str(ROOT)],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    wheels, sdists = list(dist.glob("thermofriction-*.whl")), list(dist.glob("thermofriction-*.tar.gz"))
    assert len(wheels) == 1 and len(sdists) == 1
    with zipfile.ZipFile(wheels[0]) as z:
        names = z.namelist()
    assert "thermofriction/_fmu/sources/fmu_common.c" in names and "thermofriction/_fmu/thermofriction_fmi.so" in names
    if shutil.which("x86_64-w64-mingw32-gcc"):  # built with the package where the cross compiler is (docs/fmu.md)
        assert "thermofriction/_fmu/thermofriction_fmi.dll" in names
    assert not any(n.startswith(("tests/", "core/", "src/")) for n in names)  # the package only
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = venv / "bin" / "python"
    work = tmp_path / "elsewhere"
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    out = subprocess.run([str(py), "-m", "pip", "install", "--quiet", str(wheels[0])], cwd=work, env=env,
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-3000:]
    script = textwrap.dedent("""
        import thermofriction, sys
        print(thermofriction.__file__)
    """)
    out = subprocess.run([str(py), "-c", script], cwd=work, env=env, capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.strip().startswith(str(venv)), out.stderr
    cli = venv / "bin" / "thermofriction"
    out = subprocess.run([str(cli), "simulate", "li2009-base", "--duration", "0.1", "-o", "x.csv"], cwd=work, env=env,
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    header = (work / "x.csv").read_text().splitlines()[0].split(",")
    rows = np.loadtxt(work / "x.csv", delimiter=",", skiprows=1)
    assert rows[-1, header.index("time[s]")] == pytest.approx(0.1)
    assert np.ptp(rows[:, header.index("displacement[m]")]) > 0
    out = subprocess.run([str(cli), "fmu", "li2009-model-i", "-o", "m.fmu"], cwd=work, env=env,
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    with zipfile.ZipFile(work / "m.fmu") as z:
        assert "sources/fmu_common.c" in z.namelist() and "binaries/linux64/li2009_model_i.so" in z.namelist()
