"""Fleet identification: one identification per dataset of a production batch (each on a Dask
worker), and a summary of the fleet: each parameter's distribution across the actuators, the
actuators whose values stand out, the Model I law kinds chosen, and the datasets that failed and why.

    fleet = tf.identify_fleet(["unit-001", "unit-002", ...], method="model-i")
    fleet.fits["unit-001"].model, fleet.failures, fleet.summary()
    fleet.write("fleet-out")      # NAME.toml + NAME.json per dataset, fleet.json, fleet.csv

Datasets are read here, in the process that asks, and sent to the workers, so a cluster needs no
shared file system. Each identification is seeded (``seed``) and independent of the others: the
fleet's results do not depend on where they ran.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
import os
from pathlib import Path

import numpy as np

from .. import _io
from .. import _args
from ..errors import InputError, ThermofrictionError, shorten
from ..models import PRESETS, Model, load_model
from ..results import Result, Summary, heading, lines, table
from .cluster import Runner, check_options
from .figures import fleet_figure

#: modified z-score above which a value is an outlier (Iglewicz & Hoaglin 1993: 0.6745 (x - median) / MAD)
OUTLIER_Z = 3.5
SUMMARY_FILES = ("fleet.json", "fleet.csv")


def fleet_datasets(paths) -> list[Path] | None:
    """The dataset folders of a fleet, or None when ``paths`` is one dataset (the single path).

    A fleet is two or more paths, or one folder without a dataset.toml whose sub-folders hold
    datasets (each sub-folder with a dataset.toml, in name order).

    Parameters
    ----------
    paths : str or os.PathLike or sequence of them
        The paths given (the command line's DATASET arguments).

    Returns
    -------
    list of pathlib.Path or None

    Raises
    ------
    None
        Nothing is checked: a folder that cannot be read is taken as one dataset (None), whose loading says why.
    """
    if isinstance(paths, (str, os.PathLike)):
        paths = [paths]
    paths = [Path(p) for p in paths]
    if len(paths) > 1:
        return paths
    if len(paths) == 1:
        p = paths[0]
        try:
            if p.is_dir() and not (p / "dataset.toml").exists():
                subs = sorted(d for d in p.iterdir() if d.is_dir() and (d / "dataset.toml").is_file())
                if subs:
                    return subs
        except OSError:
            return None
    return None


def _names(paths) -> list[str]:
    """A file-safe name per dataset (its folder's name), made unique with -2, -3, ..."""
    names, used = [], set()
    for p in paths:
        stem = Path(os.path.abspath(p)).name or "dataset"
        stem = "".join(c if c.isalnum() or c in "-_.+" else "_" for c in stem).lstrip(".") or "dataset"
        name, k = stem, 1
        while name in used or name + ".json" in SUMMARY_FILES or name == "fleet":
            k += 1
            name = f"{stem}-{k}"
        used.add(name)
        names.append(name)
    return names


def output_files(folder, datasets) -> list[str]:
    """The files :meth:`FleetResult.write` may write into ``folder`` for these datasets (folders or
    Dataset objects): NAME.toml and NAME.json per dataset, fleet.json and fleet.csv."""
    paths = [getattr(d, "path", d) for d in datasets]
    names = _names([p if p is not None else (getattr(d, "name", None) or "dataset") for p, d in zip(paths, datasets)])
    return ([os.path.join(folder, f"{n}{ext}") for n in names for ext in (".toml", ".json")]
            + [os.path.join(folder, f) for f in SUMMARY_FILES])


def input_files(datasets) -> list[str]:
    """Every file the fleet reads: each dataset folder's manifest and the experiment files it lists (read
    from the manifest only; a manifest that cannot be read has no other files to protect)."""
    import tomllib

    files = []
    for d in datasets:
        folder = getattr(d, "path", d)
        if folder is None:
            continue
        manifest = os.path.join(folder, "dataset.toml")
        files.append(manifest)
        try:
            with open(manifest, "rb") as fh:
                entries = tomllib.load(fh).get("experiment", [])
        except (OSError, ValueError, RecursionError):  # (the dataset's own error is reported when it is read)
            continue
        for e in entries if isinstance(entries, list) else []:
            f = e.get("file") if isinstance(e, dict) else None
            if isinstance(f, str) and f:
                files.append(os.path.join(folder, f))
    return files


def refuse_overwriting_inputs(folder, datasets, option="-o"):
    """Exit 2 before any identification when an output in ``folder`` would be one of the fleet's input
    files (a dataset folder named ``dataset`` with ``-o`` that folder: its ``dataset.toml``), the same file
    by device and inode."""
    targets = [_io.Target(f, label=f"{option} {folder}: {os.path.basename(f)}") for f in output_files(folder, datasets)
               if os.path.isdir(folder)]
    _io.refuse_inputs(targets, input_files(datasets))


def _identify_one(data, method, init, kw):
    """Runs on a worker: ("ok", FitResult) or ("failed", reason). Never raises for a bad dataset."""
    from ..identification import identify
    try:
        return "ok", identify(data, method, init=init, **kw)
    except ThermofrictionError as e:
        return "failed", str(e)
    except Exception as e:  # noqa: BLE001 - one actuator's surprise must not stop the fleet
        return "failed", f"{type(e).__name__}: {e}"


@dataclasses.dataclass(eq=False)
class FleetResult(Result):
    """``names`` in the order given; ``fits`` name -> FitResult; ``failures`` name -> reason;
    ``paths`` name -> the dataset's folder.

    Parameters
    ----------
    method : str
        The identification method.
    names : list of str
        The datasets' names, in the order given.
    paths : dict
        Name -> the dataset's folder.
    fits : dict
        Name -> FitResult, for the datasets identified.
    failures : dict
        Name -> the reason a dataset could not be read or identified.
    wall_time : float, default nan
        The run's duration [s].
    where : str, default ""
        Where the tasks ran (threads, a Dask cluster's address).
    """

    method: str
    names: list
    paths: dict
    fits: dict
    failures: dict
    wall_time: float = math.nan
    where: str = ""

    def parameter_table(self):
        """(parameter names, {dataset name: {parameter: value}}) over the successful fits, the
        parameters in the order of their first appearance."""
        order, rows = {}, {}
        for name in self.names:
            fit = self.fits.get(name)
            if fit is None:
                continue
            rows[name] = {p.name: p.value for p in fit.parameters.values() if p.vary}
            for k in rows[name]:
                order.setdefault(k, None)
        return list(order), rows

    title = "Fleet"

    def summary(self) -> Summary:
        """Each fitted parameter's distribution across the fleet (median, MAD, quartiles, extremes,
        mean and standard deviation), its outliers by a robust modified z-score above 3.5 (named),
        the law kinds chosen per parameter, the fits not adequate to their noise, and the failures."""
        params, rows = self.parameter_table()
        out = Summary({"method": self.method, "datasets": len(self.names), "identified": len(self.fits),
                       "failed": len(self.failures), "parameters": {}, "laws": {}, "not_adequate": [],
                       "failures": [{"dataset": n, "reason": r} for n, r in self.failures.items()]})
        for p in params:
            names = [n for n in rows if p in rows[n]]
            x = np.array([rows[n][p] for n in names], float)
            med = float(np.median(x))
            mad = float(np.median(np.abs(x - med)))
            d = {"n": int(x.size), "unit": self._unit(p), "median": med, "mad": mad,
                 "q1": float(np.percentile(x, 25)), "q3": float(np.percentile(x, 75)),
                 "min": float(x.min()), "max": float(x.max()), "mean": float(x.mean()),
                 "std": float(x.std(ddof=1)) if x.size > 1 else math.nan, "outliers": []}
            if x.size >= 3 and mad > 0:
                z = 0.6745 * (x - med) / mad
                d["outliers"] = [{"dataset": n, "value": float(v), "z": float(zi)}
                                 for n, v, zi in zip(names, x, z) if abs(zi) > OUTLIER_Z]
            out["parameters"][p] = d
        for name, fit in self.fits.items():
            for p, law in getattr(fit.model, "laws", {}).items():
                counts = out["laws"].setdefault(p, {})
                counts[law.kind] = counts.get(law.kind, 0) + 1
            if fit.adequate is False:
                out["not_adequate"].append({"dataset": name, "ratio": float(fit.fit_quality["ratio"])})
        return out

    def _unit(self, p):
        for fit in self.fits.values():
            if p in fit.parameters:
                return fit.parameters[p].unit
        return ""

    def _blocks(self) -> list:
        """The summary as a report: one line per parameter, then outliers, laws and failures."""
        s = self.summary()
        blocks = [heading(f"Fleet: {self.method}", f"{s['identified']} of {s['datasets']} datasets identified"
                          + (f", {s['failed']} failed" if s["failed"] else ""))]
        if s["parameters"]:
            head = ("parameter", "median", "MAD", "min", "max", "unit", "outliers")
            blocks.append(table(head, [(p, f"{d['median']:.5g}", f"{d['mad']:.3g}", f"{d['min']:.5g}",
                                        f"{d['max']:.5g}", d["unit"], ", ".join(o["dataset"] for o in d["outliers"]))
                                       for p, d in s["parameters"].items()], strip=True))
        notes = [f"outlier: {o['dataset']}: {p} = {o['value']:.5g} {d['unit']} (modified z {o['z']:+.1f})"
                 for p, d in s["parameters"].items() for o in d["outliers"]]
        notes += [f"law of {p}: " + ", ".join(f"{k} x{c}" for k, c in sorted(counts.items()))
                  for p, counts in s["laws"].items()]
        notes += [f"not adequate: {q['dataset']} (residuals {q['ratio']:.3g} x its noise)" for q in s["not_adequate"]]
        notes += [f"FAILED: {f['dataset']}: {f['reason']}" for f in s["failures"]]
        return blocks + [lines(notes)]

    def to_dict(self) -> dict:
        """The fleet as plain JSON types: the method, the summary (fleet.json's content), each dataset's folder and
        status, the fits' results JSON (docs/formats.md#results-json) by name, the failures' reasons."""
        return _io.jsonable({"method": self.method, "summary": self.summary(), "paths": self.paths,
                             "fits": {n: f.to_dict() for n, f in self.fits.items()}, "failures": self.failures,
                             "wall_time": self.wall_time, "where": self.where})

    def _frame(self) -> dict:
        """One row per dataset: its name, status, RMSE and each fitted parameter's value (None where failed)."""
        params, rows = self.parameter_table()
        frame = {"dataset": list(self.names),
                 "status": ["ok" if n in self.fits else "failed" for n in self.names],
                 "rmse": [float(self.fits[n].rmse) if n in self.fits else None for n in self.names]}
        frame.update({p: [rows.get(n, {}).get(p) for n in self.names] for p in params})
        return frame

    def plot(self):
        """A matplotlib figure: each fitted parameter across the fleet, relative to its median, outliers named."""
        return fleet_figure(self)

    def to_csv_text(self) -> str:
        """One row per dataset: name, status, rmse, then each parameter's value (empty where failed)."""
        params, rows = self.parameter_table()
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        units = {p: self._unit(p) for p in params}
        w.writerow(["dataset", "status", "rmse[m]"] + [f"{p}[{units[p]}]" if units[p] else p for p in params]
                   + ["error"])
        for name in self.names:
            fit = self.fits.get(name)
            if fit is None:
                w.writerow([name, "failed", ""] + [""] * len(params) + [self.failures.get(name, "")])
            else:
                w.writerow([name, "ok", repr(float(fit.rmse))]
                           + [repr(rows[name][p]) if p in rows[name] else "" for p in params] + [""])
        return buf.getvalue()

    def write(self, folder):
        """NAME.toml and NAME.json per identified dataset, fleet.json and fleet.csv, all published
        together (or none)."""
        folder = Path(folder)
        inputs = [os.path.join(p, "dataset.toml") for p in self.paths.values() if p is not None]
        with _io.publish_together(inputs=inputs):
            folder.mkdir(parents=True, exist_ok=True)
            for name in self.names:
                fit = self.fits.get(name)
                if fit is not None:
                    fit.model.save(folder / f"{name}.toml")
                    fit.to_json(folder / f"{name}.json")
            _io.dump_json(self.summary(), folder / "fleet.json")
            with _io.atomic_write(folder / "fleet.csv", "w", newline="") as fh:
                fh.write(self.to_csv_text())
        return folder

    def __repr__(self):
        return f"FleetResult({self.method}: {len(self.fits)} of {len(self.names)} identified)"


def identify_fleet(datasets, method="model-i", init=None, *, scheduler=None, workers=None, progress=None,
                   **identify_options) -> FleetResult:
    """Identifies every dataset with ``tf.identify(data, method, init=init, **identify_options)``, one task per
    dataset. A dataset that cannot be read or identified is recorded with its reason; the others go on.

    Parameters
    ----------
    datasets : list or str or os.PathLike
        A list of dataset folders or ``Dataset`` objects, or one folder of dataset folders.
    method : str, default "model-i"
        As for ``identify``.
    init : Model or str or os.PathLike, optional
        The initial model, as for ``identify``.
    scheduler : str or distributed.Client, optional
        Where the tasks run: None or "threads" (threads in this process, one per core, or ``workers`` of them:
        the C core releases the GIL), "sequential" (in this process, in order), "processes" (an embedded local
        Dask cluster of ``workers`` processes), an address (``tcp://HOST:8786``, a scheduler file) or a
        ``distributed.Client`` (docs/scale.md).
    workers : int, optional
        The threads or processes; default one per core. An identification is seconds of work, so each dataset is one
        task.
    progress : callable, optional
        Called with the number of datasets done.
    **identify_options
        Passed on to ``identify`` (``friction``, ``parameters``, ``free``, ``starts``, ...).

    Returns
    -------
    FleetResult
        One fit or one failure (with its reason) per dataset, and the fleet's summary.

    Raises
    ------
    InputError
        An argument of the wrong type, named; no dataset.
    """
    import time

    from ..data import Dataset, load_dataset

    if not isinstance(datasets, (str, os.PathLike, list, tuple)) or (
            isinstance(datasets, (list, tuple)) and not all(isinstance(d, (str, os.PathLike, Dataset)) for d in datasets)):
        _args.refuse("datasets", "a list of dataset folders or Datasets, or a folder of dataset folders", datasets)
    for d in [datasets] if isinstance(datasets, (str, os.PathLike)) else datasets:
        if not isinstance(d, Dataset):
            _args.path(d, "datasets")  # an empty name is not the current folder
    _args.text(method, "method")
    if not (init is None or isinstance(init, (Model, str, os.PathLike))):
        _args.refuse("init", "a Model, a model file or a preset name, or None", init)
    check_options(scheduler, workers, progress=progress)
    if isinstance(datasets, (str, os.PathLike)):
        datasets = fleet_datasets(datasets) or [datasets]
    datasets = list(datasets)
    if not datasets:
        raise InputError("datasets: give at least one dataset")
    if "progress" in identify_options:
        raise InputError("progress= is the fleet's (datasets done); identify's own progress is not shown")
    paths = [d.path if isinstance(d, Dataset) else d for d in datasets]
    names = _names([p if p is not None else (getattr(d, "name", None) or "dataset")
                    for p, d in zip(paths, datasets)])
    if isinstance(init, (str, os.PathLike)) and str(init) not in PRESETS:
        try:  # read here, so that a cluster's workers need not see the file; a plant-only file needs the data
            init = load_model(init)
        except InputError:
            init = os.fspath(init)
    elif init is not None and not isinstance(init, (Model, str)):
        raise InputError(f"init must be a Model, a model file or a preset name, got {shorten(init)}")
    t0 = time.perf_counter()
    loaded, failures = {}, {}
    for name, d in zip(names, datasets):
        if isinstance(d, Dataset):
            loaded[name] = d
            continue
        try:
            loaded[name] = load_dataset(d)
        except ThermofrictionError as e:
            failures[name] = str(e)
    todo = [n for n in names if n in loaded]
    fits = {}
    with Runner(scheduler, workers) as runner:
        base = len(names) - len(todo)
        report = (lambda done: progress(base + done)) if progress else None
        if progress:
            progress(base)
        outs = runner.map(_identify_one, [(loaded[n], method, init, identify_options) for n in todo],
                          progress=report, on_error=lambda i, reason: ("failed", reason))
        where = runner.describe()
    for name, (status, value) in zip(todo, outs):
        if status == "ok":
            fits[name] = value
        else:
            failures[name] = value
    failures = {n: failures[n] for n in names if n in failures}
    return FleetResult(method, names, {n: (str(p) if p is not None else None) for n, p in zip(names, paths)}, fits,
                       failures, time.perf_counter() - t0, where)


__all__ = ["identify_fleet", "FleetResult", "fleet_datasets", "OUTLIER_Z", "output_files", "input_files",
           "refuse_overwriting_inputs"]
