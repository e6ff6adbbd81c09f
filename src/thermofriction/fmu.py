"""FMI 2.0 and 3.0 co-simulation FMUs of any model (docs/fmu.md): ``export_fmu(model, path, fmi=2|3)``.

One prebuilt binary serves every model and both standards: the C core with the shared FMU logic
(core/fmu/fmu_common.c) and the FMI 2 and FMI 3 wrappers (fmi2_cs.c, fmi3_cs.c), built when the package
is installed, for Linux x86-64 and, when the MinGW-w64 cross compiler is there, Windows x86-64.
Exporting a model zips the binaries as ``binaries/linux64/<modelIdentifier>.so`` and
``binaries/win64/<modelIdentifier>.dll`` (FMI 3: ``x86_64-linux``, ``x86_64-windows``) with a
generated ``modelDescription.xml`` and
``resources/model.tfm``, the model description the binary reads when it is instantiated (its plant,
friction model, thermal extension, laws and every tunable parameter with its value reference). So an
export needs no compiler. Every FMU also carries its C sources (``sources/``, fmu_sources.py), from which
an importer builds it on any platform; ``platforms=`` builds the binaries at export time instead.

The FMU has the plant's drive as input (a voltage for the stick-slip actuator, a force for a mass, the
displacement for prescribed motion), the temperature [degC] for Model I and II (the ambient temperature
with a ``[heat]`` section), the load (``normal_force`` [N], or ``load_torque`` [N m] for a rotary joint) for a
model with a law of the load, and every plant, friction, law and heat parameter as a tunable parameter.
The model file's own ``[input]`` is not part of the FMU: the importer drives it.

Between communication points the FMU integrates with the core's adaptive integrator (the default), or
with ``solver="realtime"`` by fixed steps of ``step`` seconds: the friction by the core's real-time
step (realtime.h) and the plant by semi-implicit Euler, for a deterministic cost per step. The choice is
in ``resources/model.tfm`` and the step is the fixed parameter ``integrator.step``.
"""

from __future__ import annotations


import hashlib
import html
import math
import os
import platform
import re
import uuid
import warnings
import zipfile
from importlib import resources
from pathlib import Path


from . import _bridge
from ._io import Target, atomic_write
from .errors import InputError, shorten
from . import _args
from .fmu_description import (MAX_POINTS, default_experiment, description_xml2, description_xml3, resource_text,
                              variables_of)
from .fmu_sources import FOLDERS, EXTENSIONS, PLATFORMS, build_binaries, build_description, c_files, source_files
from .estimation import TemperatureEstimator
from .models import MassPlant, Model, StickSlipPlant, load_model
from .models.fit_record import fit_record_lines
from .models.load_laws import load_laws

#: The solvers an FMU can carry between communication points (docs/fmu.md#solvers).
SOLVERS = ("adaptive", "realtime")
#: The FMI versions an export can follow (docs/fmu.md).
FMI_VERSIONS = (2, 3)

_BINARY = "thermofriction_fmi.so"
_DLL = "thermofriction_fmi.dll"
# FMI 3's names of the platforms, also accepted by platforms=
_ALIASES = {FOLDERS[3][name]: name for name in PLATFORMS}


class NoWindowsBinaryWarning(UserWarning):
    """An exported FMU carries the Linux binary only (the package was built without MinGW-w64, and no
    ``platforms=`` asked for win64)."""


def binary_path(platform_name: str = "linux64") -> Path:
    """The installed FMI binary (FMI 2 and 3 in one): ``"linux64"``, built with the package on Linux, or
    ``"win64"``, the DLL cross-compiled with MinGW-w64 when the package was built where it is installed.

    Parameters
    ----------
    platform_name : {"linux64", "win64"}, default "linux64"
        The platform; any other name is taken as "linux64".

    Returns
    -------
    pathlib.Path
        The binary's path inside the installed package (the win64 one may not exist: ``.is_file()``).

    Raises
    ------
    None
        Nothing is checked.
    """
    return Path(str(resources.files("thermofriction"))) / "_fmu" / (_DLL if platform_name == "win64" else _BINARY)


def prebuilt_platforms() -> list[str]:
    """The platforms whose binary was built with the package: what an export carries by default.

    Returns
    -------
    list of str
        ``"linux64"``, and ``"win64"`` where the package was built with the MinGW-w64 cross compiler.

    Raises
    ------
    None
        Nothing is checked.
    """
    return [name for name in PLATFORMS if binary_path(name).is_file()]


def _platforms(platforms) -> tuple[str, ...] | None:
    """``platforms=``: None (the prebuilt binaries), names of ``PLATFORMS`` (FMI 3's names too), each once, or
    ``[]`` (``"none"``) for the sources only."""
    names = _args.names(platforms, "platforms")
    if names is None:
        return None
    if names == ["none"]:
        return ()
    out = []
    for name in names:
        name = _ALIASES.get(name, name)
        if name not in PLATFORMS:
            raise InputError(f"export_fmu: platform {shorten(name)}: use {', '.join(PLATFORMS)} (FMI 3's names "
                             f"{', '.join(_ALIASES)} too), or none ([]) for an FMU with its C sources only")
        if name not in out:
            out.append(name)
    return tuple(out)


def _identifier(text: str) -> str:
    ident = re.sub(r"[^A-Za-z0-9_]", "_", text).strip("_") or "thermofriction_model"
    return ident if not ident[0].isdigit() else f"tf_{ident}"


def _check_exportable(model: Model):
    """Refuses, naming the part and what to do, what the FMU cannot carry."""
    if model.heat is not None and model.heat.external_heat is not None and model.heat.external_heat.kind == "sampled":
        raise InputError("[heat] P_ext: a sampled external heat (a file of samples) cannot be baked into an FMU: give "
                         "P_ext as a step, square, sine or sawtooth waveform, or leave it out")
    laws = dict(model.laws)
    if getattr(model.thermal, "model", None) == "II":
        laws["dF"] = model.thermal.dF
    for name, law in laws.items():
        y = law.core_fields().get("y")
        n = 0 if y is None else len(y)
        if n > MAX_POINTS:
            raise InputError(f"[thermal] {name}: a law of {n} points or coefficients; an FMU takes at most {MAX_POINTS}")


def _load_input(model: Model, load: float | None = None):
    """The load input of a model with a law of the load (docs/fmu.md#the-load-input), (name, unit, what, start),
    and the load terms' common range of |load| (None: none); (None, None) without such a law. A joint's (a rotary
    prescribed motion) is ``load_torque`` [N m], any other ``normal_force`` [N]; it starts at ``load``, else at
    the middle of the range."""
    terms = [law.load for law in load_laws(model).values()]
    if not terms:
        return None, None
    ranges = [t.range for t in terms if t.range is not None]
    rng = (max(r[0] for r in ranges), min(r[1] for r in ranges)) if ranges else None
    rng = rng if rng and rng[0] < rng[1] else None
    if load is None and rng is None:
        raise InputError("export_fmu: the model has a law of the load and no load range: give the load input's start "
                         "(load=..., --load)")
    start = float(load) if load is not None else 0.5 * (rng[0] + rng[1])
    if getattr(model.plant, "rotary", False):
        return ("load_torque", "N m", "load torque on the joint, read by the laws of the load", start), rng
    return ("normal_force", "N", "normal force on the contact (its preload), read by the laws of the load", start), rng


def _check_step(model: Model, step) -> float:
    """The realtime solver's step [s]: a positive finite number, below the stability limit 2 / omega
    of semi-implicit Euler on the plant's stiffest spring (the stage's natural frequency, the mass's
    pulling spring)."""
    step = _args.number(step, "step", "s", positive=True)
    plant = model.plant
    omega, what = None, ""
    if isinstance(plant, StickSlipPlant):
        c, k, _ = plant.physical()
        omega, what = math.sqrt(k / plant.mass), "the stage's natural frequency"
    elif isinstance(plant, MassPlant) and plant.spring_stiffness:
        omega, what = math.sqrt(plant.spring_stiffness / plant.mass), "the pulling spring's frequency"
    if omega is not None and omega * step >= 2.0:
        raise InputError(f"export_fmu: step = {step:g} s is unstable for this plant: the fixed step needs "
                         f"step < 2 / omega = {2.0 / omega:.3g} s ({what}, omega = {omega:.4g} rad/s); take "
                         f"a tenth of that or less for accuracy")
    return step


def _solver(solver, integrator):
    """``solver``, or ``integrator``, its earlier name (one meaning per option name: the solver is ``solver``)."""
    _args.text(integrator, "integrator", none=True)
    if integrator is None:
        return solver
    warnings.warn("export_fmu: integrator= is now solver=; the old name will be removed", DeprecationWarning,
                  stacklevel=3)
    if solver not in ("adaptive", integrator):
        raise InputError(f"export_fmu: integrator={shorten(integrator)} and solver={shorten(solver)} contradict "
                         "each other (integrator is solver's earlier name)")
    return integrator


def _checked(model, path, temperature, model_identifier, source, solver, step, fmi, platforms, load=None):
    """export_fmu's arguments, checked before any work: (the model, its source, the temperature, the step)."""
    _args.path(path, "path")
    platforms = _platforms(platforms)
    temperature = _args.number(temperature, "temperature", "degC", none=True)  # finite
    _args.number(load, "load", "N or N m", none=True)
    _args.text(model_identifier, "model_identifier", none=True)
    _args.text(source, "source", none=True)
    _args.text(solver, "solver")
    _args.number(step, "step", "s", none=True, positive=True)  # a number (not '1e-5'), before the model is loaded
    _args.whole(fmi, "fmi")
    if isinstance(model, (str, os.PathLike)):
        source = os.fspath(model)
        model = load_model(model)
    if not isinstance(model, Model):
        raise InputError(f"export_fmu: model must be a Model, a model file or a preset name, got {shorten(model)}")
    if platform.system() != "Linux" or platform.machine() not in ("x86_64", "AMD64"):
        raise InputError(f"FMUs are exported on Linux x86-64 only (where the package builds their binaries); "
                         f"this is {platform.system()} {platform.machine()}")
    if fmi not in FMI_VERSIONS:
        raise InputError(f"export_fmu: fmi = {shorten(fmi)}: the FMI version is 2 or 3")
    binary = binary_path()
    if platforms is None and not binary.is_file():
        raise InputError(f"this installation has no FMU binary ({binary}): reinstall thermofriction on Linux x86-64 "
                         "(the package builds it with CMake)")
    if solver not in SOLVERS:
        raise InputError(f"export_fmu: solver {shorten(solver)}: use one of {', '.join(SOLVERS)}")
    if solver == "realtime":
        if step is None:
            raise InputError("export_fmu: the realtime solver needs its fixed step (step=..., --step SECONDS)")
        step = _check_step(model, step)
    elif step is not None:
        raise InputError("export_fmu: step is the realtime solver's fixed step; the adaptive solver chooses "
                         "its own (give solver='realtime', --solver realtime)")
    return model, source, temperature, step, platforms


def export_fmu(model, path, *, temperature: float | None = None, model_identifier: str | None = None,
               source: str | None = None, solver: str = "adaptive", step: float | None = None,
               fmi: int = 2, platforms=None, integrator: str | None = None,
               estimator: TemperatureEstimator | None = None, load: float | None = None) -> Path | Target:
    """Writes ``model`` as an FMI 2.0 or FMI 3.0 co-simulation FMU to ``path`` (docs/fmu.md), with its C sources
    (``sources/``: an importer compiles them for its own platform) and binaries.

    Parameters
    ----------
    model : Model or str or os.PathLike
        The model: a Model, a model file or a preset name.
    path : str or os.PathLike
        The ``.fmu`` file written (atomically: all of it or nothing).
    temperature : float, optional
        The start value of the temperature input [C] (with a heat model, of the ambient temperature); default
        the model's T_amb, else the low end of the laws' range.
    model_identifier : str, optional
        The binary's name inside the FMU: letters, digits and ``_``, not starting with a digit; default from
        the model's name.
    source : str, optional
        Where the model came from (a file or preset name), for the FMU's description.
    solver : {"adaptive", "realtime"}, default "adaptive"
        "adaptive": the core's error-controlled integrator between communication points; "realtime": fixed
        steps of ``step`` seconds, the core's real-time friction step and semi-implicit Euler for the plant
        (docs/fmu.md#solvers).
    step : float, optional
        The fixed step [s] of the "realtime" solver.
    fmi : {2, 3}, default 2
        The FMI standard's version.
    platforms : list of str, optional
        None (default): the binaries built with the package, linux64 and, when it was built with the MinGW-w64
        cross compiler, win64 (else a NoWindowsBinaryWarning says so); a list of ``"linux64"``, ``"win64"`` to
        build now with this machine's compilers (cc, x86_64-w64-mingw32-gcc); ``[]`` for the sources only.
    integrator : str, optional
        Deprecated: ``solver``'s earlier name.
    estimator : TemperatureEstimator, optional
        Adds the online temperature estimator (docs/fmu.md#temperature-estimator): inputs
        ``measured_friction_force`` (and ``proxy_temperature`` with a proxy; ``ambient_temperature`` without a
        heat model), outputs ``temperature_estimate`` and ``temperature_variance``, its parameters as
        ``estimator.*``; one estimator step per communication step (with a law of the load, at the load input the
        friction reads).
    load : float, optional
        The start value of the load input [N, or N m for a rotary joint] of a model with a law of the load
        (docs/fmu.md#the-load-input); default the middle of its load laws' range of |load|, required without one.
        Ignored by a model without a law of the load (its FMU has no load input).

    Returns
    -------
    pathlib.Path
        The FMU's path.

    Raises
    ------
    InputError
        An argument of the wrong type or value, named; what an FMU cannot carry (a sampled external heat, a
        law with more points than the binary holds), named with what to do; a path that is a folder or cannot
        be written; an unknown platform; a model with a law of the load, no load range and no ``load``.
    ComputationError
        A platform asked for that could not be built, each named with why; nothing is written.

    Warns
    -----
    NoWindowsBinaryWarning
        The installation has no win64 binary: the FMU carries linux64 only.
    """
    solver = _solver(solver, integrator)
    model, source, temperature, step, platforms = _checked(model, path, temperature, model_identifier, source,
                                                           solver, step, fmi, platforms, load)
    _check_exportable(model)
    _args.instance(estimator, TemperatureEstimator, "estimator", "a TemperatureEstimator", none=True)
    identifier = _identifier(model_identifier or model.name or (Path(source).stem if source else "model"))
    if model_identifier is not None and identifier != model_identifier:
        raise InputError(f"model identifier {model_identifier!r}: letters, digits and '_' only, not starting with a "
                         f"digit (e.g. {identifier!r})")
    heat_temperature = temperature if model.heat is None else (
        temperature if temperature is not None else (model.heat.ambient_temperature or 20.0))
    spec = _bridge.model_spec(model, temperature=heat_temperature if model.heat is not None else None)
    load_var, load_range = _load_input(model, load)
    variables = variables_of(model, spec, temperature, step, estimator, load_var)
    tfm = resource_text(model, spec, variables, solver, estimator, load_range)
    guid = "{" + str(uuid.UUID(hashlib.sha256((tfm + identifier).encode()).hexdigest()[:32])) + "}"
    tfm += f"guid {guid}\n"  # the binary refuses an instantiation with another GUID
    sources = source_files(fmi)
    if fmi == 2:
        xml = description_xml2(model, variables, identifier, guid, source, step, sources=c_files(sources))
    else:
        xml = description_xml3(model, variables, identifier, guid, source, step)
        sources["buildDescription.xml"] = build_description(identifier, sources).encode()
    target = path if isinstance(path, Target) else Path(os.fspath(path))
    if isinstance(target, Path) and target.is_dir():
        raise InputError(f"{target}: is a folder; give a file name for the FMU (e.g. {target / (identifier + '.fmu')})")
    _write_fmu(target, identifier, fmi, xml, _binaries(platforms, fmi), tfm, model, sources)
    return target


def _binaries(platforms, fmi) -> dict[str, bytes]:
    """platform -> binary: the ones built with the package (``platforms`` None), or built now."""
    if platforms is not None:
        return build_binaries(platforms, fmi)
    binaries = {name: binary_path(name).read_bytes() for name in prebuilt_platforms()}
    if "win64" not in binaries:
        warnings.warn("this installation has no Windows binary (the package was built without the MinGW-w64 cross "
                      "compiler x86_64-w64-mingw32-gcc): the FMU carries linux64 only (and its C sources); "
                      "platforms=['linux64', 'win64'] (--platforms linux64,win64) builds win64 at export time where "
                      "x86_64-w64-mingw32-gcc is installed", NoWindowsBinaryWarning, stacklevel=3)
    return binaries


def _write_fmu(target, identifier, fmi, xml, binaries, tfm, model, sources):
    """The FMU's zip archive, written atomically: the description, the binaries, the sources, the model as
    resources and the FMI headers' licence."""
    with atomic_write(target, "wb") as fh:
        with zipfile.ZipFile(fh, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", xml)
            for name, data in binaries.items():
                info = zipfile.ZipInfo(f"binaries/{FOLDERS[fmi][name]}/{identifier}.{EXTENSIONS[name]}",
                                       date_time=(2020, 1, 1, 0, 0, 0))
                info.external_attr = 0o755 << 16
                info.compress_type = zipfile.ZIP_DEFLATED
                z.writestr(info, data)
            for name, data in sources.items():
                z.writestr(f"sources/{name}", data)
            z.writestr("resources/model.tfm", tfm)
            z.writestr("resources/model.toml", model.to_toml())
            z.writestr(f"documentation/licenses/fmi{fmi}-headers.txt", _headers_licence(fmi))
            z.writestr("documentation/index.html", _documentation(model))


def _documentation(model) -> str:
    """The FMU's documentation page (FMI: documentation/index.html): the model's name and description and, for a
    fitted model, how it was fitted (its fit record), so that who runs the FMU knows what it was scored on."""
    lines = fit_record_lines(model)
    fitted = ("<h2>How it was fitted</h2><ul>" + "".join(f"<li>{html.escape(x)}</li>" for x in lines) + "</ul>"
              if lines else "<p>Not a fitted model (no fit record).</p>")
    return (f"<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{html.escape(model.name or 'model')}</title>"
            f"</head><body><h1>{html.escape(model.name or 'model')}</h1><p>{html.escape(model.description or '')}</p>"
            f"{fitted}<p>The model file is resources/model.toml.</p></body></html>")


def _headers_licence(fmi: int = 2) -> str:
    version, years = ("2.0.1", "2012-2019") if fmi == 2 else ("3.0.2", "2012-2024")
    return (f"The binary was built with the official FMI {version} headers, (C) 2008-2011 MODELISAR consortium, "
            f"{years} Modelica Association Project \"FMI\", under the 2-Clause BSD License.\n")


def __getattr__(name):
    if name == "INTEGRATORS":  # SOLVERS' earlier name
        warnings.warn("thermofriction.fmu.INTEGRATORS is now SOLVERS", DeprecationWarning, stacklevel=2)
        return SOLVERS
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["export_fmu", "binary_path", "prebuilt_platforms", "default_experiment", "SOLVERS", "FMI_VERSIONS",
           "PLATFORMS", "NoWindowsBinaryWarning"]
