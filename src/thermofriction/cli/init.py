"""`thermofriction init DIR`: a dataset manifest (dataset.toml, docs/formats.md#datasets) written from a folder of
experiment files (docs/cli.md#init)."""

from __future__ import annotations

import fnmatch
import os
import re
import sys
from pathlib import Path

from .. import _io
from ..errors import InputError, shorten

#: a temperature in a file name (docs/cli.md#init): a number with a Celsius unit after it (35.2C, 35.2degC,
#: 35.2°C, 35p2C) or a T or temp before it (T35.2, T_35.2, temp35.2); "p" may stand for the decimal point; a sign
#: before the number is read by _readings
_NUMBER = r"(?P<sign>[-\u2212]?)(?P<number>\d+(?:[.p]\d+)?)"
_NAME_PATTERNS = (re.compile(_NUMBER + r"\s*(?:°\s*C|deg_?C|C)(?![A-Za-z])", re.IGNORECASE),
                  re.compile(r"(?<![A-Za-z])(?:T|temp|temperature)[_=]?" + _NUMBER + r"(?![\d])", re.IGNORECASE))
#: a file name that says the run is held out (synth's T33C-validate.csv)
_HELD_OUT = re.compile(r"validat|hold-?out|held-?out", re.IGNORECASE)
#: the experiment files init lists
EXTENSIONS = (".csv", ".mat")


def add_init_command(sub):
    p = sub.add_parser(
        "init", help="write a dataset.toml for a folder of experiment files (CSV, .mat)",
        description="Write DIR/dataset.toml (docs/formats.md#datasets) listing every experiment file (.csv, .mat) "
                    "in DIR, with its temperature and role, once the dataset it lists is checked to load. A file's "
                    "temperature is, in this order: --temperature FILE=C; the mean of its temperature column "
                    "(temperature[C], or temperature/temperature_C in a .mat); a temperature in its name (35.2C, "
                    "35.2degC, 35p2C, T35.2, temp35.2, run_-5C; a hyphen after a letter or digit may be a separator "
                    "or a minus sign, so run-5C states none: docs/cli.md#init); else asked for on a terminal. Roles: "
                    "--validate; else the files whose names say so (validate, holdout, held-out) are held out for "
                    "validation; else, with 4 or more experiments, about a quarter of them at interior "
                    "temperatures; the others are fitted.",
        epilog="example: thermofriction init measurements --temperature run7.csv=36.5 --validate run4.csv")
    p.add_argument("folder", metavar="DIR", help="the folder of experiment files; dataset.toml is written there")
    p.add_argument("--temperature", action="append", default=[], metavar="FILE=C",
                   help="a file's temperature [C], over its column and its name; repeat for more files")
    p.add_argument("--validate", metavar="FILE,FILE,...",
                   help="the files held out for validation (role \"validate\"), comma-separated, or 'none' "
                        "(default: about a quarter, at interior temperatures, with 4 or more experiments)")
    p.add_argument("--exclude", action="append", default=[], metavar="PATTERN",
                   help="leave out the files matching a shell pattern, e.g. --exclude 'calib*'; repeat for more")
    p.add_argument("--name", help="the dataset's name (default: the folder's name)")
    p.add_argument("--force", action="store_true", help="replace an existing dataset.toml")
    p.set_defaults(run=cmd_init)
    return p


def experiment_files(folder: Path, exclude=()) -> list[str]:
    """The experiment files directly in ``folder`` (.csv, .mat; not hidden, not ``exclude``d), sorted."""
    names = [n for n in os.listdir(folder) if n.lower().endswith(EXTENSIONS) and not n.startswith(".")
             and (folder / n).is_file() and not any(fnmatch.fnmatch(n, pat) for pat in exclude)]
    return sorted(names)


def experiment_runs(folder: Path, files) -> dict:
    """{label: (file, struct or None, the struct's fields or None)}, in order: one run per file, except a MATLAB
    file holding its runs in structs (data/matlab.py: run_structs), one per struct, labelled ``runs.mat:run1``
    as tables name them (Experiment.label). A .mat that cannot be read is one run: loading it says why."""
    from ..data.matlab import run_structs
    out = {}
    for f in files:
        try:
            structs = run_structs(folder / f) if f.lower().endswith(".mat") else {}
        except InputError:
            structs = {}
        for name, fields in structs.items():
            out[f"{f}:{name}"] = (f, name, fields)
        if not structs:
            out[f] = (f, None, None)
    return out


def _readings(stem: str, m) -> set:
    """What one number in a name can mean. A hyphen before it is a minus sign at the start of the name or after
    another separator (``run_-5C``, ``T=-10``); after a letter or a digit it may as well be a separator
    (``stage-35C``, ``T-10``, ``run3-5C``), so the number reads both ways, unless one way is no plausible
    temperature (``oven-150C``). A minus sign (U+2212) is one anywhere."""
    value = float(m.group("number").replace("p", ".").replace("P", "."))
    sign, at = m.group("sign"), m.start("sign")
    separator = sign == "-" and at > 0 and (stem[at - 1].isalnum() or stem[at - 1] in "-.")
    if sign == "\u2212" or (sign == "-" and not separator):
        return {0.0 - value}  # (0.0 - 0.0 is 0.0: no -0.0 in a manifest)
    if separator:
        return {v for v in (value, 0.0 - value) if _plausible(v)} or {value}
    return {value}


def name_readings(name: str) -> set:
    """Every temperature [C] a file's name can be read to state (none, one, or several: two numbers, or a
    hyphen that is a separator or a minus sign)."""
    stem = os.path.splitext(name)[0]
    found = set()
    for pattern in _NAME_PATTERNS:
        for m in pattern.finditer(stem):
            found |= _readings(stem, m)
    return found


def temperature_from_name(name: str) -> float | None:
    """The temperature [C] a file's name states (``run_35.2C.csv``, ``run_-5C.csv``, ``T35.2.csv``,
    ``35p2degC.mat``), or None when it states none, or can be read as several different ones."""
    found = name_readings(name)
    return found.pop() if len(found) == 1 else None


def refuse_unlistable(folder, files) -> None:
    """Refuses the file names a manifest (UTF-8 text) cannot hold -- bytes that are not UTF-8, which Python
    keeps as lone surrogates, or control characters -- naming them as bytes, before any work."""
    bad = [f for f in files if not f.isprintable()]
    if bad:
        shown = ", ".join(shorten(os.fsencode(f)) for f in bad[:3]) + (f" and {len(bad) - 3} more" if bad[3:] else "")
        raise InputError(f"{folder}: a manifest (UTF-8 text) cannot name {shown}: not UTF-8, or a control "
                         f"character; rename the file, or leave it out with --exclude PATTERN")


def has_temperature_column(path: Path) -> bool:
    """Whether an experiment file records a temperature: a CSV header cell temperature[...] (first line only),
    or a .mat variable temperature / temperature_C."""
    if path.suffix.lower() == ".mat":
        import scipy.io
        try:
            names = [v[0] for v in scipy.io.whosmat(path)]
        except Exception:  # noqa: BLE001 - not a readable MATLAB file: loading the dataset says why
            return False
        return any(n in ("temperature", "temperature_C") for n in names)
    try:
        with open(path, "rb") as fh:
            head = fh.readline(1 << 16).decode("utf-8-sig", errors="replace")
    except OSError:
        return False
    return any(cell.partition("[")[0].strip().lower() == "temperature" for cell in head.split(","))


def _listed(labels) -> str:
    return f"{', '.join(labels[:5])}{', ...' if len(labels) > 5 else ''}"


def _explicit(items, files) -> dict:
    """--temperature FILE=C (FILE:STRUCT=C for a run in a MATLAB file's struct), checked: {label: temperature}."""
    from ..data.files import check_temperature
    out = {}
    for item in items:
        name, eq, value = item.rpartition("=")
        if not eq or not name:
            raise InputError(f"--temperature {shorten(item)}: expected FILE=C, e.g. --temperature run3.csv=35.2")
        if name not in files:
            raise InputError(f"--temperature {shorten(item)}: {shorten(name)} is not one of the experiments "
                             f"({_listed(files)})")
        try:
            out[name] = check_temperature(float(value), f"--temperature {name}")
        except ValueError:
            raise InputError(f"--temperature {shorten(item)}: {shorten(value)} is not a number [C]") from None
    return out


def _ask(name: str) -> float:
    """A file's temperature asked for on the terminal, until it is a plausible one."""
    from ..data.files import check_temperature
    reads = _reads(name)
    while True:
        try:
            text = input(f"temperature of {name} [C]{f' ({reads})' if reads else ''}: ").strip()
        except EOFError:
            raise InputError(f"{name}: no temperature given") from None
        try:
            return check_temperature(float(text), name)
        except ValueError:  # (an InputError is a ValueError too: the range)
            print(f"  not a plausible temperature [C]: {text!r}", file=sys.stderr)


def _reads(name: str) -> str:
    """How a name that states no temperature reads several ways ("its name reads -5 or 5 C"), or ""."""
    found = sorted(name_readings(name))
    return f"its name reads {' or '.join(f'{T:g}' for T in found)} C" if len(found) > 1 else ""


def _plausible(T) -> bool:
    """A temperature a file name states that a dataset would take (not the 500 of a run's number, say)."""
    from ..data.experiments import TEMPERATURE_RANGE
    return T is not None and TEMPERATURE_RANGE[0] <= T <= TEMPERATURE_RANGE[1]


def _temperature_of(folder: Path, run) -> tuple | None:
    """(temperature or None for the column's mean, where it came from) of a run that states one, else None: its
    column (a struct's temperature field), else its name (a struct's, then its file's)."""
    f, struct, fields = run
    if struct is None:
        if has_temperature_column(folder / f):
            return None, "column"
        return (temperature_from_name(f), "name") if _plausible(temperature_from_name(f)) else None
    from ..data.matlab import column_of
    if any((column_of(x) or ("",))[0] == "temperature" for x in fields):
        return None, "field"
    for name, source in ((struct, "struct"), (f, "name")):
        if _plausible(temperature_from_name(name)):
            return temperature_from_name(name), source
    return None


def temperatures(folder: Path, runs: dict, explicit: dict, interactive: bool) -> dict:
    """{label: (temperature or None for the column's mean, where it came from)} of the runs
    (:func:`experiment_runs`); the runs whose temperature is nowhere are asked for (``interactive``) or refused,
    all named in one message."""
    out = {}
    for label, run in runs.items():
        found = (explicit[label], "--temperature") if label in explicit else _temperature_of(folder, run)
        if found is not None:
            out[label] = found
    unknown = [r for r in runs if r not in out]
    if unknown and not interactive:
        listed = ", ".join(unknown[:8]) + (f", ... ({len(unknown)} runs)" if len(unknown) > 8 else "")
        several = [f"{f}: {_reads(f)}" for f in unknown if _reads(f)][:3]
        why = (f" unambiguously ({'; '.join(several)}; a hyphen after a letter or digit may be a separator or a minus "
               f"sign, an underscore before it makes it one: run_-5C.csv)" if several else "")
        structs = any(runs[r][1] for r in unknown)
        what = ("the run has no temperature field or column and neither its struct's name nor its file's name "
                "states one" if structs else "the file has no temperature column and its name states none")
        raise InputError(f"{folder}: no temperature for {listed}: {what}{why}; give --temperature FILE=C (e.g. "
                         f"--temperature {unknown[0]}=35.2), name the {'struct' if structs else 'file'} with its "
                         f"temperature ({'run_35p2C' if structs else 'run_35.2C.csv'}), or run init on a terminal "
                         f"to be asked")
    for r in unknown:
        out[r] = (_ask(r), "asked")
    return out


def default_validation(order) -> list:
    """The files held out by default, from the files sorted by temperature: none with fewer than 4; else about a
    quarter (at least one), evenly spread over the interior temperatures (validation inside the fitted range)."""
    n = len(order)
    if n < 4:
        return []
    k = max(1, round(n / 4))
    return [order[round((i + 1) * (n - 1) / (k + 1))] for i in range(k)]


def roles(runs: dict, temps: dict, validate, folder: Path) -> tuple[dict, str]:
    """({label: "fit" | "validate"}, how the split was made) of the runs (:func:`experiment_runs`)."""
    files = list(runs)
    if validate is not None:
        chosen = [] if validate.strip().lower() == "none" else [v.strip() for v in validate.split(",") if v.strip()]
        for v in chosen:
            if v not in files:
                raise InputError(f"--validate: {shorten(v)} is not one of the experiments in {folder} "
                                 f"({_listed(files)})")
        how = "held out as you chose (--validate)" if chosen else "none held out (--validate none)"
    elif any(_HELD_OUT.search(f) for f in files):
        chosen = [f for f in files if _HELD_OUT.search(f)]
        how = (f"{len(chosen)} of {len(files)} held out where the file name says so ('validat...', 'holdout', "
               f"'held-out'; --validate chooses others)")
    else:
        mean = {f: _mean_temperature(folder, runs[f]) if T is None else T for f, (T, _) in temps.items()}
        chosen = default_validation(sorted(files, key=lambda f: mean[f]))
        how = (f"the default split: {len(chosen)} of {len(files)} held out at interior temperatures (--validate "
               f"chooses others)" if chosen else
               "all fitted: with fewer than 4 experiments none is held out by default (report needs one: "
               "--validate FILE)")
    return {f: "validate" if f in chosen else "fit" for f in files}, how


def _mean_temperature(folder: Path, run) -> float:
    """The mean of a run's temperature column (for ordering the runs; the dataset's loading says what is wrong
    with a file)."""
    import numpy as np

    from ..data import read_experiment_csv, read_experiment_mat
    from ..data.force import is_force_file
    path, struct = folder / run[0], run[1]
    try:
        if path.suffix.lower() == ".mat":
            from ..data.matlab import read_force_mat
            cols = read_force_mat(path, struct=struct, units=None) or read_experiment_mat(path, struct=struct)
        elif is_force_file(path):
            from ..data.force import read_force_csv
            cols = read_force_csv(path)
        else:
            cols = read_experiment_csv(path)
        return float(np.mean(cols["temperature"]))
    except (InputError, KeyError, TypeError):
        return float("nan")


def manifest_text(name, runs: dict, temps, role_of) -> str:
    import tomli_w
    entries = []
    for f, (file, struct, _) in runs.items():
        entry = {"file": file} | ({"struct": struct} if struct else {})
        if temps[f][0] is not None:
            entry["temperature"] = temps[f][0]
        entry["role"] = role_of[f]
        entries.append(entry)
    head = ("# written by 'thermofriction init' (docs/formats.md#datasets); an experiment without 'temperature' takes "
            "the mean of its temperature column\n")
    return head + tomli_w.dumps({"name": name}) + "".join("\n[[experiment]]\n" + tomli_w.dumps(e) for e in entries)


def write_checked(folder: Path, text: str):
    """Loads the dataset that the manifest ``text`` lists and only then writes it to dataset.toml, atomically: when
    the dataset does not load, or init is interrupted (Ctrl-C, SIGTERM), the folder is as it was (the old manifest,
    or none). The error names the file."""
    import tomllib

    from ..data.files import manifest_dataset

    manifest = folder / "dataset.toml"
    try:
        data = manifest_dataset(tomllib.loads(text), folder, manifest)
    except InputError as e:
        raise InputError(f"{e} -- so {manifest} was not written (leave a file out with --exclude, give a temperature "
                         f"with --temperature FILE=C, or fix the file)") from None
    with _io.atomic_write(manifest, "w", encoding="utf-8") as fh:
        fh.write(text)
    return data


def _dataset_name(name, folder: Path) -> str:
    """--name, which must be UTF-8 text (a manifest is), or else the folder's name, its bytes that are not UTF-8
    replaced (U+FFFD)."""
    if not name:
        return os.fsencode(folder.resolve().name).decode("utf-8", errors="replace")
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:  # bytes of the command line that are not UTF-8 (kept as lone surrogates)
        raise InputError(f"--name {shorten(os.fsencode(name))}: not UTF-8 text") from None
    return name


def cmd_init(args) -> int:
    folder = Path(args.folder)
    if not folder.is_dir():
        raise InputError(f"{args.folder}: {'not a folder' if folder.exists() else 'no such folder'}")
    manifest = folder / "dataset.toml"
    if (manifest.exists() or manifest.is_symlink()) and not args.force:
        raise InputError(f"{manifest}: already exists; give --force to replace it")
    if _io.Target(manifest).check().kind != "file":  # (a FIFO would block the write, and no dataset reads it)
        raise InputError(f"{manifest}: not a regular file; refusing to replace it")
    files = experiment_files(folder, args.exclude)
    if not files:
        raise InputError(f"{args.folder}: no experiment files ({', '.join(EXTENSIONS)}) in this folder")
    refuse_unlistable(args.folder, files)
    runs = experiment_runs(folder, files)
    explicit = _explicit(args.temperature, list(runs))
    temps = temperatures(folder, runs, explicit, interactive=sys.stdin is not None and sys.stdin.isatty())
    role_of, how = roles(runs, temps, args.validate, folder)
    data = write_checked(folder, manifest_text(_dataset_name(args.name, folder), runs, temps, role_of))
    width = max(map(len, runs))
    source = {"--temperature": "given", "column": "mean of its temperature column", "name": "from the file name",
              "field": "mean of its temperature field", "struct": "from the struct's name", "asked": "as you typed it"}
    for e in data.experiments:
        print(f"  {e.label:<{width}}  {e.temperature:8.4g} C  {e.role:<8}  ({source[temps[e.label][1]]})")
    print(f"roles: {how}")
    print(f"wrote {manifest} ({len(data.fit)} fit, {len(data.validate)} validate)")
    return 0


__all__ = ["add_init_command", "cmd_init", "temperature_from_name", "default_validation", "experiment_files"]
