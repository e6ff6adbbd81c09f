"""Input waveforms (docs/formats.md#inputs): what drives a plant, in volts (or newtons, or metres).

Each waveform is evaluated by the C core, so the integrator and these objects agree exactly,
and exposes its corner times (where it or its slope jumps); the integrator stops at every one.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import MISSING, dataclass, field, fields
from pathlib import Path

import numpy as np

from . import _bridge
from ._reading import read_bytes, strict_float
from .errors import InputError, shorten, unknown_keys

def _finite(name, value, where):
    if isinstance(value, (str, bytes, bool, np.bool_)):  # float("1e5") would pass: a number is asked for
        raise InputError(f"{where}: '{name}' must be a number, got {shorten(value)}")
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{where}: '{name}' must be a number, got {shorten(value)}") from None
    except OverflowError:  # an integer beyond the float range, e.g. 10**400
        raise InputError(f"{where}: '{name}' must be finite, got an integer too large for a number") from None
    if not math.isfinite(value):
        raise InputError(f"{where}: '{name}' must be finite, got {value!r}")
    return value


def _positive(name, value, where):
    value = _finite(name, value, where)
    if value <= 0:
        raise InputError(f"{where}: '{name}' must be positive, got {value!r}")
    return value


class Waveform:
    """Common interface: ``w(t)``, ``w.corners(t0, t1)``, ``w.period``, ``w.to_dict()``."""

    kind = "zero"
    period: float | None = None

    def core_fields(self) -> dict:
        """The numbers the C core's tf_waveform takes (amplitude, frequency, rise, offset,
        direction, slew, t0, t, v); absent ones are zero (direction: +1)."""
        return {}

    def __call__(self, t):
        return _bridge.waveform_eval(self, np.ascontiguousarray(np.atleast_1d(t), dtype=float))

    def corners(self, t0: float, t1: float) -> np.ndarray:
        """Corner times in [t0, t1]."""
        return _bridge.waveform_corners(self, t0, t1)

    def to_dict(self) -> dict:
        d = {"waveform": self.kind}
        d.update({f.name: getattr(self, f.name) for f in fields(self)})
        return d

    def spec(self) -> str:
        """The ``--input`` form of this waveform."""
        return self.kind + ":" + ",".join(f"{k}={v!r}" for k, v in self.to_dict().items() if k != "waveform")


@dataclass(frozen=True)
class Zero(Waveform):
    kind = "zero"

    def core_fields(self):
        return {}


@dataclass(frozen=True)
class Sawtooth(Waveform):
    """Rises linearly for ``rise`` of each period from ``offset`` to ``offset + amplitude``,
    falls linearly in the rest. ``direction=-1`` mirrors it in time (fast rise, slow fall),
    which drives a stick-slip actuator the other way with the same, unipolar voltage range.

    Parameters
    ----------
    amplitude : float
        The rise, in the input's unit (V for an actuator's voltage, N for a mass's force, m or rad for a prescribed motion,
        W for an external heat).
    frequency : float
        The frequency [Hz], > 0.
    rise : float, default 0.99
        The fraction of each period spent rising, between 0 and 1.
    offset : float, default 0.0
        The low level, in the same unit as ``amplitude``.
    direction : {1, -1}, default 1
        -1 mirrors the waveform in time (fast rise, slow fall).

    Raises
    ------
    InputError
        A field that is not a finite number or out of its range, named with the waveform
        (``sawtooth: 'rise' must be between 0 and 1``).

    Examples
    --------
    >>> import thermofriction as tf
    >>> w = tf.Sawtooth(amplitude=30.0, frequency=5.0, rise=0.5)
    >>> w.period
    0.2
    >>> [round(float(x), 9) for x in w([0.0, 0.05, 0.1])]
    [0.0, 15.0, 30.0]
    """

    amplitude: float
    frequency: float
    rise: float = 0.99
    offset: float = 0.0
    direction: int = 1
    kind = "sawtooth"

    def __post_init__(self):
        w = "sawtooth"
        object.__setattr__(self, "amplitude", _finite("amplitude", self.amplitude, w))
        object.__setattr__(self, "frequency", _positive("frequency", self.frequency, w))
        object.__setattr__(self, "offset", _finite("offset", self.offset, w))
        rise = _finite("rise", self.rise, w)
        if not 0 < rise < 1:
            raise InputError(f"sawtooth: 'rise' must be between 0 and 1 (exclusive), got {rise!r}")
        object.__setattr__(self, "rise", rise)
        if isinstance(self.direction, (bool, np.bool_)) or not isinstance(self.direction, (int, float, np.integer, np.floating)) or self.direction not in (1, -1):
            raise InputError(f"sawtooth: 'direction' must be +1 or -1, got {self.direction!r}")
        object.__setattr__(self, "direction", int(self.direction))

    @property
    def period(self):
        return 1.0 / self.frequency

    def core_fields(self):
        return {"amplitude": self.amplitude, "frequency": self.frequency, "rise": self.rise, "offset": self.offset,
                "direction": self.direction}


@dataclass(frozen=True)
class Sine(Waveform):
    """``offset + amplitude * sin(2 pi frequency t)``: starts at ``offset``, rising.

    Parameters
    ----------
    amplitude : float
        The amplitude, in the input's unit (V for an actuator's voltage, N for a mass's force, m or rad for a prescribed motion,
        W for an external heat).
    frequency : float
        The frequency [Hz], > 0.
    offset : float, default 0.0
        The mean level, in the same unit as ``amplitude``.

    Raises
    ------
    InputError
        A field that is not a finite number or out of its range, named with the waveform
        (``sawtooth: 'rise' must be between 0 and 1``).

    Examples
    --------
    >>> import thermofriction as tf
    >>> w = tf.Sine(amplitude=2.0, frequency=10.0, offset=1.0)
    >>> [round(float(x), 9) for x in w([0.0, 0.025])]
    [1.0, 3.0]
    """

    amplitude: float
    frequency: float
    offset: float = 0.0
    kind = "sine"

    def __post_init__(self):
        object.__setattr__(self, "amplitude", _finite("amplitude", self.amplitude, "sine"))
        object.__setattr__(self, "frequency", _positive("frequency", self.frequency, "sine"))
        object.__setattr__(self, "offset", _finite("offset", self.offset, "sine"))

    @property
    def period(self):
        return 1.0 / self.frequency

    def core_fields(self):
        return {"amplitude": self.amplitude, "frequency": self.frequency, "offset": self.offset}


@dataclass(frozen=True)
class Square(Waveform):
    """Between ``offset`` and ``offset + amplitude``: ramps up over ``slew`` seconds at the start
    of each period, holds, ramps down over ``slew`` at ``duty`` of the period, holds.

    Parameters
    ----------
    amplitude : float
        The step between the levels, in the input's unit (V for an actuator's voltage, N for a mass's force, m or rad for a prescribed motion,
        W for an external heat).
    frequency : float
        The frequency [Hz], > 0.
    slew : float
        The ramps' duration [s], > 0 and shorter than the high and low parts of the period.
    offset : float, default 0.0
        The low level, in the same unit as ``amplitude``.
    duty : float, default 0.5
        The fraction of the period from the start of the rise to the start of the fall, between 0 and 1.

    Raises
    ------
    InputError
        A field that is not a finite number or out of its range, named with the waveform
        (``sawtooth: 'rise' must be between 0 and 1``).
    """

    amplitude: float
    frequency: float
    slew: float
    offset: float = 0.0
    duty: float = 0.5
    kind = "square"

    def __post_init__(self):
        w = "square"
        object.__setattr__(self, "amplitude", _finite("amplitude", self.amplitude, w))
        f = _positive("frequency", self.frequency, w)
        object.__setattr__(self, "frequency", f)
        slew = _positive("slew", self.slew, w)
        duty = _finite("duty", self.duty, w)
        if not 0 < duty < 1:
            raise InputError(f"square: 'duty' must be between 0 and 1 (exclusive), got {duty!r}")
        if slew >= duty / f or slew >= (1 - duty) / f:
            raise InputError(f"square: 'slew' ({slew!r} s) must be shorter than the high and low parts of the period")
        object.__setattr__(self, "slew", slew)
        object.__setattr__(self, "duty", duty)
        object.__setattr__(self, "offset", _finite("offset", self.offset, w))

    @property
    def period(self):
        return 1.0 / self.frequency

    def core_fields(self):  # the core reads the duty cycle from 'rise'
        return {"amplitude": self.amplitude, "frequency": self.frequency, "rise": self.duty, "offset": self.offset,
                "slew": self.slew}


@dataclass(frozen=True)
class Step(Waveform):
    """``offset`` before ``time``, ``offset + amplitude`` after, ramped over ``slew`` seconds
    (``slew=0``: an ideal step, which the integrator handles exactly by stopping there).

    Parameters
    ----------
    amplitude : float
        The step, in the input's unit (V for an actuator's voltage, N for a mass's force, m or rad for a prescribed motion,
        W for an external heat).
    time : float, default 0.0
        When the step starts [s].
    slew : float, default 0.0
        The ramp's duration [s], >= 0.
    offset : float, default 0.0
        The level before the step, in the same unit as ``amplitude``.

    Raises
    ------
    InputError
        A field that is not a finite number or out of its range, named with the waveform
        (``sawtooth: 'rise' must be between 0 and 1``).
    """

    amplitude: float
    time: float = 0.0
    slew: float = 0.0
    offset: float = 0.0
    kind = "step"

    def __post_init__(self):
        object.__setattr__(self, "amplitude", _finite("amplitude", self.amplitude, "step"))
        object.__setattr__(self, "time", _finite("time", self.time, "step"))
        slew = _finite("slew", self.slew, "step")
        if slew < 0:
            raise InputError(f"step: 'slew' must not be negative, got {slew!r}")
        object.__setattr__(self, "slew", slew)
        object.__setattr__(self, "offset", _finite("offset", self.offset, "step"))

    def core_fields(self):
        return {"amplitude": self.amplitude, "offset": self.offset, "slew": self.slew, "t0": self.time}


@dataclass(frozen=True, eq=False)
class Sampled(Waveform):
    """Linear interpolation through (time, value) pairs; held constant beyond the ends.
    ``file`` records where the samples came from, for saving a model.

    Parameters
    ----------
    time : array_like
        The sample times [s], finite and strictly increasing; at least two.
    value : array_like
        The values, in the input's unit (V for an actuator's voltage, N for a mass's force, m or rad for a prescribed motion,
        W for an external heat); as many as ``time``.
    file : str, optional
        The file the samples were read from (a model file's ``sampled:file=...``).

    Raises
    ------
    InputError
        Arrays that are not numbers, of unequal lengths or shorter than two, non-finite, or times that do not
        increase strictly, named with the file.
    """

    time: np.ndarray
    value: np.ndarray
    file: str | None = field(default=None)
    kind = "sampled"

    def __post_init__(self):
        where = f"sampled waveform{f' {self.file}' if self.file else ''}"
        for name in ("time", "value"):  # arrays of numbers only: no text, no booleans read as 0/1
            a = getattr(self, name)
            if not isinstance(a, (list, tuple, np.ndarray)) or np.asarray(a).dtype.kind not in "iuf":
                raise InputError(f"{where}: {name} must be an array of numbers, got {type(a).__name__} {shorten(a)}")
        t = np.ascontiguousarray(self.time, dtype=float)
        v = np.ascontiguousarray(self.value, dtype=float)
        if t.ndim != 1 or t.shape != v.shape or t.size < 2:
            raise InputError(f"{where}: needs at least two (time, value) pairs of equal length")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
            raise InputError(f"{where}: times and values must be finite")
        if np.any(np.diff(t) <= 0):
            i = int(np.argmax(np.diff(t) <= 0)) + 1
            raise InputError(f"{where}: time must increase strictly (sample {i + 1}: {float(t[i])!r} after {float(t[i - 1])!r})")
        object.__setattr__(self, "time", t)
        object.__setattr__(self, "value", v)

    def to_dict(self):
        if self.file:
            return {"waveform": "sampled", "file": self.file}
        return {"waveform": "sampled", "time": self.time.tolist(), "value": self.value.tolist()}

    def spec(self):
        if not self.file:
            raise InputError("a sampled waveform without a file has no --input form")
        return f"sampled:file={self.file}"

    def core_fields(self):
        return {"t": self.time, "v": self.value}

    @classmethod
    def from_csv(cls, path, base_dir=None, columns=None):
        """Reads ``time[s]`` and one value column (docs/formats.md#inputs); ``columns``: the value column's
        allowed names and units (read_two_column_csv)."""
        p = Path(path)
        if base_dir is not None and not p.is_absolute():
            p = Path(base_dir) / p
        time, value = read_two_column_csv(p, "time", columns)
        return cls(time, value, file=str(path))


def read_two_column_csv(path: Path, first: str, columns: dict | None = None):
    """A CSV with a header ``first[unit]`` and one value column; time units s or ms.

    Parameters
    ----------
    path : pathlib.Path
        The file.
    first : str
        The first column's name (``"time"``).
    columns : dict, optional
        The value column's allowed names, each with its units and their scales to SI (``{"normal_force": {"N": 1.0,
        "mN": 1e-3}}``); the values are returned in SI. None: any header, the values as they are.

    Returns
    -------
    tuple of numpy.ndarray
        (the first column in seconds, the values).

    Raises
    ------
    InputError
        A file that cannot be read or is not UTF-8 CSV, a wrong header or unit, fewer than two data rows, a
        value that is not a number, named with the file and line.
    """
    try:
        text = read_bytes(path, "CSV file").decode("utf-8-sig")
        reader = csv.reader(io.StringIO(text, newline=""))
        numbered = [(reader.line_num, r) for r in reader]  # line_num: the file's line where the row ends
    except OSError as e:
        raise InputError(f"{path}: cannot read ({e.strerror or e})") from None
    except UnicodeDecodeError as e:
        raise InputError(f"{path}: not UTF-8 text ({e.reason} at byte {e.start})") from None
    except ValueError as e:  # a NUL byte in the path
        raise InputError(f"{str(path)!r}: not a usable file name ({e})") from None
    except csv.Error as e:
        raise InputError(f"{path}: line {reader.line_num}: not a valid CSV row ({e})") from None
    numbered = [(n, r) for n, r in numbered if r and any(c.strip() for c in r)]
    lines = [n for n, _ in numbered]
    rows = [r for _, r in numbered]
    if len(rows) < 3:
        raise InputError(f"{path}: needs a header row and at least two data rows")
    header = [h.strip() for h in rows[0]]
    if len(header) != 2:
        raise InputError(f"{path}: line {lines[0]}: expected two columns ({first}[s] and a value), got {len(header)}")
    name, _, unit = header[0].partition("[")
    unit = unit.rstrip("]") or "s"
    if name.strip() != first:
        raise InputError(f"{path}: line {lines[0]}: the first column must be '{first}[s]', got {shorten(header[0])}")
    scale = {"s": 1.0, "ms": 1e-3}.get(unit)
    if scale is None:
        raise InputError(f"{path}: line {lines[0]}: unknown time unit {shorten(unit)} (use s or ms)")
    value_scale = 1.0 if columns is None else _value_scale(path, lines[0], header[1], columns)
    data = np.empty((len(rows) - 1, 2))
    for k, (i, row) in enumerate(zip(lines[1:], rows[1:]), start=2):
        if len(row) != 2:
            raise InputError(f"{path}: line {i}: expected 2 values, got {len(row)}")
        for j, cell in enumerate(row):
            try:
                data[k - 2, j] = strict_float(cell)
            except ValueError:
                raise InputError(f"{path}: line {i}, column '{header[j]}': not a number: "
                                 f"{shorten(cell.strip())}") from None
            if not math.isfinite(data[k - 2, j]):
                raise InputError(f"{path}: line {i}, column '{header[j]}': not finite: {shorten(cell.strip())}")
    t = data[:, 0] * scale
    far = np.nonzero(np.abs(t) > 1e12)[0]  # the C core's time limit (simulation.MAX_TIME)
    if far.size:
        raise InputError(f"{path}: line {lines[far[0] + 1]}: time {t[far[0]]:g} s is beyond the limit of 1e12 s")
    bad = np.nonzero(np.diff(t) <= 0)[0]  # after scaling: ms to s can merge neighbouring values
    if bad.size:
        raise InputError(f"{path}: line {lines[bad[0] + 2]}: time must increase strictly")
    return t, data[:, 1] * value_scale


def _value_scale(path, line, head: str, columns: dict) -> float:
    """The value column's scale to SI from its header ``name[unit]``, refused naming the file and line where the
    name or the unit is not one of ``columns``."""
    name, _, unit = head.partition("[")
    name, unit = name.strip(), unit.rstrip("]").strip()
    allowed = " or ".join(f"{n}[{next(iter(u))}]" for n, u in columns.items())
    if name not in columns:
        raise InputError(f"{path}: line {line}: the value column must be {allowed}, got {shorten(head)}")
    if unit not in columns[name]:
        raise InputError(f"{path}: line {line}: unknown unit {shorten(unit)} of {name} (use "
                         f"{', '.join(columns[name])})")
    return float(columns[name][unit])


_KINDS = {"sawtooth": Sawtooth, "sine": Sine, "square": Square, "step": Step}


def waveform_from_dict(d: dict, where: str = "[input]", base_dir=None) -> Waveform:
    """Builds a waveform from a model file's ``[input]`` table or a parsed ``--input`` spec.

    Parameters
    ----------
    d : dict
        ``waveform`` (the kind: sawtooth, sine, square, step, sampled) and the waveform's fields; a sampled one
        takes ``file``, or ``time`` and ``value`` arrays.
    where : str, default "[input]"
        The table's place, for the messages.
    base_dir : str or os.PathLike, optional
        The folder a sampled waveform's relative ``file`` is read from.

    Returns
    -------
    Waveform

    Raises
    ------
    InputError
        Not a table, an unknown kind or key, a bad value, a sampled file that cannot be read, named with
        ``where``.
    """
    if not isinstance(d, dict):
        raise InputError(f"{where}: must be a table such as {{ waveform = \"sawtooth\", amplitude = 30, frequency = 5 }}")
    d = dict(d)
    kind = d.pop("waveform", None)
    if kind is None:
        raise InputError(f"{where}: missing 'waveform' (one of: {', '.join([*_KINDS, 'sampled'])})")
    if kind == "sampled":
        if "file" in d:
            extra = set(d) - {"file"}
            if extra:
                raise InputError(f"{where}: {unknown_keys(extra, ['file'], 'sampled')}")
            if not isinstance(d["file"], str) or not d["file"].strip():
                raise InputError(f"{where}: sampled 'file' must be a file name, got {d['file']!r}")
            return Sampled.from_csv(d["file"], base_dir)
        extra = set(d) - {"time", "value"}
        if extra:
            raise InputError(f"{where}: {unknown_keys(extra, ['file', 'time', 'value'], 'sampled')}")
        if not {"time", "value"} <= set(d):
            raise InputError(f"{where}: sampled takes 'file', or 'time' and 'value' arrays")
        try:
            return Sampled(np.asarray(d["time"], float), np.asarray(d["value"], float))
        except (TypeError, ValueError, OverflowError):
            raise InputError(f"{where}: sampled 'time' and 'value' must be arrays of numbers") from None
    cls = _KINDS.get(kind) if isinstance(kind, str) else None
    if cls is None:
        raise InputError(f"{where}: unknown waveform {shorten(kind)} (one of: {', '.join([*_KINDS, 'sampled'])})")
    names = [f.name for f in fields(cls)]
    unknown = set(d) - set(names)
    if unknown:
        raise InputError(f"{where}: {unknown_keys(unknown, names, kind)}")
    missing = [f.name for f in fields(cls) if f.default is MISSING and f.name not in d]
    if missing:
        raise InputError(f"{where}: {kind} needs {', '.join(missing)}")
    try:
        return cls(**d)
    except InputError as e:
        raise InputError(f"{where}: {e}") from None


def parse_waveform(spec: str) -> Waveform:
    """Parses an ``--input`` spec such as ``sawtooth:amplitude=30,frequency=5,rise=0.999`` or
    ``sampled:file=u.csv`` (docs/formats.md): the waveform's kind, a colon, its fields as ``key=value``.

    Parameters
    ----------
    spec : str
        The spec; the keys are the fields of the waveform's class (``Sawtooth``, ``Sine``, ``Square``,
        ``Step``, ``Sampled``).

    Returns
    -------
    Waveform
        The waveform.

    Raises
    ------
    InputError
        Not a string; an unknown kind or key; a value that is not a number or out of range, named
        (``--input sawtooth:...: 'rise' must be between 0 and 1``).

    Examples
    --------
    >>> import thermofriction as tf
    >>> tf.parse_waveform("sawtooth:amplitude=30,frequency=5,rise=0.999")
    Sawtooth(amplitude=30.0, frequency=5.0, rise=0.999, offset=0.0, direction=1)
    """
    if not isinstance(spec, str):
        raise InputError(f"spec must be a string, a waveform spec such as 'sawtooth:amplitude=30,frequency=5', "
                         f"got {type(spec).__name__} {shorten(spec)}")
    where = f"--input {shorten(spec, 100)}"
    if not spec.isprintable():  # so that every message below, which quotes parts of it, is one line
        raise InputError(f"{where}: contains a control character (a line break, tab or NUL)")
    kind, sep, rest = spec.strip().partition(":")
    d: dict = {"waveform": kind.strip()}
    if rest.strip():
        for item in rest.split(","):
            key, eq, value = item.partition("=")
            key = key.strip()
            if not eq or not key:
                raise InputError(f"{where}: expected key=value, got {shorten(item.strip())}")
            if key in d:
                raise InputError(f"{where}: {shorten(key)} given twice")
            if key == "file":
                d[key] = value.strip()
                continue
            try:
                num = strict_float(value)
            except ValueError:
                raise InputError(f"{where}: {shorten(key)} must be a number, got {shorten(value.strip())}") from None
            d[key] = int(num) if key == "direction" and num.is_integer() else num
    return waveform_from_dict(d, where)


__all__ = ["Waveform", "Zero", "Sawtooth", "Sine", "Square", "Step", "Sampled", "parse_waveform",
           "waveform_from_dict", "read_two_column_csv"]
