"""Design sweeps: one simulation per point of a grid (temperature x load x input x model parameters),
reduced to a few summary metrics per point, batched many points per Dask task.

    res = tf.sweep(model, grid={"temperature": np.arange(30, 42.25, 0.25), "amplitude": [10, 20, 30]},
                   duration=0.4, metrics=["mean_step", "final_displacement"])
    res["temperature"], res["mean_step"], res.failed          # arrays, one entry per point
    res.to_csv("sweep.csv")                                    # or .to_parquet(...), .to_dataframe()

The points are the Cartesian product of the grid's axes in the order given, the last varying
fastest. Every point is simulated on its own from the same arguments, so the result does not depend
on where or in which order the points ran: a cluster's run equals ``scheduler="sequential"``'s.
"""

from __future__ import annotations

import csv
import dataclasses
import math

import numpy as np

from .. import _io
from .. import _args
from ..simulation import AutoSwitch, Dopri5, Rodas4, StepSizeController
from .._reading import strict_float
from ..errors import InputError, ThermofrictionError, shorten
from ..models import Model, load_model
from ..models.load_laws import load_laws
from ..waveforms import Sampled, Waveform
from ..results import Result, Summary, collecting, heading, lines
from .cluster import Runner, check_options
from .figures import sweep_figure

#: the most points of one sweep (their coordinates and metrics are held in memory: ~100 bytes each)
MAX_POINTS = 50_000_000


def _mean_step(res):
    return float(res.step_sizes.mean()) if res.step_sizes.size else math.nan


def _last_step(res):
    return float(res.step_sizes[-1]) if res.step_sizes.size else math.nan


#: name -> (unit, what it is, function of a SimulationResult)
METRICS = {
    "mean_step": ("m", "mean displacement per input cycle", _mean_step),
    "last_step": ("m", "displacement over the last full input cycle", _last_step),
    "mean_velocity": ("m/s", "mean step per cycle times the input frequency", lambda r: float(r.mean_velocity)),
    "final_displacement": ("m", "displacement at the end of the run", lambda r: float(r.displacement[-1])),
    "displacement_range": ("m", "largest minus smallest displacement", lambda r: float(np.ptp(r.displacement))),
    "peak_friction_force": ("N", "largest |friction force|", lambda r: float(np.max(np.abs(r.friction_force)))),
}
DEFAULT_METRICS = ("mean_step", "final_displacement", "peak_friction_force")
_INPUT_UNITS = {"stick-slip": "V", "mass": "N", "prescribed": "m"}
_WAVEFORM_UNITS = {"frequency": "Hz", "rise": "", "duty": "", "slew": "s", "time": "s", "direction": ""}


def check_run_options(duration, sample_rate, solver, controller, scheduler, workers, batch_size, progress):
    """The options sweep and propagate share -- each run's length and rate, its integrator, where the runs go --
    checked before any work: one InputError naming the argument."""
    _args.number(duration, "duration", "s")
    _args.number(sample_rate, "sample_rate", "Hz")
    if solver is not None and not isinstance(solver, (str, Dopri5, Rodas4, AutoSwitch)):
        _args.refuse("solver", "Dopri5(), Rodas4(), AutoSwitch() or one of their names", solver)
    _args.instance(controller, StepSizeController, "controller", "a StepSizeController", none=True)
    check_options(scheduler, workers, batch_size, progress)


# -- the grid ---------------------------------------------------------------------------------

def parse_axis(text: str):
    """``NAME=START:STOP:STEP`` (STOP included when the steps reach it), ``NAME=V1,V2,...`` or
    ``NAME=V``: (name, values).

    Parameters
    ----------
    text : str
        One ``--grid`` axis, e.g. ``temperature=30:42:0.25`` or ``amplitude=10,20,30``.

    Returns
    -------
    tuple
        (name, list of float).

    Raises
    ------
    InputError
        Not NAME=..., a value that is not a finite number, a range without START <= STOP and a positive STEP,
        named with the axis.
    """
    _args.text(text, "text")
    name, eq, spec = text.partition("=")
    name, spec = name.strip(), spec.strip()
    where = f"--grid {shorten(text)}"
    if not eq or not name or not spec:
        raise InputError(f"{where}: expected NAME=START:STOP:STEP or NAME=V1,V2,... "
                         f"(e.g. temperature=30:42:0.25, amplitude=10,20,30)")

    def number(s):
        try:
            v = strict_float(s.strip())
        except ValueError:
            raise InputError(f"{where}: not a number: {shorten(s.strip())}") from None
        if not math.isfinite(v):
            raise InputError(f"{where}: values must be finite, got {shorten(s.strip())}")
        return v

    if ":" in spec:
        parts = spec.split(":")
        if len(parts) != 3:
            raise InputError(f"{where}: a range is START:STOP:STEP, e.g. 30:42:0.25")
        start, stop, step = (number(p) for p in parts)
        if step <= 0 or stop < start:
            raise InputError(f"{where}: a range needs START <= STOP and a positive STEP")
        count = (stop - start) / step
        if count >= MAX_POINTS:
            raise InputError(f"{where}: {count:.3g} values, above the limit of {MAX_POINTS} points")
        n = int(math.floor(count + 1e-9)) + 1  # STOP itself when it is (to rounding) a whole number of steps
        return name, start + step * np.arange(n)
    return name, np.array([number(v) for v in spec.split(",")])


def _as_axis(name, values):
    try:
        arr = np.atleast_1d(np.asarray(values, dtype=float))
    except (TypeError, ValueError):
        raise InputError(f"grid '{name}': values must be numbers, got {shorten(values)}") from None
    if arr.ndim != 1 or arr.size == 0 or not np.all(np.isfinite(arr)):
        raise InputError(f"grid '{name}': give a non-empty list of finite numbers, got {shorten(values)}")
    return arr


def _kinds(model: Model, waveform, names):
    """Each grid name's kind ("temperature", "load", "input", "parameter") and unit, checked against the model."""
    from ..fitting.parameters import target_of, unit_of  # loads SciPy: only when a sweep runs

    fields = {f.name for f in dataclasses.fields(waveform)} if dataclasses.is_dataclass(waveform) else set()
    kinds, units = {}, {}
    for name in names:
        if name == "temperature":
            kinds[name], units[name] = "temperature", "C"
        elif name == "load":
            if not load_laws(model):
                raise InputError("grid 'load': the model has no law of the load (docs/models.md#laws-of-temperature-"
                                 "and-load): every point would be the same")
            kinds[name], units[name] = "load", "N m" if getattr(model.plant, "rotary", False) else "N"
        elif name in fields and not isinstance(waveform, Sampled):
            kinds[name] = "input"
            units[name] = _WAVEFORM_UNITS.get(name, _INPUT_UNITS.get(model.plant.type, ""))
        else:
            try:
                target_of(model, name)
            except InputError as e:
                if name in model.laws:  # a Model I parameter: its law's coefficients are the knobs
                    raise InputError(f"grid '{name}': it follows a law of temperature in this model: sweep its "
                                     f"coefficients ({', '.join(name + '.' + c for c in model.laws[name].coefficient_names())}) "
                                     f"or use a model without the law") from None
                what = f"the input's fields ({', '.join(sorted(fields))}), " if fields else ""
                raise InputError(f"grid '{name}': not temperature, {what}or a parameter of the model: {e}") from None
            kinds[name], units[name] = "parameter", unit_of(model, name)
    return kinds, units


# -- one batch of points (runs on a worker) ---------------------------------------------------

def _run_batch(model, waveform, temperature, load, names, kinds, coords, metrics, sim):
    """Simulates each row of ``coords``; returns (values (n, len(metrics)), errors {row: reason},
    warnings). A point that fails is NaN with its reason; the others go on."""
    from ..fitting.parameters import with_values
    from ..simulation import simulate

    values = np.full((coords.shape[0], len(metrics)), np.nan)
    errors, seen = {}, {}
    for i, row in enumerate(coords):
        point = dict(zip(names, (float(v) for v in row)))
        with collecting() as caught:  # the point's findings, as values
            try:
                T = point.get("temperature", temperature)
                L = point.get("load", load)
                inp = {n: v for n, v in point.items() if kinds[n] == "input"}
                if "direction" in inp:
                    inp["direction"] = int(inp["direction"])
                params = {n: v for n, v in point.items() if kinds[n] == "parameter"}
                m = with_values(model, params) if params else model
                w = dataclasses.replace(waveform, **inp) if inp else waveform
                res = simulate(m, temperature=T, input=w, load=L, **sim)
                values[i] = [METRICS[k][2](res) for k in metrics]
            except ThermofrictionError as e:
                errors[i] = str(e)
            except Exception as e:  # noqa: BLE001 - one point's surprise must not stop the sweep
                errors[i] = f"{type(e).__name__}: {e}"
        for w in caught:
            seen.setdefault(f"{w.category.__name__}: {w.message}", None)
    return values, errors, list(seen)


# -- the result -------------------------------------------------------------------------------

@dataclasses.dataclass(eq=False)
class SweepResult(Result):
    """One row per point: the coordinates, then the metrics (NaN where the point failed).

    ``res[name]`` is a column (coordinates and metrics by name), ``units[name]`` its unit;
    ``errors`` maps a failed row's index to its reason; ``ok`` is a boolean column.

    Parameters
    ----------
    coordinates : tuple of str
        The grid's names, in order.
    metrics : tuple of str
        The metrics' names.
    columns : dict
        Name -> column (numpy.ndarray), coordinates and metrics.
    units : dict
        Name -> unit.
    errors : dict
        A failed row's index -> its reason.
    warnings : list of str
        The runs' warnings.
    wall_time : float, default nan
        The run's duration [s].
    where : str, default ""
        Where the tasks ran (threads, a Dask cluster's address).
    """

    coordinates: tuple
    metrics: tuple
    columns: dict
    units: dict
    errors: dict
    warnings: list
    wall_time: float = math.nan
    where: str = ""

    def __getitem__(self, name):
        return self.columns[name]

    def __len__(self):
        return len(next(iter(self.columns.values()))) if self.columns else 0

    @property
    def ok(self) -> np.ndarray:
        ok = np.ones(len(self), bool)
        ok[list(self.errors)] = False
        return ok

    @property
    def failed(self) -> int:
        return len(self.errors)

    def header(self, name) -> str:
        return f"{name}[{self.units[name]}]" if self.units.get(name) else name

    def to_records(self) -> np.ndarray:
        """A NumPy structured array (named fields)."""
        names = list(self.coordinates) + list(self.metrics)
        rec = np.empty(len(self), dtype=[(n, float) for n in names] + [("error", object)])
        for n in names:
            rec[n] = self.columns[n]
        rec["error"] = [self.errors.get(i, "") for i in range(len(self))]
        return rec

    title = "Sweep"

    def summary(self) -> Summary:
        return Summary([("points", len(self)), ("failed", self.failed), ("grid", ", ".join(self.coordinates)),
                        ("metrics", ", ".join(self.metrics)), ("wall time", f"{self.wall_time:.3g} s"),
                        ("where", self.where)])

    def _frame(self) -> dict:
        """One column per coordinate and metric, headed with its unit, then ``error`` (empty where the point ran)."""
        data = {self.header(n): self.columns[n] for n in self.coordinates + self.metrics}
        data["error"] = [self.errors.get(i, "") for i in range(len(self))]
        return data

    def to_dict(self) -> dict:
        """The sweep as plain JSON types: the grid's and the metrics' names, their units and columns (SI), the
        failed points' reasons by row, the warnings."""
        return _io.jsonable({"coordinates": list(self.coordinates), "metrics": list(self.metrics),
                             "units": self.units, "columns": self.columns,
                             "errors": {str(k): v for k, v in self.errors.items()}, "warnings": self.warnings,
                             "wall_time": self.wall_time, "where": self.where})

    def _blocks(self) -> list:
        blocks = super()._blocks()
        if self.warnings:
            blocks += [heading("Warnings"), lines(self.warnings)]
        return blocks

    def plot(self, metric=None, x=None):
        """A matplotlib figure of ``metric`` (default the first) against the grid coordinate ``x`` (default the
        first), one line per value of the other coordinates (at most a few)."""
        return sweep_figure(self, metric, x)

    def to_csv(self, path):
        """Writes the table atomically: a header with units, numbers exact to the last bit (repr),
        an ``error`` column (empty where the point ran)."""
        with _io.atomic_write(path, "w", newline="") as fh:
            self.write_csv(fh)

    def write_csv(self, fh):
        """The CSV table into an open text file (``to_csv`` writes a file atomically)."""
        names = list(self.coordinates) + list(self.metrics)
        cols = [self.columns[n] for n in names]
        w = csv.writer(fh, lineterminator="\n")
        w.writerow([self.header(n) for n in names] + ["error"])
        for i in range(len(self)):
            w.writerow([repr(float(c[i])) for c in cols] + [self.errors.get(i, "")])

    def to_parquet(self, path):
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError:
            raise InputError(f"{path}: writing Parquet needs pyarrow (pip install pyarrow); or write a .csv") from None
        names = list(self.coordinates) + list(self.metrics)
        table = pa.table({**{self.header(n): self.columns[n] for n in names},
                          "error": [self.errors.get(i, "") for i in range(len(self))]})
        with _io.atomic_write(path, "wb") as fh:
            pq.write_table(table, fh)

    def to_mat(self, path):
        """The table as a MATLAB file: one column vector per CSV column, named as the header with its unit as a
        suffix (``temperature_C``), and ``error`` a cell array of text (empty where the point ran)."""
        from ..data.matlab import matlab_name, save_mat
        names = list(self.coordinates) + list(self.metrics)
        variables = {matlab_name(self.header(n)): np.asarray(self.columns[n], float) for n in names}
        variables["error"] = np.array([self.errors.get(i, "") for i in range(len(self))], dtype=object)
        save_mat(path, variables)

    def save(self, path):
        """``.parquet`` as Parquet (needs pyarrow), ``.mat`` as a MATLAB file, anything else as CSV."""
        name = str(getattr(path, "path", path)).lower()
        if name.endswith(".parquet"):
            return self.to_parquet(path)
        return self.to_mat(path) if name.endswith(".mat") else self.to_csv(path)

    def __repr__(self):
        return (f"SweepResult({len(self)} points over {', '.join(self.coordinates)}; metrics "
                f"{', '.join(self.metrics)}; {self.failed} failed)")


# -- the sweep --------------------------------------------------------------------------------

def _grid(grid):
    if isinstance(grid, (list, tuple)):  # ["temperature=30:42:0.25", ...] as on the command line
        axes = [parse_axis(g) if isinstance(g, str) else g for g in grid]
        if not all(isinstance(a, tuple) and len(a) == 2 for a in axes):
            raise InputError(f"grid: a list holds axes 'NAME=VALUES' (as --grid does), got {shorten(grid)}")
        seen = {}
        for g, (name, _) in zip(grid, axes):
            if name in seen:  # a dict would keep the last one: the first was dropped without a word
                raise InputError(f"--grid {shorten(g)}: the axis '{name}' is given twice (first as --grid "
                                 f"{shorten(seen[name])}): give each axis once, all its values in one --grid")
            seen[name] = g
        grid = dict(axes)
    if not isinstance(grid, dict) or not grid:
        raise InputError(f"grid must be a non-empty dict of name -> values, got {type(grid).__name__} {shorten(grid)}")
    axes = {str(k): _as_axis(k, v) for k, v in grid.items()}
    n = math.prod(a.size for a in axes.values())
    if n > MAX_POINTS:
        raise InputError(f"the grid has {n:.3g} points, above the limit of {MAX_POINTS}")
    return axes, n


def points(axes: dict) -> np.ndarray:
    """The grid's points, one row each: the Cartesian product, the last axis varying fastest."""
    mesh = np.meshgrid(*axes.values(), indexing="ij")
    return np.column_stack([m.ravel() for m in mesh]) if mesh else np.empty((1, 0))


def sweep(model, grid, *, input: Waveform | None = None, duration: float = 1.0, temperature=None,
          metrics=DEFAULT_METRICS, sample_rate: float = 10_000.0, solver=None, controller=None,
          scheduler=None, workers=None, batch_size=None, progress=None, load=None) -> SweepResult:
    """Simulates ``model`` at every point of ``grid`` and returns one row of ``metrics`` per point.

    Parameters
    ----------
    model : Model or str or os.PathLike
        The model: a Model, a model file or a preset name.
    grid : dict
        Name -> values; the points are every combination. Names are ``temperature`` [C], ``load`` [N, or N m for a
        rotary joint; a model with a law of the load only], a field of the input
        waveform (``amplitude``, ``frequency``, ``rise``, ...), or any parameter the model can be given by name
        (``sigma0``, ``fc``, a law coefficient ``sigma0.b``, ``dF.values[1]``, a plant's ``m_e``), in the
        model file's units.
    input : Waveform, optional
        The waveform; default the model's ``[input]``.
    duration : float, default 1.0
        Each simulation's length [s].
    temperature : float, optional
        The temperature [C] of the points when the grid has no ``temperature`` axis.
    metrics : sequence of str, default ("mean_step", "final_displacement", "peak_friction_force")
        Names from ``METRICS``: the mean step per cycle [m], the final displacement [m], the peak friction
        force [N], ...
    sample_rate : float, default 10000.0
        The output grid's rate [Hz].
    solver : AutoSwitch or Dopri5 or Rodas4 or str, optional
        As for ``simulate``.
    controller : StepSizeController, optional
        As for ``simulate``.
    scheduler : str or distributed.Client, optional
        Where the tasks run: None or "threads" (threads in this process, one per core, or ``workers`` of them:
        the C core releases the GIL), "sequential" (in this process, in order), "processes" (an embedded local
        Dask cluster of ``workers`` processes), an address (``tcp://HOST:8786``, a scheduler file) or a
        ``distributed.Client`` (docs/scale.md).
    workers : int, optional
        The threads or processes; default one per core.
    batch_size : int, optional
        Points per task; default chunks sized from the first points' time, at least ~20 ms of work each on
        threads and ~100 ms on Dask, at least 4 per worker (docs/scale.md).
    progress : callable, optional
        Called with the number of points done.
    load : float, optional
        The load [N or N m] of the points when the grid has no ``load`` axis (a model with a law of the load needs
        one or the other; a model without one ignores it).

    Returns
    -------
    SweepResult
        One row per point: the grid's values and the metrics (``to_dataframe``, ``to_csv``); a point whose
        simulation failed has NaN metrics and its reason.

    Raises
    ------
    InputError
        An argument of the wrong type or value, named; an unknown grid name or metric; a grid of no points; a
        ``load`` axis for a model without a law of the load, or no load for one with.
    """
    import time

    model = _args.model(model, Model, loader=load_model)  # the argument types (_args.py): before any work
    _args.number(temperature, "temperature", "degC", none=True)
    load = _args.number(load, "load", "N or N m", none=True)
    check_run_options(duration, sample_rate, solver, controller, scheduler, workers, batch_size, progress)
    if not isinstance(metrics, str):
        metrics = _args.names(metrics, "metrics", none=False)
    waveform = input if input is not None else model.input
    if waveform is None:
        raise InputError("the model has no [input]: give input= (e.g. tf.Sawtooth(amplitude=30, frequency=5))")
    if not isinstance(waveform, Waveform):
        raise InputError(f"input must be a Waveform, got {shorten(waveform)}")
    if isinstance(metrics, str):
        metrics = [m.strip() for m in metrics.split(",") if m.strip()]
    metrics = tuple(dict.fromkeys(metrics))
    unknown = [m for m in metrics if m not in METRICS]
    if unknown or not metrics:
        raise InputError(f"unknown metric {shorten(unknown[0]) if unknown else '(none given)'} "
                         f"(one of: {', '.join(METRICS)})")
    axes, n = _grid(grid)
    names = tuple(axes)
    kinds, units = _kinds(model, waveform, names)
    if model.thermal is not None and "temperature" not in axes and temperature is None and model.heat is None:
        raise InputError("the model depends on temperature: give a temperature axis in the grid "
                         "(temperature=30:42:0.25) or temperature=C for every point")
    if load_laws(model) and "load" not in axes and load is None:
        raise InputError(f"the model has a law of the load ({', '.join(load_laws(model))}): give a load axis in the "
                         "grid (load=20:100:20) or load=N for every point")
    coords = points(axes)
    sim = dict(duration=duration, sample_rate=sample_rate, solver=solver, controller=controller)
    t0 = time.perf_counter()
    with Runner(scheduler, workers) as runner:
        def lost(span, reason):  # every point of a chunk the cluster could not run
            a, b = span
            return np.full((b - a, len(metrics)), np.nan), {k: reason for k in range(b - a)}, []
        spans, outs = runner.map_chunks(
            _run_batch, n, lambda a, b: (model, waveform, temperature, load, names, kinds, coords[a:b], metrics,
                                         sim),
            batch_size=batch_size, progress=progress, on_error=lost)
        where = runner.describe()
    values = np.vstack([o[0] for o in outs]) if outs else np.empty((0, len(metrics)))
    errors, seen = {}, {}
    for (a, _), (_, errs, warns) in zip(spans, outs):
        errors.update({a + i: reason for i, reason in errs.items()})
        for w in warns:
            seen.setdefault(w, None)
    columns = {name: coords[:, j] for j, name in enumerate(names)}
    columns.update({m: values[:, j] for j, m in enumerate(metrics)})
    units.update({m: METRICS[m][0] for m in metrics})
    return SweepResult(names, metrics, columns, units, dict(sorted(errors.items())), list(seen),
                       time.perf_counter() - t0, where)


__all__ = ["sweep", "SweepResult", "METRICS", "DEFAULT_METRICS", "parse_axis", "points", "MAX_POINTS"]
