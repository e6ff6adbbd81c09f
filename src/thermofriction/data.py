"""Measured data (SPEC 7): experiment CSV files with units in their headers, dataset folders with
a ``dataset.toml`` manifest, and synthetic datasets with realistic sensor effects."""

from __future__ import annotations

import csv
import dataclasses
import math
import tomllib
from pathlib import Path, PurePosixPath

import numpy as np
import tomli_w

from ._io import atomic_write
from .errors import InputError, unknown_keys
from .models import Model, load_model
from .simulate import StepSizeController, simulate
from .waveforms import Sampled, Waveform, parse_waveform

_LENGTH = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "nm": 1e-9}
_UNITS = {"time": {"s": 1.0, "ms": 1e-3}, "voltage": {"V": 1.0, "mV": 1e-3}, "displacement": _LENGTH,
          "stage_displacement": _LENGTH, "temperature": {"C": 1.0}}
_SI = {"time": "s", "voltage": "V", "displacement": "m", "stage_displacement": "m", "temperature": "C"}
REQUIRED = ("time", "voltage", "displacement")


@dataclasses.dataclass(eq=False)
class Experiment:
    """One measured run, in SI units (temperature in degC)."""

    file: str
    time: np.ndarray
    voltage: np.ndarray
    displacement: np.ndarray
    temperature: float
    role: str = "fit"
    description: str = ""
    temperature_signal: np.ndarray | None = None
    stage_displacement: np.ndarray | None = None
    input: Waveform | None = None

    @property
    def sample_rate(self) -> float:
        return float(1.0 / np.median(np.diff(self.time)))

    @property
    def duration(self) -> float:
        return float(self.time[-1] - self.time[0])

    def temperature_input(self):
        """What simulate() takes: the recorded signal where it varies beyond sensor noise
        (peak-to-peak above 0.5 C), else the constant temperature."""
        sig = self.temperature_signal
        if sig is not None and float(np.ptp(sig)) > 0.5:
            return Sampled(self.time, sig)
        return self.temperature


@dataclasses.dataclass(eq=False)
class Dataset:
    path: Path | None
    experiments: list
    name: str | None = None
    description: str = ""

    @property
    def fit(self):
        return [e for e in self.experiments if e.role == "fit"]

    @property
    def validate(self):
        return [e for e in self.experiments if e.role == "validate"]

    @property
    def temperatures(self):
        return [e.temperature for e in self.experiments]


def _parse_header(path, header):
    cols = []
    for j, raw in enumerate(header):
        cell = raw.strip()
        name, br, unit = cell.partition("[")
        name = name.strip()
        if br:
            if not unit.endswith("]"):
                raise InputError(f"{path}: line 1, column {j + 1}: '{cell}' must be name[unit]")
            unit = unit[:-1].strip()
        else:
            unit = _SI.get(name, "")
        if name not in _UNITS:
            raise InputError(f"{path}: line 1, column {j + 1}: unknown column '{name}' "
                             f"(columns: {', '.join(_UNITS)})")
        if unit not in _UNITS[name]:
            raise InputError(f"{path}: line 1, column '{cell}': unknown unit '{unit}' for {name} "
                             f"(one of: {', '.join(_UNITS[name])})")
        if any(c[0] == name for c in cols):
            raise InputError(f"{path}: line 1: column '{name}' appears twice")
        cols.append((name, _UNITS[name][unit], cell))
    missing = [r for r in REQUIRED if r not in [c[0] for c in cols]]
    if missing:
        raise InputError(f"{path}: line 1: missing column(s) {', '.join(missing)} "
                         f"(needs time[s], voltage[V], displacement[um])")
    return cols


def read_experiment_csv(path):
    """Reads one experiment CSV (SPEC 7) into SI arrays; any problem is one InputError naming the
    file, line and column."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{path}: cannot read ({e})") from None
    lines = text.splitlines()
    if not lines or not lines[0].strip():
        raise InputError(f"{path}: empty file (needs a header row: time[s],voltage[V],displacement[um])")
    cols = _parse_header(path, next(csv.reader([lines[0]])))
    ncol = len(cols)
    data = []
    for i, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        cells = line.split(",")
        if len(cells) != ncol:
            raise InputError(f"{path}: line {i}: {len(cells)} values, expected {ncol}")
        row = []
        for j, cell in enumerate(cells):
            try:
                v = float(cell)
            except ValueError:
                raise InputError(f"{path}: line {i}, column '{cols[j][2]}': not a number: {cell.strip()!r}") from None
            if not math.isfinite(v):
                raise InputError(f"{path}: line {i}, column '{cols[j][2]}': not finite: {cell.strip()!r}")
            row.append(v)
        data.append(row)
    if len(data) < 10:
        raise InputError(f"{path}: {len(data)} data rows; an experiment needs at least 10 samples")
    arr = np.array(data)
    out = {name: arr[:, j] * scale for j, (name, scale, _) in enumerate(cols)}
    t = out["time"]
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0))
        raise InputError(f"{path}: line {i + 3}: time must increase strictly ({t[i + 1]!r} s after {t[i]!r} s)")
    med = float(np.median(dt))
    irregular = np.abs(dt - med) > 0.01 * med
    if np.any(irregular):
        i = int(np.argmax(irregular))
        raise InputError(f"{path}: line {i + 3}: irregular sampling (interval {dt[i]:.6g} s, typical {med:.6g} s)")
    if "temperature" in out:
        T = out["temperature"]
        bad = (T < -100) | (T > 300)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise InputError(f"{path}: line {i + 2}, column 'temperature': {T[i]!r} C is not a plausible temperature")
    return out


_MANIFEST_KEYS = ("name", "description", "experiment")
_EXPERIMENT_KEYS = ("file", "temperature", "role", "description", "input")


def load_dataset(path) -> Dataset:
    """Reads a dataset folder: ``dataset.toml`` and the experiment files it lists."""
    folder = Path(path)
    manifest = folder / "dataset.toml" if folder.is_dir() else folder
    if folder.is_dir():
        pass
    elif folder.name == "dataset.toml" and folder.exists():
        folder = folder.parent
    else:
        raise InputError(f"{path}: no such dataset folder")
    if not manifest.exists():
        raise InputError(f"{folder}: no dataset.toml in this folder")
    try:
        meta = tomllib.loads(manifest.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{manifest}: TOML syntax error: {e}") from None
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{manifest}: cannot read ({e})") from None
    unknown = set(meta) - set(_MANIFEST_KEYS)
    if unknown:
        raise InputError(f"{manifest}: {unknown_keys(unknown, _MANIFEST_KEYS)}")
    entries = meta.get("experiment")
    if not isinstance(entries, list) or not entries:
        raise InputError(f"{manifest}: no [[experiment]] entries")
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
        if not isinstance(f, str) or not f:
            raise InputError(f"{where}: missing 'file'")
        rel = PurePosixPath(f)
        target = (folder / f).resolve()
        if rel.is_absolute() or Path(f).is_absolute() or ".." in rel.parts or root not in (target, *target.parents):
            raise InputError(f"{where}: file '{f}' must be a path inside the dataset folder")
        role = e.get("role", "fit")
        if role not in ("fit", "validate"):
            raise InputError(f"{where}: 'role' must be \"fit\" or \"validate\", got {role!r}")
        cols = read_experiment_csv(folder / f)
        T = e.get("temperature")
        if T is not None and (isinstance(T, bool) or not isinstance(T, (int, float)) or not math.isfinite(T)):
            raise InputError(f"{where}: 'temperature' must be a number [C], got {T!r}")
        sig = cols.get("temperature")
        if T is None:
            if sig is None:
                raise InputError(f"{where}: no temperature: give 'temperature' or a temperature[C] column in {f}")
            T = float(np.mean(sig))
        desc = e.get("description", "")
        if not isinstance(desc, str):
            raise InputError(f"{where}: 'description' must be a string")
        inp = None
        if "input" in e:
            if not isinstance(e["input"], str):
                raise InputError(f"{where}: 'input' must be a waveform spec such as \"sawtooth:amplitude=30,frequency=5\"")
            try:
                inp = parse_waveform(e["input"])
            except InputError as err:
                raise InputError(f"{where}: {err}") from None
        exps.append(Experiment(f, cols["time"], cols["voltage"], cols["displacement"], float(T), role, desc,
                               sig, cols.get("stage_displacement"), inp))
    name = meta.get("name")
    return Dataset(folder, exps, name if isinstance(name, str) else None, str(meta.get("description", "")))


def save_dataset(dataset: Dataset, folder) -> Path:
    """Writes the experiments (time[s], voltage[V], displacement[um], and temperature[C] and
    stage_displacement[um] where present) and dataset.toml, each file atomically."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    entries = []
    for e in dataset.experiments:
        cols = {"time[s]": e.time, "voltage[V]": e.voltage, "displacement[um]": e.displacement * 1e6}
        if e.temperature_signal is not None:
            cols["temperature[C]"] = e.temperature_signal
        if e.stage_displacement is not None:
            cols["stage_displacement[um]"] = e.stage_displacement * 1e6
        with atomic_write(folder / e.file, "w", newline="") as fh:
            fh.write(",".join(cols) + "\n")
            np.savetxt(fh, np.column_stack(list(cols.values())), delimiter=",", fmt="%.10g")
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
    with atomic_write(folder / "dataset.toml", "w") as fh:
        fh.write(tomli_w.dumps(meta))
    dataset.path = folder
    return folder


def synthesize(model: Model, temperatures, *, validate=(), duration=2.0, sample_rate=10_000.0, input=None,
               noise=20e-9, quantization=0.0, temperature_noise=0.0, drift=0.0, record_temperature=None,
               record_stage=False, seed=0, name=None) -> Dataset:
    """A dataset simulated from ``model`` with realistic sensor effects: white displacement noise
    (std ``noise`` [m]), quantisation to multiples of ``quantization`` [m], a slow linear drift of
    ``drift`` [m/s] with a random sign, and a recorded temperature with sensor noise
    (``temperature_noise`` [C]; recorded when that is non-zero or ``record_temperature``). Seeded and
    reproducible; each experiment has its own random stream, so adding one changes no other."""
    waveform = input or model.input
    if waveform is None:
        raise InputError("the model has no [input]: give input=")
    for label, v in (("noise", noise), ("quantization", quantization), ("temperature_noise", temperature_noise)):
        if not (v >= 0 and math.isfinite(v)):
            raise InputError(f"{label} must be a non-negative number, got {v!r}")
    if record_temperature is None:
        record_temperature = temperature_noise > 0
    runs = [(float(T), "fit") for T in temperatures] + [(float(T), "validate") for T in validate]
    if not runs:
        raise InputError("give at least one temperature")
    exps = []
    for i, (T, role) in enumerate(runs):
        rng = np.random.default_rng([int(seed), i])
        res = simulate(model, duration, temperature=T, input=waveform, sample_rate=sample_rate,
                       controller=StepSizeController(rtol=1e-10))
        x = res.displacement + noise * rng.standard_normal(res.time.size)
        if drift:
            x = x + drift * (1 if rng.random() < 0.5 else -1) * res.time
        if quantization > 0:
            x = np.round(x / quantization) * quantization
        stage = None
        if record_stage:
            stage = res.stage_displacement + noise * rng.standard_normal(res.time.size)
            if quantization > 0:
                stage = np.round(stage / quantization) * quantization
        sig = T + temperature_noise * rng.standard_normal(res.time.size) if record_temperature else None
        desc = (f"{model.name or 'model'} at {T:g} C, input {waveform.spec() if not isinstance(waveform, Sampled) else 'sampled'}, "
                f"noise {noise:g} m, quantisation {quantization:g} m, seed {seed}")
        exps.append(Experiment(f"T{T:g}C{'-validate' if role == 'validate' else ''}.csv", res.time, res.input, x, T,
                               role, desc, sig, stage, None if isinstance(waveform, Sampled) else waveform))
    return Dataset(None, exps, name or f"synthetic-{model.name or 'model'}",
                   f"synthesised by thermofriction from {model.name or 'a model'}")


def _float_list(text, what):
    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"{what}: expected comma-separated numbers, got '{text}'") from None
    if not all(math.isfinite(v) for v in vals):
        raise InputError(f"{what}: temperatures must be finite")
    return vals


def add_synth_command(subparsers):
    s = subparsers.add_parser(
        "synth", help="synthesise a dataset from a model, with realistic sensor effects",
        description="Simulate MODEL at each temperature and write a dataset folder (SPEC 7) with sensor "
                    "noise, quantisation, optional drift and a noisy temperature record. Seeded and reproducible.")
    s.add_argument("model", metavar="MODEL", help="model file or preset")
    s.add_argument("--temperatures", required=True, metavar="C,C,...", help="fit temperatures [C]")
    s.add_argument("--validate", default="", metavar="C,C,...", help="held-out temperatures (role validate)")
    s.add_argument("--duration", type=float, default=2.0, metavar="S", help="seconds per experiment (default: 2)")
    s.add_argument("--sample-rate", type=float, default=10_000.0, metavar="HZ", help="default: 10000")
    s.add_argument("--input", metavar="SPEC", help="input waveform (default: the model's)")
    s.add_argument("--noise", type=float, default=20e-9, metavar="M", help="displacement noise std [m] (default: 2e-8)")
    s.add_argument("--quantization", type=float, default=0.0, metavar="M", help="sensor resolution [m] (default: 0)")
    s.add_argument("--temperature-noise", type=float, default=0.0, metavar="C",
                   help="temperature sensor noise std [C]; records a temperature column (default: 0)")
    s.add_argument("--drift", type=float, default=0.0, metavar="M_PER_S", help="sensor drift [m/s] (default: 0)")
    s.add_argument("--record-stage", action="store_true", help="also record the stage displacement")
    s.add_argument("--seed", type=int, default=0, help="random seed (default: 0)")
    s.add_argument("-o", "--output", required=True, metavar="DIR", help="dataset folder to write")
    s.set_defaults(run=cmd_synth)


def cmd_synth(args) -> int:
    model = load_model(args.model)
    if not (args.duration > 0 and args.sample_rate > 0):
        raise InputError("--duration and --sample-rate must be positive")
    data = synthesize(model, _float_list(args.temperatures, "--temperatures"),
                      validate=_float_list(args.validate, "--validate"), duration=args.duration,
                      sample_rate=args.sample_rate, input=parse_waveform(args.input) if args.input else None,
                      noise=args.noise, quantization=args.quantization, temperature_noise=args.temperature_noise,
                      drift=args.drift, record_stage=args.record_stage, seed=args.seed)
    folder = save_dataset(data, args.output)
    print(f"wrote {len(data.experiments)} experiments and dataset.toml to {folder}")
    return 0


__all__ = ["Experiment", "Dataset", "read_experiment_csv", "load_dataset", "save_dataset", "synthesize",
           "add_synth_command"]
