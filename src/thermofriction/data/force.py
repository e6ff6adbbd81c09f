"""Force and torque experiments (docs/force-data.md): a measured motion and the friction force or torque it
produced, read from CSV files whose headers give the units, linear (m, N) or rotary (rad, N m), or from MATLAB
files (data/matlab.py: read_force_mat) with the same columns.

**The motion that drives the model** (``motion = "auto" | "position" | "velocity"``, the dataset's option) is
chosen, checked and turned into the driving waveform by data/motion.py.

**Sign convention**: the friction column has the sign of the velocity in sliding (the force or torque that the
drive spends against friction). A column that opposes the motion (a reaction-torque sensor) is refused at loading
(:func:`check_sign`); ``flip_sign = true`` in the manifest reads it negated.
"""

from __future__ import annotations

import csv
import dataclasses
import functools
import warnings
from pathlib import Path

import numpy as np

from ..errors import InputError, shorten
from .command import COMMAND_SI, COMMAND_UNITS, MEASURED_KEYS, column_key_of, measured_force
from .csv import TIME_LIMIT, VALUE_LIMIT, _line_of, _scan, header_cell, read_experiment_bytes
from .experiments import MIN_SAMPLES, Experiment
from .load import LOAD_COLUMNS, load_column, run_load
from .motion import (MOTIONS, POSITION_MISMATCH_ERROR, MotionCheck, MotionWarning, SamplingWarning, check_motion,
                     check_motion_option, choose_motion, motion_waveform, quantum, v_smooth_for, velocity_lag,
                     velocity_of, velocity_resolution, velocity_scale, with_v_smooth)

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
    # a run's load (docs/formats.md#loads): constant over the run
    # (no motion kind: a joint's axial preload in N is a normal force)
    "normal_force": {u: (s, None) for u, s in _FORCE.items()},
    "load_torque": {u: (s, None) for u, s in _TORQUE.items()},
    # a warm-up record (docs/formats.md#warm-up-records): the ambient temperature and a proxy's (winding, housing)
    "ambient_temperature": {"C": (1.0, None)},
    "proxy_temperature": {"C": (1.0, None)},
    **COMMAND_UNITS,  # a drive's command instead of the friction (data/command.py)
}
_UNITS["displacement"] = _UNITS["position"]
_SI = {"time": "s", "position": "m", "displacement": "m", "velocity": "m/s", "friction_force": "N",
       "friction_torque": "N*m", "normal_force": "N", "load_torque": "N*m", "temperature": "C", "ambient_temperature": "C",
       "proxy_temperature": "C", **COMMAND_SI}
#: a load file's value column (``simulate --load-file``): its names and units with their scales to SI
LOAD_FILE_UNITS = {k: {u: s for u, (s, _) in _UNITS[k].items()} for k in LOAD_COLUMNS}
#: the columns that hold temperatures [C], each checked for plausibility
TEMPERATURE_COLUMNS = ("temperature", "ambient_temperature", "proxy_temperature")
#: Header names that mark a force (torque) experiment, as opposed to an actuator's (voltage, displacement).
MARKERS = ("friction_force", "friction_torque", "position", "velocity", *COMMAND_UNITS)
#: A sampling interval this many times the median one is a gap in the record (warned about).
GAP_RATIO = 10.0
EXAMPLE = "time[s],position[rad],velocity[rad/s],friction_torque[N*m]"

#: The sign check: sliding samples are those faster than this fraction of the 95th percentile speed; a
#: friction column whose sign (the offset removed) opposes the velocity's on at least OPPOSED_FRACTION of them
#: is refused.
SLIDING_FRACTION = 0.05
OPPOSED_FRACTION = 0.75


@dataclasses.dataclass(eq=False)
class ForceExperiment(Experiment):
    """One run of measured motion and measured friction, in SI units: ``displacement`` is the position [m or
    rad], ``force`` the friction force or torque [N or N m] (sign convention: that of the velocity in sliding),
    ``velocity`` the recorded velocity column (None without one), ``rotary`` whether the units are angles and
    torques. ``motion`` is what drives the model, "velocity" (the column) or "position" (its derivative); None
    means the column where there is one. ``motion_check`` compares the column with the position's derivative
    (:class:`MotionCheck`; None without a column or when ``motion = "position"`` was asked). ``input`` is the
    motion waveform that drives a prescribed-motion model (:func:`motion_waveform`); ``voltage`` is None."""

    force: np.ndarray | None = None
    velocity: np.ndarray | None = None
    rotary: bool = False
    motion: str | None = None
    motion_check: MotionCheck | None = None
    #: "friction" (a friction sensor's record) or "command" (a drive's command, or current x torque_constant,
    #: in ``force``: data/command.py), and the header of the column it was read from
    measured_quantity: str = "friction"
    column: str | None = None
    #: a warm-up record (docs/formats.md#warm-up-records): the ambient temperature [C] per sample, with no
    #: contact temperature known (``temperature`` is then the ambient's mean, a label only)
    ambient_temperature: np.ndarray | None = None
    #: a proxy temperature [C] per sample (a winding's or housing's sensor, lagging the contact), or None
    proxy_temperature: np.ndarray | None = None
    #: the record (its manifest file) this one continues: it starts in the thermal state that one ended in
    continues: str | None = None

    @property
    def warm_up(self) -> bool:
        """Whether the run is a warm-up record: an ambient temperature and no contact temperature."""
        return self.ambient_temperature is not None

    @property
    def motion_source(self) -> str:
        """"velocity" or "position": what drives the model."""
        if self.motion is not None:
            return self.motion
        return "velocity" if self.velocity is not None else "position"

    @property
    def drive_velocity(self) -> np.ndarray:
        """The velocity the model is driven with at the sample times."""
        return velocity_of(self.time, self.displacement, self.velocity if self.motion_source == "velocity" else None)

    @functools.cached_property
    def velocity_resolution(self) -> float | None:
        """The step of the driving velocity [m/s or rad/s] where it is quantised, else None
        (:func:`velocity_resolution`)."""
        return velocity_resolution(self.time, self.displacement,
                                   self.velocity if self.motion_source == "velocity" else None)

    @property
    def force_unit(self) -> str:
        return "N m" if self.rotary else "N"

    @property
    def force_column(self) -> str:
        """The header of ``force`` in SI units as a CSV file writes it."""
        kind = "command" if self.measured_quantity == "command" else "friction"
        return f"{kind}_torque[N*m]" if self.rotary else f"{kind}_force[N]"


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


# -- sign convention -------------------------------------------------------------------------------

def check_sign(path, velocity, force, column: str = "friction_force"):
    """Refuses a friction column that opposes the motion: over the sliding samples (faster than
    SLIDING_FRACTION of the 95th percentile speed), ``force - b`` has the sign opposite to the velocity's on at
    least OPPOSED_FRACTION of them and the fitted level c of ``force = b + c sgn(v)`` is negative (b, the
    sensor's offset, fitted where the motion goes both ways, else 0)."""
    v = np.asarray(velocity, float)
    F = np.asarray(force, float)
    speed = np.abs(v)
    top = float(np.quantile(speed, 0.95)) if speed.size else 0.0
    sliding = speed > SLIDING_FRACTION * top
    if not top > 0 or int(sliding.sum()) < 10:
        return
    s, f = np.sign(v[sliding]), F[sliding]
    if np.any(s > 0) and np.any(s < 0):
        (b, c), *_ = np.linalg.lstsq(np.column_stack([np.ones(s.size), s]), f, rcond=None)
    else:
        b, c = 0.0, float(np.mean(s * f))
    tol = 1e-9 * float(np.max(np.abs(f)))  # (a constant column's rounding is no sign)
    opposed = float(np.mean((f - b) * s < -tol))
    if c < -1e3 * tol and opposed >= OPPOSED_FRACTION:
        raise InputError(f"{path}: the {column} column opposes the motion: on {100 * opposed:.0f} % of the "
                         f"{s.size} sliding samples its sign (offset {b:.4g} removed) is the opposite of the "
                         f"velocity's (level {c:.4g}). thermofriction reads friction with the sign of the velocity "
                         f"(the force the drive spends against it); a reaction sensor measures the opposite: give "
                         f"flip_sign = true in the experiment's [[experiment]] entry of dataset.toml (or at the top "
                         f"of it, for every experiment) to read the column negated")


# -- files -----------------------------------------------------------------------------------------

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


def column_key(name: str) -> str:
    """The key of a force file's column in the columns read (:func:`read_force_csv`)."""
    if name == "displacement":
        return "position"
    if column_key_of(name):
        return column_key_of(name)
    return "force" if name in ("friction_force", "friction_torque") else name


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
        key = column_key(name)
        for k, c in enumerate(cols):
            if c[0] == key:
                raise InputError(f"{where}: {shorten(cell)} duplicates column {k + 1} ({c[2]})")
        scale, kind = _UNITS[name][unit]
        if kind is not None:
            kinds[cell] = kind
        cols.append((key, scale, cell))
    check_force_columns_present(path, [c[0] for c in cols], "line 1: ", EXAMPLE)
    return cols, units_kind(path, kinds, "line 1: ")


def check_force_columns_present(path, names, where: str, example: str):
    """The columns a force experiment needs (``names``: the keys of :func:`column_key`), or one InputError."""
    measured = [n for n in MEASURED_KEYS if n in names]
    if not measured:
        raise InputError(f"{path}: {where}no friction_force[N] or friction_torque[N*m] column: a force experiment "
                         f"records the friction it measures (e.g. {example}), or, for a drive without a torque "
                         f"sensor, its command_force[N], command_torque[N*m] or current[A]")
    if len(measured) > 1:
        raise InputError(f"{path}: {where}both a friction and a command (current) column: a force experiment "
                         f"records one of them")
    missing = [n for n in ("time", "position") if n not in names]
    if missing:
        what = "the motion: a position[...] (or displacement[...]) column" if "position" in missing else "time[s]"
        raise InputError(f"{path}: {where}a force experiment needs {what}"
                         f"{' and time[s]' if len(missing) > 1 else ''} (e.g. {example})")


def units_kind(path, kinds: dict, where: str) -> bool:
    """Whether the columns' units (``kinds``: label -> "linear" | "rotary") are rotary; a mix is an error."""
    if len(set(kinds.values())) > 1:
        lin = [c for c, k in kinds.items() if k == "linear"]
        rot = [c for c, k in kinds.items() if k == "rotary"]
        raise InputError(f"{path}: {where}mixed linear ({', '.join(lin)}) and rotary ({', '.join(rot)}) units: a "
                         f"linear experiment records m, m/s and N; a rotary one rad, rad/s and N*m")
    return set(kinds.values()) == {"rotary"}


def check_force_values(path, out: dict, where, where_row):
    """The rules of every force experiment on its columns in SI units (``out``: key -> array): finite values
    within the limits, at least MIN_SAMPLES rows, time strictly increasing (a gap of more than GAP_RATIO
    median intervals warned about), plausible temperatures. ``where(key, row)`` says where a value is (CSV: line
    and column; MATLAB: variable and element), ``where_row(row)`` where a row is."""
    from ..plausible import kelvin_hint
    from .experiments import TEMPERATURE_RANGE
    first = [(int(np.argmax(~np.isfinite(a))), k, key) for k, (key, a) in enumerate(out.items())
             if not np.isfinite(a).all()]
    if first:  # the first bad value row by row, as a reader meets it
        r, _, key = min(first)
        raise InputError(f"{path}: {where(key, r)}: not a finite number")
    n = out["time"].size
    if n < MIN_SAMPLES:
        raise InputError(f"{path}: {n} data row{'s' if n != 1 else ''}; an experiment needs at least {MIN_SAMPLES}")
    for key, a in out.items():
        lim = TIME_LIMIT if key == "time" else VALUE_LIMIT
        big = np.abs(a) > lim
        if big.any():
            raise InputError(f"{path}: {where(key, int(np.argmax(big)))}: beyond the limit of {lim:g} in magnitude")
    t = out["time"]
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0))
        raise InputError(f"{path}: {where('time', i + 1)}: time must increase strictly ({t[i + 1]:.10g} s after "
                         f"{t[i]:.10g} s on {where_row(i)})")
    med = float(np.median(dt))
    gaps = np.flatnonzero(dt > GAP_RATIO * med)
    if gaps.size:
        i = int(gaps[np.argmax(dt[gaps])])
        warnings.warn(f"{path}: {where_row(i + 1)}: a gap of {dt[i]:.4g} s in the record, "
                      f"{dt[i] / med:.0f} times the typical interval of {med:.4g} s ({gaps.size} such gap"
                      f"{'s' if gaps.size > 1 else ''}); the motion is interpolated linearly across it",
                      SamplingWarning, stacklevel=3)
    for key in (k for k in TEMPERATURE_COLUMNS if k in out):
        lo, hi = TEMPERATURE_RANGE
        T = out[key]
        badT = (T < lo) | (T > hi)
        if badT.any():
            i = int(np.argmax(badT))
            raise InputError(f"{path}: {where(key, i)}: {T[i]:g} C is not a plausible temperature "
                             f"(expected {lo:g} to {hi:g} C{kelvin_hint(float(T[i]))})")


def read_force_csv(path) -> dict:
    """Reads one force (torque) experiment CSV into SI arrays: a dict with ``time``, ``position``, ``force``,
    ``rotary``, ``headers`` (key -> the header cell) and, where given, ``velocity`` and ``temperature``. Any
    problem is one InputError naming the file, line and column. Irregular sampling is accepted (time must
    increase strictly); a gap of more than GAP_RATIO times the median interval is a SamplingWarning. The
    velocity is not compared with the position here (:func:`choose_motion` does, at loading)."""
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
    index = {c[0]: j for j, c in enumerate(cols)}
    out = {name: arr[:, j] * scale for j, (name, scale, _) in enumerate(cols)}

    def where(key, row):
        j = index[key]
        return f"line {_line_of(body, row)}, column {j + 1} ({cols[j][2]})"

    check_force_values(path, out, where, lambda row: f"line {_line_of(body, row)}")
    out["rotary"] = rotary
    out["headers"] = {c[0]: c[2] for c in cols}
    return out


def force_experiment(path, name, *, temperature, role, description, from_zero, motion: str = "auto",
                     flip_sign: bool = False, struct=None, columns=None, torque_constant=None,
                     ambient_temperature=None, continues=None, load=None) -> ForceExperiment:
    """A :class:`ForceExperiment` from the file ``path`` (``name`` as the manifest gives it; ``struct``: the
    MATLAB struct holding the run); ``temperature`` is the manifest's (None: the column's
    mean); ``from_zero`` moves a clock time to start at zero; ``motion`` chooses what drives the model
    (:func:`choose_motion`); ``flip_sign`` negates the friction column (a reaction sensor); the friction's sign
    is then checked (:func:`check_sign`). ``columns``: the file's columns when already read (a MATLAB file's,
    data/matlab.py: read_force_mat); None reads ``path`` as a CSV file. A drive's command (or a current times
    ``torque_constant``) in place of the friction is read by data/command.py: measured_force. A run with an
    ambient temperature (an ``ambient_temperature[C]`` column, or the manifest's ``ambient_temperature``) and no
    contact temperature is a warm-up record (:func:`warm_up_columns`); ``continues``: the manifest file it
    continues. ``load``: the manifest's load [N or N m], else a load column's (:func:`run_load`)."""
    cols = read_force_csv(path) if columns is None else columns
    t, _ = from_zero(cols["time"], None)
    sig = cols.get("temperature")
    ambient, proxy = warm_up_columns(path, cols, temperature, ambient_temperature, continues)
    if temperature is None and ambient is not None:
        temperature = float(np.mean(ambient))  # a label: the contact's temperature is what a warm-up fit finds
    if temperature is None:
        if sig is None:
            raise InputError(f"{path}: no temperature: give 'temperature' in the manifest or a temperature[C] column"
                             f" (or, for a warm-up record, an ambient_temperature[C] column)")
        temperature = float(np.mean(sig))
    v = cols.get("velocity")
    F, quantity, column = measured_force(path, cols, torque_constant)
    F = np.asarray(F, float)
    if F.size and np.ptp(F) <= 1e-12 * np.max(np.abs(F)):  # its noise estimate would be 0: nothing to weigh a fit by
        raise InputError(f"{path}: column {column or 'friction'}: the force does not vary (every sample is "
                         f"{F[0]:g}): a stuck load cell? A constant record has no friction to identify")
    F = -F if flip_sign else F
    source, check = choose_motion(path, t, cols["position"], v, motion, cols.get("headers"))
    drive_v = velocity_of(t, cols["position"], v if source == "velocity" else None)
    column = column or ("friction_torque" if cols["rotary"] else "friction_force")
    if not flip_sign:
        check_sign(path, drive_v, F, column)
    return ForceExperiment(file=name, time=t, voltage=None, displacement=cols["position"], temperature=temperature,
                           temperature_signal=sig, role=role, description=description,
                           input=motion_waveform(t, drive_v, cols["position"][0]), force=F, velocity=v,
                           rotary=cols["rotary"], struct=struct, motion=source, motion_check=check, measured_quantity=quantity,
                           column=column, headers=_headers(path, cols), ambient_temperature=ambient,
                           proxy_temperature=proxy, continues=continues, load=run_load(path, cols, load),
                           load_signal=load_column(cols))


def warm_up_columns(path, cols: dict, temperature, ambient_temperature, continues) -> tuple:
    """(ambient, proxy) of a run, each an array [C] or None: the ``ambient_temperature[C]`` column, or the
    manifest's ``ambient_temperature`` as a constant; the ``proxy_temperature[C]`` column. Refused, naming the
    file: both an ambient column and the manifest key; an ambient temperature beside a contact temperature (a
    ``temperature`` column or key: the run is then a soak run, and its ambient says nothing); a proxy or
    ``continues`` without an ambient."""
    n = cols["time"].size
    ambient = cols.get("ambient_temperature")
    if ambient is not None and ambient_temperature is not None:
        raise InputError(f"{path}: both an ambient_temperature[C] column and the manifest's 'ambient_temperature': "
                         f"give one")
    if ambient is None and ambient_temperature is not None:
        ambient = np.full(n, float(ambient_temperature))
    if ambient is not None and (temperature is not None or cols.get("temperature") is not None):
        raise InputError(f"{path}: an ambient temperature beside the contact's (a 'temperature' key or a "
                         f"temperature[C] column): a warm-up record has no contact temperature; a soak run at a "
                         f"known temperature needs no ambient")
    proxy = cols.get("proxy_temperature")
    if ambient is None and (proxy is not None or continues is not None):
        what = "a proxy_temperature[C] column" if proxy is not None else "'continues'"
        raise InputError(f"{path}: {what} belongs to a warm-up record, which needs the ambient temperature (an "
                         f"ambient_temperature[C] column or the manifest's 'ambient_temperature')")
    return ambient, proxy


def _headers(path, cols) -> dict:
    """Per column read, (where the file holds it, the unit its header declared): what a unit warning names
    (unit_scale.py). A MATLAB file's variables come with their units (``cols["units"]``), a CSV file's header
    cells hold theirs."""
    units = cols.get("units")
    if units is not None:
        return {k: (where, units[k]) for k, where in cols.get("headers", {}).items() if k in units}
    return {k: (f"column {cell}", header_cell(path, 0, cell, _SI, EXAMPLE)[1]) for k, cell in
            cols.get("headers", {}).items()}


def write_force_csv(path, time, position, force, *, velocity=None, temperature=None, rotary=False, column=None):
    """Writes a force experiment CSV (SI units in the header), atomically; ``column`` the force column's header
    (default the friction's, e.g. ``command_torque[N*m]`` or ``current[A]`` for a drive's command)."""
    from .._io import atomic_write
    head = ["time[s]", "position[rad]" if rotary else "position[m]"]
    data = [time, position]
    if velocity is not None:
        head.append("velocity[rad/s]" if rotary else "velocity[m/s]")
        data.append(velocity)
    head.append(column or ("friction_torque[N*m]" if rotary else "friction_force[N]"))
    data.append(force)
    if temperature is not None:
        head.append("temperature[C]")
        data.append(np.broadcast_to(np.asarray(temperature, float), np.shape(time)))
    arr = np.column_stack([np.asarray(c, float) for c in data])
    with atomic_write(Path(path), "w") as fh:
        fh.write(",".join(head) + "\n")
        np.savetxt(fh, arr, delimiter=",", fmt="%.12g")


__all__ = ["ForceExperiment", "SamplingWarning", "MotionWarning", "MotionCheck", "MOTIONS", "read_force_csv",
           "force_experiment", "is_force_file", "is_force_data", "units_of", "motion_waveform", "write_force_csv",
           "GAP_RATIO", "velocity_lag", "velocity_scale", "check_motion", "choose_motion", "quantum",
           "velocity_resolution", "v_smooth_for", "warm_up_columns", "TEMPERATURE_COLUMNS", "LOAD_FILE_UNITS", "with_v_smooth", "check_sign", "check_motion_option",
           "POSITION_MISMATCH_ERROR"]
