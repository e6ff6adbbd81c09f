"""Limits that hold (issue 17): every reproduction of the issue's "Limits that hold" section, run as a
user (the command line) or a programmer (the Python API) would.

Each command-line case runs in a fresh interpreter under a time limit (a hang fails it) and a
memory cap (reading /dev/zero to the end fails it), in a folder of its own, and is checked for its
exit status, its one message, no traceback, no crash, no file written and no input changed. The
cases are grouped by class; docs/hardening.md's attack table gives the counts for each class and
``test_the_attack_table_matches_the_cases`` keeps the two equal.
"""

import dataclasses
import hashlib
import math
import os
import re
import resource
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf

FIT = "T33C.csv"
TIMEOUT = 60      # s: a case that takes longer hangs
MEMORY = 3 << 30  # bytes of address space: a case that reads an endless input runs out of it


@pytest.fixture(scope="session")
def dataset(tmp_path_factory):
    """Two fit temperatures and one held out, 401 rows each."""
    folder = tmp_path_factory.mktemp("limits") / "data"
    out = _run(["synth", "li2009-model-i", "--temperatures", "33,38", "--validate", "35", "--duration", "0.2",
                "--sample-rate", "2000", "-o", str(folder)], Path(folder).parent)
    assert out.returncode == 0, out.stderr
    return folder


def _limit_memory():  # pragma: no cover - runs in the child
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))


def _run(argv, cwd):
    return subprocess.run([sys.executable, "-m", "thermofriction", *map(str, argv)], capture_output=True, text=True,
                          cwd=cwd, timeout=TIMEOUT, preexec_fn=_limit_memory)


from test_bad_input import GOOD  # noqa: E402  (the same valid model file)
NO_FC = GOOD.replace("fc = 0.9\n", "")
NO_SIGMA0 = GOOD.replace("sigma0 = 1.9e6\n", "")


def _csv_edit(edit):
    """A dataset edit: ``edit(lines)`` -> lines of the fit experiment (line 1 is the header)."""
    def apply(data):
        f = data / FIT
        f.write_text("".join(line + "\n" for line in edit(f.read_text().splitlines())))
    return apply


def _column(j, value):
    return _csv_edit(lambda L: [L[0]] + [",".join(value if k == j else c for k, c in enumerate(r.split(",")))
                                         for r in L[1:]])


def _shift_time(data, by=1e6):
    for f in data.glob("*.csv"):
        L = f.read_text().splitlines()
        f.write_text("".join(line + "\n" for line in
                             [L[0]] + [",".join([repr(float(r.split(",")[0]) + by), *r.split(",")[1:]])
                                       for r in L[1:]]))


def _fifo(name):
    def make(work):
        os.mkfifo(work / name)
    return make


def _fifo_in_data(name):
    def make(data):
        (data / name).unlink()
        os.mkfifo(data / name)
    return make


@dataclasses.dataclass
class Case:
    """argv placeholders: {data} a copy of the dataset, {model} m.toml (text ``model``), {work} the
    case's folder, {out} an output path that must not exist afterwards. ``expect``: "refuse" (one
    error line, exit ``status``) or "run" (exit 0; ``words`` then appear in a warning line)."""

    cls: str
    name: str
    argv: list
    words: list
    status: int = 2
    expect: str = "refuse"
    model: str = None
    data: object = None      # callable(data folder): edits the dataset copy
    work: object = None      # callable(work folder): makes more inputs
    files: dict = dataclasses.field(default_factory=dict)


SIM = ["simulate", "li2009-model-i", "--temperature", "35"]
MODEL = ["simulate", "{model}", "--duration", "0.05", "-o", "{out}"]
VALIDATE = ["validate", "li2009-model-i", "{data}", "--json", "{out}"]
IDENTIFY = ["identify", "{data}", "-q", "-o", "{out}"]

CASES = [
    # -- the output grid: every stored row counted, time within the core's limit
    Case("output size", "cycle starts count against the sample limit",
         [*SIM, "--input", "sawtooth:amplitude=30,frequency=1e6", "--duration", "100", "--sample-rate", "1",
          "-o", "{out}"], ["100000001 output samples", "period starts", "limit of 10000000"]),
    Case("output size", "cycle starts under a lowered limit",
         [*SIM, "--input", "sawtooth:amplitude=30,frequency=1e3", "--duration", "1", "--sample-rate", "10",
          "--max-samples", "500", "-o", "{out}"], ["1001 output samples", "period starts", "limit of 500"]),
    Case("output size", "duration 1e300 at 1e-300 Hz", [*SIM, "--duration", "1e300", "--sample-rate", "1e-300",
                                                       "-o", "{out}"], ["1e+300 s", "limit of 1e+12 s"]),
    Case("output size", "duration 1e13 at 1e-12 Hz", [*SIM, "--duration", "1e13", "--sample-rate", "1e-12",
                                                     "-o", "{out}"], ["1e+13 s", "limit of 1e+12 s"]),
    Case("output size", "1e300 Hz input", MODEL, ["period starts", "1e+300 Hz", "lower the input's frequency"],
         model=GOOD.replace("frequency = 5.0", "frequency = 1e300")),
    # -- values whose derived quantities overflow
    Case("extreme values", "wn = 1e200", MODEL, ["[plant]", "derived 'k' overflows", "wn = 1e+200"],
         model=GOOD.replace("wn = 6685.5", "wn = 1e200")),
    Case("extreme values", "masses of 1e308", MODEL, ["[plant]", "derived 'c' overflows", "m = 1e+308"],
         model=GOOD.replace("m = 0.05", "m = 1e308").replace("m_e = 0.02", "m_e = 1e308")),
    Case("extreme values", "exp law a = 1, b = 100", [*MODEL, "--temperature", "35"],
         ["[thermal] sigma0", "'exp' law gives inf at 35 C", "overflow"],
         model=NO_SIGMA0 + '\n[thermal]\nmodel = "I"\nsigma0 = { law = "exp", a = 1, b = 100 }\n'),
    Case("extreme values", "200-coefficient poly", [*MODEL, "--temperature", "35"],
         ["[thermal] fc", "200 coefficients", "more than 16"],
         model=NO_FC + '\n[thermal]\nmodel = "I"\nfc = { law = "poly", c = [' + ", ".join(["1.0"] * 200) + "] }\n"),
    Case("extreme values", "poly overflowing at the temperature", [*MODEL, "--temperature", "300"],
         ["[thermal] fc", "'poly' law gives inf at 300 C"],
         model=NO_FC + '\n[thermal]\nmodel = "I"\nfc = { law = "poly", c = [' + ", ".join(["1e300"] * 16) + "] }\n"),
    Case("extreme values", "one-point pwl", [*MODEL, "--temperature", "35"],
         ["[thermal] fc", "at least two points"],
         model=NO_FC + '\n[thermal]\nmodel = "I"\nfc = { law = "pwl", T = [30.0], values = [0.9] }\n'),
    Case("extreme values", "one-point table, Model II", [*MODEL, "--temperature", "35"],
         ["[thermal] dF", "at least two points"],
         model=GOOD + '\n[thermal]\nmodel = "II"\ndF = { law = "table", T = [30.0], values = [0.1] }\n'),
    # -- inputs that never end
    Case("endless inputs", "model file is /dev/zero", ["simulate", "/dev/zero", "-o", "{out}"],
         ["/dev/zero", "character device", "not a regular file"]),
    Case("endless inputs", "model file is a FIFO", ["simulate", "{work}/m.fifo", "-o", "{out}"],
         ["m.fifo", "FIFO", "not a regular file"], work=_fifo("m.fifo")),
    Case("endless inputs", "temperature file is /dev/zero",
         ["simulate", "li2009-model-i", "--temperature-file", "/dev/zero", "-o", "{out}"],
         ["/dev/zero", "character device"]),
    Case("endless inputs", "temperature file is a FIFO",
         ["simulate", "li2009-model-i", "--temperature-file", "{work}/T.fifo", "-o", "{out}"],
         ["T.fifo", "FIFO"], work=_fifo("T.fifo")),
    Case("endless inputs", "sampled input is /dev/zero", [*SIM, "--input", "sampled:file=/dev/zero", "-o", "{out}"],
         ["/dev/zero", "character device"]),
    Case("endless inputs", "sampled input in a model file is a FIFO", MODEL, ["u.fifo", "FIFO"],
         model=GOOD.split("[input]")[0] + '[input]\nwaveform = "sampled"\nfile = "u.fifo"\n', work=_fifo("u.fifo")),
    Case("endless inputs", "experiment CSV is a FIFO", VALIDATE, [FIT, "FIFO"], data=_fifo_in_data(FIT)),
    Case("endless inputs", "dataset.toml is a FIFO", VALIDATE, ["dataset.toml", "FIFO"],
         data=_fifo_in_data("dataset.toml")),
    Case("endless inputs", "experiment CSV links to /dev/zero", VALIDATE, [FIT, "inside the dataset folder"],
         data=lambda d: ((d / FIT).unlink(), (d / FIT).symlink_to("/dev/zero"))),
    # -- arguments
    Case("arguments", "identify --seed -5", [*IDENTIFY, "--seed", "-5"], ["--seed", "at least 0"]),
    Case("arguments", "identify --starts 100000000", [*IDENTIFY, "--starts", "100000000"],
         ["--starts", "at most 10000"]),
    Case("arguments", "identify --reference-temperature 1e300",
         [*IDENTIFY, "--method", "model-ii", "--reference-temperature", "1e300"],
         ["--reference-temperature", "not a plausible temperature"]),
    Case("arguments", "identify --reference-temperature without model-ii",
         [*IDENTIFY, "--reference-temperature", "35"], ["--reference-temperature", "model-ii only"]),
    Case("arguments", "identify --rtol 5", [*IDENTIFY, "--rtol", "5"], ["--rtol", "below 1"]),
    Case("arguments", "synth --seed -5", ["synth", "li2009-model-i", "--temperatures", "35", "--seed", "-5",
                                          "-o", "{out}"], ["seed", "0 or more"]),
    Case("arguments", "option value 1_0", [*SIM, "--duration", "1_0", "-o", "{out}"], ["--duration", "'1_0'"]),
    # -- quiet numerics
    Case("quiet numerics", "constant measured displacement", VALIDATE,
         [FIT, "span", "undefined (NaN)"], expect="run", data=_column(2, "5")),
    Case("quiet numerics", "data at 1e300", IDENTIFY, [FIT, "line 2", "column 3", "beyond the limit of 1e+100"],
         data=_column(2, "1e300")),
    Case("quiet numerics", "1_0 in a CSV", VALIDATE, [FIT, "line 5", "column 3", "not a number: '1_0'"],
         data=_csv_edit(lambda L: L[:4] + [L[4].rsplit(",", 1)[0] + ",1_0"] + L[5:])),
    Case("quiet numerics", "1_0 in a temperature file",
         ["simulate", "li2009-model-i", "--temperature-file", "{work}/T.csv", "-o", "{out}"],
         ["T.csv", "line 3", "'3_1'"], files={"T.csv": "time[s],temperature[C]\n0,31\n0.1,3_1\n"}),
    Case("quiet numerics", "time starting at 1e6 s", VALIDATE, [], expect="run", data=_shift_time),
    Case("quiet numerics", "time beyond 1e12 s", VALIDATE, [FIT, "beyond the limit of 1e+12 s"],
         data=lambda d: _shift_time(d, 1e13)),
    Case("quiet numerics", "temperature file not covering the run",
         ["simulate", "li2009-model-i", "--temperature-file", "{work}/T.csv", "--duration", "0.1", "-o", "{out}"],
         ["T.csv", "covers 5..6 s", "the run 0..0.1 s"], expect="run",
         files={"T.csv": "time[s],temperature[C]\n5,31\n6,32\n"}),
    Case("quiet numerics", "a 1 MB key", MODEL, ["unknown key", "characters)"],
         model=GOOD.replace("fc = 0.9", "fc = 0.9\n" + "k" * 1_000_000 + " = 1")),
    Case("quiet numerics", "a 100 kB waveform value", [*SIM, "--input", "sine:amplitude=" + "9" * 100_000 + "x",
                                                     "-o", "{out}"], ["amplitude", "characters)"]),
    Case("quiet numerics", "huge but finite bristle stiffness", [*MODEL, "--max-steps", "20000"],
         ["integration failed", "maximum number of steps"], status=1,
         model=GOOD.replace("sigma0 = 1.9e6", "sigma0 = 1e300")),
]


def _digest(folder: Path):
    """Every file under ``folder`` with a hash of its content (FIFOs by name only: reading one waits)."""
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_symlink() or not p.is_file():
            out[str(p.relative_to(folder))] = "special"
        else:
            out[str(p.relative_to(folder))] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


def run_case(case, dataset, work):
    """Runs one case; returns the outcome as a dict of the attack table's columns (and the output)."""
    import shutil

    data = work / "data"
    if case.data is not None or "{data}" in case.argv:
        shutil.copytree(dataset, data, symlinks=True)
    if case.data is not None:
        case.data(data)
    if case.model is not None:
        (work / "m.toml").write_text(case.model)
    for name, text in case.files.items():
        (work / name).write_text(text)
    if case.work is not None:
        case.work(work)
    out = {"simulate": "out.csv", "validate": "out.json", "identify": "out.toml"}.get(case.argv[0], "out.file")
    paths = {"data": data, "model": work / "m.toml", "work": work, "out": work / out}  # names the command writes
    before = _digest(work)
    try:
        out = _run([a.format(**paths) for a in case.argv], work)
    except subprocess.TimeoutExpired:
        return {"hang": True}
    after = _digest(work)
    return {"hang": False, "out": out, "crash": out.returncode < 0, "traceback": "Traceback" in out.stderr,
            "partial": paths["out"].exists() or set(after) - set(before),
            "destroyed": {k: v for k, v in before.items() if after.get(k) != v}}


@pytest.mark.parametrize("case", CASES, ids=[f"{c.cls}: {c.name}" for c in CASES])
def test_limit_case(case, dataset, tmp_path):
    r = run_case(case, dataset, tmp_path)
    assert not r["hang"], f"no answer within {TIMEOUT} s"
    out = r["out"]
    assert not r["crash"] and not r["traceback"], out.stderr
    assert not r["destroyed"], r["destroyed"]
    lines = out.stderr.splitlines()
    assert all(line.startswith(("thermofriction: error: ", "thermofriction: warning: ", "usage: ", " "))
               or re.match(r"thermofriction \w+: error: ", line) for line in lines), out.stderr
    assert all(len(line) < 2000 for line in lines), "a message echoes a long value whole"
    assert "encountered in" not in out.stderr, "a NumPy floating-point warning reached the user"
    if case.expect == "refuse":
        assert out.returncode == case.status, out.stderr
        errors = [line for line in lines if re.match(r"thermofriction( \w+)?: error: ", line)]
        assert len(errors) == 1, out.stderr
        for word in case.words:
            assert word in errors[0], f"{word!r} not in {errors[0]!r}"
        assert not r["partial"], "an output was written"
    else:
        assert out.returncode == 0, out.stderr
        warned = [line for line in lines if line.startswith("thermofriction: warning: ")]
        for word in case.words:
            assert any(word in w for w in warned), f"{word!r} not in the warnings {warned!r}"


def test_the_attack_table_matches_the_cases():
    """docs/hardening.md's "limits: ..." rows give, per class, the number of cases here and the clean
    refusals among them (the others run, correctly, with a warning where one is due); the last five
    columns are zero because test_limit_case fails on any hang, crash, traceback, partial file or
    changed input."""
    text = (Path(__file__).parent.parent / "docs" / "hardening.md").read_text()
    rows = {}
    for line in text.splitlines():
        m = re.match(r"\|\s*limits: ([^|]+?)\s*\|(.*)\|\s*$", line)
        if m:
            rows[m.group(1)] = [int(c) for c in re.findall(r"\d+", m.group(2))]
    expected = {}
    for c in CASES:
        n, refused = expected.get(c.cls, (0, 0))
        expected[c.cls] = (n + 1, refused + (c.expect == "refuse"))
    api = len(API_CASES)
    expected["Python API"] = (api, api)
    assert set(rows) == set(expected)
    for cls, (n, refused) in expected.items():
        assert rows[cls] == [n, refused, 0, 0, 0, 0, 0], cls


# -- the late start works: the same metrics as the record that starts at zero -----------------------

def test_a_record_starting_at_1e6_s_gives_the_metrics_of_one_starting_at_zero(dataset, tmp_path):
    import shutil

    shifted = tmp_path / "shifted"
    shutil.copytree(dataset, shifted)
    _shift_time(shifted)
    model = tf.load_model("li2009-model-i")
    a, b = tf.validate(model, tf.load_dataset(dataset)), tf.validate(model, tf.load_dataset(shifted))
    assert tf.load_dataset(shifted).experiments[0].time[0] == 0.0
    for x, y in zip(a.experiments, b.experiments):
        assert y["max_error_pct"] == pytest.approx(x["max_error_pct"], rel=1e-3)
        assert y["rmse_offset_removed"] == pytest.approx(x["rmse_offset_removed"], rel=1e-3)


def test_a_late_start_that_cannot_move_is_kept_and_explained(dataset, tmp_path):
    """A manifest input whose phase a shift would change (a 1e6 + 0.05 s start on a 5 Hz input) keeps
    the record's time; a failure there names the late start."""
    import shutil

    data = tmp_path / "d"
    shutil.copytree(dataset, data)
    _shift_time(data, 1e6 + 0.05)
    exp = tf.load_dataset(data).experiments[0]
    assert exp.time[0] == pytest.approx(1e6 + 0.05)


def test_the_step_underflow_message_names_a_late_start():
    from thermofriction import _bridge
    from thermofriction.simulation import _explain

    model = tf.load_model("li2009-model-i")
    e = _bridge.CoreFailure("the step size fell below the resolution of the time variable", "step_underflow", 1e6,
                            1e-10, np.zeros(5), False)
    msg = str(_explain(e, model, tf.Dopri5(), tf.StepSizeController(), model.input,
                       ("x_p", "v_p", "x_e", "v_e", "z")))
    assert "late start" in msg and "start the time at 0" in msg


# -- the sample limit in the Python API ------------------------------------------------------------

def test_sample_limit_counts_the_joined_rows(model_i):
    """A 1 kHz input on a 10 Hz grid over 1 s stores 11 + 990 rows: the limit sees all of them, and
    exactly that many pass."""
    inp = tf.Sawtooth(30, 1000, 0.99)
    with pytest.raises(tf.InputError, match="1001 output samples"):
        tf.simulate(model_i, 1.0, temperature=35, input=inp, sample_rate=10, max_samples=1000)
    res = tf.simulate(model_i, 1.0, temperature=35, input=inp, sample_rate=10, max_samples=1001)
    assert res.time.size == 11 and res.step_sizes.size == 1000


def test_many_cycle_starts_are_refused_before_they_are_allocated(model_i):
    import tracemalloc

    tracemalloc.start()
    with pytest.raises(tf.InputError, match="period starts"):
        tf.simulate(model_i, 100.0, temperature=35, input=tf.Sawtooth(30, 1e6, 0.99), sample_rate=1)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 50e6


# -- the Python API: the package's InputError, naming the argument ---------------------------------

def _save_to_tmp(model):
    model.save("/tmp")


API_CASES = {
    "simulate('path')": (lambda m: tf.simulate("li2009-model-i.toml", 0.1), "model must be a Model.*load_model"),
    "input='sawtooth:...'": (lambda m: tf.simulate(m, 0.1, temperature=35, input="sawtooth:amplitude=30,frequency=5"),
                             "input must be a Waveform.*parse_waveform"),
    "Model(None, None)": (lambda m: tf.Model(None, None), "'plant' must be"),
    "Model(plant, None)": (lambda m: tf.Model(m.plant, None), "'friction' must be"),
    "LuGre(sigma0='1e5')": (lambda m: tf.LuGre(sigma0="1e5", sigma1=1.0, fc=1.0), "'sigma0' must be a number"),
    "LuGre(fc=nan)": (lambda m: tf.LuGre(sigma0=1e5, sigma1=1.0, fc=math.nan), "'fc' must be finite"),
    "GMS(k=('a',))": (lambda m: tf.GMS(k=("a",), w=(1.0,), C=1.0, fc=1.0), r"'k\[0\]' must be a number"),
    "Exp(a='1')": (lambda m: tf.Exp("1", 0.1), "'a' must be a number"),
    "one-point PWL in a model": (lambda m: tf.Model(m.plant, tf.LuGre(sigma0=1e5, sigma1=1.0, fc=1.0),
                                                        tf.ModelII(tf.PWL([30.0], [0.1]))),
                                 "dF: law 'pwl' needs at least two points"),
    "Poly 200": (lambda m: tf.Poly([1.0] * 200), "200 coefficients"),
    "Sawtooth(amplitude='30')": (lambda m: tf.Sawtooth("30", 5), "'amplitude' must be a number"),
    "parse_waveform(5)": (lambda m: tf.parse_waveform(5), "spec must be a string"),
    "max_steps=1.5": (lambda m: tf.StepSizeController(max_steps=1.5), "max_steps must be a positive whole number"),
    "atol=nan": (lambda m: tf.StepSizeController(atol=math.nan), "atol must be a positive finite number"),
    "atol of the wrong length": (lambda m: tf.simulate(m, 0.01, temperature=35,
                                                       controller=tf.StepSizeController(atol=(1e-9, 1e-9))),
                                 "atol must be one number or one per state"),
    "first_step=inf": (lambda m: tf.StepSizeController(first_step=math.inf), "first_step must be"),
    "solver='fast'": (lambda m: tf.simulate(m, 0.01, temperature=35, solver="fast"), "unknown solver"),
    "solver=5": (lambda m: tf.simulate(m, 0.01, temperature=35, solver=5), "solver must be"),
    "max_samples=2.5": (lambda m: tf.simulate(m, 0.01, temperature=35, max_samples=2.5), "max_samples must be"),
    "duration='1'x": (lambda m: tf.simulate(m, "one", temperature=35), "duration must be a number"),
    "t_eval beyond 1e12 s": (lambda m: tf.simulate(m, temperature=35, t_eval=[0.0, 1e13]), "limit of 1e\\+12 s"),
    "model.save('/tmp')": (_save_to_tmp, "is a folder"),
    "identify seed=-5": (lambda m: tf.identify([object()], "base", seed=-5), "seed must be"),
    "identify starts=1e8": (lambda m: tf.identify([object()], "base", starts=100_000_000), "starts must be"),
    "identify reference_temperature=1e300": (lambda m: tf.identify([object()], "model-ii",
                                                                   reference_temperature=1e300),
                                             "reference_temperature must be"),
    "identify reference_temperature, model-i": (lambda m: tf.identify([object()], "model-i",
                                                                      reference_temperature=35.0),
                                                "model-ii' only"),
    "synthesize seed=-5": (lambda m: tf.synthesize(m, [35.0], duration=0.05, seed=-5), "seed must be"),
}


@pytest.mark.parametrize("name", list(API_CASES))
def test_public_functions_raise_the_package_error_naming_the_argument(name, model_i):
    call, pattern = API_CASES[name]
    with pytest.raises(tf.InputError, match=pattern):
        call(model_i)


def test_max_steps_accepts_whole_numbers_of_any_integer_type():
    assert tf.StepSizeController(max_steps=np.int64(20)).max_steps == 20
    assert tf.StepSizeController(atol=(1e-9,) * 5).atol == (1e-9,) * 5


# -- quiet numerics in the Python API -------------------------------------------------------------

def test_a_constant_measurement_gives_nan_percentages_and_a_warning(dataset, model_i):
    data = tf.load_dataset(dataset)
    exp = data.experiments[0]
    exp.displacement = np.full_like(exp.displacement, 5e-6)
    res = tf.validate(model_i, data)
    m = res.experiments[0]
    assert math.isnan(m["max_error_pct"]) and math.isnan(m["nrmse"]) and math.isnan(m["final_error_pct"])
    assert m["rmse_offset_removed"] > 0  # the absolute error is still defined
    assert any("undefined (NaN)" in w for w in res.warnings)
    # the summary of the others is not hidden by the NaN
    assert res.summary()["fit"]["max_error_pct"] == res.experiments[1]["max_error_pct"]


def test_a_temperature_signal_not_covering_the_run_warns(model_i):
    T = tf.Sampled(np.array([5.0, 6.0]), np.array([31.0, 32.0]))
    with pytest.warns(tf.TemperatureRangeWarning, match="covers 5..6 s, the run 0..0.1 s"):
        tf.simulate(model_i, 0.1, temperature=T, sample_rate=1000)
    with warnings.catch_warnings():
        warnings.simplefilter("error", tf.TemperatureRangeWarning)
        tf.simulate(model_i, 0.1, temperature=tf.Sampled(np.array([0.0, 0.1]), np.array([31.0, 32.0])),
                    sample_rate=1000)


def test_no_numpy_warning_for_extreme_but_finite_parameters():
    import tomllib

    from thermofriction.models import model_from_dict

    for edit in (("sigma0 = 1.9e6", "sigma0 = 1e300"), ("sigma1 = 2.3", "sigma1 = 1e300")):
        m = model_from_dict(tomllib.loads(GOOD.replace(*edit)))
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            warnings.simplefilter("ignore", tf.PassivityWarning)
            with pytest.raises(tf.SolverError):
                tf.simulate(m, 0.01, sample_rate=1000)


def test_strict_numbers():
    from thermofriction._reading import strict_float

    assert strict_float(" 1.5e3 ") == 1500.0
    for text in ("1_0", "1_000.5", "1e1_0"):
        with pytest.raises(ValueError):
            strict_float(text)


def test_long_values_are_shortened_in_messages():
    from thermofriction.errors import shorten, unknown_keys

    assert shorten("abc") == "'abc'"
    long = shorten("x" * 1_000_000)
    assert len(long) < 100 and "1000002 characters" in long
    msg = unknown_keys(["k" * 1_000_000], ["a", "b"])
    assert len(msg) < 200
    assert "and 3 more" in unknown_keys([f"k{i}" for i in range(8)], ["a"])


def test_cli_max_starts_is_identify_max_starts():
    from thermofriction import cli
    from thermofriction.identification import MAX_STARTS

    assert cli.MAX_STARTS == MAX_STARTS


def test_out_of_memory_advice_names_only_options_the_command_has(monkeypatch, capsys, tmp_path):
    """identify ran out of memory with advice about --duration and --sample-rate, which it lacks."""
    from thermofriction import cli

    def exhausted(args):
        raise MemoryError

    monkeypatch.setattr(cli, "cmd_identify", exhausted)
    monkeypatch.setattr(cli, "cmd_simulate", exhausted)
    assert cli.main(["identify", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert "out of memory" in err and "--starts" in err and "--duration" not in err
    assert cli.main(["simulate", "li2009-model-i"]) == 1
    assert "--duration" in capsys.readouterr().err
