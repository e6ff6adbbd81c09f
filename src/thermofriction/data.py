"""Measured data (SPEC 7): experiment CSV files with units in their headers, dataset folders with
a ``dataset.toml`` manifest, and synthetic datasets with realistic sensor effects.

    data = tf.load_dataset("data/")            # checks everything; one clear InputError otherwise
    data.fit, data.validate                     # experiments by role
    data = tf.synthesize(model, [30.8, 35.7, 41.5], validate=[33.0], noise=20e-9, seed=1)
    tf.save_dataset(data, "data/")
"""

from __future__ import annotations

import csv
import dataclasses
import math
import os
import tomllib
import warnings
from pathlib import Path, PurePosixPath

import numpy as np
import tomli_w

from ._io import atomic_write
from .errors import InputError, unknown_keys
from .models import Model, load_model, require_actuator
from .simulate import StepSizeController, simulate
from .waveforms import Sampled, Waveform, parse_waveform

_LENGTH = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6, "nm": 1e-9}  # micro sign and Greek mu
_UNITS = {"time": {"s": 1.0, "ms": 1e-3}, "voltage": {"V": 1.0, "mV": 1e-3}, "displacement": _LENGTH,
          "stage_displacement": _LENGTH, "temperature": {"C": 1.0}}
_SI = {"time": "s", "voltage": "V", "displacement": "m", "stage_displacement": "m", "temperature": "C"}
REQUIRED = ("time", "voltage", "displacement")
MIN_SAMPLES = 10
SAMPLING_TOLERANCE = 0.01           # relative deviation of an interval from the median interval
TEMPERATURE_RANGE = (-100.0, 300.0)  # [degC] what a temperature sensor on an actuator can plausibly read
TEMPERATURE_VARIES = 0.5            # [degC] peak-to-peak above which a recorded temperature is a signal
ROLES = ("fit", "validate")
MAX_ROWS = 10_000_000               # data rows per experiment file; ~1.5 GB peak at the limit (docs/limits.md)
MAX_ROWS_ENV = "THERMOFRICTION_MAX_ROWS"


def max_rows() -> int:
    """The row limit of experiment files: ``THERMOFRICTION_MAX_ROWS`` when set, else ``MAX_ROWS``."""
    text = os.environ.get(MAX_ROWS_ENV, "").strip()
    if not text:
        return MAX_ROWS
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise InputError(f"{MAX_ROWS_ENV}={text!r}: must be a positive whole number of rows")
    return n


@dataclasses.dataclass(eq=False)
class Experiment:
    """One measured run, in SI units (temperature in degC).

    ``temperature`` is the manifest's value or else the mean of the recorded ``temperature_signal``;
    ``input`` is the exact waveform when the manifest gives one (``input = "sawtooth:..."``), else
    None (the recorded ``voltage`` is the input)."""

    file: str
    time: np.ndarray
    voltage: np.ndarray
    displacement: np.ndarray
    temperature: float
    temperature_signal: np.ndarray | None = None
    stage_displacement: np.ndarray | None = None
    role: str = "fit"
    description: str = ""
    input: Waveform | None = None

    @property
    def sample_rate(self) -> float:
        """[Hz] from the median sampling interval."""
        return float(1.0 / np.median(np.diff(self.time)))

    @property
    def duration(self) -> float:
        """[s] from the first to the last sample."""
        return float(self.time[-1] - self.time[0])

    def temperature_input(self):
        """What ``simulate(..., temperature=...)`` takes: the recorded temperature where it varies
        beyond its sensor noise, else the constant ``temperature``. "Varies" means a peak-to-peak
        above 0.5 C after a moving average over 2 % of the record (which removes white sensor noise
        but keeps thermal changes, slow on that scale); the smoothed signal is what is returned,
        as a ``Sampled`` waveform, so that sensor noise does not enter the simulation."""
        sig = self.temperature_signal
        if sig is None:
            return self.temperature
        smooth = _moving_average(np.asarray(sig, float), max(1, len(sig) // 50))
        if float(np.ptp(smooth)) > TEMPERATURE_VARIES:
            return Sampled(np.asarray(self.time, float), smooth)
        return self.temperature


def _moving_average(x, w):
    """Centred moving average over ``w`` samples (made odd), the window truncated at the ends;
    O(n) by cumulative sums."""
    n = x.size
    if w <= 1 or n < 3:
        return x
    half = w // 2
    m = float(np.mean(x))
    c = np.concatenate([[0.0], np.cumsum(x - m)])
    i = np.arange(n)
    lo, hi = np.clip(i - half, 0, n), np.clip(i + half + 1, 0, n)
    return m + (c[hi] - c[lo]) / (hi - lo)


@dataclasses.dataclass(eq=False)
class Dataset:
    """Experiments and where they came from (``path``: the folder, or None if not saved)."""

    path: Path | None = None
    name: str | None = None
    description: str = ""
    experiments: list = dataclasses.field(default_factory=list)

    @property
    def fit(self) -> list:
        return [e for e in self.experiments if e.role == "fit"]

    @property
    def validate(self) -> list:
        return [e for e in self.experiments if e.role == "validate"]

    @property
    def temperatures(self) -> list:
        return [e.temperature for e in self.experiments]


# -- experiment files -------------------------------------------------------------------------

def _parse_header(path, header):
    """[(name, scale to SI, the header cell)] for the header row, or one InputError."""
    cols = []
    for j, raw in enumerate(header):
        cell = raw.strip()
        where = f"{path}: line 1, column {j + 1}"
        name, br, unit = cell.partition("[")
        name = name.strip()
        if br:
            if not unit.endswith("]"):
                raise InputError(f"{where}: '{cell}' must be name[unit], e.g. displacement[um]")
            unit = unit[:-1].strip()
        else:
            unit = _SI.get(name, "")
        if not name:
            raise InputError(f"{where}: empty column name (columns: {', '.join(_UNITS)})")
        if name not in _UNITS:
            raise InputError(f"{where}: unknown column '{name}' (columns: {', '.join(_UNITS)})")
        if unit not in _UNITS[name]:
            raise InputError(f"{where} ('{cell}'): unknown unit '{unit}' for {name} "
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
                v = float(cell)
            except ValueError:
                raise InputError(f"{path}: line {i}, column {j + 1} ({cols[j][2]}): not a number: "
                                 f"{cell.strip()!r}") from None
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


def read_experiment_csv(path) -> dict:
    """Reads one experiment CSV (SPEC 7) into SI arrays: a dict with ``time``, ``voltage``,
    ``displacement`` and, where the file has them, ``temperature`` and ``stage_displacement``.

    The format is strict; any problem is one InputError naming the file and, where it applies, the
    line (the header is line 1) and the column."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder, not an experiment CSV file") from None
    except OSError as e:
        raise InputError(f"{path}: cannot read ({e.strerror or e})") from None
    except ValueError as e:  # a NUL byte in the path
        raise InputError(f"{str(path)!r}: not a usable file name ({e})") from None
    rows = raw.count(b"\n") + (not raw.endswith(b"\n")) - 1  # data rows, blank lines included
    limit = max_rows()
    if rows > limit:
        raise InputError(f"{path}: {rows} data rows, more than the limit of {limit} (each row takes ~150 bytes "
                         f"of memory while loading): downsample the file, or raise the limit with the "
                         f"environment variable {MAX_ROWS_ENV}=N")
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

    bad = ~np.isfinite(arr)
    if bad.any():
        r, j = (int(v) for v in np.argwhere(bad)[0])
        raise InputError(f"{path}: line {_line_of(body, r)}, column {j + 1} ({cols[j][2]}): "
                         f"not a finite number ({float(arr[r, j])})")
    if n < MIN_SAMPLES:
        raise InputError(f"{path}: {n} data row{'s' if n != 1 else ''}; an experiment needs at least "
                         f"{MIN_SAMPLES} samples")
    out = {name: arr[:, j] * scale for j, (name, scale, _) in enumerate(cols)}
    jt = [c[0] for c in cols].index("time")
    t = out["time"]
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0))
        raise InputError(f"{path}: line {_line_of(body, i + 1)}, column {jt + 1} ({cols[jt][2]}): time must "
                         f"increase strictly ({float(arr[i + 1, jt]):.10g} after {float(arr[i, jt]):.10g} "
                         f"on line {_line_of(body, i)})")
    med = float(np.median(dt))
    irregular = np.abs(dt - med) > SAMPLING_TOLERANCE * med
    if np.any(irregular):
        i = int(np.argmax(irregular))
        raise InputError(f"{path}: line {_line_of(body, i + 1)}, column {jt + 1} ({cols[jt][2]}): irregular "
                         f"sampling: interval {dt[i]:.6g} s, median {med:.6g} s (the intervals may differ "
                         f"by at most {100 * SAMPLING_TOLERANCE:g} %)")
    if "temperature" in out:
        jT = [c[0] for c in cols].index("temperature")
        T = out["temperature"]
        lo, hi = TEMPERATURE_RANGE
        bad = (T < lo) | (T > hi)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise InputError(f"{path}: line {_line_of(body, i)}, column {jT + 1} ({cols[jT][2]}): {float(T[i]):g} C "
                             f"is not a plausible temperature (expected {lo:g} to {hi:g} C)")
    return out


# -- datasets ---------------------------------------------------------------------------------

_MANIFEST_KEYS = ("name", "description", "experiment")
_EXPERIMENT_KEYS = ("file", "temperature", "role", "description", "input")


def _is_inside(f: str) -> bool:
    """Whether the manifest path ``f`` is a plain relative path that stays in its folder."""
    rel = PurePosixPath(f.replace("\\", "/"))
    return bool(f) and not (rel.is_absolute() or Path(f).is_absolute() or ".." in rel.parts
                            or f.startswith("~") or (len(f) > 1 and f[1] == ":"))


def _check_temperature(T, where):
    # (an int is always finite, and math.isfinite would overflow on one beyond the float range)
    if isinstance(T, bool) or not isinstance(T, (int, float)) or (isinstance(T, float) and not math.isfinite(T)):
        raise InputError(f"{where}: 'temperature' must be a number [C], got {T!r}")
    lo, hi = TEMPERATURE_RANGE
    if not lo <= T <= hi:
        raise InputError(f"{where}: temperature {T!r} C is not plausible (expected {lo:g} to {hi:g} C)")
    return float(T)


def load_dataset(path) -> Dataset:
    """Reads a dataset folder (SPEC 7): ``dataset.toml`` and the experiment files it lists,
    all checked; any problem is one InputError naming the file (and its line, column or
    ``[[experiment]] N`` entry)."""
    folder = Path(path)
    if folder.is_dir():
        manifest = folder / "dataset.toml"
    elif folder.name == "dataset.toml" and folder.is_file():
        manifest, folder = folder, folder.parent
    elif folder.exists():
        raise InputError(f"{path}: not a dataset folder (a folder with a dataset.toml)")
    else:
        raise InputError(f"{path}: no such dataset folder")
    if not manifest.is_file():
        raise InputError(f"{folder}: no dataset.toml in this folder")
    try:
        meta = tomllib.loads(manifest.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{manifest}: TOML syntax error: {e}") from None
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{manifest}: cannot read ({e})") from None
    except RecursionError:  # tomllib recurses once per level of nested arrays or inline tables
        raise InputError(f"{manifest}: TOML nested too deeply") from None
    unknown = set(meta) - set(_MANIFEST_KEYS)
    if unknown:
        raise InputError(f"{manifest}: {unknown_keys(unknown, _MANIFEST_KEYS)}")
    name = meta.get("name")
    if name is not None and not isinstance(name, str):
        raise InputError(f"{manifest}: 'name' must be a string, got {name!r}")
    description = meta.get("description", "")
    if not isinstance(description, str):
        raise InputError(f"{manifest}: 'description' must be a string, got {description!r}")
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
        if target is None or not _is_inside(f) or root not in (target, *target.parents):
            raise InputError(f"{where}: file '{f}' must be a relative path inside the dataset folder "
                             f"(no absolute paths, no '..', no symbolic links leading out)")
        role = e.get("role", "fit")
        if role not in ROLES:
            raise InputError(f"{where}: 'role' must be \"fit\" or \"validate\", got {role!r}")
        T = e.get("temperature")
        if T is not None:
            T = _check_temperature(T, where)
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
        cols = read_experiment_csv(folder / f)
        sig = cols.get("temperature")
        if T is None:
            if sig is None:
                raise InputError(f"{where}: no temperature: give 'temperature' or a temperature[C] column in {f}")
            T = float(np.mean(sig))
        exps.append(Experiment(file=f, time=cols["time"], voltage=cols["voltage"], displacement=cols["displacement"],
                               temperature=T, temperature_signal=sig,
                               stage_displacement=cols.get("stage_displacement"), role=role, description=desc,
                               input=inp))
    return Dataset(path=folder, name=name, description=description, experiments=exps)


def save_dataset(dataset: Dataset, folder) -> Path:
    """Writes ``folder`` (created if needed): one CSV per experiment (``time[s],voltage[V],
    displacement[um]``, and ``temperature[C]`` and ``stage_displacement[um]`` where present, ten
    significant digits) and ``dataset.toml``, each file atomically. Returns the folder and sets
    ``dataset.path`` to it."""
    folder = Path(folder)
    files = [e.file for e in dataset.experiments]
    if not files:
        raise InputError("the dataset has no experiments to save")
    for f in files:
        if not isinstance(f, str) or not _is_inside(f):
            raise InputError(f"experiment file '{f}' must be a relative path inside the dataset folder")
    dup = sorted({f for f in files if files.count(f) > 1})
    if dup:
        raise InputError(f"two experiments would be written to the same file: {', '.join(dup)}")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        for f in files:
            (folder / f).parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise InputError(f"{folder}: cannot create the dataset folder ({err.strerror or err})") from None
    entries = []
    for e in dataset.experiments:
        cols = {"time[s]": e.time, "voltage[V]": e.voltage, "displacement[um]": np.asarray(e.displacement) * 1e6}
        if e.temperature_signal is not None:
            cols["temperature[C]"] = e.temperature_signal
        if e.stage_displacement is not None:
            cols["stage_displacement[um]"] = np.asarray(e.stage_displacement) * 1e6
        try:
            with atomic_write(folder / e.file, "w", newline="") as fh:
                fh.write(",".join(cols) + "\n")
                np.savetxt(fh, np.column_stack([np.asarray(v, float) for v in cols.values()]), delimiter=",",
                           fmt="%.10g")
        except OSError as err:
            raise InputError(f"{folder / e.file}: cannot write ({err.strerror or err})") from None
        entry = {"file": e.file, "temperature": float(e.temperature), "role": e.role}
        if e.description:
            entry["description"] = e.description
        if e.input is not None:
            entry["input"] = e.input.spec()
        entries.append(entry)
    meta = {}
    if dataset.name:
        meta["name"] = dataset.name
    if dataset.description:
        meta["description"] = dataset.description
    meta["experiment"] = entries
    try:
        with atomic_write(folder / "dataset.toml", "w") as fh:
            fh.write(tomli_w.dumps(meta))
    except OSError as err:
        raise InputError(f"{folder / 'dataset.toml'}: cannot write ({err.strerror or err})") from None
    dataset.path = folder
    return folder


# -- synthetic datasets -----------------------------------------------------------------------

def _nonneg(label, v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        raise InputError(f"{label} must be a number, got {v!r}") from None
    if not (v >= 0 and math.isfinite(v)):
        raise InputError(f"{label} must be a non-negative number, got {v!r}")
    return v


def _temperatures(values, label):
    if values is None:
        return []
    if isinstance(values, (int, float, np.number)):
        values = [values]
    return [_check_temperature(float(T) if isinstance(T, np.number) else T, label) for T in values]


def synthesize(model: Model, temperatures, *, validate=(), duration=2.0, sample_rate=10_000.0, input=None,
               noise=20e-9, quantization=0.0, temperature_noise=0.0, drift=0.0, record_temperature=None,
               record_stage=False, seed=0, name=None) -> Dataset:
    """A dataset simulated from ``model`` at each temperature (role "fit") and at each ``validate``
    temperature (role "validate"), with realistic sensor effects:

    - white Gaussian displacement noise of std ``noise`` [m];
    - a slow linear sensor drift of ``drift`` [m/s] with a random sign;
    - quantisation of the displacement to multiples of ``quantization`` [m] (0: none);
    - a recorded temperature column with sensor noise of std ``temperature_noise`` [C], when
      ``record_temperature`` (default None: when ``temperature_noise`` > 0);
    - the stage displacement, with the same noise and quantisation, when ``record_stage``.

    The manifest's temperature is the true one. ``input`` defaults to the model's ``[input]``.
    Seeded and reproducible: each experiment draws from its own stream
    (``default_rng([seed, i])`` for the i-th fit temperature, ``[seed, j, 1]`` for the j-th
    validate one), so adding an experiment changes no other."""
    require_actuator(model, "synthesize")
    waveform = input if input is not None else model.input
    if waveform is None:
        raise InputError(f"{'model ' + repr(model.name) if model.name else 'the model'} has no [input] "
                         f"waveform: give input= (e.g. tf.Sawtooth(amplitude=30, frequency=5))")
    fit_T = _temperatures(temperatures, "temperatures")
    val_T = _temperatures(validate, "validate")
    if not fit_T and not val_T:
        raise InputError("give at least one temperature")
    noise = _nonneg("noise", noise)
    quantization = _nonneg("quantization", quantization)
    temperature_noise = _nonneg("temperature_noise", temperature_noise)
    try:
        drift = float(drift)
        duration = float(duration)
        sample_rate = float(sample_rate)
    except (TypeError, ValueError):
        raise InputError("drift, duration and sample_rate must be numbers") from None
    if not math.isfinite(drift):
        raise InputError(f"drift must be a finite number [m/s], got {drift!r}")
    if not (duration > 0 and math.isfinite(duration)):
        raise InputError(f"duration must be positive [s], got {duration!r}")
    if not (sample_rate > 0 and math.isfinite(sample_rate)):
        raise InputError(f"sample_rate must be positive [Hz], got {sample_rate!r}")
    if duration * sample_rate + 1 < MIN_SAMPLES:
        raise InputError(f"duration x sample_rate gives fewer than {MIN_SAMPLES} samples")
    if record_temperature is None:  # a self-heating model's temperature is an output: always recorded
        record_temperature = temperature_noise > 0 or model.heat is not None
    runs = [(T, "fit", [int(seed), i]) for i, T in enumerate(fit_T)]
    runs += [(T, "validate", [int(seed), j, 1]) for j, T in enumerate(val_T)]
    label = model.name or "model"
    spec = "a sampled waveform" if isinstance(waveform, Sampled) else waveform.spec()
    exps = []
    used = set()
    for T, role, stream in runs:
        rng = np.random.default_rng(stream)
        res = simulate(model, duration, temperature=T, input=waveform, sample_rate=sample_rate,
                       controller=StepSizeController(rtol=1e-10))
        x = res.displacement + noise * rng.standard_normal(res.time.size)
        sign = 0
        if drift:
            sign = 1 if rng.random() < 0.5 else -1
            x = x + sign * drift * (res.time - res.time[0])
        if quantization > 0:
            x = np.round(x / quantization) * quantization
        stage = None
        if record_stage:
            stage = res.stage_displacement + noise * rng.standard_normal(res.time.size)
            if quantization > 0:
                stage = np.round(stage / quantization) * quantization
        T_true = res.temperature if model.heat is not None else T  # with [heat], T is the ambient one
        sig = T_true + temperature_noise * rng.standard_normal(res.time.size) if record_temperature else None
        effects = [f"noise {noise:g} m"]
        if quantization:
            effects.append(f"quantisation {quantization:g} m")
        if drift:
            effects.append(f"drift {sign * drift:+g} m/s")
        if record_temperature:
            effects.append(f"temperature noise {temperature_noise:g} C")
        desc = (f"synthesised from {label} at {T:g} C: input {spec}, {duration:g} s at {sample_rate:g} Hz, "
                f"{', '.join(effects)}, seed {seed}")
        stem = f"T{T:.10g}C{'-validate' if role == 'validate' else ''}"
        file, k = f"{stem}.csv", 1
        while file in used:
            k += 1
            file = f"{stem}-{k}.csv"
        used.add(file)
        exps.append(Experiment(file=file, time=res.time, voltage=res.input, displacement=x, temperature=T,
                               temperature_signal=sig, stage_displacement=stage, role=role, description=desc,
                               input=None if isinstance(waveform, Sampled) else waveform))
    return Dataset(path=None, name=name or f"synthetic-{label}",
                   description=f"synthesised by thermofriction from {label}", experiments=exps)


# -- command line -----------------------------------------------------------------------------

def _float_list(text, what):
    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"{what}: expected comma-separated numbers, got '{text}'") from None
    if not all(math.isfinite(v) for v in vals):
        raise InputError(f"{what}: temperatures must be finite numbers, got '{text}'")
    return vals


def add_synth_command(subparsers):
    """Registers ``thermofriction synth`` on an argparse subparsers object."""
    s = subparsers.add_parser(
        "synth", help="synthesise a measured dataset from a model, with realistic sensor effects",
        description="Simulate MODEL at each temperature and write a dataset folder (SPEC 7: dataset.toml "
                    "and one experiment CSV per temperature) with white displacement noise, quantisation, "
                    "an optional slow sensor drift, a noisy temperature record and the stage displacement. "
                    "Seeded and reproducible: the same options give the same files, and each experiment "
                    "has its own random stream, so adding a temperature changes no other experiment.",
        epilog="example: thermofriction synth li2009-model-i --temperatures 30.8,33.9,35.7,38.4,41.5 "
               "--validate 33,40 --noise 20e-9 --quantization 5e-9 -o data")
    s.add_argument("model", metavar="MODEL", help="model file (.toml) or preset name, e.g. li2009-model-i")
    s.add_argument("--temperatures", required=True, metavar="C,C,...",
                   help="temperatures [C] of the experiments with role 'fit', comma-separated")
    s.add_argument("--validate", default="", metavar="C,C,...",
                   help="temperatures [C] of held-out experiments (role 'validate'), comma-separated")
    s.add_argument("--duration", type=float, default=2.0, metavar="S",
                   help="length of each experiment [s] (default: 2)")
    s.add_argument("--sample-rate", type=float, default=10_000.0, metavar="HZ",
                   help="sampling rate of the recorded signals [Hz] (default: 10000)")
    s.add_argument("--input", metavar="SPEC",
                   help="input waveform, e.g. sawtooth:amplitude=30,frequency=5,rise=0.999 "
                        "(default: the model's [input])")
    s.add_argument("--noise", type=float, default=20e-9, metavar="M",
                   help="standard deviation of the white displacement-sensor noise [m] (default: 2e-8)")
    s.add_argument("--quantization", type=float, default=0.0, metavar="M",
                   help="displacement-sensor resolution [m]: values are rounded to multiples of it "
                        "(default: 0, none)")
    s.add_argument("--temperature-noise", type=float, default=0.0, metavar="C",
                   help="standard deviation of the temperature-sensor noise [C]; a non-zero value "
                        "records a temperature[C] column (default: 0)")
    s.add_argument("--drift", type=float, default=0.0, metavar="M_PER_S",
                   help="slow linear displacement-sensor drift [m/s], with a random sign per experiment "
                        "(default: 0)")
    s.add_argument("--record-temperature", action="store_true", default=None,
                   help="write a temperature[C] column (the true temperature plus --temperature-noise)")
    s.add_argument("--record-stage", action="store_true",
                   help="also write the stage displacement (stage_displacement[um], same noise), "
                        "for identifying the plant")
    s.add_argument("--seed", type=int, default=0, metavar="N", help="random seed (default: 0)")
    s.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="dataset folder to write (created if needed; files in it are replaced)")
    s.set_defaults(run=cmd_synth)
    return s


def cmd_synth(args) -> int:
    """``thermofriction synth``: writes the dataset and prints one line per file."""
    for opt, v in (("--duration", args.duration), ("--sample-rate", args.sample_rate)):
        if not (v > 0 and math.isfinite(v)):
            raise InputError(f"{opt} must be a positive number, got {v!r}")
    for opt, v in (("--noise", args.noise), ("--quantization", args.quantization),
                   ("--temperature-noise", args.temperature_noise)):
        if not (v >= 0 and math.isfinite(v)):
            raise InputError(f"{opt} must be a non-negative number, got {v!r}")
    if not math.isfinite(args.drift):
        raise InputError(f"--drift must be a finite number, got {args.drift!r}")
    fit_T = _float_list(args.temperatures, "--temperatures")
    if not fit_T:
        raise InputError("--temperatures: give at least one temperature, e.g. --temperatures 30.8,35.7,41.5")
    val_T = _float_list(args.validate or "", "--validate")
    model = load_model(args.model)
    waveform = parse_waveform(args.input) if args.input else None
    if waveform is None and model.input is None:
        raise InputError(f"{args.model}: the model has no [input] waveform: give --input, "
                         f"e.g. --input sawtooth:amplitude=30,frequency=5")
    try:
        data = synthesize(model, fit_T, validate=val_T, duration=args.duration, sample_rate=args.sample_rate,
                          input=waveform, noise=args.noise, quantization=args.quantization,
                          temperature_noise=args.temperature_noise, drift=args.drift,
                          record_temperature=args.record_temperature, record_stage=args.record_stage,
                          seed=args.seed)
    except InputError as e:
        raise InputError(f"synth: {e}") from None
    folder = save_dataset(data, args.output)
    for e in data.experiments:
        print(f"wrote {folder / e.file} ({e.role}, {e.temperature:g} C, {e.time.size} samples)")
    print(f"wrote {folder / 'dataset.toml'} ({len(data.fit)} fit, {len(data.validate)} validate)")
    return 0


__all__ = ["Experiment", "Dataset", "read_experiment_csv", "load_dataset", "save_dataset", "synthesize",
           "add_synth_command", "cmd_synth"]
