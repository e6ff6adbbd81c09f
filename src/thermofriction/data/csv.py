"""Reading one experiment CSV file: units in the headers (docs/formats.md#datasets), every value
checked, errors naming the file, line and column."""

from __future__ import annotations

import csv
import warnings
from pathlib import Path

import numpy as np

from .._reading import read_input_file, strict_float
from .. import _args
from ..errors import InputError, shorten
from ..plausible import kelvin_hint
from .experiments import _SI, _UNITS, MAX_ROWS_ENV, MIN_SAMPLES, REQUIRED, SAMPLING_TOLERANCE, TEMPERATURE_RANGE, max_rows

#: Magnitude limits on an experiment's values in SI units: time within the simulator's +-1e12 s
#: (simulation.MAX_TIME); other values within 1e100, so that squares and sums of squares over ten
#: million rows (metrics, least squares) stay finite.
TIME_LIMIT = 1e12
VALUE_LIMIT = 1e100


def header_cell(path, j, raw, si, example):
    """A header cell ``name[unit]`` of column ``j`` (0-based) as (name, unit, the cell, where it is);
    without a unit, the column's SI unit from ``si``."""
    cell = raw.strip()
    where = f"{path}: line 1, column {j + 1}"
    name, br, unit = cell.partition("[")
    name = name.strip()
    if br:
        if not unit.endswith("]"):
            raise InputError(f"{where}: {shorten(cell)} must be name[unit], e.g. {example}")
        unit = unit[:-1].strip()
    else:
        unit = si.get(name, "")
    return name, unit, cell, where


def _parse_header(path, header):
    """[(name, scale to SI, the header cell)] for the header row, or one InputError."""
    cols = []
    for j, raw in enumerate(header):
        name, unit, cell, where = header_cell(path, j, raw, _SI, "displacement[um]")
        if not name:
            raise InputError(f"{where}: empty column name (columns: {', '.join(_UNITS)})")
        if name not in _UNITS:
            raise InputError(f"{where}: unknown column {shorten(name)} (columns: {', '.join(_UNITS)})")
        if unit not in _UNITS[name]:
            raise InputError(f"{where} ({shorten(cell)}): unknown unit {shorten(unit)} for {name} "
                             f"(one of: {', '.join(u for u in _UNITS[name] if u != 'μm')})")
        for k, c in enumerate(cols):
            if c[0] == name:
                raise InputError(f"{where}: duplicate column '{name}' (also column {k + 1})")
        cols.append((name, _UNITS[name][unit], cell))
    missing = [r for r in REQUIRED if r not in [c[0] for c in cols]]
    if missing:
        raise InputError(f"{path}: line 1: missing column{'s' if len(missing) > 1 else ''} {', '.join(missing)} "
                         f"(an experiment needs time[s], voltage[V], displacement[um])")
    return cols


def _scan(path, body, cols):
    """The slow, exact reader: the data rows one by one, so that an error names its line and
    column. Returns the array when every cell is a number."""
    ncol = len(cols)
    data = []
    for i, line in enumerate(body.split("\n"), start=2):
        if not line.strip():
            continue
        cells = line.rstrip("\r").split(",")
        if len(cells) != ncol:
            raise InputError(f"{path}: line {i}: {len(cells)} values, expected {ncol} "
                             f"({', '.join(c[2] for c in cols)})")
        row = []
        for j, cell in enumerate(cells):
            try:
                v = strict_float(cell)
            except ValueError:
                raise InputError(f"{path}: line {i}, column {j + 1} ({cols[j][2]}): not a number: "
                                 f"{shorten(cell.strip())}") from None
            row.append(v)
        data.append(row)
    return np.array(data, dtype=float).reshape(-1, ncol)


def _line_of(body, row):
    """The file's line number (header = 1) of data row ``row`` (0-based; blank lines skipped)."""
    n = -1
    for i, line in enumerate(body.split("\n"), start=2):
        if line.strip():
            n += 1
            if n == row:
                return i
    return row + 2


def read_experiment_bytes(path: Path) -> bytes:
    """An experiment CSV file's bytes, refused as one InputError when it cannot be read or has more data
    rows than the limit (checked before anything is parsed). Actuator and force experiments alike."""
    raw = read_input_file(path, "experiment CSV file")
    rows = raw.count(b"\n") + (not raw.endswith(b"\n")) - 1  # data rows, blank lines included
    limit = max_rows()
    if rows > limit:
        raise InputError(f"{path}: {rows} data rows, more than the limit of {limit} (each row takes ~150 bytes "
                         f"of memory while loading): downsample the file, or raise the limit with the "
                         f"environment variable {MAX_ROWS_ENV}=N")
    return raw


def read_experiment_csv(path, with_headers: bool = False) -> dict:
    """Reads one experiment CSV (docs/formats.md) into SI arrays: a dict with ``time``, ``voltage``,
    ``displacement`` and, where the file has them, ``temperature`` and ``stage_displacement``.

    The format is strict; any problem is one InputError naming the file and, where it applies, the
    line (the header is line 1) and the column.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    with_headers : bool, default False
        Also return, per column, (where the file holds it, the unit its header declared), for a dataset's checks.

    Returns
    -------
    dict
        Column -> numpy.ndarray in SI units (s, V, m, C); with ``with_headers``, (that dict, the headers).

    Raises
    ------
    InputError
        A file that cannot be read, is not UTF-8, has a bad header, unit or value, too few or too many rows, or
        times that do not increase, named with the file, line and column.
    """
    _args.path(path, "path")
    _args.flag(with_headers, "with_headers")
    path = Path(path)
    raw = read_experiment_bytes(path)
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        line = raw[:e.start].count(b"\n") + 1
        raise InputError(f"{path}: line {line}: not UTF-8 text") from None
    del raw  # ~0.4 GB for 10 M rows
    if not text or text.isspace():  # (no copy, unlike strip())
        raise InputError(f"{path}: empty file (an experiment needs a header row such as "
                         f"time[s],voltage[V],displacement[um] and at least {MIN_SAMPLES} data rows)")
    head, _, body = text.partition("\n")
    del text
    if not head.strip():
        raise InputError(f"{path}: line 1: blank; the first line must be the header row, "
                         f"e.g. time[s],voltage[V],displacement[um]")
    try:
        header = next(csv.reader([head.rstrip("\r")]))
    except csv.Error as e:  # e.g. a field beyond the csv module's size limit
        raise InputError(f"{path}: line 1: not a valid CSV header row ({e})") from None
    cols = _parse_header(path, header)
    ncol = len(cols)
    if not body or body.isspace():
        raise InputError(f"{path}: no data rows (only the header)")

    arr = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:  # the fast path; on any failure the exact scanner finds and names the bad cell
            # from the file, not io.StringIO(body): that holds 4 bytes per character (3 GB at 10 M rows)
            arr = np.loadtxt(path, delimiter=",", comments=None, ndmin=2, dtype=float, skiprows=1,
                             encoding="utf-8-sig")
        except ValueError:
            arr = None
    if arr is None or arr.ndim != 2 or arr.shape[1] != ncol:
        arr = _scan(path, body, cols)
    n = arr.shape[0]

    if n < MIN_SAMPLES:
        bad = ~np.isfinite(arr)
        if bad.any():
            r, j = (int(v) for v in np.argwhere(bad)[0])
            raise InputError(f"{path}: line {_line_of(body, r)}, column {j + 1} ({cols[j][2]}): "
                             f"not a finite number ({float(arr[r, j])})")
        raise InputError(f"{path}: {n} data row{'s' if n != 1 else ''}; an experiment needs at least "
                         f"{MIN_SAMPLES} samples")
    index = {name: j for j, (name, _, _) in enumerate(cols)}

    def where(name, row, short=False):
        if short:
            return f"line {_line_of(body, row)}"
        j = index[name]
        return f"line {_line_of(body, row)}, column {j + 1} ({cols[j][2]})"

    out = check_columns(path, {name: arr[:, j] for j, (name, _, _) in enumerate(cols)},
                        {name: scale for name, scale, _ in cols}, where)
    if with_headers:  # the header cells, for a dataset's plausibility checks
        return out, {c[0]: c[2] for c in cols}
    return out


def check_columns(path, raw: dict, scale: dict, where) -> dict:
    """The rules every experiment file obeys (docs/formats.md#experiment-files), on its columns in
    the file's units (``raw``: name -> array; ``scale``: name -> factor to SI): every value finite
    and within the limits, time strictly increasing and uniformly sampled, plausible temperatures.
    Returns the columns in SI units. ``where(name, row)`` says where a value is (``short=True``:
    the row alone), for the one InputError."""
    names = list(raw)
    first = [(int(np.argmax(~np.isfinite(raw[c]))), k) for k, c in enumerate(names) if not np.isfinite(raw[c]).all()]
    if first:  # the first bad value row by row, as a reader meets it
        r, k = min(first)
        raise InputError(f"{path}: {where(names[k], r)}: not a finite number ({float(raw[names[k]][r])})")
    out = {name: np.asarray(raw[name], float) * scale[name] for name in names}
    for name in names:
        limit = TIME_LIMIT if name == "time" else VALUE_LIMIT
        big = np.abs(out[name]) > limit
        if big.any():
            r = int(np.argmax(big))
            raise InputError(f"{path}: {where(name, r)}: {float(out[name][r]):g} "
                             f"{_SI[name]} is beyond the limit of {limit:g} {_SI[name]} in magnitude"
                             + (" (the simulator's time limit)" if name == "time" else
                                " (the metrics and the fit square the values: they would overflow)"))
    t = out["time"]
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0))
        raise InputError(f"{path}: {where('time', i + 1)}: time must increase strictly "
                         f"({float(raw['time'][i + 1]):.10g} after {float(raw['time'][i]):.10g} "
                         f"on {where('time', i, short=True)})")
    med = float(np.median(dt))
    irregular = np.abs(dt - med) > SAMPLING_TOLERANCE * med
    if np.any(irregular):
        i = int(np.argmax(irregular))
        raise InputError(f"{path}: {where('time', i + 1)}: irregular "
                         f"sampling: interval {dt[i]:.6g} s, median {med:.6g} s (the intervals may differ "
                         f"by at most {100 * SAMPLING_TOLERANCE:g} %)")
    if "temperature" in out:
        T = out["temperature"]
        lo, hi = TEMPERATURE_RANGE
        bad = (T < lo) | (T > hi)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise InputError(f"{path}: {where('temperature', i)}: {float(T[i]):g} C "
                             f"is not a plausible temperature (expected {lo:g} to {hi:g} C{kelvin_hint(float(T[i]))})")
    return out
