"""Force (torque) experiment files (docs/force-data.md, docs/formats.md#force-experiment-files): units, the
motion that drives the model, irregular sampling, the messages for bad files, the rotary prescribed motion, and
the model's steady sliding against the analytic LuGre friction-velocity curve (an independent oracle)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import tomli_w

import thermofriction as tf
from thermofriction.data.force import ForceExperiment, SamplingWarning, motion_waveform, read_force_csv
from thermofriction.data.motion import SUBSTEPS
from thermofriction.errors import InputError
from thermofriction.models import PrescribedMotion
from thermofriction.models.plants import rotary_unit
from thermofriction.measurements import steady_state_curve

from conftest import run_cli


def _write(path, header, rows):
    path.write_text(header + "\n" + "\n".join(",".join(f"{v:.12g}" for v in r) for r in rows) + "\n")
    return path


def _sine_rows(n=50, rotary=True):
    t = np.linspace(0.0, 1.0, n)
    x = 0.2 * np.sin(2 * np.pi * t)
    v = 0.2 * 2 * np.pi * np.cos(2 * np.pi * t)
    F = 0.5 * np.tanh(v / 0.05)
    return t, x, v, F


def _dataset(folder, files, roles=None):
    entries = [{"file": f, "temperature": 30.0, "role": (roles or {}).get(f, "fit")} for f in files]
    (folder / "dataset.toml").write_text(tomli_w.dumps({"experiment": entries}))
    return folder


def test_units_convert_to_si(tmp_path):
    """deg, deg/s and mN*m are read as rad, rad/s and N m: the numbers written in those units come back in SI."""
    t, x, v, F = _sine_rows()
    p = _write(tmp_path / "a.csv", "time[ms],position[deg],velocity[deg/s],friction_torque[mN*m]",
               np.column_stack([t * 1e3, np.degrees(x), np.degrees(v), F * 1e3]))
    cols = read_force_csv(p)
    assert cols["rotary"] is True
    np.testing.assert_allclose(cols["time"], t, rtol=1e-11, atol=1e-15)
    np.testing.assert_allclose(cols["position"], x, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(cols["velocity"], v, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(cols["force"], F, rtol=1e-10, atol=1e-14)
    p = _write(tmp_path / "b.csv", "time[s],displacement[mm],friction_force[mN]",
               np.column_stack([t, x * 1e3, F * 1e3]))
    cols = read_force_csv(p)
    assert cols["rotary"] is False and "velocity" not in cols
    np.testing.assert_allclose(cols["position"], x, rtol=1e-10, atol=1e-14)


def test_the_drive_gives_the_model_each_samples_own_velocity():
    """The motion waveform's slope on both sides of every sample is that sample's velocity (no half-sample
    lag), and its position at the samples is the trapezoidal integral of the velocity (the waveform's velocity is
    linear between samples, in SUBSTEPS steps: tests/test_joint_coverage.py)."""
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.5e-3, 1.5e-3, 200))
    t -= t[0]
    v = np.sin(7 * t) + 0.3 * rng.normal(size=t.size)
    w = motion_waveform(t, v)
    eps = 0.25 * np.min(np.diff(t)) / SUBSTEPS  # inside the step around each sample, where the slope is constant
    inner = t[1:]  # the last sample too: the motion goes on half an interval beyond it
    right = (w(inner + eps) - w(inner)) / eps
    left = (w(inner) - w(inner - eps)) / eps
    np.testing.assert_allclose(right, v[1:], rtol=1e-5, atol=1e-6 * np.ptp(v))
    np.testing.assert_allclose(left, v[1:], rtol=1e-5, atol=1e-6 * np.ptp(v))
    trapezoid = np.concatenate([[0.0], np.cumsum(0.5 * np.diff(t) * (v[1:] + v[:-1]))])
    np.testing.assert_allclose(w(t), trapezoid, rtol=1e-12, atol=1e-12 * np.ptp(trapezoid))


def test_position_only_drives_by_its_gradient(tmp_path):
    """Without a velocity column the velocity is the position's second-order gradient: exact for a parabola,
    on irregular samples too."""
    rng = np.random.default_rng(0)
    t = np.sort(rng.uniform(0, 1, 40))
    t[0] = 0.0
    x = 0.3 * t ** 2 - 0.1 * t
    _write(tmp_path / "p.csv", "time[s],position[m],friction_force[N]",
           np.column_stack([t, x, 1.0 + 0.1 * t]))  # (a force that varies: a constant one is refused)
    data = tf.load_dataset(_dataset(tmp_path, ["p.csv"]))
    exp = data.experiments[0]
    assert isinstance(exp, ForceExperiment) and exp.velocity is None
    inner = slice(1, -1)  # the end samples are one-sided (first order)
    np.testing.assert_allclose(exp.drive_velocity[inner], (0.6 * t - 0.1)[inner], rtol=1e-6, atol=1e-12)


def test_irregular_sampling_is_accepted_and_a_gap_is_warned(tmp_path):
    t = np.linspace(0.0, 1.0, 60)
    t = t + np.random.default_rng(1).uniform(-0.3, 0.3, t.size) * (t[1] - t[0])
    t[0] = 0.0
    t[40:] += 0.5  # a gap of ~30 intervals between rows 40 and 41 (lines 41 and 42)
    x, v = 0.2 * t ** 2, 0.4 * t
    F = 0.5 * np.tanh(v / 0.05)
    p = _write(tmp_path / "g.csv", "time[s],position[rad],velocity[rad/s],friction_torque[N*m]",
               np.column_stack([t, x, v, F]))
    with pytest.warns(SamplingWarning, match=r"g.csv: line 42: a gap of 0.5\d* s"):
        cols = read_force_csv(p)
    assert len(cols["time"]) == 60


@pytest.mark.parametrize("header, rows, message", [
    ("time[s],friction_force[N]", None, r"line 1: a force experiment needs the motion: a position"),
    ("time[s],position[rad],friction_force[N]", None, r"mixed linear \(friction_force\[N\]\) and rotary "
                                                      r"\(position\[rad\]\) units"),
    ("time[s],position[m],velocity[rad/s],friction_force[N]", None, r"mixed linear .* and rotary \(velocity"),
    ("time[s],position[m],friction_torque[N*m]", None, r"mixed linear \(position\[m\]\) and rotary"),
    ("time[s],position[rad],velocity[rad/s]", None, r"no friction_force\[N\] or friction_torque\[N\*m\] column"),
    ("time[s],voltage[V],position[m],friction_force[N]", None, r"column 2: unknown column 'voltage' .* own"),
    ("time[s],position[furlong],friction_force[N]", None, r"column 2 \('position\[furlong\]'\): unknown unit"),
    ("time[s],position[m],friction_force[N]", "backwards", r"line 7, column 1 \(time\[s\]\): time must increase"),
    ("time[s],position[m],friction_force[N]", "nan", r"line 5, column 3 \(friction_force\[N\]\): not a finite"),
])
def test_bad_files_get_one_clear_message(tmp_path, header, rows, message):
    t, x, v, F = _sine_rows(20)
    data = np.column_stack([t, x, F] if header.count(",") == 2 else [t, x, v, F])
    text = header + "\n" + "\n".join(",".join(f"{c:.9g}" for c in r) for r in data) + "\n"
    lines = text.split("\n")
    if rows == "backwards":
        lines[6] = "0.0" + lines[6][lines[6].index(","):]
    if rows == "nan":
        cells = lines[4].split(",")
        cells[2] = "nan"
        lines[4] = ",".join(cells)
    p = tmp_path / "bad.csv"
    p.write_text("\n".join(lines))
    with pytest.raises(InputError, match=message) as e:
        read_force_csv(p)
    assert str(p) in str(e.value)


def test_a_velocity_in_the_wrong_unit_is_an_error(tmp_path):
    """The position checks the velocity: deg/s written as rad/s (57 times too fast) is refused at loading,
    naming the scale; a velocity 20 % off is warned about (motion "auto" then drives by the position);
    motion = "position" ignores the column, whatever its unit."""
    from thermofriction.data.force import MotionWarning
    t, x, v, F = _sine_rows(200)
    _write(tmp_path / "u.csv", "time[s],position[rad],velocity[rad/s],friction_torque[N*m]",
           np.column_stack([t, x, np.degrees(v), F]))
    _dataset(tmp_path, ["u.csv"])
    with pytest.raises(InputError, match=r"u.csv: the velocity column velocity\[rad/s\], integrated over time, "
                                         r"departs from the position column position\[rad\] by .*57.\d+ times "
                                         r"the position's derivative.*check the units"):
        tf.load_dataset(tmp_path)
    exp = tf.load_dataset(tmp_path, motion="position").experiments[0]
    assert exp.motion_source == "position"
    _write(tmp_path / "u.csv", "time[s],position[rad],velocity[rad/s],friction_torque[N*m]",
           np.column_stack([t, x, 1.2 * v, F]))
    with pytest.warns(MotionWarning, match=r"u.csv: the velocity column velocity\[rad/s\] is not the position's "
                                           r"derivative: its scale is 1.2\d* times.*the position drives the model"):
        exp = tf.load_dataset(tmp_path).experiments[0]
    assert exp.motion_source == "position"


def test_datasets_do_not_mix_kinds_or_units(tmp_path):
    t, x, v, F = _sine_rows(20)
    _write(tmp_path / "r.csv", "time[s],position[rad],friction_torque[N*m]", np.column_stack([t, x, F]))
    _write(tmp_path / "l.csv", "time[s],position[m],friction_force[N]", np.column_stack([t, x, F]))
    _write(tmp_path / "a.csv", "time[s],voltage[V],displacement[m]", np.column_stack([t, 10 * t, 1e-6 * t]))
    with pytest.raises(InputError, match=r"dataset.toml: the dataset mixes rotary \(r.csv\) and linear \(l.csv\)"):
        tf.load_dataset(_dataset(tmp_path, ["r.csv", "l.csv"]))
    with pytest.raises(InputError, match="mixes force .* with actuator"):
        tf.load_dataset(_dataset(tmp_path, ["r.csv", "a.csv"]))


def test_cli_bad_force_file_exits_2_without_traceback(tmp_path):
    t, x, v, F = _sine_rows(20)
    _write(tmp_path / "f.csv", "time[s],friction_torque[N*m]", np.column_stack([t, F]))
    _dataset(tmp_path, ["f.csv"])
    r = run_cli("identify", tmp_path, "--method", "base", "-q")
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr
    assert "f.csv: line 1: a force experiment needs the motion" in r.stderr


def test_rotary_units_are_the_linear_ones_read_in_angles():
    assert rotary_unit("N/m") == "N m/rad"
    assert rotary_unit("N s/m") == "N m s/rad"
    assert rotary_unit("N") == "N m"
    assert rotary_unit("m/s") == "rad/s"
    assert rotary_unit("m") == "rad"
    assert rotary_unit("N/s") == "N m/s"
    assert rotary_unit("N/m/C") == "N m/rad/C"
    assert rotary_unit("1/C") == "1/C"


def test_rotary_prescribed_motion_round_trips_through_a_model_file(tmp_path):
    m = tf.Model(PrescribedMotion(motion="rotary", sensor_offset=0.012), tf.LuGre(sigma0=1e3, sigma1=0.1, fc=0.8))
    m.save(tmp_path / "joint.toml")
    text = (tmp_path / "joint.toml").read_text()
    assert 'motion = "rotary"' in text and "sensor_offset = 0.012" in text
    back = tf.load_model(tmp_path / "joint.toml")
    assert back.plant.rotary and back.plant.sensor_offset == 0.012
    (tmp_path / "bad.toml").write_text('[plant]\ntype = "prescribed"\nmotion = "spiral"\n[friction]\nmodel = '
                                       '"coulomb"\nfc = 1.0\n')
    with pytest.raises(InputError, match=r"bad.toml: \[plant\]: 'motion' must be \"linear\" or \"rotary\""):
        tf.load_model(tmp_path / "bad.toml")


@pytest.mark.parametrize("rotary", [False, True])
def test_steady_sliding_matches_the_analytic_lugre_curve(rotary):
    """Independent oracle: LuGre in steady sliding is F_ss(v) = (fc + (fs - fc) exp(-(v/vs)^2)) sgn(v) + sigma2 v,
    whatever the units are called. The simulated curve agrees to the solver's tolerance (1e-6 of fs)."""
    p = dict(sigma0=2.5e3, sigma1=0.2, sigma2=0.4, fc=0.7, fs=1.1, vs=0.25)
    m = tf.Model(PrescribedMotion(motion="rotary" if rotary else "linear"), tf.LuGre(**p))
    v = np.array([-1.5, -0.3, -0.02, 0.004, 0.1, 0.25, 0.7, 2.0])
    analytic = (p["fc"] + (p["fs"] - p["fc"]) * np.exp(-(v / p["vs"]) ** 2)) * np.sign(v) + p["sigma2"] * v
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        simulated = steady_state_curve(m, v)
    np.testing.assert_allclose(simulated, analytic, rtol=0, atol=1e-6 * p["fs"])
    assert math.isclose(steady_state_curve(m, [0.0])[0], 0.0)


@pytest.mark.parametrize("rotary", [False, True])
def test_save_dataset_writes_force_experiments_that_load_back_exactly(tmp_path, rotary):
    """A force dataset read from files in mm, deg and mN (converted to SI), saved by save_dataset and loaded
    again: the same experiments to the last bit, in SI columns with their units in the headers, and no
    'input' in the manifest (a force run's motion is its record)."""
    t, x, v, F = _sine_rows(rotary=rotary)
    header = ("time[ms],position[deg],velocity[deg/s],friction_torque[mN*m]" if rotary
              else "time[ms],position[mm],velocity[mm/s],friction_force[mN]")
    scale = np.degrees(1.0) if rotary else 1e3
    (tmp_path / "in").mkdir()
    _write(tmp_path / "in" / "r.csv", header, np.column_stack([t * 1e3, x * scale, v * scale, F * 1e3]))
    _dataset(tmp_path / "in", ["r.csv"])
    data = tf.load_dataset(tmp_path / "in")
    tf.save_dataset(data, tmp_path / "out")
    again = tf.load_dataset(tmp_path / "out")
    a, b = data.experiments[0], again.experiments[0]
    for name in ("time", "displacement", "velocity", "force"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert b.rotary is rotary
    head = (tmp_path / "out" / "r.csv").read_text().splitlines()[0]
    assert head == ("time[s],position[rad],velocity[rad/s],friction_torque[N*m]" if rotary
                    else "time[s],position[m],velocity[m/s],friction_force[N]")
    assert "input" not in (tmp_path / "out" / "dataset.toml").read_text()
