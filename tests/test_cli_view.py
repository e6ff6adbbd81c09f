"""What the terminal shows: validate's table (units, whole names at 80 columns, as in a pipe or a
CI log) and identify --procedure both (what the paper's procedure did, not "0 points, nan nm")."""

import os
import re
import subprocess
import sys

import pytest

from conftest import run_cli

LONG = "stage-B_run-0042_recorded-2024-05-17_ambient-33.5C.csv"


@pytest.fixture(scope="module")
def model_ii_data(tmp_path_factory):
    folder = tmp_path_factory.mktemp("view") / "d"
    r = run_cli("synth", "li2009-model-ii", "--temperatures", "31,35,38,41", "--validate", "33.5", "--duration", "0.2",
                "--sample-rate", "2000", "--seed", "5", "-o", folder)
    assert r.returncode == 0, r.stderr
    # one run under a long name, as lab files are named
    text = (folder / "dataset.toml").read_text()
    (folder / "T33.5C-validate.csv").rename(folder / LONG)
    (folder / "dataset.toml").write_text(text.replace("T33.5C-validate.csv", LONG))
    return folder


def test_validate_table_shows_units_and_whole_names_at_80_columns(model_ii_data):
    env = {**os.environ, "COLUMNS": "80"}
    r = subprocess.run([sys.executable, "-m", "thermofriction", "validate", "li2009-model-ii", model_ii_data],
                       capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stderr
    out = r.stdout
    assert LONG in out  # not cut to "stage-B_ru…"
    assert "…" not in out
    header = next(line for line in out.splitlines() if "file" in line and "role" in line)
    for col in ("T [C]", "max error [%]", "RMSE [nm]", "NRMSE", "final error [%]", "step error [%]"):
        assert col in header, (col, header)  # each header whole, on one line, with its unit
    assert "offset removed" in out and "docs/formats.md#validation-metrics" in out
    # a row per experiment
    assert len([line for line in out.splitlines() if re.search(r"\.csv\s", line)]) == 5


def test_identify_both_procedures_says_what_the_paper_procedure_did(model_ii_data, tmp_path):
    r = run_cli("identify", model_ii_data, "--method", "model-ii", "--procedure", "both", "--starts", "1")
    assert r.returncode == 0, r.stderr
    out = r.stdout
    assert "nan nm" not in out and not re.search(r"data points\s*=\s*0\b", out)
    paper = out[out.index("[[Fit: model-ii (paper)]]"):]
    for words in ("reference temperature 31 C", "breakpoint", "slope", "um/N", "dF(T) read through that line",
                  "no trajectory fit", "validate"):
        assert words in paper, (words, paper)
    # the direct fit above it still reports its points and RMSE
    direct = out[:out.index("[[Fit: model-ii (paper)]]")]
    assert re.search(r"data points\s*=\s*[1-9]\d*", direct) and re.search(r"rmse\s*=\s*[\d.]+ nm", direct)


def test_identify_in_a_pipe_prints_a_line_per_stage_and_quiet_prints_none(model_ii_data):
    """stderr is a pipe here, as in a CI log: the stages say what they do in plain lines (not nothing, and not a
    terminal status line's control codes) -- at most one per interval (issue 41: 5 s by default, so quick work says
    nothing; 0.05 s here); --quiet silences it."""
    env = dict(os.environ, THERMOFRICTION_PROGRESS_INTERVAL="0.05")
    r = subprocess.run([sys.executable, "-m", "thermofriction", "identify", str(model_ii_data), "--method",
                        "model-i", "--starts", "1"], capture_output=True, text=True, timeout=300, env=env)
    assert r.returncode == 0, r.stderr
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) >= 3, r.stderr
    assert "\x1b[" not in r.stderr
    assert any("31" in line for line in lines)  # a per-temperature stage names its temperature
    q = subprocess.run([sys.executable, "-m", "thermofriction", "identify", str(model_ii_data), "--method",
                        "model-i", "--starts", "1", "--quiet"], capture_output=True, text=True, timeout=300, env=env)
    assert q.returncode == 0 and q.stderr.strip() == "", q.stderr
