"""Saving a dataset folder (docs/formats.md#datasets): the experiment files and ``dataset.toml``, published
together, atomically."""

from __future__ import annotations

import tomllib
from pathlib import Path, PurePosixPath

import numpy as np
import tomli_w

from .. import _args
from .._io import atomic_write
from ..errors import InputError
from .experiments import Dataset
from .files import is_inside
from .force import ForceExperiment
from .matlab import force_mat_variables

def check_dataset_folder(folder, overwrite=False, hint="overwrite=True"):
    """Before any work: refuses (exit 2) a path that is not a folder, a folder that already holds a
    dataset (unless ``overwrite``) and a place where no file can be created."""
    from .._io import OutputError, check_folder
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise OutputError(f"{folder}: cannot create the dataset folder (a file of that name exists)")
    if (folder / "dataset.toml").exists() or (folder / "dataset.toml").is_symlink():
        if not overwrite:
            raise OutputError(f"{folder}: already holds a dataset (dataset.toml); give {hint} to replace it")
    check_folder(folder)


def _listed_files(folder: Path) -> list[Path]:
    """The files an existing manifest lists (inside the folder), or [] when it cannot be read."""
    try:
        meta = tomllib.loads((folder / "dataset.toml").read_text(encoding="utf-8"))
        entries = meta.get("experiment", [])
        files = [e.get("file") for e in entries if isinstance(e, dict)]
    except (OSError, UnicodeDecodeError, ValueError, RecursionError, AttributeError, TypeError):
        return []
    root = folder.resolve()
    out = []
    for f in files:
        if isinstance(f, str) and f.strip() and is_inside(f):
            try:
                target = (folder / f).resolve()
            except (OSError, ValueError, RuntimeError):
                continue
            if root in target.parents:
                out.append(folder / f)
    return out


def save_dataset(dataset: Dataset, folder, *, overwrite: bool = False) -> Path:
    """Writes ``folder`` (created if needed): one CSV per experiment (``time[s],voltage[V],
    displacement[um]``, and ``temperature[C]`` and ``stage_displacement[um]`` where present, ten
    significant digits; a force experiment's own columns, every digit, a warm-up record's
    ``ambient_temperature[C]`` and ``proxy_temperature[C]`` among them, and its ``continues`` in the
    manifest) and ``dataset.toml``, and sets ``dataset.path`` to it.

    A folder that already holds a dataset is refused unless ``overwrite``; then the files its old
    manifest lists and the new one does not are removed. The files are published as a set: every
    file is written to a temporary one first; then the old manifest is removed, the CSV files are
    renamed into place and the manifest comes last. A write interrupted between those renames
    leaves a folder without ``dataset.toml``, which ``load_dataset`` refuses, naming the
    temporary files left; on an error nothing is changed and folders created for it are removed.

    Parameters
    ----------
    dataset : Dataset
        The experiments to write (``synthesize``'s, or a loaded dataset).
    folder : str or os.PathLike
        The dataset folder written.
    overwrite : bool, default False
        Replace a dataset already in ``folder``.

    Returns
    -------
    pathlib.Path
        The folder.

    Raises
    ------
    InputError
        An argument of the wrong type, named; a folder holding a dataset without ``overwrite``; a folder that
        cannot be written (``OutputError``, an InputError, naming it).
    """
    from .._io import publish_together
    _args.instance(dataset, Dataset, "dataset", "a Dataset")
    _args.path(folder, "folder")
    _args.flag(overwrite, "overwrite")
    folder = Path(folder)
    files = [e.file for e in dataset.experiments]
    if not files:
        raise InputError("the dataset has no experiments to save")
    for f in files:
        if not isinstance(f, str) or not is_inside(f):
            raise InputError(f"experiment file '{f}' must be a relative path inside the dataset folder")
    # several runs may share one MATLAB file, each in its own struct
    dup = sorted({f for f in files if files.count(f) > 1 and not _structs_apart(dataset.experiments, f)})
    if dup:
        raise InputError(f"two experiments would be written to the same file: {', '.join(dup)}")
    if any(PurePosixPath(f.replace("\\", "/")) == PurePosixPath("dataset.toml") for f in files):
        raise InputError("an experiment file cannot be named dataset.toml (the manifest)")
    check_dataset_folder(folder, overwrite)
    created = _make_folders(folder, files)  # folders made here, removed again if the writing fails
    manifest = folder / "dataset.toml"
    try:
        with publish_together() as staged:
            entries = []
            mat = {}  # MATLAB file -> its variables, written once all its runs are in
            for e in dataset.experiments:
                entries.append(_write_experiment(e, folder, mat))
            for f, variables in mat.items():
                from .matlab import save_mat
                save_mat(folder / f, variables)
            meta = {}
            if dataset.name:
                meta["name"] = dataset.name
            if dataset.description:
                meta["description"] = dataset.description
            meta["experiment"] = entries
            if manifest.exists() or manifest.is_symlink():
                new = {(folder / f).resolve() for f in files}
                old = [p for p in _listed_files(folder) if p.resolve() not in new]
                from .._io import refuse_inputs, Target
                refuse_inputs([Target(p) for p in old if p.is_file()], staged.inputs)
                staged.remove_before.append(manifest)  # no manifest while the files change
                staged.remove_after.extend(old)        # the old dataset's files the new one does not list
            with atomic_write(manifest, "w") as fh:  # staged last: renamed last
                fh.write(tomli_w.dumps(meta))
    except BaseException:
        _remove_folders(created)
        raise
    dataset.path = folder
    return folder


def _write_experiment(e, folder, mat) -> dict:
    """Writes one experiment (a CSV file, or its variables into ``mat`` for a MATLAB file written later);
    returns its [[experiment]] table."""
    if isinstance(e, ForceExperiment) and _is_mat(e.file):
        if e.struct:
            mat.setdefault(e.file, {})[e.struct] = force_mat_variables(e)
        else:
            mat[e.file] = force_mat_variables(e)
        return _entry(e)
    if isinstance(e, ForceExperiment):  # measured motion and friction: its own columns
        unit = ("rad", "rad/s") if e.rotary else ("m", "m/s")
        cols = {"time[s]": e.time, f"position[{unit[0]}]": e.displacement}
        if e.velocity is not None:
            cols[f"velocity[{unit[1]}]"] = e.velocity
        cols[e.force_column] = e.force  # a command read from a current is written in N or N m
        if e.temperature_signal is not None:
            cols["temperature[C]"] = e.temperature_signal
        for key in ("ambient_temperature", "proxy_temperature"):  # a warm-up record's (formats.md#warm-up-records)
            if getattr(e, key) is not None:
                cols[f"{key}[C]"] = getattr(e, key)
        with atomic_write(folder / e.file, "w", newline="") as fh:
            fh.write(",".join(cols) + "\n")
            np.savetxt(fh, np.column_stack([np.asarray(v, float) for v in cols.values()]), delimiter=",",
                       fmt="%.17g")  # every digit: a measured record read back is the same record
        return _entry(e)
    if _is_mat(e.file):
        run = _mat_variables(e)
        if e.struct:
            mat.setdefault(e.file, {})[e.struct] = run
        else:
            mat[e.file] = run
        return _entry(e)
    cols = {"time[s]": e.time, "voltage[V]": e.voltage,
            "displacement[um]": np.asarray(e.displacement) * 1e6}
    if e.temperature_signal is not None:
        cols["temperature[C]"] = e.temperature_signal
    if e.stage_displacement is not None:
        cols["stage_displacement[um]"] = np.asarray(e.stage_displacement) * 1e6
    with atomic_write(folder / e.file, "w", newline="") as fh:
        fh.write(",".join(cols) + "\n")
        np.savetxt(fh, np.column_stack([np.asarray(v, float) for v in cols.values()]), delimiter=",",
                   fmt="%.10g")
    return _entry(e)


def _make_folders(folder, files) -> list:
    """The dataset folder and its experiment files' subfolders, where missing; returns those made."""
    created = []
    try:
        for d in [folder] + [(folder / f).parent for f in files]:
            missing = []
            while not d.exists():
                missing.append(d)
                d = d.parent
            for m in reversed(missing):
                m.mkdir()
                created.append(m)
    except OSError as err:
        _remove_folders(created)
        raise InputError(f"{folder}: cannot create the dataset folder ({err.strerror or err})") from None
    return created


def _is_mat(f):
    from .matlab import is_matlab
    return is_matlab(f)


def _structs_apart(experiments, f):
    """Whether the experiments written to file ``f`` can share it: a MATLAB file, each run in its own struct."""
    structs = [e.struct for e in experiments if e.file == f]
    return _is_mat(f) and all(structs) and len(set(structs)) == len(structs)


def _mat_variables(e) -> dict:
    """An experiment as MATLAB variables (docs/formats.md#matlab-files), lengths in um as in the CSV files."""
    out = {"time": np.asarray(e.time, float), "voltage": np.asarray(e.voltage, float),
           "displacement_um": np.asarray(e.displacement, float) * 1e6}
    if e.temperature_signal is not None:
        out["temperature"] = np.asarray(e.temperature_signal, float)
    if e.stage_displacement is not None:
        out["stage_displacement_um"] = np.asarray(e.stage_displacement, float) * 1e6
    return out


def _entry(e) -> dict:
    """An experiment's [[experiment]] table."""
    warm = getattr(e, "warm_up", False)  # no contact temperature: its ambient is in its file, not a key
    entry = {"file": e.file, **({} if warm else {"temperature": float(e.temperature)}), "role": e.role}
    if warm and e.continues is not None:
        entry["continues"] = e.continues
    if getattr(e, "struct", None):
        entry["struct"] = e.struct
    if e.description:
        entry["description"] = e.description
    if e.input is not None and not isinstance(e, ForceExperiment):  # a force run's motion is its record
        entry["input"] = e.input.spec()
    if isinstance(e, ForceExperiment) and e.velocity is not None:  # what drove it, as it was loaded
        entry["motion"] = e.motion_source
    if isinstance(e, ForceExperiment) and e.load is not None:  # the run's constant load (a column's mean)
        entry["load"] = float(e.load)
    return entry


def _remove_folders(created):
    for d in reversed(created):
        try:
            d.rmdir()  # only if still empty
        except OSError:
            pass


__all__ = ["save_dataset", "check_dataset_folder"]
