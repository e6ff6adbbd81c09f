"""Dataset folders: a ``dataset.toml`` manifest naming its experiment CSV files
(docs/formats.md#datasets); loading checks everything, saving writes atomically."""

from __future__ import annotations

import contextlib
import dataclasses
import math
import tomllib
import warnings
from pathlib import Path, PurePosixPath

import numpy as np

from .._reading import read_text
from ..results import collecting, emit
from .. import _args
from ..errors import InputError, UnitWarning, shorten, unknown_keys
from ..waveforms import parse_waveform
from .csv import read_experiment_csv
from .command import check_torque_constant
from .force import check_motion_option, force_experiment, is_force_data, is_force_file, units_of
from .matlab import is_matlab, read_force_mat
from .motion import one_motion_warning
from ..plausible import (SUSPICIOUS, displacement_doubt, displacement_problem, input_voltage_problem, kelvin_hint,
                         voltage_problem)
from .experiments import ROLES, TEMPERATURE_RANGE, Dataset, Experiment

_MANIFEST_KEYS = ("name", "description", "motion", "flip_sign", "torque_constant", "experiment")
_EXPERIMENT_KEYS = ("file", "temperature", "role", "description", "input", "struct", "units", "motion", "flip_sign",
                    "torque_constant", "ambient_temperature", "continues", "load")
#: the manifest's keys that apply to force experiments only (data/force.py), at the top (every experiment)
#: or in an [[experiment]] entry
_FORCE_KEYS = ("motion", "flip_sign", "torque_constant")


def is_inside(f: str) -> bool:
    """Whether the manifest path ``f`` is a plain relative path that stays in its folder."""
    rel = PurePosixPath(f.replace("\\", "/"))
    return bool(f) and not (rel.is_absolute() or Path(f).is_absolute() or ".." in rel.parts
                            or f.startswith("~") or (len(f) > 1 and f[1] == ":"))


def check_temperature(T, where):
    # (an int is always finite, and math.isfinite would overflow on one beyond the float range)
    if isinstance(T, bool) or not isinstance(T, (int, float)) or (isinstance(T, float) and not math.isfinite(T)):
        raise InputError(f"{where}: 'temperature' must be a number [C], got {T!r}")
    lo, hi = TEMPERATURE_RANGE
    if not lo <= T <= hi:
        raise InputError(f"{where}: temperature {T!r} C is not plausible (expected {lo:g} to {hi:g} C"
                         f"{kelvin_hint(T)})")
    return float(T)


def _from_zero(time, inp):
    """An experiment logged with a clock's time (it starts later than it lasts, e.g. at 1e6 s or an
    epoch time) is moved to start at zero: the simulation starts there at rest, and far from zero a
    double resolves time too coarsely for the solver (2e-10 s at 1e6 s). The manifest's input moves
    with it when that is exact (a periodic input by a whole number of periods, a step by its
    time); otherwise the time is kept."""
    t0 = float(time[0])
    if not t0 > float(time[-1]) - t0:
        return time, inp
    if inp is not None:
        if inp.period is not None:
            k = round(t0 / inp.period)
            if abs(k * inp.period - t0) > 1e-9 * inp.period:
                return time, inp
        elif inp.kind == "step":
            inp = dataclasses.replace(inp, time=inp.time - t0)
        else:
            return time, inp
    return time - t0, inp


def _force_options(table: dict, where: str, defaults: dict) -> dict:
    """The force experiments' options (``motion``, ``flip_sign``, ``torque_constant``: data/command.py) of a
    manifest table, over ``defaults``."""
    out = dict(defaults)
    if "torque_constant" in table:
        out["torque_constant"] = check_torque_constant(table["torque_constant"], where)
    if "motion" in table:
        out["motion"] = check_motion_option(table["motion"], where)
    if "flip_sign" in table:
        if not isinstance(table["flip_sign"], bool):
            raise InputError(f"{where}: 'flip_sign' must be true or false, got {shorten(table['flip_sign'])}")
        out["flip_sign"] = table["flip_sign"]
    return out


def _load_key(e: dict, where: str):
    """A force experiment's ``load`` [N or N m] (docs/formats.md#loads): a finite number, or None."""
    if "load" not in e:
        return None
    v = e["load"]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise InputError(f"{where}: 'load' must be a number [N, or N m for a joint], got {shorten(v)}")
    return float(v)


def _warm_up_keys(e: dict, where: str, before: list) -> dict:
    """A warm-up record's manifest keys (docs/formats.md#warm-up-records): ``ambient_temperature`` [C] and
    ``continues`` (the file of an earlier entry whose thermal end state this record starts from)."""
    out = {}
    if "ambient_temperature" in e:
        out["ambient_temperature"] = check_temperature(e["ambient_temperature"], where)
    if "continues" in e:
        c = e["continues"]
        if not isinstance(c, str) or c not in [x.file for x in before]:
            raise InputError(f"{where}: 'continues' must name the file of an earlier [[experiment]] entry, got "
                             f"{shorten(c)}")
        out["continues"] = c
    return out


def load_dataset(path, *, motion: str | None = None) -> Dataset:
    """Reads a dataset folder (docs/formats.md): ``dataset.toml`` and the experiment files it lists,
    all checked; any problem is one InputError naming the file (and its line, column or
    ``[[experiment]] N`` entry).

    Parameters
    ----------
    path : str or os.PathLike
        The dataset's folder, or its ``dataset.toml``.
    motion : {"auto", "position", "velocity"}, optional
        What drives the models of force experiments (docs/force-data.md#the-motion-that-drives-the-model);
        given, it overrides the manifest's ``motion`` keys; None: the manifest's, else "auto".

    Returns
    -------
    Dataset
        The experiments (CSV or MATLAB files) in SI units, with their roles ("fit", "validate").

    Raises
    ------
    InputError
        A folder without ``dataset.toml``, a bad manifest key, a file that cannot be read or whose columns,
        units or samples are wrong: one message naming the file and where in it.
    """
    _args.path(path, "path")
    if motion is not None:
        check_motion_option(motion, "motion")
    folder = Path(path)
    if folder.is_dir():
        manifest = folder / "dataset.toml"
    elif folder.name == "dataset.toml" and folder.exists():
        manifest, folder = folder, folder.parent
    elif folder.exists():
        raise InputError(f"{path}: not a dataset folder (a folder with a dataset.toml)")
    else:
        raise InputError(f"{path}: no such dataset folder")
    if not manifest.exists():  # (a FIFO or a device named dataset.toml is refused by the reader)
        from .._io import stale_temporaries
        left = stale_temporaries(folder)
        if left:  # save_dataset removes the manifest first and renames the new one last
            raise InputError(f"{folder}: no dataset.toml, and temporary files of an interrupted write "
                             f"({', '.join(left[:3])}{', ...' if len(left) > 3 else ''}): the dataset was not "
                             f"completely written; write it again")
        raise InputError(f"{folder}: no dataset.toml in this folder")
    try:
        meta = tomllib.loads(read_text(manifest, "dataset manifest (dataset.toml)"))
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{manifest}: TOML syntax error: {e}") from None
    except OSError as e:
        raise InputError(f"{manifest}: cannot read ({e.strerror or e})") from None
    except UnicodeDecodeError as e:
        raise InputError(f"{manifest}: not UTF-8 text ({e.reason} at byte {e.start})") from None
    except RecursionError:  # tomllib recurses once per level of nested arrays or inline tables
        raise InputError(f"{manifest}: TOML nested too deeply") from None
    with collecting() as found:
        data = manifest_dataset(meta, folder, manifest, motion=motion)
    emit(one_motion_warning(found))  # the files whose velocity columns lag alike: said once
    data.sha256 = dataset_sha256(data)
    return data


def manifest_dataset(meta: dict, folder: Path, manifest: Path, *, motion: str | None = None) -> Dataset:
    """The dataset that a manifest's table (``meta``, as TOML reads it) lists, its files in ``folder``, all checked;
    messages name ``manifest``. Apart from :func:`load_dataset` so that ``init`` checks a manifest before it
    writes it (cli/init.py)."""
    unknown = set(meta) - set(_MANIFEST_KEYS)
    if unknown:
        raise InputError(f"{manifest}: {unknown_keys(unknown, _MANIFEST_KEYS)}")
    name = meta.get("name")
    if name is not None and not isinstance(name, str):
        raise InputError(f"{manifest}: 'name' must be a string, got {name!r}")
    description = meta.get("description", "")
    if not isinstance(description, str):
        raise InputError(f"{manifest}: 'description' must be a string, got {description!r}")
    options = _force_options(meta, str(manifest), {"motion": "auto", "flip_sign": False, "torque_constant": None})
    entries = meta.get("experiment")
    if entries is None:
        raise InputError(f"{manifest}: no [[experiment]] entries (a dataset needs at least one)")
    if not isinstance(entries, list) or not entries:
        raise InputError(f"{manifest}: 'experiment' must be a list of [[experiment]] tables (at least one)")
    root = folder.resolve()
    exps = []
    for n, e in enumerate(entries, start=1):
        where = f"{manifest}: [[experiment]] {n}"
        if not isinstance(e, dict):
            raise InputError(f"{where}: must be a table")
        unknown = set(e) - set(_EXPERIMENT_KEYS)
        if unknown:
            raise InputError(f"{where}: {unknown_keys(unknown, _EXPERIMENT_KEYS)}")
        f = e.get("file")
        if f is None:
            raise InputError(f"{where}: missing 'file' (the experiment's CSV, relative to the dataset folder)")
        if not isinstance(f, str) or not f.strip() or not f.isprintable():
            raise InputError(f"{where}: 'file' must be a file name, got {f!r}")
        try:
            target = (folder / f).resolve()
        except (OSError, ValueError, RuntimeError):  # a NUL byte, a name too long, a symlink loop
            target = None
        if target is None or not is_inside(f) or root not in (target, *target.parents):
            raise InputError(f"{where}: file '{f}' must be a relative path inside the dataset folder "
                             f"(no absolute paths, no '..', no symbolic links leading out)")
        role = e.get("role", "fit")
        if role not in ROLES:
            raise InputError(f"{where}: 'role' must be \"fit\" or \"validate\", got {role!r}")
        T = e.get("temperature")
        if T is not None:
            T = check_temperature(T, where)
        desc = e.get("description", "")
        if not isinstance(desc, str):
            raise InputError(f"{where}: 'description' must be a string, got {desc!r}")
        inp = None
        if "input" in e:
            if not isinstance(e["input"], str):
                raise InputError(f"{where}: 'input' must be a waveform spec such as "
                                 f"\"sawtooth:amplitude=30,frequency=5\"")
            try:
                inp = parse_waveform(e["input"])
            except InputError as err:
                raise InputError(f"{where}: {err}") from None
            problem = input_voltage_problem(inp)
            if problem:
                raise InputError(f"{where}: 'input': {problem}")
        opts = _force_options(e, where, options)
        if motion is not None:
            opts["motion"] = motion
        force_cols = _read_force_mat(folder / f, e, where) if is_matlab(folder / f) else None
        if force_cols is not None or is_force_file(folder / f):  # measured motion and friction: data/force.py
            if inp is not None:
                raise InputError(f"{where}: 'input' does not apply to a force experiment (its motion is measured)")
            for key in ("struct", "units"):
                if force_cols is None and key in e:
                    raise InputError(f"{where}: '{key}' applies to MATLAB files (.mat) only; a CSV file declares its "
                                     f"units in its header")
            exps.append(force_experiment(folder / f, f, temperature=T, role=role, description=desc,
                                         from_zero=_from_zero, struct=e.get("struct"), columns=force_cols,
                                         load=_load_key(e, where), **_warm_up_keys(e, where, exps), **opts))
            if "torque_constant" in e and not (exps[-1].column or "").startswith("current"):
                raise InputError(f"{where}: 'torque_constant' applies to a current[A] column; {f} records "
                                 f"{exps[-1].column}")
            continue
        for key in (*_FORCE_KEYS, "ambient_temperature", "continues", "load"):
            if key in e or key in meta:
                raise InputError(f"{where if key in e else manifest}: '{key}' applies to force experiments only "
                                 f"({f} records a voltage and a displacement)")
        cols, headers = _read_experiment(folder / f, e, where)
        for column in ("displacement", "stage_displacement"):  # a parser reads any numbers; a dataset is physics
            if column in cols:
                label, unit = headers[column]
                problem = displacement_problem(cols[column], unit)
                if problem:
                    raise InputError(f"{folder / f}: {label}: {problem}")
                doubt = displacement_doubt(cols[column], unit)
                if doubt:  # (stacklevel: the caller of load_dataset)
                    warnings.warn(f"{SUSPICIOUS}{folder / f}: {label}: {doubt}", UnitWarning, stacklevel=3)
        problem = voltage_problem(cols["voltage"])
        if problem:
            raise InputError(f"{folder / f}: {headers['voltage'][0]}: {problem}")
        cols["time"], inp = _from_zero(cols["time"], inp)
        sig = cols.get("temperature")
        if T is None:
            if sig is None:
                raise InputError(f"{where}: no temperature: give 'temperature' or a temperature[C] column in {f}")
            T = float(np.mean(sig))
        exps.append(Experiment(file=f, time=cols["time"], voltage=cols["voltage"], displacement=cols["displacement"],
                               temperature=T, temperature_signal=sig,
                               stage_displacement=cols.get("stage_displacement"), role=role, description=desc,
                               input=inp, struct=e.get("struct"), headers=headers))
    try:  # one kind of experiment per dataset, and force data in one kind of units (data/force.py)
        if is_force_data(exps):
            units_of(exps)
    except InputError as err:
        raise InputError(f"{manifest}: {err}") from None
    return Dataset(path=folder, name=name, description=description, experiments=exps)


def _read_experiment(path: Path, entry: dict, where: str):
    """An experiment file's columns (SI) and, per column, (where it is, its unit): a CSV file, or a
    MATLAB file (docs/formats.md#matlab-files) with the entry's optional 'struct' and 'units'."""
    from .matlab import is_matlab, read_experiment_mat
    if not is_matlab(path):
        for key in ("struct", "units"):
            if key in entry:
                raise InputError(f"{where}: '{key}' applies to MATLAB files (.mat) only; a CSV file declares its "
                                 f"units in its header")
        cols, headers = read_experiment_csv(path, with_headers=True)
        return cols, {k: (f"column {h}", h.partition("[")[2].rstrip("]")) for k, h in headers.items()}
    struct, units = _mat_options(entry, where)
    with _units_where(path, where):
        return read_experiment_mat(path, struct=struct, units=units, with_headers=True)


def _mat_options(entry: dict, where: str):
    """A MATLAB file's manifest options, 'struct' and 'units', checked."""
    struct, units = entry.get("struct"), entry.get("units")
    if struct is not None and (not isinstance(struct, str) or not struct.isidentifier()):
        raise InputError(f"{where}: 'struct' must be the name of a struct variable in {entry['file']}, got {struct!r}")
    if units is not None and not isinstance(units, dict):
        raise InputError(f"{where}: 'units' must be a table such as {{ displacement = \"um\" }}, got {units!r}")
    return struct, units


@contextlib.contextmanager
def _units_where(path, where):
    """An error in the manifest's 'units' table named by its [[experiment]] entry."""
    try:
        yield
    except InputError as err:
        if str(err).startswith(f"{path}: units:"):  # the manifest's table: say where it is
            raise InputError(f"{where}: {str(err)[len(str(path)) + 2:]}") from None
        raise


def _read_force_mat(path: Path, entry: dict, where: str):
    """A MATLAB file's force experiment columns (data/matlab.py: read_force_mat), or None for an actuator's."""
    struct, units = _mat_options(entry, where)
    with _units_where(path, where):
        return read_force_mat(path, struct=struct, units=units)


def dataset_sha256(data) -> tuple[str, str]:
    """(what was hashed, its SHA-256): for a dataset read from a folder, its files -- the manifest
    and every experiment file, sorted by path -- hashed as ``sha256sum`` lists them and that list
    hashed again (``sha256sum FILES | sha256sum`` in the folder gives the same); otherwise the
    experiments' numbers (time and each recorded signal -- voltage, displacement, force -- as little-endian
    float64, in order). The one definition: fitted models' provenance and the reports' footers. A dataset
    from ``load_dataset`` carries the hash of its files as they were loaded."""
    import hashlib
    import os

    if getattr(data, "sha256", None) is not None:  # hashed when it was loaded
        return data.sha256
    folder = getattr(data, "path", None)
    experiments = list(getattr(data, "experiments", data))
    if folder is not None:
        files = sorted({"dataset.toml", *(e.file for e in experiments)})
        if all(os.path.isfile(os.path.join(folder, f)) for f in files):
            listing = hashlib.sha256()
            for f in files:
                h = hashlib.sha256()
                with open(os.path.join(folder, f), "rb") as fh:
                    for block in iter(lambda: fh.read(1 << 20), b""):
                        h.update(block)
                listing.update(f"{h.hexdigest()}  {f}\n".encode())
            return str(folder), listing.hexdigest()
    h = hashlib.sha256()
    for e in experiments:
        for name in ("time", "voltage", "displacement", "force"):
            a = getattr(e, name, None)
            if a is not None:
                h.update(np.ascontiguousarray(a, dtype="<f8").tobytes())
    return "experiments in memory", h.hexdigest()
