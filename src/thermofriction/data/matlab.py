"""MATLAB files (docs/formats.md#matlab-files): experiments read from ``.mat`` files, simulation results
written to them.

An experiment is a set of vectors named like the CSV columns, the unit a suffix of the name
(``time``, ``voltage``, ``displacement_um``, ``temperature_C``: the CSV header ``displacement[um]``
becomes ``displacement_um``; no suffix means the SI unit). They are the file's variables, or the
fields of one struct in it (the manifest's ``struct = "run1"``), so that one file can hold several
runs. Other variables are ignored: a MATLAB workspace saved whole carries more than the run.
SciPy reads MATLAB's formats up to v7; a v7.3 file (HDF5) gets a message saying how to save it
instead."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import InputError, shorten
from .. import _args
from .experiments import _SI, _UNITS, MIN_SAMPLES, REQUIRED, max_rows, MAX_ROWS_ENV
from . import force
from .force import EXAMPLE, check_force_columns_present, check_force_values, column_key, units_kind

#: longest first, so that stage_displacement_um is not read as a "displacement" with unit "stage..."
_COLUMNS = sorted(_UNITS, key=len, reverse=True)
_HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"


def is_matlab(path) -> bool:
    return str(path).lower().endswith(".mat")


def column_of(variable: str):
    """(column, unit) that a variable's name declares (the unit possibly unknown), or None for a
    variable that is not a column."""
    for name in _COLUMNS:
        if variable == name:
            return name, _SI[name]
        if variable.startswith(name + "_"):
            return name, variable[len(name) + 1:]
    return None


def _units_of(name):
    return ", ".join(name + "_" + u for u in _UNITS[name] if u.isascii())


def _load(path: Path) -> dict:
    """The file's variables (scipy.io.loadmat), or one InputError naming the file."""
    import scipy.io
    try:
        with open(path, "rb") as fh:
            head = fh.read(512 + len(_HDF5_MAGIC))
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder, not a MATLAB file") from None
    except OSError as e:
        raise InputError(f"{path}: cannot read ({e.strerror or e})") from None
    if not head:  # an interrupted copy, a file created and never written
        raise InputError(f"{path}: empty file (0 bytes): not a MATLAB file (an interrupted copy?)")
    if head[512:].startswith(_HDF5_MAGIC) or head.startswith(_HDF5_MAGIC):
        raise InputError(f"{path}: a MATLAB v7.3 (HDF5) file, which thermofriction does not read: save it with "
                         f"save('{path.name}', ..., '-v7') in MATLAB, or write the run as CSV "
                         f"(docs/formats.md#experiment-files)")
    try:
        return scipy.io.loadmat(path, squeeze_me=False, struct_as_record=True, mat_dtype=False)
    except NotImplementedError as e:  # SciPy's word for v7.3
        raise InputError(f"{path}: not readable as a MATLAB file up to v7 ({e}); save it with '-v7' in MATLAB "
                         f"or write the run as CSV") from None
    except Exception as e:  # noqa: BLE001 - whatever SciPy's reader meets in damaged bytes (MatReadError,
        # zlib.error from a corrupted compressed v7 stream, ValueError, ...), the file is what is wrong
        raise InputError(f"{path}: not a readable MATLAB file, damaged or truncated? "
                         f"({shorten(str(e) or type(e).__name__)})") from None


def _vector(path, label, value) -> np.ndarray:
    """A real numeric vector (1xN or Nx1) as float64, or one InputError naming the variable."""
    a = value
    if not isinstance(a, np.ndarray):
        raise InputError(f"{path}: {label}: must be a numeric vector, got {shorten(a)}")
    if a.dtype.kind not in "iuf":
        what = {"b": "logical", "c": "complex", "U": "text (char)", "S": "text (char)", "O": "a cell array or struct",
                "V": "a struct"}.get(a.dtype.kind, a.dtype.name)
        raise InputError(f"{path}: {label}: must be a real numeric vector (double), got {what}")
    if a.ndim > 2 or (a.ndim == 2 and min(a.shape) > 1):
        raise InputError(f"{path}: {label}: must be a vector (1xN or Nx1), got a {'x'.join(map(str, a.shape))} array")
    return a.reshape(-1).astype(float)


def run_structs(path) -> dict:
    """{name: its field names} of the struct variables of a MATLAB file that each hold a run
    (docs/formats.md#matlab-files), sorted by name, when the file holds its runs that way: it has no ``time``
    variable of its own, and these structs have a ``time`` field (a struct array too: reading it says why it is
    refused). {} for a file of plain variables (one run) or one without such structs; a file that cannot be
    read raises InputError naming it."""
    variables = {k: v for k, v in _load(Path(path)).items() if not k.startswith("__")}
    if any((column_of(v) or ("",))[0] == "time" for v in variables):
        return {}
    out = {}
    for name in sorted(variables):
        value = variables[name]
        fields = value.dtype.names if isinstance(value, np.ndarray) else None
        if fields and any((column_of(f) or ("",))[0] == "time" for f in fields):
            out[name] = tuple(fields)
    return out


def read_experiment_mat(path, struct: str | None = None, units: dict | None = None, with_headers: bool = False):
    """Reads one experiment from a MATLAB file into SI arrays, as ``read_experiment_csv`` does
    from a CSV file: a dict with ``time``, ``voltage``, ``displacement`` and, where present,
    ``temperature`` and ``stage_displacement`` (docs/formats.md#matlab-files).

    Parameters
    ----------
    path : str or os.PathLike
        The ``.mat`` file.
    struct : str, optional
        The name of a struct variable whose fields hold the run; default the file's variables.
    units : dict, optional
        Units of columns whose variable has no unit suffix (the manifest's ``units`` table, e.g.
        ``{"displacement": "um"}``); a suffix that disagrees with it is an error.
    with_headers : bool, default False
        Also return, per column, (where the file holds it, the unit its header declared), for a dataset's checks.

    Returns
    -------
    dict
        Column -> numpy.ndarray in SI units; with ``with_headers``, (that dict, the headers).

    Raises
    ------
    InputError
        A file that cannot be read, a missing struct or variable, a bad unit or value, named with the file and
        the variable.
    """
    from .csv import check_columns

    _args.path(path, "path")
    _args.text(struct, "struct", none=True)
    _args.instance(units, dict, "units", "a dict (column -> unit)", none=True)
    _args.flag(with_headers, "with_headers")
    path = Path(path)
    variables = {k: v for k, v in _load(path).items() if not k.startswith("__")}
    origin = "variable"
    if struct is not None:
        if struct not in variables:
            found = ", ".join(sorted(variables)) or "none"
            raise InputError(f"{path}: no variable '{struct}' (the manifest's 'struct'; variables: {found})")
        s = variables[struct]
        if not (isinstance(s, np.ndarray) and s.dtype.names):
            raise InputError(f"{path}: variable '{struct}': must be a struct (the manifest's 'struct' names one), "
                             f"got {'a ' + s.dtype.name + ' array' if isinstance(s, np.ndarray) else shorten(s)}")
        if s.size != 1:
            raise InputError(f"{path}: variable '{struct}': must be one struct, got a "
                             f"{'x'.join(map(str, s.shape))} struct array (give each run its own struct)")
        rec = s.reshape(-1)[0]
        variables = {name: rec[name] for name in s.dtype.names}
        origin = f"struct '{struct}', field"
    units = dict(units or {})
    for name, unit in units.items():
        if name not in _UNITS:
            raise InputError(f"{path}: units: unknown column '{shorten(name)}' (columns: {', '.join(_UNITS)})")
        if not isinstance(unit, str) or unit not in _UNITS[name]:
            raise InputError(f"{path}: units: unknown unit {shorten(unit)} for {name} "
                             f"(one of: {', '.join(u for u in _UNITS[name] if u.isascii())})")
    found, odd = {}, {}  # column -> (variable, unit); column -> why a variable of its name is not it
    for var in variables:
        col = column_of(var)
        if col is None:
            continue
        name, unit = col
        if unit not in _UNITS[name]:  # e.g. displacement_inch, time_offset: an error only if nothing else is the column
            odd.setdefault(name, f"'{var}': unknown unit {shorten(unit)} for {name} (one of: {_units_of(name)})")
            continue
        if name in found:
            raise InputError(f"{path}: {origin} '{var}' and '{found[name][0]}' are both the {name} (give one)")
        if var == name and name in units:
            unit = units[name]
        elif name in units and units[name] != unit:
            raise InputError(f"{path}: {origin} '{var}' declares {unit}, the manifest's units {units[name]}: "
                             f"give the unit once")
        found[name] = (var, unit)
    for name, why in odd.items():
        if name not in found:
            raise InputError(f"{path}: {origin} {why}")
    missing = [r for r in REQUIRED if r not in found]
    if missing:
        names = ", ".join(sorted(variables)) or "none"
        raise InputError(f"{path}: {'struct ' + repr(struct) + ': ' if struct else ''}missing "
                         f"{', '.join(missing)} (an experiment needs vectors time, voltage and displacement, "
                         f"a unit suffix where not SI, e.g. displacement_um; found: {shorten(names)})")
    raw = {}
    for name, (var, unit) in found.items():
        raw[name] = _vector(path, f"{origin} '{var}'", variables[var])
    n = len(raw["time"])
    for name, a in raw.items():
        if len(a) != n:
            raise InputError(f"{path}: {origin} '{found[name][0]}' has {len(a)} values, '{found['time'][0]}' "
                             f"{n}: the vectors of a run must have one value per sample")
    limit = max_rows()
    if n > limit:
        raise InputError(f"{path}: {n} samples, more than the limit of {limit}: downsample the run, or raise the "
                         f"limit with the environment variable {MAX_ROWS_ENV}=N")
    if n < MIN_SAMPLES:
        raise InputError(f"{path}: {n} sample{'s' if n != 1 else ''}; an experiment needs at least "
                         f"{MIN_SAMPLES} samples")

    def where(name, row, short=False):
        return f"element {row + 1}" if short else f"{origin} '{found[name][0]}', element {row + 1}"

    out = check_columns(path, raw, {name: _UNITS[name][unit] for name, (_, unit) in found.items()}, where)
    if with_headers:
        return out, {name: (f"{origin} '{var}'", unit) for name, (var, unit) in found.items()}
    return out


def matlab_name(header: str) -> str:
    """A CSV header such as ``velocity[m/s]`` as a MATLAB variable name: ``velocity_m_per_s``."""
    name, _, unit = header.partition("[")
    unit = unit.rstrip("]").replace("/", "_per_").replace(" ", "_")
    return re.sub(r"\W", "_", f"{name}_{unit}" if unit else name)


def save_mat(path, variables: dict):
    """Writes MATLAB variables (v5 format, readable by MATLAB and Octave) atomically."""
    import scipy.io

    from .._io import atomic_write
    with atomic_write(path, "wb") as fh:
        scipy.io.savemat(fh, variables, do_compression=True, oned_as="column")


# -- force (torque) experiments -------------------------------------------------------------------

def _force_suffixes() -> dict:
    """column -> {variable suffix: unit} for force experiments: the CSV units as ``matlab_name`` spells them
    (``N*m`` -> ``N_m``, ``rad/s`` -> ``rad_per_s``), ASCII only."""
    out = {}
    for name, units in force._UNITS.items():
        out[name] = {matlab_name(f"x[{u}]")[2:]: u for u in units if u.isascii()}
    return out


def _force_column_of(variable: str, suffixes: dict):
    """(column, unit or None for an unknown suffix, the suffix) that a variable's name declares, or None."""
    for name in sorted(suffixes, key=len, reverse=True):
        if variable == name:
            return name, force._SI[name], ""
        if variable.startswith(name + "_"):
            suffix = variable[len(name) + 1:]
            return name, suffixes[name].get(suffix), suffix
    return None


def _run_variables(path, variables: dict, struct):
    """The run's variables (the file's, or the fields of struct ``struct``) and how to name one."""
    if struct is None:
        return variables, "variable"
    if struct not in variables:
        found = ", ".join(sorted(variables)) or "none"
        raise InputError(f"{path}: no variable '{struct}' (the manifest's 'struct'; variables: {found})")
    s = variables[struct]
    if not (isinstance(s, np.ndarray) and s.dtype.names):
        raise InputError(f"{path}: variable '{struct}': must be a struct (the manifest's 'struct' names one), "
                         f"got {'a ' + s.dtype.name + ' array' if isinstance(s, np.ndarray) else shorten(s)}")
    if s.size != 1:
        raise InputError(f"{path}: variable '{struct}': must be one struct, got a "
                         f"{'x'.join(map(str, s.shape))} struct array (give each run its own struct)")
    rec = s.reshape(-1)[0]
    return {name: rec[name] for name in s.dtype.names}, f"struct '{struct}', field"


def read_force_mat(path, struct: str | None = None, units: dict | None = None, *, variables=None) -> dict | None:
    """Reads one force (torque) experiment from a MATLAB file into SI arrays, as
    :func:`thermofriction.data.force.read_force_csv` does from a CSV file: a dict with ``time``, ``position``,
    ``force``, ``rotary``, ``headers``, ``units`` (key -> the unit read) and, where present, ``velocity`` and
    ``temperature``. The vectors are named as the CSV columns with the unit a suffix (``time``, ``position_rad``, ``velocity_deg_per_s``,
    ``friction_torque_N_m``, ``friction_force_mN``, ``temperature``; no suffix: SI), the file's variables or
    the fields of struct ``struct``; ``units`` gives units of variables without a suffix (the manifest's table).

    Returns None when the run holds no force variable (a ``friction_force`` or ``friction_torque``, or a
    ``position`` or ``velocity`` without a ``voltage``): an actuator's run, for :func:`read_experiment_mat`.
    ``variables``: the file's variables when already loaded."""
    FORCE_UNITS = force._UNITS
    path = Path(path)
    if variables is None:
        variables = {k: v for k, v in _load(path).items() if not k.startswith("__")}
    run, origin = _run_variables(path, variables, struct)
    suffixes = _force_suffixes()
    columns = {v: c for v in run if (c := _force_column_of(v, suffixes)) is not None}
    names = {c[0] for c in columns.values()}
    voltage = any((column_of(v) or ("",))[0] == "voltage" for v in run)
    if not ({"friction_force", "friction_torque"} & names or ({"position", "velocity"} & names and not voltage)):
        return None
    units = dict(units or {})
    for name, unit in units.items():
        if name not in FORCE_UNITS:
            raise InputError(f"{path}: units: unknown column '{shorten(name)}' (columns: {', '.join(FORCE_UNITS)})")
        if not isinstance(unit, str) or unit not in FORCE_UNITS[name]:
            raise InputError(f"{path}: units: unknown unit {shorten(unit)} for {name} "
                             f"(one of: {', '.join(u for u in FORCE_UNITS[name] if u.isascii())})")
    found, odd = {}, {}  # key -> (variable, column, unit); key -> why a variable of its name is not it
    for var, (name, unit, suffix) in columns.items():
        key = column_key(name)
        if unit is None:
            odd.setdefault(key, f"'{var}': unknown unit suffix {shorten(suffix)} for {name} (one of: "
                                f"{', '.join(name + '_' + s for s in suffixes[name])})")
            continue
        if key in found:
            raise InputError(f"{path}: {origin} '{var}' and '{found[key][0]}' are both the {key} (give one)")
        if var == name and name in units:
            unit = units[name]
        elif name in units and units[name] != unit:
            raise InputError(f"{path}: {origin} '{var}' declares {unit}, the manifest's units {units[name]}: "
                             f"give the unit once")
        found[key] = (var, name, unit)
    for key, why in odd.items():
        if key not in found:
            raise InputError(f"{path}: {origin} {why}")
    mat_example = "time, position_rad, velocity_rad_per_s, friction_torque_N_m"
    check_force_columns_present(path, list(found), f"{'struct ' + repr(struct) + ': ' if struct else ''}",
                                f"{EXAMPLE}, as MATLAB variables {mat_example}")
    raw = {key: _vector(path, f"{origin} '{var}'", run[var]) for key, (var, _, _) in found.items()}
    n = len(raw["time"])
    for key, a in raw.items():
        if len(a) != n:
            raise InputError(f"{path}: {origin} '{found[key][0]}' has {len(a)} values, '{found['time'][0]}' "
                             f"{n}: the vectors of a run must have one value per sample")
    limit = max_rows()
    if n > limit:
        raise InputError(f"{path}: {n} samples, more than the limit of {limit}: downsample the run, or raise the "
                         f"limit with the environment variable {MAX_ROWS_ENV}=N")
    kinds = {}
    out = {}
    for key, (var, name, unit) in found.items():
        scale, kind = FORCE_UNITS[name][unit]
        if kind is not None:
            kinds[f"'{var}' ({unit})" if var == name else f"'{var}'"] = kind
        out[key] = raw[key] * scale
    rotary = units_kind(path, kinds, "")
    check_force_values(path, out, lambda key, row: f"{origin} '{found[key][0]}', element {row + 1}",
                       lambda row: f"element {row + 1}")
    out["rotary"] = rotary
    out["headers"] = {key: f"{origin} '{var}'" for key, (var, _, _) in found.items()}
    out["units"] = {key: unit for key, (_, _, unit) in found.items()}
    return out


def force_mat_variables(e) -> dict:
    """A force experiment as MATLAB variables, SI with the unit a suffix as ``matlab_name`` spells it:
    ``time``, ``position_rad`` (``position_m``), ``velocity_rad_per_s`` (``velocity_m_per_s``) when recorded,
    ``friction_torque_N_m`` (``friction_force_N``), ``temperature`` when recorded, a warm-up record's
    ``ambient_temperature`` and ``proxy_temperature`` [C]."""
    rot = e.rotary
    out = {"time": np.asarray(e.time, float),
           "position_rad" if rot else "position_m": np.asarray(e.displacement, float)}
    if e.velocity is not None:
        out["velocity_rad_per_s" if rot else "velocity_m_per_s"] = np.asarray(e.velocity, float)
    kind = "command" if getattr(e, "measured_quantity", "friction") == "command" else "friction"
    out[f"{kind}_torque_N_m" if rot else f"{kind}_force_N"] = np.asarray(e.force, float)
    if e.temperature_signal is not None:
        out["temperature"] = np.asarray(e.temperature_signal, float)
    for key in ("ambient_temperature", "proxy_temperature"):  # a warm-up record's (formats.md#warm-up-records)
        if getattr(e, key, None) is not None:
            out[key] = np.asarray(getattr(e, key), float)
    return out


__all__ = ["read_experiment_mat", "read_force_mat", "force_mat_variables", "is_matlab", "save_mat",
           "matlab_name"]
