"""Bad input, one table (issue 6, docs/cli.md): every malformed-input class and every numerical failure,
run through the command line as a user would.

Each row checks (1) the exit status (2 usage/data, 1 failed computation), (2) one clear error line
on stderr that names the file, line, key or value (no traceback), and (3) that nothing was written:
the ``-o``/``--json`` targets do not exist and the working folder holds exactly the files it held
before the run (no partial output, no stray temporary file).

The data rows corrupt copies of a small dataset made once per session by ``thermofriction synth``."""

import dataclasses
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from child_signals import default_signals
from conftest import run_cli

FIT = "T35.7C.csv"  # the dataset's fit experiment: time[s],voltage[V],displacement[um],temperature[C]


@pytest.fixture(scope="session")
def valid_dataset(tmp_path_factory):
    """A valid dataset (two experiments, 401 rows each, with a temperature column)."""
    folder = tmp_path_factory.mktemp("valid") / "data"
    out = run_cli("synth", "li2009-model-i", "--temperatures", "35.7", "--validate", "33", "--duration", "0.2",
                  "--sample-rate", "2000", "--temperature-noise", "0.05", "-o", folder)
    assert out.returncode == 0, out.stderr
    assert (folder / FIT).read_text().splitlines()[0] == "time[s],voltage[V],displacement[um],temperature[C]"
    return folder


# -- corruptions of the fit experiment's lines (index 0 is line 1, the header) ---------------------

def drop_column(j):
    return lambda lines: [",".join(c for k, c in enumerate(line.split(",")) if k != j) for line in lines]


def set_cell(line, j, value):
    def edit(lines):
        cells = lines[line - 1].split(",")
        cells[j - 1] = value
        lines[line - 1] = ",".join(cells)
        return lines
    return edit


def time_goes_back(lines):
    cells = lines[6].split(",")       # line 7 gets line 5's time
    cells[0] = lines[4].split(",")[0]
    lines[6] = ",".join(cells)
    return lines


def short_row(lines):
    lines[4] = lines[4].rsplit(",", 1)[0]  # line 5 loses its last value
    return lines


GOOD = """[plant]
type = "stick-slip"
xi = 0.2488
wn = 6685.5
K = 0.096e-6
m = 0.05
m_e = 0.02

[friction]
model = "lugre"
sigma0 = 1.9e6
sigma1 = 2.3
fc = 0.9

[input]
waveform = "sawtooth"
amplitude = 30.0
frequency = 5.0
rise = 0.999
"""

# a stiff single mass: bristles of 1e10 N/m, heavily damped (the explicit method needs ~1e5 steps/s)
STIFF = """[plant]
type = "mass"
m = 1.0
k_s = 2.0
v_0 = 0.1

[friction]
model = "lugre"
sigma0 = 1e10
sigma1 = 1e5
vd = 1e-3
sigma2 = 0.4
fc = 1.0
fs = 1.5
vs = 0.001
"""


@dataclasses.dataclass
class Row:
    """argv placeholders: {data} the corrupted dataset copy, {model} the model file, {work} the
    working folder, {out}/{json}/{fitted} output paths that must not exist afterwards."""

    name: str
    argv: list
    status: int
    words: list              # each must appear in the error line
    csv: object = None       # lines -> lines, applied to the fit experiment
    manifest: object = None  # text -> text, applied to dataset.toml
    remove: str = None       # a dataset file to delete
    model: str = None        # text of {model}
    files: dict = dataclasses.field(default_factory=dict)  # more files in {work}
    env: dict = dataclasses.field(default_factory=dict)


VALIDATE = ["validate", "li2009-model-i", "{data}", "--json", "{json}"]
SIMULATE = ["simulate", "{model}", "-o", "{out}", "--duration", "0.2", "--sample-rate", "1000"]
PRESET_I = ["simulate", "li2009-model-i", "--temperature", "35", "--duration", "0.2", "-o", "{out}"]

ROWS = [
    # experiment files (docs/formats.md#datasets)
    Row("missing column", VALIDATE, 2, [FIT, "line 1", "missing column displacement"], csv=drop_column(2)),
    Row("unknown unit", VALIDATE, 2, [FIT, "line 1", "column 3", "unknown unit 'furlong'"],
        csv=lambda L: [L[0].replace("[um]", "[furlong]"), *L[1:]]),
    Row("non-monotonic time", VALIDATE, 2, [FIT, "line 7", "column 1", "time must increase"], csv=time_goes_back),
    Row("NaN value", VALIDATE, 2, [FIT, "line 10", "column 3", "displacement[um]", "not a finite number"],
        csv=set_cell(10, 3, "nan")),
    Row("infinite value", VALIDATE, 2, [FIT, "line 12", "column 4", "not a finite number"],
        csv=set_cell(12, 4, "inf")),
    Row("not a number", VALIDATE, 2, [FIT, "line 8", "column 2", "'1.2.3'"], csv=set_cell(8, 2, "1.2.3")),
    Row("short row", VALIDATE, 2, [FIT, "line 5", "3 values, expected 4"], csv=short_row),
    Row("empty file", VALIDATE, 2, [FIT, "empty file"], csv=lambda L: []),
    Row("missing file", VALIDATE, 2, [FIT, "no such file"], remove=FIT),
    Row("too many rows", VALIDATE, 2, [FIT, "401 data rows", "limit of 100", "THERMOFRICTION_MAX_ROWS"],
        env={"THERMOFRICTION_MAX_ROWS": "100"}),
    Row("bad data, identify", ["identify", "{data}", "-q", "-o", "{fitted}", "--json", "{json}"], 2,
        [FIT, "line 10", "not a finite number"], csv=set_cell(10, 3, "nan")),
    # dataset manifests
    Row("manifest unknown key", VALIDATE, 2, ["dataset.toml", "[[experiment]] 1", "'colour'"],
        manifest=lambda t: t.replace('role = "fit"', 'role = "fit"\ncolour = "red"')),
    Row("manifest TOML syntax error", VALIDATE, 2, ["dataset.toml", "TOML syntax error", "line"],
        manifest=lambda t: t.replace("[[experiment]]", "[[experiment]", 1)),
    Row("manifest names a missing CSV", VALIDATE, 2, ["nowhere.csv", "no such file"],
        manifest=lambda t: t.replace(f'"{FIT}"', '"nowhere.csv"')),
    Row("missing dataset folder", ["validate", "li2009-model-i", "{work}/nodata", "--json", "{json}"], 2,
        ["nodata", "no such dataset folder"]),
    # model files (docs/formats.md#model-files)
    Row("missing model file", ["simulate", "{work}/nowhere.toml", "-o", "{out}"], 2, ["nowhere.toml", "no such file"]),
    Row("unknown key", SIMULATE, 2, ["'mu'", "[friction]"], model=GOOD.replace("fc = 0.9", "fc = 0.9\nmu = 0.3")),
    Row("unknown law key", [*SIMULATE, "--temperature", "35"], 2, ["'c'", "exp"],
        model=GOOD + '\n[thermal]\nmodel = "I"\nfs = { law = "exp", a = 1.0, b = -0.01, c = 3 }\n'),
    Row("negative mass", SIMULATE, 2, ["[plant]", "'m' must be positive", "-1"],
        model=GOOD.replace("m = 0.05", "m = -1")),
    Row("number and law", [*SIMULATE, "--temperature", "35"], 2, ["'fc'", "both as a number"],
        model=GOOD + '\n[thermal]\nmodel = "I"\nfc = { law = "const", value = 1.0 }\n'),
    Row("Model II lambda <= 0", ["simulate", "li2009-model-ii", "--temperature", "46", "-o", "{out}"], 2,
        ["Model II", "lambda", "<= 0", "46 C"]),
    Row("TOML syntax error", SIMULATE, 2, ["m.toml", "TOML syntax error", "line 9"],
        model=GOOD.replace("[friction]", "[friction")),
    Row("model [input] unknown kind", SIMULATE, 2, ["[input]", "unknown waveform 'triangle'"],
        model=GOOD.replace('"sawtooth"', '"triangle"')),
    # waveform specs (docs/formats.md#inputs, --input)
    Row("waveform unknown kind", [*SIMULATE, "--input", "triangle:amplitude=1"], 2, ["unknown waveform 'triangle'"],
        model=GOOD),
    Row("waveform missing key", [*SIMULATE, "--input", "sawtooth:amplitude=30"], 2, ["sawtooth", "frequency"],
        model=GOOD),
    Row("waveform non-numeric value", [*SIMULATE, "--input", "sine:amplitude=abc,frequency=5"], 2,
        ["amplitude", "abc"], model=GOOD),
    Row("waveform without values", [*SIMULATE, "--input", "sine:amplitude"], 2, ["expected key=value"], model=GOOD),
    Row("waveform bad value", [*SIMULATE, "--input", "sawtooth:amplitude=30,frequency=-5"], 2,
        ["'frequency' must be positive"], model=GOOD),
    Row("sampled file missing", [*SIMULATE, "--input", "sampled:file={work}/u.csv"], 2, ["u.csv"], model=GOOD),
    # temperature files
    Row("temperature file bad line", [*PRESET_I[:2], "--temperature-file", "{work}/T.csv", *PRESET_I[4:]], 2,
        ["T.csv", "line 3", "temperature[C]", "'abc'"], files={"T.csv": "time[s],temperature[C]\n0,31\n0.1,abc\n"}),
    Row("temperature file missing", [*PRESET_I[:2], "--temperature-file", "{work}/T.csv", *PRESET_I[4:]], 2,
        ["T.csv"]),
    # limits and options
    Row("output folder missing", ["simulate", "li2009-model-i", "--temperature", "35", "--duration", "0.05",
                                  "-o", "{work}/nodir/out.csv"], 2, ["nodir", "does not exist"]),
    Row("output folder missing, second output", ["identify", "{data}", "-q", "-o", "{fitted}", "--json",
                                                 "{work}/nodir/r.json"], 2, ["nodir", "does not exist"]),
    Row("too many samples", [*PRESET_I, "--duration", "1e6"], 2,
        ["10000000001 output samples", "limit of 10000000", "--max-samples"]),
    Row("lowered sample limit", [*PRESET_I, "--max-samples", "100"], 2, ["2001 output samples", "limit of 100"]),
    # numerical failures (exit status 1): the message names the time, the state and the likely cause
    Row("NaN or infinite state", [*PRESET_I, "--input", "step:amplitude=1e308"], 1,
        ["t = 0 s", "NaN or infinite", "state x_p = 0", "input 1e+308", "extreme"]),
    Row("step-size underflow", [*PRESET_I, "--input", "step:amplitude=1e300"], 1,
        ["t = ", "step size fell below", "state x_p = ", "input 1e+300", "extreme"]),
    Row("too many steps", [*PRESET_I, "--max-steps", "20"], 1,
        ["t = ", "maximum number of steps", "state x_p = ", "--max-steps, now 20"]),
    Row("stiff problem, explicit method", ["simulate", "{model}", "-o", "{out}", "--duration", "5", "--sample-rate",
                                           "100", "--solver", "dopri5", "--max-steps", "20000"], 1,
        ["t = ", "(step", "dopri5", "state x = ", "looks stiff", "--solver rodas4", "--solver auto"], model=STIFF),
]


def _files(folder: Path):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.mark.parametrize("row", ROWS, ids=[r.name for r in ROWS])
def test_bad_input_is_one_clear_error_and_writes_nothing(row, valid_dataset, tmp_path, monkeypatch):
    """Exit status, one error line naming the culprit (no traceback), and no file written."""
    work = tmp_path
    data = work / "data"
    if any(r is not None for r in (row.csv, row.manifest, row.remove)) or "{data}" in row.argv:
        shutil.copytree(valid_dataset, data)
    if row.csv:
        f = data / FIT
        lines = row.csv(f.read_text().splitlines())
        f.write_text("".join(line + "\n" for line in lines))
    if row.manifest:
        f = data / "dataset.toml"
        f.write_text(row.manifest(f.read_text()))
    if row.remove:
        (data / row.remove).unlink()
    if row.model is not None:
        (work / "m.toml").write_text(row.model)
    for name, text in row.files.items():
        (work / name).write_text(text)
    for k, v in row.env.items():
        monkeypatch.setenv(k, v)
    paths = {"data": data, "model": work / "m.toml", "work": work, "out": work / "out.csv",
             "json": work / "out.json", "fitted": work / "fitted.toml"}
    before = _files(work)

    out = run_cli(*[a.format(**paths) for a in row.argv], cwd=work)

    assert out.returncode == row.status, out.stderr
    assert "Traceback" not in out.stderr
    lines = out.stderr.splitlines()
    errors = [line for line in lines if line.startswith("thermofriction: error: ")]
    assert len(errors) == 1, out.stderr
    assert all(line.startswith(("thermofriction: error: ", "thermofriction: warning: ")) for line in lines), out.stderr
    for word in row.words:
        assert word in errors[0], f"{word!r} not in {errors[0]!r}"
    for key in ("out", "json", "fitted"):
        assert not paths[key].exists()
    assert _files(work) == before  # no partial output, no stray temporary file


def test_the_table_covers_every_required_class():
    """The classes issue 6 requires are all rows of the table (so none is dropped by accident)."""
    required = {"missing column", "unknown unit", "non-monotonic time", "NaN value", "empty file", "missing file",
                "unknown key", "negative mass", "number and law", "Model II lambda <= 0", "TOML syntax error",
                "waveform unknown kind", "waveform missing key", "waveform non-numeric value",
                "NaN or infinite state", "step-size underflow", "too many steps", "stiff problem, explicit method",
                "too many samples", "too many rows"}
    assert required <= {r.name for r in ROWS}


def test_ctrl_c_exits_130_and_leaves_no_partial_file(tmp_path):
    """SIGINT while the output is being written: exit status 130, one message, no output file and
    no temporary file left behind (atomic output)."""
    out_csv = tmp_path / "out.csv"
    proc = subprocess.Popen([sys.executable, "-m", "thermofriction", "simulate", "li2009-model-i", "--temperature",
                             "35", "--duration", "100", "-o", str(out_csv)], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=default_signals)
    try:
        deadline = time.monotonic() + 120
        while not list(tmp_path.glob(".out.csv.*.tmp")):  # wait until it is writing 1,000,001 rows
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline
            time.sleep(0.02)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert "interrupted" in err and "Traceback" not in err
    assert os.listdir(tmp_path) == []


def test_row_limit_boundary_and_bad_setting(valid_dataset, monkeypatch):
    """THERMOFRICTION_MAX_ROWS: a file with exactly the limit loads, one row more is refused naming
    the count, the limit and the variable; a malformed setting is an InputError naming it."""
    import thermofriction as tf
    from thermofriction.data import read_experiment_csv

    monkeypatch.setenv("THERMOFRICTION_MAX_ROWS", "401")
    assert read_experiment_csv(valid_dataset / FIT)["time"].size == 401
    monkeypatch.setenv("THERMOFRICTION_MAX_ROWS", "400")
    with pytest.raises(tf.InputError, match=r"401 data rows, more than the limit of 400.*THERMOFRICTION_MAX_ROWS"):
        read_experiment_csv(valid_dataset / FIT)
    monkeypatch.setenv("THERMOFRICTION_MAX_ROWS", "many")
    with pytest.raises(tf.InputError, match="THERMOFRICTION_MAX_ROWS='many'"):
        read_experiment_csv(valid_dataset / FIT)


def test_fast_reader_keeps_bom_crlf_and_blank_lines(valid_dataset, tmp_path):
    """The fast path reads the file itself (not a copy of its text): a byte-order mark, CRLF line
    ends and blank lines give the same numbers as the plain file."""
    from thermofriction.data import read_experiment_csv

    text = (valid_dataset / FIT).read_text()
    lines = text.splitlines()
    odd = tmp_path / "odd.csv"
    odd.write_bytes(("\ufeff" + "\r\n".join(lines[:5] + [""] + lines[5:]) + "\r\n").encode())
    plain, other = read_experiment_csv(valid_dataset / FIT), read_experiment_csv(odd)
    assert plain.keys() == other.keys()
    for k in plain:
        assert (plain[k] == other[k]).all()


def test_sample_limit_boundary(model_i):
    """max_samples: exactly the limit runs, one more is refused (before any work), None lifts it."""
    import thermofriction as tf

    assert tf.simulate(model_i, 0.01, temperature=35, sample_rate=1000, max_samples=11).time.size == 11
    with pytest.raises(tf.InputError, match="11 output samples.*limit of 10"):
        tf.simulate(model_i, 0.01, temperature=35, sample_rate=1000, max_samples=10)
    with pytest.raises(tf.InputError, match="t_eval"):
        tf.simulate(model_i, temperature=35, t_eval=[0.0, 0.001, 0.002], max_samples=2)
    assert tf.simulate(model_i, 0.01, temperature=35, sample_rate=1000, max_samples=None).time.size == 11
