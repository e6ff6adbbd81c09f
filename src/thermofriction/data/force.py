"""Force and torque experiments (docs/force-data.md): a measured motion and the friction force or torque it
produced, read from CSV files whose headers give the units, linear (m, N) or rotary (rad, N m).

The motion drives a prescribed-motion model. A ``velocity`` column drives it when given (the position is then
only checked against it); otherwise the velocity is estimated from the position (``numpy.gradient``, second
order on irregular samples). Either way the driving waveform is a piecewise-linear position whose slope is the
sample's own velocity within half an interval of each sample (:func:`motion_waveform`), so that the model sees
at each sample time exactly the velocity measured there, with no half-sample lag.
"""

from __future__ import annotations

import csv
import dataclasses
import warnings
from pathlib import Path

import numpy as np

from ..errors import InputError, shorten
from ..waveforms import Sampled
from .csv import TIME_LIMIT, VALUE_LIMIT, _line_of, _scan, header_cell, read_experiment_bytes
from .experiments import MIN_SAMPLES, Experiment

_LINEAR_POSITION = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6, "nm": 1e-9}
_ROTARY_POSITION = {"rad": 1.0, "deg": np.pi / 180.0}
_LINEAR_VELOCITY = {"m/s": 1.0, "mm/s": 1e-3, "um/s": 1e-6}
_ROTARY_VELOCITY = {"rad/s": 1.0, "deg/s": np.pi / 180.0}
_FORCE = {"N": 1.0, "mN": 1e-3}
_TORQUE = {"N*m": 1.0, "Nm": 1.0, "N m": 1.0, "mN*m": 1e-3, "mNm": 1e-3, "mN m": 1e-3}

#: column -> {unit: (scale to SI, "linear" | "rotary" | None)}
_UNITS = {
    "time": {"s": (1.0, None), "ms": (1e-3, None)},
    "position": {**{u: (s, "linear") for u, s in _LINEAR_POSITION.items()},
                 **{u: (s, "rotary") for u, s in _ROTARY_POSITION.items()}},
    "velocity": {**{u: (s, "linear") for u, s in _LINEAR_VELOCITY.items()},
                 **{u: (s, "rotary") for u, s in _ROTARY_VELOCITY.items()}},
    "friction_force": {u: (s, "linear") for u, s in _FORCE.items()},
    "friction_torque": {u: (s, "rotary") for u, s in _TORQUE.items()},
    "temperature": {"C": (1.0, None)},
}
_UNITS["displacement"] = _UNITS["position"]
_SI = {"time": "s", "position": "m", "displacement": "m", "velocity": "m/s", "friction_force": "N",
       "friction_torque": "N*m", "temperature": "C"}
#: Header names that mark a force (torque) experiment, as opposed to an actuator's (voltage, displacement).
MARKERS = ("friction_force", "friction_torque", "position", "velocity")
#: A sampling interval this many times the median one is a gap in the record (warned about).
GAP_RATIO = 10.0
#: The integrated velocity may depart from the recorded position by this fraction of the position's range
#: before a warning; by POSITION_MISMATCH_ERROR (a wrong unit in a header, typically) it is an error.
POSITION_MISMATCH_WARN = 0.05
POSITION_MISMATCH_ERROR = 0.5
EXAMPLE = "time[s],position[rad],velocity[rad/s],friction_torque[N*m]"


class SamplingWarning(UserWarning):
    """A force experiment's record has a gap, or its velocity and position disagree."""


@dataclasses.dataclass(eq=False)
class ForceExperiment(Experiment):
    """One run of measured motion and measured friction, in SI units: ``displacement`` is the position [m or
    rad], ``force`` the friction force or torque [N or N m], ``velocity`` the recorded velocity (None when
    the position drives the model), ``rotary`` whether the units are angles and torques. ``input`` is the
    motion waveform that drives a prescribed-motion model (:func:`motion_waveform`); ``voltage`` is None."""

    force: np.ndarray | None = None
    velocity: np.ndarray | None = None
    rotary: bool = False

    @property
    def drive_velocity(self) -> np.ndarray:
        """The velocity the model is driven with at the sample times."""
        return _velocity(self.time, self.displacement, self.velocity)

    @property
    def force_unit(self) -> str:
        return "N m" if self.rotary else "N"


def is_force_data(experiments) -> bool:
    """Whether ``experiments`` (a dataset or a list) are force experiments; a mix is an error."""
    exps = list(getattr(experiments, "experiments", experiments))
    kinds = {isinstance(e, ForceExperiment) for e in exps}
    if len(kinds) > 1:
        raise InputError("the dataset mixes force (torque) experiments with actuator (voltage, displacement) ones; "
                         "keep them in separate datasets")
    return kinds == {True}


def units_of(experiments) -> bool:
    """True for rotary experiments (rad, N m), False for linear ones; a mix is an error."""
    exps = [e for e in getattr(experiments, "experiments", experiments)]
    kinds = {e.rotary for e in exps}
    if len(kinds) > 1:
        rot = next(e.file for e in exps if e.rotary)
        lin = next(e.file for e in exps if not e.rotary)
        raise InputError(f"the dataset mixes rotary ({rot}) and linear ({lin}) experiments: one joint or one "
                         f"stage per dataset")
    return kinds == {True}


def _velocity(time, position, velocity):
    if velocity is not None:
        return np.asarray(velocity, float)
    return np.gradient(np.asarray(position, float), np.asarray(time, float))


def motion_waveform(time, velocity) -> Sampled:
    """A continuous position whose slope is ``velocity[i]`` on each sample's half-intervals either side: knots
    at the samples and at the midpoints between them, positions by the trapezoidal rule at the samples. At a
    sample time both one-sided slopes equal the sample's velocity, so the model sees it exactly there."""
    t = np.asarray(time, float)
    v = np.asarray(velocity, float)
    dt = np.diff(t)
    x = np.concatenate([[0.0], np.cumsum(0.5 * dt * (v[:-1] + v[1:]))])
    knots = np.empty(2 * len(t))
    values = np.empty_like(knots)
    knots[0::2], values[0::2] = t, x
    knots[1:-1:2], values[1:-1:2] = t[:-1] + 0.5 * dt, x[:-1] + 0.5 * dt * v[:-1]
    # half an interval beyond the last sample, so that the velocity there is the last sample's too (a
    # sampled waveform is held constant after its last knot)
    knots[-1], values[-1] = t[-1] + 0.5 * dt[-1], x[-1] + 0.5 * dt[-1] * v[-1]
    return Sampled(knots, values)


def is_force_file(path) -> bool:
    """Whether the CSV's header names a column of a force experiment (read from its first line only)."""
    import os
    if not os.path.isfile(path):  # a FIFO or device would block the open: the reader refuses it, by name
        return False
    try:
        with open(path, "rb") as fh:
            head = fh.readline(1 << 16).decode("utf-8-sig", errors="replace")
    except (OSError, ValueError):
        return False  # the actuator reader says what is wrong
    names = {cell.partition("[")[0].strip() for cell in head.strip().split(",")}
    return any(m in names for m in MARKERS)


def _parse_header(path, header):
    cols, kinds = [], {}
    for j, raw in enumerate(header):
        name, unit, cell, where = header_cell(path, j, raw, _SI, "friction_force[N]")
        if name not in _UNITS:
            hint = " (an actuator's voltage belongs in a dataset of its own)" if name == "voltage" else ""
            raise InputError(f"{where}: unknown column {shorten(name) or '(empty)'} in a force experiment "
                             f"(columns: {', '.join(_UNITS)}){hint}")
        if unit not in _UNITS[name]:
            raise InputError(f"{where} ({shorten(cell)}): unknown unit {shorten(unit)} for {name} "
                             f"(one of: {', '.join(u for u in _UNITS[name] if u not in ('μm', 'Nm', 'N m', 'mNm', 'mN m'))})")
        key = "position" if name == "displacement" else name
        key = "force" if name in ("friction_force", "friction_torque") else key
        for k, c in enumerate(cols):
            if c[0] == key:
                raise InputError(f"{where}: {shorten(cell)} duplicates column {k + 1} ({c[2]})")
        scale, kind = _UNITS[name][unit]
        if kind is not None:
            kinds[cell] = kind
        cols.append((key, scale, cell))
    names = [c[0] for c in cols]
    if "force" not in names:
        raise InputError(f"{path}: line 1: no friction_force[N] or friction_torque[N*m] column: a force experiment "
                         f"records the friction it measures (e.g. {EXAMPLE})")
    missing = [n for n in ("time", "position") if n not in names]
    if missing:
        what = "the motion: a position[...] (or displacement[...]) column" if "position" in missing else "time[s]"
        raise InputError(f"{path}: line 1: a force experiment needs {what}"
                         f"{' and time[s]' if len(missing) > 1 else ''} (e.g. {EXAMPLE})")
    if len(set(kinds.values())) > 1:
        lin = [c for c, k in kinds.items() if k == "linear"]
        rot = [c for c, k in kinds.items() if k == "rotary"]
        raise InputError(f"{path}: line 1: mixed linear ({', '.join(lin)}) and rotary ({', '.join(rot)}) units: a "
                         f"linear experiment records m, m/s and N; a rotary one rad, rad/s and N*m")
    return cols, set(kinds.values()) == {"rotary"}


def read_force_csv(path) -> dict:
    """Reads one force (torque) experiment CSV into SI arrays: a dict with ``time``, ``position``, ``force``,
    ``rotary`` and, where given, ``velocity`` and ``temperature``. Any problem is one InputError naming the
    file, line and column. Irregular sampling is accepted (time must increase strictly); a gap of more than
    GAP_RATIO times the median interval is a SamplingWarning."""
    path = Path(path)
    raw = read_experiment_bytes(path)
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        line = raw[:e.start].count(b"\n") + 1
        raise InputError(f"{path}: line {line}: not UTF-8 text") from None
    head, _, body = text.partition("\n")
    if not head.strip():
        raise InputError(f"{path}: line 1: blank; the first line must be the header row, e.g. {EXAMPLE}")
    try:
        header = next(csv.reader([head.rstrip("\r")]))
    except csv.Error as e:
        raise InputError(f"{path}: line 1: not a valid CSV header row ({e})") from None
    cols, rotary = _parse_header(path, header)
    if not body.strip():
        raise InputError(f"{path}: no data rows (only the header)")
    arr = _scan(path, body, cols)
    bad = ~np.isfinite(arr)
    if bad.any():
        r, j = (int(v) for v in np.argwhere(bad)[0])
        raise InputError(f"{path}: line {_line_of(body, r)}, column {j + 1} ({cols[j][2]}): not a finite number")
    n = arr.shape[0]
    if n < MIN_SAMPLES:
        raise InputError(f"{path}: {n} data row{'s' if n != 1 else ''}; an experiment needs at least {MIN_SAMPLES}")
    out = {name: arr[:, j] * scale for j, (name, scale, _) in enumerate(cols)}
    for j, (name, _, cell) in enumerate(cols):
        lim = TIME_LIMIT if name == "time" else VALUE_LIMIT
        big = np.abs(out[name]) > lim
        if big.any():
            r = int(np.argmax(big))
            raise InputError(f"{path}: line {_line_of(body, r)}, column {j + 1} ({cell}): beyond the limit of "
                             f"{lim:g} in magnitude")
    jt = [c[0] for c in cols].index("time")
    t = out["time"]
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0))
        raise InputError(f"{path}: line {_line_of(body, i + 1)}, column {jt + 1} ({cols[jt][2]}): time must increase "
                         f"strictly ({t[i + 1]:.10g} s after {t[i]:.10g} s on line {_line_of(body, i)})")
    med = float(np.median(dt))
    gaps = np.flatnonzero(dt > GAP_RATIO * med)
    if gaps.size:
        i = int(gaps[np.argmax(dt[gaps])])
        warnings.warn(f"{path}: line {_line_of(body, i + 1)}: a gap of {dt[i]:.4g} s in the record, "
                      f"{dt[i] / med:.0f} times the typical interval of {med:.4g} s ({gaps.size} such gap"
                      f"{'s' if gaps.size > 1 else ''}); the motion is interpolated linearly across it",
                      SamplingWarning, stacklevel=2)
    if "temperature" in out:
        from ..plausible import kelvin_hint
        from .experiments import TEMPERATURE_RANGE
        lo, hi = TEMPERATURE_RANGE
        T = out["temperature"]
        badT = (T < lo) | (T > hi)
        if badT.any():
            i = int(np.argmax(badT))
            jT = [c[0] for c in cols].index("temperature")
            raise InputError(f"{path}: line {_line_of(body, i)}, column {jT + 1}: {T[i]:g} C is not a plausible "
                             f"temperature (expected {lo:g} to {hi:g} C{kelvin_hint(float(T[i]))})")
    if "velocity" in out:
        _check_consistency(path, t, out["position"], out["velocity"], rotary, cols)
    out["rotary"] = rotary
    out["headers"] = {c[0]: c[2] for c in cols}
    return out


def _check_consistency(path, t, x, v, rotary, cols):
    """The recorded velocity, integrated, against the recorded position."""
    span = float(np.ptp(x))
    moved = np.concatenate([[0.0], np.cumsum(0.5 * np.diff(t) * (v[:-1] + v[1:]))])
    if span <= 0:
        return
    dev = float(np.max(np.abs(moved - (x - x[0]))))
    if dev <= POSITION_MISMATCH_WARN * span:
        return
    head = {c[0]: c[2] for c in cols}
    message = (f"{path}: the velocity column {head['velocity']}, integrated over time, departs from the position "
               f"column {head['position']} by {dev / span:.3g} of the position's range")
    if dev > POSITION_MISMATCH_ERROR * span:
        raise InputError(f"{message}: check the units in the header (the velocity drives the model; the position "
                         f"is only checked against it)")
    warnings.warn(f"{message} (the velocity drives the model)", SamplingWarning, stacklevel=3)


def force_experiment(path, name, *, temperature, role, description, from_zero) -> ForceExperiment:
    """A :class:`ForceExperiment` from the file ``path`` (``name`` as the manifest gives it); ``temperature``
    is the manifest's (None: the column's mean); ``from_zero`` moves a clock time to start at zero."""
    cols = read_force_csv(path)
    force = cols["force"]
    if np.ptp(force) <= 1e-12 * np.max(np.abs(force)):  # its noise estimate would be 0: nothing to weigh a fit by
        raise InputError(f"{path}: column {cols['headers']['force']}: the force does not vary (every sample is "
                         f"{force[0]:g}): a stuck load cell? A constant record has no friction to identify")
    t, _ = from_zero(cols["time"], None)
    sig = cols.get("temperature")
    if temperature is None:
        if sig is None:
            raise InputError(f"{path}: no temperature: give 'temperature' in the manifest or a temperature[C] column")
        temperature = float(np.mean(sig))
    v = cols.get("velocity")
    drive_v = _velocity(t, cols["position"], v)
    return ForceExperiment(file=name, time=t, voltage=None, displacement=cols["position"], temperature=temperature,
                           temperature_signal=sig, role=role, description=description,
                           input=motion_waveform(t, drive_v), force=cols["force"], velocity=v,
                           rotary=cols["rotary"])


def write_force_csv(path, time, position, force, *, velocity=None, temperature=None, rotary=False):
    """Writes a force experiment CSV (SI units in the header), atomically."""
    from .._io import atomic_write
    head = ["time[s]", "position[rad]" if rotary else "position[m]"]
    data = [time, position]
    if velocity is not None:
        head.append("velocity[rad/s]" if rotary else "velocity[m/s]")
        data.append(velocity)
    head.append("friction_torque[N*m]" if rotary else "friction_force[N]")
    data.append(force)
    if temperature is not None:
        head.append("temperature[C]")
        data.append(np.broadcast_to(np.asarray(temperature, float), np.shape(time)))
    arr = np.column_stack([np.asarray(c, float) for c in data])
    with atomic_write(Path(path), "w") as fh:
        fh.write(",".join(head) + "\n")
        np.savetxt(fh, arr, delimiter=",", fmt="%.12g")


__all__ = ["ForceExperiment", "SamplingWarning", "read_force_csv", "force_experiment", "is_force_file",
           "is_force_data", "units_of", "motion_waveform", "write_force_csv", "GAP_RATIO"]
