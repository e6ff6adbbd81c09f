"""Property-based tests (Hypothesis) of every parser of user data (docs/formats.md, docs/cli.md, issue 6 "Hardening"):
experiment CSV files, temperature / sampled-waveform CSV files, dataset manifests, model files,
``--input`` waveform specs, the model save/load round trip and the command line's handling of bad data.

Oracles, one per test (each docstring names its own):
- robustness: on arbitrary or mutated input a parser returns a valid object or raises InputError
  whose one-line message names the file (and the line, key or value where it applies) -- never
  another exception;
- round trip: values generated, written in the file format, read back unchanged;
- the file text itself: an error about a corrupted line names that line;
- the command line: bad data gives exit status 2, one message line, no traceback, no output file.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from conftest import run_cli
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

import thermofriction as tf
from thermofriction.data import load_dataset, read_experiment_csv
from thermofriction.errors import InputError
from thermofriction.models import Model, load_model, model_from_dict
from thermofriction.waveforms import Sampled, Waveform, parse_waveform, read_two_column_csv

SRC = Path(tf.__file__).parent
FAST = settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
SLOW = settings(max_examples=50, deadline=None, suppress_health_check=list(HealthCheck))


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz")


@contextlib.contextmanager
def inside(folder):
    """Runs the block with ``folder`` as the working directory (relative paths stay in it)."""
    old = os.getcwd()
    os.chdir(folder)
    try:
        yield
    finally:
        os.chdir(old)


def check_error(err: InputError, *names: str):
    """An InputError message fit for the user: one line, naming at least one of ``names``."""
    msg = str(err)
    assert type(err) is InputError, type(err)
    assert msg and "\n" not in msg and "\r" not in msg, repr(msg)
    assert any(n in msg for n in names), (names, msg)
    return msg


def lines_named(msg):
    return [int(n) for n in re.findall(r"\bline (\d+)", msg)]


def mutate(text: str, edits) -> str:
    """Applies (fraction of the length, operation, token) edits to ``text``."""
    for frac, op, tok in edits:
        i = int(frac * len(text))
        if op == "insert":
            text = text[:i] + tok + text[i:]
        elif op == "replace":
            text = text[:i] + tok + text[i + max(1, len(tok)):]
        else:
            text = text[:i] + text[i + 1 + len(tok) % 7:]
    return text


TOKENS = [",", "\n", "\r", "\r\n", '"', "\x00", "nan", "inf", "-inf", "1e999", "-1e400", "1e-400", "[", "]",
          "[um]", "[xx]", "[]", "time", "temperature[C]", "voltage[V]", "", " ", "\t", "\ufeff", "ÿ", "é", "µ",
          "1111111111", "0", "-", "e", ".", "#", ";", "9" * 400, "1_0", "0x10", "١", "\u2028", "=", ":",
          "\\", "'", "{", "}", "[[experiment]]", "true", "file", "law", "=[", "= {", "10" * 30]
edits_st = st.lists(st.tuples(st.floats(0, 1), st.sampled_from(["insert", "replace", "delete"]),
                              st.sampled_from(TOKENS)), min_size=1, max_size=6)


# =============================================================================================
# 1. Experiment CSV files (docs/formats.md#datasets)
# =============================================================================================

UNITS = {"time": {"s": 1.0, "ms": 1e-3}, "voltage": {"V": 1.0, "mV": 1e-3},
         "displacement": {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "nm": 1e-9},
         "stage_displacement": {"m": 1.0, "mm": 1e-3, "um": 1e-6, "nm": 1e-9}, "temperature": {"C": 1.0}}
finite = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e300, max_value=1e300)
#: an experiment file's values are limited to 1e100 in SI units (docs/limits.md; issue 17)
data_value = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e100, max_value=1e100)


@st.composite
def experiment_files(draw):
    """(file text, {column: expected SI values}) for a valid experiment file."""
    names = ["time", "voltage", "displacement"]
    names += draw(st.lists(st.sampled_from(["temperature", "stage_displacement"]), unique=True))
    names = draw(st.permutations(names))
    n = draw(st.integers(10, 25))
    header, cols, expected = [], [], {}
    for name in names:
        unit = draw(st.sampled_from([*UNITS[name], None]))
        header.append(name if unit is None else f"{name}[{unit}]")
        scale = 1.0 if unit is None else UNITS[name][unit]
        if name == "time":
            t0, dt = draw(st.floats(-1e3, 1e3)), draw(st.floats(1e-6, 1.0))
            vals = [t0 + k * dt for k in range(n)]
        elif name == "temperature":
            vals = draw(st.lists(st.floats(-100, 300), min_size=n, max_size=n))
        else:
            vals = draw(st.lists(data_value, min_size=n, max_size=n))
        cols.append(vals)
        expected[name] = np.array(vals) * scale
    nl = draw(st.sampled_from(["\n", "\r\n"]))
    pad = draw(st.sampled_from(["", " "]))
    rows = [",".join(pad + repr(c[k]) + pad for c in cols) for k in range(n)]
    blank = draw(st.sets(st.integers(0, n), max_size=3))
    body = []
    for k, row in enumerate(rows):
        if k in blank:
            body.append("")
        body.append(row)
    text = draw(st.sampled_from(["", "\ufeff"])) + ",".join(header) + nl + nl.join(body) + \
        draw(st.sampled_from(["", nl, nl + nl]))
    return text, expected


def check_experiment(out: dict):
    """What read_experiment_csv promises about a file it accepts."""
    assert {"time", "voltage", "displacement"} <= set(out)
    n = len(out["time"])
    assert n >= 10
    for v in out.values():
        assert v.shape == (n,) and np.all(np.isfinite(v))
    assert np.all(np.diff(out["time"]) > 0)
    if "temperature" in out:
        assert np.all((out["temperature"] >= -100) & (out["temperature"] <= 300))


@FAST
@given(experiment_files())
def test_experiment_csv_round_trip(scratch, case):
    """Round trip: a file written from generated floats, in any listed units, column order, CRLF or
    LF, with a BOM and blank lines, reads back as exactly those floats times the unit's SI scale."""
    text, expected = case
    path = scratch / "exp.csv"
    path.write_bytes(text.encode("utf-8"))
    out = read_experiment_csv(path)
    assert set(out) == set(expected)
    for name, vals in expected.items():
        np.testing.assert_array_equal(out[name], vals, err_msg=name)


@FAST
@given(experiment_files(), edits_st, st.sampled_from([b"", b"\xff", b"\xc3", b"\x00"]), st.integers(0, 10 ** 6))
@example(("time[s],voltage[V],displacement[m]\n" + "".join(f"{k},1,2\n" for k in range(12)), {}),
         [(0.0, "insert", '"' + "1" * 200_000)], b"", 0)  # a header field beyond the csv module's limit
def test_experiment_csv_never_crashes(scratch, case, edits, junk, where):
    """Property: a mutated experiment file either reads as a valid experiment or raises an
    InputError naming the file and, where it names a line, a line that exists."""
    text = mutate(case[0], edits)
    raw = text.encode("utf-8")
    if junk:
        i = where % (len(raw) + 1)
        raw = raw[:i] + junk + raw[i:]
    path = scratch / "mutated.csv"
    path.write_bytes(raw)
    try:
        out = read_experiment_csv(path)
    except InputError as e:
        msg = check_error(e, str(path))
        nlines = raw.count(b"\n") + 1
        assert all(1 <= n <= nlines for n in lines_named(msg)), (msg, nlines)
    else:
        check_experiment(out)


@FAST
@given(st.binary(max_size=600))
def test_experiment_csv_arbitrary_bytes(scratch, raw):
    """Property: arbitrary bytes read as a valid experiment or raise an InputError naming the file."""
    path = scratch / "bytes.csv"
    path.write_bytes(raw)
    try:
        check_experiment(read_experiment_csv(path))
    except InputError as e:
        check_error(e, str(path))


@FAST
@given(experiment_files(), st.data())
def test_experiment_csv_error_names_the_bad_line(scratch, case, data):
    """Oracle: the file text. One data cell replaced by a non-number -> the error names that
    line (counted in the file, header = 1, blank lines included) and that column's header."""
    text, _ = case
    lines = text.split("\n")
    data_lines = [i for i, line in enumerate(lines) if i > 0 and line.strip()]
    i = data.draw(st.sampled_from(data_lines))
    cells = lines[i].split(",")
    j = data.draw(st.integers(0, len(cells) - 1))
    cells[j] = data.draw(st.sampled_from(["abc", "1..2", "--1", "x1", "1e"]))
    lines[i] = ",".join(cells)
    path = scratch / "badline.csv"
    path.write_text("\n".join(lines), encoding="utf-8")
    with pytest.raises(InputError) as e:
        read_experiment_csv(path)
    msg = check_error(e.value, str(path))
    assert lines_named(msg) == [i + 1], msg
    assert f"column {j + 1}" in msg, msg


# =============================================================================================
# 1b. Temperature files and sampled waveforms: time[s] and one value column
# =============================================================================================

@st.composite
def two_column_files(draw):
    n = draw(st.integers(2, 20))
    t = sorted(draw(st.sets(st.integers(-10 ** 6, 10 ** 6), min_size=n, max_size=n)))
    step = draw(st.sampled_from([1e-3, 0.5, 1.0, 7.25]))
    t = [k * step for k in t]
    v = draw(st.lists(finite, min_size=n, max_size=n))
    unit = draw(st.sampled_from(["s", "ms"]))
    rows = [f"{a!r},{b!r}" for a, b in zip(t, v)]
    blank = draw(st.sets(st.integers(0, n), max_size=3))
    lines = [f"time[{unit}],temperature[C]"]
    for k, row in enumerate(rows):
        if k in blank:
            lines.append("")
        lines.append(row)
    return "\n".join(lines) + "\n", np.array(t) * {"s": 1.0, "ms": 1e-3}[unit], np.array(v)


@FAST
@given(two_column_files())
def test_temperature_file_round_trip(scratch, case):
    """Round trip: a --temperature-file / sampled:file= CSV written from generated floats reads back
    as those floats (time scaled to s), both directly and through the --input spec."""
    text, t, v = case
    path = scratch / "T.csv"
    path.write_text(text, encoding="utf-8")
    tt, vv = read_two_column_csv(path, "time")
    np.testing.assert_array_equal(tt, t)
    np.testing.assert_array_equal(vv, v)
    w = parse_waveform(f"sampled:file={path}")
    assert isinstance(w, Sampled) and w.file == str(path)
    np.testing.assert_array_equal(w.time, t)
    np.testing.assert_array_equal(w.value, v)


@FAST
@given(two_column_files(), edits_st, st.sampled_from([b"", b"\xff", b"\xc3", b"\x00"]), st.integers(0, 10 ** 6))
@example(("time[s],T\n0,1\n1,2\n", None, None), [(0.5, "insert", '"' + "1" * 200_000)], b"", 0)
def test_temperature_file_never_crashes(scratch, case, edits, junk, where):
    """Property: a mutated temperature file gives a valid sampled waveform or an InputError naming
    the file and an existing line -- never UnicodeDecodeError, csv.Error, ValueError."""
    raw = mutate(case[0], edits).encode("utf-8")
    if junk:
        i = where % (len(raw) + 1)
        raw = raw[:i] + junk + raw[i:]
    path = scratch / "Tmut.csv"
    path.write_bytes(raw)
    try:
        w = Sampled.from_csv(path)
    except InputError as e:
        msg = check_error(e, str(path))
        assert all(1 <= n <= raw.count(b"\n") + 1 for n in lines_named(msg)), msg
    else:
        assert w.time.size >= 2 and np.all(np.diff(w.time) > 0) and np.all(np.isfinite(w.value))


@FAST
@given(two_column_files(), st.data())
def test_temperature_file_error_names_the_bad_line(scratch, case, data):
    """Oracle: the file text. A non-number on one line -> the error names that line, counted in
    the file with its blank lines (a bug found here: blank lines shifted the line numbers)."""
    lines = case[0].split("\n")
    i = data.draw(st.sampled_from([k for k, line in enumerate(lines) if k > 0 and line.strip()]))
    a, b = lines[i].split(",")
    lines[i] = data.draw(st.sampled_from([f"abc,{b}", f"{a},x", f"{a},1e999"]))
    path = scratch / "Tbad.csv"
    path.write_text("\n".join(lines), encoding="utf-8")
    with pytest.raises(InputError) as e:
        read_two_column_csv(path, "time")
    assert lines_named(check_error(e.value, str(path))) == [i + 1]


# =============================================================================================
# 4. --input waveform specs
# =============================================================================================

num = st.floats(-1e6, 1e6)
pos = st.floats(1e-3, 1e4)


@st.composite
def waveform_params(draw):
    """(kind, {parameter: value}) for a valid waveform."""
    kind = draw(st.sampled_from(["sawtooth", "sine", "square", "step"]))
    if kind == "sawtooth":
        p = {"amplitude": draw(num), "frequency": draw(pos), "rise": draw(st.floats(1e-6, 1 - 1e-6)),
             "offset": draw(num), "direction": draw(st.sampled_from([1, -1]))}
    elif kind == "sine":
        p = {"amplitude": draw(num), "frequency": draw(pos), "offset": draw(num)}
    elif kind == "square":
        f, duty = draw(pos), draw(st.floats(0.01, 0.99))
        slew = min(duty, 1 - duty) / f * draw(st.floats(1e-3, 0.99))
        p = {"amplitude": draw(num), "frequency": f, "slew": slew, "offset": draw(num), "duty": duty}
    else:
        p = {"amplitude": draw(num), "time": draw(num), "slew": draw(st.floats(0, 1e3)), "offset": draw(num)}
    required = {"sawtooth": 2, "sine": 2, "square": 3, "step": 1}[kind]
    keys = list(p)
    keep = keys[:required] + [k for k in keys[required:] if draw(st.booleans())]
    return kind, {k: p[k] for k in draw(st.permutations(keep))}


@FAST
@given(waveform_params(), st.sampled_from(["", " "]), st.sampled_from([repr, lambda x: f"{x:.17g}"]))
def test_waveform_spec_round_trip(case, space, fmt):
    """Round trip: a spec built from generated numbers (any key order, spaces) gives a waveform
    with exactly those parameters; its own .spec() parses back to an equal waveform."""
    kind, p = case
    spec = f"{kind}:" + ",".join(f"{space}{k}{space}={space}{fmt(v)}{space}" for k, v in p.items())
    w = parse_waveform(spec)
    assert w.kind == kind
    for k, v in p.items():
        assert getattr(w, k) == v, (k, getattr(w, k), v)
    assert parse_waveform(w.spec()) == w
    assert np.all(np.isfinite(w(np.linspace(0.0, 1.0, 7))))


@FAST
@given(st.one_of(st.text(max_size=80),
                 st.builds(lambda c, e: mutate(f"{c[0]}:" + ",".join(f"{k}={v!r}" for k, v in c[1].items()), e),
                           waveform_params(), edits_st)))
@example("sawtooth:amplitude=1,frequency=1,direction=1e300")
@example("sampled:file=a\x00b")
@example("sampled:file=")
def test_waveform_spec_never_crashes(scratch, spec):
    """Property: any text given to --input gives a waveform or an InputError quoting the spec (or
    the file a sampled: spec names) -- never ValueError, TypeError, OverflowError."""
    with inside(scratch):
        try:
            w = parse_waveform(spec)
        except InputError as e:
            names = ["--input"]
            if "file=" in spec:
                file = spec.partition("file=")[2].split(",")[0].strip()[:20] or "."
                names += [file, repr(file)[1:-1]]
            check_error(e, *names)
        else:
            assert isinstance(w, Waveform)


# =============================================================================================
# 3 and 5. Model files: robustness and the save/load round trip
# =============================================================================================

posf = st.floats(1e-6, 1e6)
nonneg = st.floats(0, 1e3)
anyf = st.floats(-1e6, 1e6)


@st.composite
def laws(draw):
    kind = draw(st.sampled_from(["const", "linear", "exp", "poly", "pwl", "table"]))
    d = {"law": kind}
    if kind == "const":
        d["value"] = draw(posf)
    elif kind in ("linear", "exp"):
        d.update(a=draw(anyf), b=draw(st.floats(-1, 1)))
    elif kind == "poly":
        d["c"] = draw(st.lists(anyf, min_size=1, max_size=4))
    else:
        n = draw(st.integers(2, 5))
        d["T"] = sorted(draw(st.sets(st.floats(-100, 300), min_size=n, max_size=n)))
        d["values"] = draw(st.lists(anyf, min_size=n, max_size=n))
    if draw(st.booleans()):
        lo = draw(st.floats(-100, 200))
        d["range"] = [lo, lo + draw(st.floats(0.5, 100))]
    return d


@st.composite
def model_dicts(draw):
    """A valid model file's contents (docs/formats.md#model-files), as a dict."""
    d = {}
    if draw(st.booleans()):
        d["name"] = draw(st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=20))
    if draw(st.booleans()):
        d["description"] = draw(st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=40))
    ptype = draw(st.sampled_from(["stick-slip-modal", "stick-slip-physical", "mass", "prescribed"]))
    if ptype == "stick-slip-modal":
        d["plant"] = {"type": "stick-slip", "m": draw(posf), "m_e": draw(posf), "xi": draw(nonneg),
                      "wn": draw(posf), "K": draw(anyf)}
    elif ptype == "stick-slip-physical":
        d["plant"] = {"type": "stick-slip", "m": draw(posf), "m_e": draw(posf), "c": draw(nonneg),
                      "k": draw(posf), "T_em": draw(anyf)}
    elif ptype == "mass":
        d["plant"] = {"type": "mass", "m": draw(posf)}
        if draw(st.booleans()):
            d["plant"].update(k_s=draw(posf), v_0=draw(anyf))
    else:
        d["plant"] = {"type": "prescribed"}
    fmodel = draw(st.sampled_from(["lugre", "coulomb", "stribeck", "dahl", "elastoplastic", "gms"]))
    fc, sigma0 = draw(posf), draw(posf)
    p = {"fc": fc}
    if fmodel in ("lugre", "dahl", "elastoplastic"):
        p["sigma0"] = sigma0
    if fmodel in ("lugre", "elastoplastic"):
        p["sigma1"] = draw(nonneg)
    if fmodel == "elastoplastic":
        p["z_ba"] = fc / sigma0 * draw(st.floats(0, 0.99))
    if fmodel in ("lugre", "stribeck", "elastoplastic", "gms") and draw(st.booleans()):
        p.update(fs=fc * (1 + draw(st.floats(0, 2))), vs=draw(posf), delta=draw(st.floats(0.1, 4)))
    if fmodel != "dahl" and draw(st.booleans()):
        p["sigma2"] = draw(nonneg)
    if draw(st.booleans()):
        p["v_smooth"] = draw(posf)
    if fmodel == "gms":
        n = draw(st.integers(1, 4))
        p["k"] = draw(st.lists(posf, min_size=n, max_size=n))
        p["w"] = [1.0 / n] * n
        p["C"] = draw(posf)
    friction = {"model": fmodel}
    th = draw(st.sampled_from(["none", "I", "II", None]))
    if th == "I":
        thermal = {"model": "I"}
        movable = [k for k in p if k not in ("k", "w", "z_ba", "fs", "vs", "delta")]
        for k in draw(st.lists(st.sampled_from(movable), unique=True, min_size=1)):
            thermal[k] = draw(laws())
            del p[k]
    elif th == "II":
        thermal = {"model": "II", "dF": draw(laws())}
        if draw(st.booleans()):
            thermal["form"] = draw(st.sampled_from(["scale", "offset"]))
    elif th == "none":
        thermal = {"model": "none"}
    friction.update(p)
    d["friction"] = friction
    if th is not None:
        d["thermal"] = thermal
    if draw(st.booleans()):
        kind, wp = draw(waveform_params())
        d["input"] = {"waveform": kind, **wp}
    elif draw(st.booleans()):
        n = draw(st.integers(2, 6))
        d["input"] = {"waveform": "sampled", "time": sorted(draw(st.sets(st.floats(0, 10), min_size=n, max_size=n))),
                      "value": draw(st.lists(anyf, min_size=n, max_size=n))}
    return d


def assert_contains(given_, got, where=""):
    """Every generated key is in the parsed model's file form with the same value."""
    if isinstance(given_, dict):
        assert isinstance(got, dict), where
        for k, v in given_.items():
            assert k in got, f"{where}.{k} missing"
            assert_contains(v, got[k], f"{where}.{k}")
    elif isinstance(given_, list):
        assert list(got) == given_, where
    else:
        assert got == given_ and type(got) is type(given_), (where, got, given_)


@SLOW
@given(model_dicts())
def test_model_save_load_round_trip(scratch, d):
    """Round trip: a generated valid model parses to the values generated, and Model.save then
    load_model gives an equal model (same file form, and == where the input is not sampled)."""
    m = model_from_dict(d, "generated")
    assert_contains(d, m.to_dict())
    path = scratch / "model.toml"
    m.save(path)
    m2 = load_model(path)
    assert m2.to_dict() == m.to_dict()
    if not isinstance(m.input, Sampled):
        assert m2 == m
    assert not list(scratch.glob(".model.toml.*"))


def toml_values():
    leaves = st.one_of(st.booleans(), st.integers(-10 ** 20, 10 ** 20), st.sampled_from([10 ** 400, -10 ** 400]),
                       st.floats(), st.text(max_size=10),
                       st.sampled_from(["lugre", "I", "II", "exp", "sawtooth", "sampled", "stick-slip", "../x",
                                        "a\x00b", "__import__('os').system('touch PWNED')"]))
    return st.recursive(leaves, lambda c: st.one_of(st.lists(c, max_size=3),
                                                     st.dictionaries(st.sampled_from(
                                                         ["law", "a", "b", "value", "model", "waveform", "file",
                                                          "type", "m", "x"]), c, max_size=3)), max_leaves=6)


def paths_of(d, prefix=()):
    out = [prefix]
    if isinstance(d, dict):
        for k, v in d.items():
            out += paths_of(v, prefix + (k,))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            out += paths_of(v, prefix + (i,))
    return out


@st.composite
def mutated(draw, base):
    """``base`` with a few keys replaced by arbitrary TOML values, deleted or added."""
    import copy
    d = copy.deepcopy(draw(base))
    added = []
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(paths_of(d)))
        op = draw(st.sampled_from(["set", "delete", "add"]))
        parent = d
        for k in path[:-1]:
            parent = parent[k]
        if not path:
            continue
        if op == "set":
            parent[path[-1]] = draw(toml_values())
        elif op == "delete" and isinstance(parent, dict):
            del parent[path[-1]]
        elif op == "add" and isinstance(parent[path[-1]], dict):
            key = draw(st.sampled_from(["x", "unknown_key", "sigma9", "law", "value", "file", "range"]))
            parent[path[-1]][key] = draw(toml_values())
    return d


@FAST
@given(mutated(model_dicts()))
@example({"plant": {"type": ["stick-slip"]}, "friction": {"model": "coulomb", "fc": 1.0}})
@example({"plant": {"type": "mass", "m": 10 ** 400}, "friction": {"model": "coulomb", "fc": 1.0}})
@example({"plant": {"type": "mass", "m": 1.0}, "friction": {"model": "coulomb", "fc": 1.0}, "input": 3})
@example({"plant": {"type": "mass", "m": 1.0}, "friction": {"model": "coulomb", "fc": 1.0},
          "input": {"waveform": "sampled", "file": 3}})
def test_model_dict_never_crashes(scratch, d):
    """Property: a model file with keys replaced by arbitrary values, deleted or added either
    loads as a Model or raises an InputError naming the file -- never TypeError (unhashable
    values), OverflowError (huge integers), ValueError (NUL in a file name)."""
    with inside(scratch):
        try:
            m = model_from_dict(d, "fuzz.toml", base_dir=scratch)
        except InputError as e:
            check_error(e, "fuzz.toml")
        else:
            assert isinstance(m, Model)
            tomli_w.dumps(m.to_dict())  # what it accepts, it can save
    assert not (scratch / "PWNED").exists()


@FAST
@given(model_dicts(), st.sampled_from(["x", "unknown_key"]), st.sampled_from(["", "plant", "friction", "thermal",
                                                                               "input"]))
def test_model_unknown_key_is_named(scratch, d, key, section):
    """Property (docs/formats.md#model-files: unknown keys are errors): an unknown key anywhere is
    an InputError naming it."""
    if section:
        assume(isinstance(d.get(section), dict))
        d[section][key] = 1.0
    else:
        d[key] = 1.0
    with pytest.raises(InputError) as e:
        model_from_dict(d, "fuzz.toml")
    assert f"'{key}'" in check_error(e.value, "fuzz.toml")


@FAST
@given(st.one_of(st.builds(lambda d, e: mutate(tomli_w.dumps(d), e), model_dicts(), edits_st),
                 st.text(max_size=200)),
       st.sampled_from([b"", b"\xff", b"\x00"]))
@example("a = " + "[" * 5000 + "]" * 5000, b"")
@example("a = " + "{b = " * 3000 + "1" + "}" * 3000, b"")
def test_model_file_text_never_crashes(scratch, text, junk):
    """Property: a model file whose text is mutated (or arbitrary, or nested thousands deep) loads
    or raises an InputError naming the file -- no tomllib error or RecursionError leaks."""
    path = scratch / "fuzz-text.toml"
    path.write_bytes(junk + text.encode("utf-8"))
    with inside(scratch):
        try:
            assert isinstance(load_model(path), Model)
        except InputError as e:
            check_error(e, str(path))


@pytest.mark.parametrize("name", ["a" * 5000 + ".toml", "bad\x00name.toml", "/nonexistent/dir/m.toml"])
def test_model_file_name_is_not_a_crash(name):
    """Property: an unusable model file name (too long, NUL byte, missing folder) is an InputError."""
    with pytest.raises(InputError) as e:
        load_model(name)
    assert "\n" not in str(e.value)


# =============================================================================================
# 2. Dataset manifests
# =============================================================================================

def _experiment_text(n=12, temperature=None):
    head = "time[s],voltage[V],displacement[um]" + (",temperature[C]" if temperature is not None else "")
    rows = [f"{k * 1e-3!r},{k * 0.5!r},{k * 0.01!r}" + (f",{temperature!r}" if temperature is not None else "")
            for k in range(n)]
    return head + "\n" + "\n".join(rows) + "\n"


@pytest.fixture(scope="module")
def dataset_dir(scratch):
    folder = scratch / "ds"
    (folder / "sub").mkdir(parents=True)
    (folder / "run.csv").write_text(_experiment_text())
    (folder / "sub" / "run2.csv").write_text(_experiment_text(temperature=35.0))
    (scratch / "x.csv").write_text(_experiment_text(temperature=35.0))  # a valid file outside the folder
    return folder


@st.composite
def manifests(draw):
    d = {}
    if draw(st.booleans()):
        d["name"] = draw(st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=20))
    if draw(st.booleans()):
        d["description"] = draw(st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=40))
    exps = []
    for _ in range(draw(st.integers(1, 3))):
        e = {"file": draw(st.sampled_from(["run.csv", "sub/run2.csv", "./run.csv", "sub/./run2.csv"]))}
        if "run2" not in e["file"] or draw(st.booleans()):
            e["temperature"] = draw(st.floats(-100, 300))
        if draw(st.booleans()):
            e["role"] = draw(st.sampled_from(["fit", "validate"]))
        if draw(st.booleans()):
            e["description"] = draw(st.text(st.characters(blacklist_categories=("Cs",)), max_size=30))
        if draw(st.booleans()):
            kind, p = draw(waveform_params())
            for k in ("amplitude", "offset"):  # a manifest's input is a voltage: at most +-10 kV (plausible.py)
                if k in p:
                    p[k] = p[k] / 200.0
            e["input"] = f"{kind}:" + ",".join(f"{k}={v!r}" for k, v in p.items())
        exps.append(e)
    d["experiment"] = exps
    return d


@FAST
@given(manifests())
def test_manifest_round_trip(dataset_dir, meta):
    """Round trip: a generated valid manifest loads with exactly its names, temperatures (else the
    mean of the temperature column), roles (default fit), descriptions and input waveforms."""
    (dataset_dir / "dataset.toml").write_text(tomli_w.dumps(meta), encoding="utf-8")
    data = load_dataset(dataset_dir)
    assert data.name == meta.get("name") and data.description == meta.get("description", "")
    assert len(data.experiments) == len(meta["experiment"])
    for e, m in zip(data.experiments, meta["experiment"]):
        assert e.file == m["file"]
        assert e.temperature == m.get("temperature", 35.0)
        assert e.role == m.get("role", "fit") and e.description == m.get("description", "")
        assert (e.input is None) == ("input" not in m)
        if "input" in m:
            assert e.input == parse_waveform(m["input"])
        assert e.time.size == 12


@FAST
@given(st.one_of(mutated(manifests()),
                 st.builds(lambda d, e: mutate(tomli_w.dumps(d), e), manifests(), edits_st),
                 st.text(max_size=200)))
@example({"experiment": [{"file": "run.csv", "temperature": 10 ** 400}]})
@example({"experiment": [{"file": "run\x00.csv", "temperature": 30.0}]})
@example({"experiment": [{"file": "run.csv", "temperature": 30.0, "input": "sampled:file=a\x00b"}]})
@example("experiment = " + "[" * 5000 + "]" * 5000)
def test_manifest_never_crashes(dataset_dir, meta):
    """Property: a mutated or arbitrary manifest loads as a Dataset whose files are all inside the
    folder, or raises an InputError naming the manifest (or the experiment file it names)."""
    manifest = dataset_dir / "dataset.toml"
    manifest.write_text(meta if isinstance(meta, str) else tomli_w.dumps(meta), encoding="utf-8")
    root = dataset_dir.resolve()
    with inside(dataset_dir):
        try:
            data = load_dataset(dataset_dir)
        except InputError as e:
            check_error(e, str(dataset_dir))
        else:
            for e in data.experiments:
                target = (dataset_dir / e.file).resolve()
                assert root in target.parents
    assert not (dataset_dir / "PWNED").exists()


ESCAPES = ["../x.csv", "sub/../../x.csv", "{outside}", "~/x.csv", "C:/x.csv", "C:\\x.csv", "..\\x.csv",
           "link-file.csv", "link-dir/x.csv", "sub/../link-dir/x.csv"]


@pytest.mark.parametrize("file", ESCAPES)
def test_manifest_paths_cannot_escape(tmp_path, file):
    """Property: a manifest cannot make the reader open a file outside the dataset folder -- not by
    '..', an absolute path, a home or drive prefix, nor a symbolic link (to a file or a folder)
    pointing out -- although each target is a valid experiment file; the error names the entry
    and the path."""
    folder = tmp_path / "ds"
    folder.mkdir()
    outside = tmp_path / "x.csv"
    outside.write_text(_experiment_text())
    (folder / "link-file.csv").symlink_to(outside)
    (folder / "link-dir").symlink_to(tmp_path, target_is_directory=True)
    file = file.format(outside=outside)
    (folder / "dataset.toml").write_text(tomli_w.dumps({"experiment": [{"file": file, "temperature": 30.0}]}))
    with pytest.raises(InputError) as e:
        load_dataset(folder)
    msg = check_error(e.value, str(folder / "dataset.toml"))
    assert "[[experiment]] 1" in msg and file in msg and "inside the dataset folder" in msg


def test_manifest_symlink_inside_is_allowed(tmp_path):
    """Control for the escape test: a link that stays inside the folder is a valid path."""
    folder = tmp_path / "ds"
    (folder / "sub").mkdir(parents=True)
    (folder / "sub" / "run.csv").write_text(_experiment_text())
    (folder / "alias.csv").symlink_to(folder / "sub" / "run.csv")
    (folder / "dataset.toml").write_text(tomli_w.dumps({"experiment": [{"file": "alias.csv", "temperature": 30.0}]}))
    assert load_dataset(folder).experiments[0].time.size == 12


@SLOW
@given(st.lists(st.sampled_from(["..", ".", "sub", "x.csv", "run.csv", "link-dir", "~", "C:", ""]),
                min_size=1, max_size=5),
       st.sampled_from(["/", "\\"]), st.booleans())
def test_manifest_generated_paths_stay_inside(tmp_path_factory, parts, sep, absolute):
    """Property: for generated relative/absolute paths built of '..', links and real names, a
    dataset that loads only ever read files inside its folder (x.csv exists only outside)."""
    base = tmp_path_factory.mktemp("esc")
    folder = base / "ds"
    (folder / "sub").mkdir(parents=True)
    (base / "x.csv").write_text(_experiment_text())
    (folder / "run.csv").write_text(_experiment_text())
    (folder / "sub" / "run.csv").write_text(_experiment_text())
    (folder / "link-dir").symlink_to(base, target_is_directory=True)
    f = (str(folder) + sep if absolute else "") + sep.join(parts)
    (folder / "dataset.toml").write_text(tomli_w.dumps({"experiment": [{"file": f, "temperature": 30.0}]}))
    try:
        data = load_dataset(folder)
    except InputError as e:
        check_error(e, str(folder))
    else:
        assert not absolute
        target = (folder / data.experiments[0].file).resolve()
        assert folder.resolve() in target.parents


# =============================================================================================
# Nothing executes from data
# =============================================================================================

def test_no_code_execution_from_data_files():
    """Property: the readers of model and dataset files use only tomllib, csv and number parsing:
    no eval/exec/pickle/yaml/allow_pickle anywhere in the package's Python sources."""
    bad = re.compile(r"\b(eval|exec|compile|__import__)\s*\(|\bpickle\b|\bmarshal\b|\byaml\b|allow_pickle\s*=\s*True"
                     r"|\bshelve\b|\bsubprocess\b|os\.system")
    # the one module that runs a program: the C compiler on the package's own FMU sources, when an export asks for
    # platforms (an argument list, no shell; issue 44) -- subprocess only, nothing else of the pattern
    compiler = {"fmu_sources.py": re.compile(r"\bsubprocess\b")}
    hits = [f"{p.name}:{i}: {line.strip()}" for p in SRC.glob("*.py")
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
            if bad.search(line.split("#")[0])
            and not (p.name in compiler and not bad.search(compiler[p.name].sub("", line.split("#")[0])))]
    assert not hits, hits


# =============================================================================================
# The command line (docs/cli.md): bad data -> status 2, one line, no traceback, no output file
# =============================================================================================

def _run_main(argv):
    """The command line in this process: (status, stdout, stderr)."""
    from thermofriction.cli import main
    out, err = io.StringIO(), io.StringIO()
    saved = warnings.showwarning
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                status = main([str(a) for a in argv])
            except SystemExit as e:  # argparse usage errors
                status = e.code
    finally:
        warnings.showwarning = saved
    return status, out.getvalue(), err.getvalue()


def _check_refused(status, stdout, stderr, outputs):
    assert status == 2, (status, stderr)
    assert "Traceback" not in stderr and "Traceback" not in stdout
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("thermofriction: error: "), stderr
    for p in outputs:
        assert not p.exists(), p
        assert not list(p.parent.glob(f".{p.name}.*")), "temporary file left behind"


@st.composite
def bad_cli_cases(draw, folder):
    """(argv, output files) where one input is bad data; the library itself raises InputError."""
    out = folder / "out.csv"
    kind = draw(st.sampled_from(["model", "spec", "tfile", "dataset"]))
    if kind == "model":
        text = mutate(tomli_w.dumps(draw(model_dicts())), draw(edits_st))
        path = folder / "bad-model.toml"
        path.write_bytes(text.encode("utf-8"))
        try:
            load_model(path)
            assume(False)
        except InputError:
            pass
        return ["simulate", path, "--temperature", "35", "--duration", "0.001", "-o", out], [out]
    if kind == "spec":
        kind_, p = draw(waveform_params())
        spec = mutate(f"{kind_}:" + ",".join(f"{k}={v!r}" for k, v in p.items()), draw(edits_st))
        assume("\x00" not in spec and not spec.startswith("-"))
        with inside(folder):
            try:
                parse_waveform(spec)
                assume(False)
            except InputError:
                pass
        return ["simulate", "li2009-model-i", "--temperature", "35", "--duration", "0.001", "--input", spec,
                "-o", out], [out]
    if kind == "tfile":
        text = mutate(draw(two_column_files())[0], draw(edits_st))
        path = folder / "bad-T.csv"
        path.write_bytes(text.encode("utf-8"))
        try:
            Sampled.from_csv(path)
            assume(False)
        except InputError:
            pass
        return ["simulate", "li2009-model-i", "--temperature-file", path, "--duration", "0.001", "-o", out], [out]
    ds = folder / "bad-ds"
    ds.mkdir(exist_ok=True)
    (ds / "run.csv").write_text(mutate(_experiment_text(), draw(edits_st)), encoding="utf-8")
    meta = draw(st.one_of(manifests(), mutated(manifests())))
    (ds / "dataset.toml").write_text(tomli_w.dumps(meta), encoding="utf-8")
    try:
        load_dataset(ds)
        assume(False)
    except InputError:
        pass
    js = folder / "metrics.json"
    return ["validate", "li2009-model-i", ds, "--json", js], [js]


@settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.data())
def test_cli_bad_data_in_process(tmp_path_factory, data):
    """Property (docs/cli.md): generated bad model files, --input specs, temperature files and datasets
    make the command line exit with status 2, print one 'thermofriction: error:' line and no
    traceback, and write no output file (nor a temporary one)."""
    folder = tmp_path_factory.mktemp("cli")
    argv, outputs = data.draw(bad_cli_cases(folder))
    with inside(folder):
        _check_refused(*_run_main(argv), outputs)


@settings(max_examples=6, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
@given(st.data())
def test_cli_bad_data_subprocess(tmp_path_factory, data):
    """Property (docs/cli.md), as a user runs it (a fresh interpreter): bad data -> status 2, one
    message line, no traceback, no output file."""
    folder = tmp_path_factory.mktemp("cli-sub")
    argv, outputs = data.draw(bad_cli_cases(folder))
    out = run_cli(*argv, cwd=folder)
    _check_refused(out.returncode, out.stdout, out.stderr, outputs)
