"""The C sources every exported FMU carries, and binaries built from them at export time (docs/fmu.md#sources).

The package installs the FMU's sources (the C core, core/fmu's shared logic and wrappers, the official FMI
headers) in ``thermofriction/_fmu/sources``. An FMI 2 export lists its C files in the model description's
``<SourceFiles>``, an FMI 3 export in ``sources/buildDescription.xml``; any importer (or ``cc *.c``) compiles
them into the FMU's binary for its own platform. ``build_binaries`` compiles them for the platforms asked
(``export_fmu(..., platforms=...)``, ``thermofriction fmu --platforms``) with the compilers on this machine.
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from importlib import resources
from pathlib import Path
from xml.sax.saxutils import quoteattr

from .errors import ComputationError

#: The platforms an export can build (FMI 2 names; FMI 3's in ``FOLDERS``), their compiler and command line.
#: The flags are those of the package's own CMake build (Release: -O3, C99, nothing exported but fmi*).
PLATFORMS = ("linux64", "win64")
COMPILERS = {"linux64": "cc", "win64": "x86_64-w64-mingw32-gcc"}
#: Where each platform's compiler comes from (Debian/Ubuntu packages), for the message when it is missing.
PACKAGES = {"linux64": "build-essential", "win64": "gcc-mingw-w64-x86-64"}
_FLAGS = {"linux64": ["-fPIC", "-fvisibility=hidden", "-Wl,--no-undefined", "-Wl,--as-needed"],
          "win64": ["-static-libgcc", "-Wl,--no-undefined"]}
#: The binary's file extension per platform, and its folder in an FMU of each FMI version.
EXTENSIONS = {"linux64": "so", "win64": "dll"}
FOLDERS = {2: {"linux64": "linux64", "win64": "win64"}, 3: {"linux64": "x86_64-linux", "win64": "x86_64-windows"}}
_TIMEOUT = 600  # seconds for one platform's compilation (about 10 s on a loaded 2-core machine)


def sources_dir() -> Path:
    """The installed sources (``thermofriction/_fmu/sources``)."""
    return Path(str(resources.files("thermofriction"))) / "_fmu" / "sources"


def source_files(fmi: int) -> dict[str, bytes]:
    """The FMU's ``sources/`` folder for FMI version ``fmi``: its path inside the folder -> its content. The
    other standard's wrapper and headers are left out; the public headers are in ``thermofriction/``."""
    root = sources_dir()
    other = "fmi3" if fmi == 2 else "fmi2"
    files = {}
    for p in sorted(root.rglob("*")):
        if p.is_file() and p.suffix in (".c", ".h") and not p.name.startswith(other):
            files[p.relative_to(root).as_posix()] = p.read_bytes()
    if not any(name.endswith(".c") for name in files):
        raise ComputationError(f"this installation has no FMU sources ({root}): reinstall thermofriction")
    return files


def c_files(files: dict[str, bytes]) -> list[str]:
    """The files an importer compiles (and links into one shared library): the C files of ``source_files``."""
    return [name for name in files if name.endswith(".c")]


def build_description(identifier: str, files: dict[str, bytes]) -> str:
    """``sources/buildDescription.xml`` of an FMI 3.0 FMU: one build configuration, its C99 files."""
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', '<fmiBuildDescription fmiVersion="3.0">',
             f'  <BuildConfiguration modelIdentifier={quoteattr(identifier)}>',
             '    <SourceFileSet language="C99">']
    lines += [f'      <SourceFile name={quoteattr(name)}/>' for name in c_files(files)]
    # no <Library name="m"/>: MSVC has no libm (the C runtime has the math), and Linux importers load libm
    lines += ['    </SourceFileSet>', '  </BuildConfiguration>', '</fmiBuildDescription>', '']
    return "\n".join(lines)


def _compile(platform_name: str, compiler: str, files: dict[str, bytes], work: Path) -> bytes:
    """One platform's binary from ``files`` (written into ``work``); ComputationError with the compiler's
    first lines of output if it fails."""
    src = work / platform_name
    for name, data in files.items():
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        (src / name).write_bytes(data)
    out = work / f"thermofriction_fmi.{EXTENSIONS[platform_name]}"
    cmd = [compiler, "-std=c99", "-O3", "-DNDEBUG", "-shared", *_FLAGS[platform_name], "-o", str(out),
           *c_files(files)] + (["-lm"] if platform_name == "linux64" else [])
    try:
        run = subprocess.run(cmd, cwd=src, capture_output=True, text=True, timeout=_TIMEOUT)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise ComputationError(f"{platform_name}: {compiler} could not run ({exc})") from None
    if run.returncode != 0 or not out.is_file():
        first = "\n  ".join((run.stderr or run.stdout).strip().splitlines()[:5])
        raise ComputationError(f"{platform_name}: {compiler} failed (exit status {run.returncode}):\n  {first}")
    return out.read_bytes()


def build_binaries(platforms, fmi: int) -> dict[str, bytes]:
    """Compiles the FMU's sources for each of ``platforms`` (names of ``PLATFORMS``) with this machine's
    compilers: platform -> the binary. Every platform is tried; if any cannot be built, one ComputationError
    names each that could not and why (its compiler missing, and the package that has it, or its errors)."""
    files = source_files(fmi)
    binaries, failures = {}, []
    with tempfile.TemporaryDirectory(prefix="thermofriction-fmu-") as tmp:
        for name in platforms:
            compiler = shutil.which(COMPILERS[name])
            if compiler is None:
                failures.append(f"{name}: no {COMPILERS[name]} on PATH (Debian/Ubuntu: apt-get install "
                                f"{PACKAGES[name]})")
                continue
            try:
                binaries[name] = _compile(name, compiler, files, Path(tmp))
            except ComputationError as exc:
                failures.append(str(exc))
    if failures:
        built = f"; built: {', '.join(binaries)}" if binaries else ""
        raise ComputationError("could not build the FMU for " + "; ".join(failures) + built + ". Nothing written: "
                               "leave the platform out of --platforms (platforms=); the FMU carries its C sources, "
                               "from which an importer builds it")
    return binaries


__all__ = ["PLATFORMS", "COMPILERS", "FOLDERS", "sources_dir", "source_files", "build_description",
           "build_binaries"]
