"""Hardening IV (issue 41): identify on a drive's command data (docs/force-data.md#drives-without-a-torque-sensor).

A fit that cannot stand is a failure, not a success with a model ``validate`` refuses: a command misaligned with
the motion by more than the delay search covers (exit 1), a fitted inertia that is not positive (exit 1), a
record at rest (a data error, exit 2, before the fit); nothing is written on failure, and every model file
``identify`` writes is one ``validate`` accepts. The truth is test_identify_command's (a joint of J = 0.012 kg m^2
with LuGre friction under two summed sines, integrated by SciPy, independently of the package).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import tomli_w

sys.path.insert(0, str(Path(__file__).resolve().parent))

from conftest import run_cli  # noqa: E402
from test_identify_command import DT, J_TRUE, NOISE, OFFSET, _lugre_run, make_command_dataset, motion  # noqa: E402

import thermofriction as tf  # noqa: E402
from thermofriction.errors import ComputationError, InputError  # noqa: E402

INIT = f"""[plant]
type = "prescribed"
motion = "rotary"
inertia = {J_TRUE}

[friction]
model = "lugre"
sigma0 = 60.0
sigma1 = 0.04
fc = 0.2
fs = 0.28
vs = 0.3
sigma2 = 0.02
"""


def write_run(folder, x, v, u):
    """A one-run command dataset from its position, velocity (None: no column) and command columns."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    t = DT * np.arange(len(u))
    columns, header = ([t, x, u], "time[s],position[rad],command_torque[N*m]") if v is None else \
        ([t, x, v, u], "time[s],position[rad],velocity[rad/s],command_torque[N*m]")
    np.savetxt(folder / "run0.csv", np.column_stack(columns), delimiter=",", comments="", fmt="%.12g", header=header)
    (folder / "dataset.toml").write_text(tomli_w.dumps({"name": "drive", "experiment": [
        {"file": "run0.csv", "temperature": 25.0}]}))
    return folder


def wrong_sign_inertia(folder):
    """The command of the test joint with its inertia term negated (-J a): no moving part does this."""
    t = np.arange(0.0, 4.0, DT)
    x, v, a = motion(t)
    u = -J_TRUE * a + _lugre_run(0.0, 4.0, 0) + OFFSET + np.random.default_rng(1).normal(0.0, NOISE, t.size)
    return write_run(folder, x, v, u)


def at_rest(folder):
    """A drive that never moved: position and velocity 0, the command its offset and noise."""
    n = 2000
    u = OFFSET + np.random.default_rng(2).normal(0.0, NOISE, n)
    return write_run(folder, np.zeros(n), np.zeros(n), u)


def dither(folder):
    """A drive at rest whose encoder's last count flickers (1 urad either way): no motion, only quantisation."""
    n = 4000
    rng = np.random.default_rng(3)
    return write_run(folder, 1e-6 * rng.integers(-1, 2, n), None, OFFSET + rng.normal(0.0, NOISE, n))


def late(folder):
    """The test joint's command recorded 0.5 s late: ten times the automatic delay search's range (half the
    motion's time scale rms(v)/rms(a), about 50 ms)."""
    make_command_dataset(folder, delay=0.5)
    return Path(folder)


def delayed(folder):
    """The test joint's command 8 ms late: a fit that stands."""
    make_command_dataset(folder, delay=0.008)
    return Path(folder)


def assert_refused(r, status, *phrases):
    """One clear message on stderr, the exit status, no traceback."""
    assert r.returncode == status, (r.returncode, r.stderr)
    assert "Traceback" not in r.stderr and "Traceback" not in r.stdout, r.stderr
    errors = [line for line in r.stderr.splitlines() if line.startswith("thermofriction: error:")]
    assert len(errors) == 1, r.stderr
    for phrase in phrases:
        assert phrase in errors[0], errors[0]


# each failing record: (its maker, the initial model or None, the exit status, what the message says, the API's error)
FAILURES = {
    "late": (late, None, 1, ("misaligned in time", "--delay MIN:MAX"), ComputationError),
    "wrong-sign-inertia": (wrong_sign_inertia, None, 1, ("inertia is not positive", "kg m^2"), ComputationError),
    "at-rest-full-init": (at_rest, INIT, 2, ("run0.csv", "does not move"), InputError),
    "at-rest-no-init": (at_rest, None, 2, ("run0.csv", "does not move"), InputError),
    "dither-at-rest": (dither, None, 2, ("run0.csv", "does not move", "within 2 steps of its resolution"), InputError),
}


@pytest.mark.parametrize("case", list(FAILURES))
def test_failed_command_fit_exits_cleanly_and_writes_nothing(tmp_path, case):
    """The command line: exit 1 (a fit that cannot stand) or 2 (a record at rest), one message, no output written
    and an existing output left as it was."""
    make, init, status, phrases, _ = FAILURES[case]
    data = make(tmp_path / "data")
    args = ["identify", data, "--method", "base", "--starts", "1", "-o", tmp_path / "fit.toml",
            "--json", tmp_path / "fit.json"]
    if init:
        (tmp_path / "init.toml").write_text(init)
        args += ["--init", tmp_path / "init.toml"]
    (tmp_path / "fit.json").write_text("kept")
    assert_refused(run_cli(*args), status, *phrases)
    assert not (tmp_path / "fit.toml").exists()
    assert (tmp_path / "fit.json").read_text() == "kept"


@pytest.mark.parametrize("case", list(FAILURES))
def test_failed_command_fit_raises_in_the_api(tmp_path, case):
    """tf.identify: the same outcome as an exception, InputError for the data, ComputationError for the fit."""
    make, init, _, phrases, error = FAILURES[case]
    data = tf.load_dataset(make(tmp_path / "data"))
    if init:
        (tmp_path / "init.toml").write_text(init)
        init = str(tmp_path / "init.toml")
    with pytest.raises(error) as raised:
        tf.identify(data, method="base", starts=1, init=init)
    assert type(raised.value) is error  # not an InputError for a failed fit, nor the reverse
    for phrase in phrases:
        assert phrase in str(raised.value)


@pytest.mark.parametrize("case", ["delayed-8ms", "late", "wrong-sign-inertia", "dither-at-rest"])
def test_every_model_identify_writes_is_one_validate_accepts(tmp_path, case):
    """The round trip: where identify exits 0, validate accepts the model file it wrote (exit 0) and predicts the
    command at the noise; where it fails, there is no file (before issue 41, the wrong-sign inertia wrote a model
    with no inertia, which validate refused)."""
    data = (delayed if case == "delayed-8ms" else FAILURES[case][0])(tmp_path / "data")
    fit = tmp_path / "fit.toml"
    r = run_cli("identify", data, "--method", "base", "--starts", "1", "-o", fit)
    if r.returncode != 0:
        assert r.returncode in (1, 2) and not fit.exists(), r.stderr
        return
    assert case == "delayed-8ms", r.stdout  # the bad records must not get here
    v = run_cli("validate", fit, data, "--json", tmp_path / "v.json")
    assert v.returncode == 0, v.stderr
    model = tf.load_model(fit)
    assert model.plant.inertia == pytest.approx(J_TRUE, rel=0.05) and model.plant.delay == pytest.approx(0.008, abs=DT)
    assert tf.validate(model, tf.load_dataset(data)).predictions[0].rmse < 1.3 * NOISE


def test_delay_search_grid_and_its_bound():
    """The scan's grid (one formula for the scan before the fit and the search in it) and the check at its end: the
    half the motion's time scale rms(v)/rms(a) either way at 1 ms, a quarter of a short record; a delay at the end
    is refused, one within is not."""
    from thermofriction.measurements.delay import AUTO, check_not_at_end, search_range

    t = np.arange(0.0, 4.0, DT)
    w = 2 * np.pi * 1.0  # a 1 Hz sine: rms(v)/rms(a) = 1/w = 159 ms
    dt, ks, why = search_range(AUTO, [t], [np.cos(w * t)], [-w * np.sin(w * t)])
    assert dt == pytest.approx(DT) and ks[-1] == 80 and ks[0] == -80 and "time scale" in why
    dt, ks, why = search_range(AUTO, [t[:100]], [np.cos(w * t[:100])], [-w * np.sin(w * t[:100])])
    assert ks[-1] == 25 and "quarter of the shortest record" in why
    check_not_at_end(AUTO, 1, np.arange(-50, 51), DT, "")  # within: an estimate
    check_not_at_end(AUTO, 99, np.arange(-50, 51), DT, "")
    for i in (0, 100):
        with pytest.raises(ComputationError, match="misaligned in time by 50 ms or more"):
            check_not_at_end(AUTO, i, np.arange(-50, 51), DT, "")
