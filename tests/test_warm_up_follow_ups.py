"""Issue 45's warm-up follow-ups: validation refuses warm-up records (no contact temperature to score a model at),
by name, exit 2 and no output (docs/self-heating.md#warm-up-without-a-contact-temperature)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import thermofriction as tf

from warmup_truth import Truth, initial_model

HEADER = "time[s],position[rad],velocity[rad/s],friction_torque[N*m]"


def _dataset(folder, warm=True):
    """A force dataset of one run: a warm-up record (an ambient column, no contact temperature) or, with
    ``warm=False``, the same run at a known contact temperature."""
    folder.mkdir(parents=True, exist_ok=True)
    t = np.arange(0.0, 20.0, 0.05)
    v = np.sin(t)
    cols = [t, 1 - np.cos(t), v, 0.8 * np.tanh(v / 1e-2) + 0.1 * v]
    header = HEADER
    if warm:
        cols.append(np.full(t.size, 25.0))
        header += ",ambient_temperature[C]"
    np.savetxt(folder / "w.csv", np.column_stack(cols), delimiter=",", comments="", header=header)
    folder.joinpath("dataset.toml").write_text('[[experiment]]\nfile = "w.csv"\n' +
                                               ("" if warm else "temperature = 30.0\n"))
    return folder


def test_validate_refuses_a_warm_up_record_by_name(tmp_path):
    """A warm-up record's temperature is the ambient's mean only as a label: scoring a model there would be a
    silently wrong number, so validate raises InputError naming the file; the same run with a contact
    temperature is scored (the refusal is the record's, not the model's)."""
    model = initial_model(Truth())
    data = tf.load_dataset(_dataset(tmp_path / "warm"))
    with pytest.raises(tf.InputError, match=r"^w\.csv: a warm-up record .* cannot be scored"):
        tf.validate(model, data)
    v = tf.validate(model, tf.load_dataset(_dataset(tmp_path / "soak", warm=False)))
    assert len(v.predictions) == 1 and v.predictions[0].temperature == pytest.approx(30.0)


@pytest.mark.parametrize("command", ["validate", "report"])
def test_the_command_line_refuses_a_warm_up_record_with_exit_2_and_writes_nothing(tmp_path, command):
    """``thermofriction validate`` and ``report`` on a warm-up record: exit 2, one line naming the file, no
    traceback, no output file."""
    data = _dataset(tmp_path / "data")
    initial_model(Truth()).save(tmp_path / "m.toml")
    out = tmp_path / ("metrics.json" if command == "validate" else "report.html")
    args = [str(tmp_path / "m.toml"), str(data)] + (["--json", str(out)] if command == "validate" else
                                                    ["-o", str(out)])
    run = subprocess.run([sys.executable, "-m", "thermofriction", command, *args], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 2, run.stderr
    assert "w.csv: a warm-up record" in run.stderr and "Traceback" not in run.stderr
    assert not out.exists()
