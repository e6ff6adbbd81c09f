"""The command line as a user meets it: help, outputs, and one clear message per bad input
with the right exit status and no file written."""

import numpy as np
import pytest

from conftest import run_cli


def test_help_lists_every_simulate_option():
    out = run_cli("simulate", "--help")
    assert out.returncode == 0
    for opt in ("--temperature", "--temperature-file", "--input", "--duration", "--sample-rate", "-o",
                "--solver", "--rtol", "--atol", "--max-steps", "li2009-model-i", "sawtooth:amplitude"):
        assert opt in out.stdout


def test_simulate_writes_the_spec7_csv(tmp_path):
    out = run_cli("simulate", "li2009-model-i", "--temperature", "35.7", "--duration", "0.4",
                  "--sample-rate", "1000", "-o", tmp_path / "run.csv")
    assert out.returncode == 0, out.stderr
    assert "step per cycle" in out.stdout
    lines = (tmp_path / "run.csv").read_text().splitlines()
    assert lines[0] == ("time[s],input[V],stage_displacement[m],displacement[m],velocity[m/s],friction_force[N],"
                        "temperature[C],z[m]")
    data = np.loadtxt(tmp_path / "run.csv", delimiter=",", skiprows=1)
    assert data.shape == (401, 8)
    assert np.allclose(data[:, 6], 35.7) and data[-1, 3] > 0


def test_temperature_file_and_input_override(tmp_path):
    (tmp_path / "T.csv").write_text("time[s],temperature[C]\n0,31\n0.4,40\n")
    out = run_cli("simulate", "li2009-model-ii", "--temperature-file", tmp_path / "T.csv", "--input",
                  "sawtooth:amplitude=30,frequency=10,rise=0.999", "--duration", "0.4", "--sample-rate", "500",
                  "-o", tmp_path / "o.csv")
    assert out.returncode == 0, out.stderr
    data = np.loadtxt(tmp_path / "o.csv", delimiter=",", skiprows=1)
    assert data[0, 6] == 31 and data[-1, 6] == 40
    assert data[25, 1] == pytest.approx(30 * 0.05 * 10 / 0.999)  # the override's ramp, half-way up


GOOD = """[plant]
type = "stick-slip"
xi = 0.2488
wn = 6685.5
K = 0.096e-6
m = 0.05
m_e = 0.05

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

# (name, model text or None for the preset, extra args, exit status, words the message must contain)
CASES = [
    ("missing file", None, ["simulate", "nowhere.toml"], 2, "nowhere.toml: no such file"),
    ("unknown key", GOOD.replace("fc = 0.9", "fc = 0.9\nmu = 0.3"), [], 2, "mu"),
    ("negative mass", GOOD.replace("m = 0.05", "m = -1"), [], 2, "'m' must be positive"),
    ("number and law", GOOD + '\n[thermal]\nmodel = "I"\nfc = { law = "const", value = 1.0 }\n', [], 2,
     "both as a number"),
    ("TOML syntax error", GOOD.replace("[friction]", "[friction"), [], 2, "TOML syntax error"),
    ("bad waveform spec", GOOD, ["--input", "sawtooth:amplitude=30,frequency=-5"], 2, "'frequency' must be positive"),
    ("unknown waveform", GOOD, ["--input", "triangle:amplitude=1"], 2, "unknown waveform 'triangle'"),
    ("malformed spec", GOOD, ["--input", "sine:amplitude"], 2, "expected key=value"),
    ("lambda <= 0", None, ["simulate", "li2009-model-ii", "--temperature", "46"], 2, "lambda"),
    ("no temperature", None, ["simulate", "li2009-model-i"], 2, "give a temperature"),
    ("bad duration", GOOD, ["--duration", "-1"], 2, "--duration"),
    ("solver failure", GOOD, ["--max-steps", "20"], 1, "integration failed at t ="),
]


@pytest.mark.parametrize("text,args,status,words", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input_gets_one_clear_message_and_no_output(text, args, status, words, tmp_path):
    out_file = tmp_path / "out.csv"
    if text is not None:
        (tmp_path / "m.toml").write_text(text)
        argv = ["simulate", tmp_path / "m.toml", *args, "-o", out_file]
    else:
        argv = [*args, "-o", out_file]
    out = run_cli(*argv, cwd=tmp_path)
    assert out.returncode == status, out.stderr
    assert words in out.stderr
    assert "Traceback" not in out.stderr
    errors = [line for line in out.stderr.splitlines() if "error" in line]
    assert len(errors) == 1, out.stderr
    assert not out_file.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out.csv")]


def test_bad_temperature_file_names_file_line_and_column(tmp_path):
    (tmp_path / "T.csv").write_text("time[s],temperature[C]\n0,31\n0.1,abc\n")
    out = run_cli("simulate", "li2009-model-i", "--temperature-file", tmp_path / "T.csv", "-o", tmp_path / "o.csv")
    assert out.returncode == 2
    assert "T.csv: line 3, column 'temperature[C]'" in out.stderr
    assert not (tmp_path / "o.csv").exists()
