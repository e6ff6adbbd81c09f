"""A drive's delay, honestly (issue 40 item 6; docs/force-data.md#drives-without-a-torque-sensor): ``delay=`` /
``--delay auto|none|VALUE|MIN:MAX``, the automatic range read off the data and said, an estimate at a range's end
refused with the range and how to widen it, and a fit on an independent truth.

The truth (made here with SciPy's solve_ivp, not the package's simulation): a rotary joint J = 0.01 kg m^2 with
LuGre friction (sigma0 = 60 N m/rad, sigma1 = 0.04 N m s/rad, fc = 0.2 N m, fs = 0.28 N m, vs = 0.3 rad/s,
sigma2 = 0.02 N m s/rad) in a position loop (feedforward and PD) following two summed sines. A digital drive
computes its torque command u_k at t_k = k ms (1 kHz), logs it at t_k, and realises it 5 ms later, held for one
sample (zero-order hold): the torque on [t_k + 5 ms, t_k + 6 ms) is u_k. The log carries independent noise
(4 mN m: a current measurement's noise; the realised torque carries none) and an offset of 0.03 N m. The loop
runs 1 s before the log starts (the record begins mid-motion). Position and velocity are sampled at t_k.

The command is the mean of J a + F over its hold interval, J (v(t_k+6ms) - v(t_k+5ms))/dt + mean F (the momentum
integrated over it; this test checks that relation to 1e-3 of the command's range), and that is what the
measurement compares it with (measurements/command.py): the delay it finds is the transport delay, 5 ms. (Before it
took the mean it compared point samples of J a + F, which a held command matches half a sample later on average:
it found 5.5 ms, and sigma1 biased, below.)"""

from __future__ import annotations

import functools
import math
import sys
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))

from conftest import run_cli  # noqa: E402
from test_identify_command import make_command_dataset  # noqa: E402

import thermofriction as tf  # noqa: E402
from thermofriction.errors import ComputationError, InputError  # noqa: E402
from thermofriction.measurements.delay import DelaySpec, parse_delay  # noqa: E402

J = 0.01
LUGRE = dict(sigma0=60.0, sigma1=0.04, fc=0.2, fs=0.28, vs=0.3, sigma2=0.02)
DT, HOLD_DELAY, NOISE, OFFSET = 1e-3, 5, 0.004, 0.03
EFFECTIVE = HOLD_DELAY * DT  # the transport delay: the measurement compares the mean over the hold


def reference(t):
    (a1, f1), (a2, f2) = (0.5, 0.5), (0.1, 2.3)
    w1, w2 = 2 * math.pi * f1, 2 * math.pi * f2
    return (a1 * np.sin(w1 * t) + a2 * np.sin(w2 * t), a1 * w1 * np.cos(w1 * t) + a2 * w2 * np.cos(w2 * t),
            -a1 * w1 ** 2 * np.sin(w1 * t) - a2 * w2 ** 2 * np.sin(w2 * t))


def _rhs(t, s, tau):
    x, v, z = s
    g = LUGRE["fc"] + (LUGRE["fs"] - LUGRE["fc"]) * math.exp(-(v / LUGRE["vs"]) ** 2)
    zd = v - LUGRE["sigma0"] * abs(v) * z / g
    return [v, (tau - LUGRE["sigma0"] * z - LUGRE["sigma1"] * zd - LUGRE["sigma2"] * v) / J, zd]


@functools.lru_cache(maxsize=2)
def servo(duration=4.0, pre=1.0):
    """(t, x, v, the command u_k without noise and offset, the friction) of the log, which starts ``pre`` into
    the run."""
    n0, n = int(round(pre / DT)), int(round((duration + pre) / DT))
    t = DT * np.arange(n) - pre
    _, vr, ar = reference(t + HOLD_DELAY * DT)
    x, v, u, F, s = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), [0.0, 0.0, 0.0]
    for j in range(n):
        x[j], v[j] = s[0], s[1]
        held = u[j - HOLD_DELAY] if j >= HOLD_DELAY else 0.0
        F[j] = held - J * _rhs(t[j], s, held)[1]
        r0, r1, _ = reference(t[j])
        u[j] = J * ar[j] + 0.2 * math.tanh(vr[j] / 0.05) + 0.02 * vr[j] + 10 * (r0 - x[j]) + 0.4 * (r1 - v[j])
        tau = u[j - HOLD_DELAY] if j >= HOLD_DELAY else 0.0
        if j < n - 1:
            s = solve_ivp(_rhs, (t[j], t[j + 1]), s, args=(tau,), method="LSODA", rtol=1e-10, atol=1e-12).y[:, -1]
    return t[n0:] + pre, x[n0:], v[n0:], u[n0:], F[n0:]


def servo_dataset(folder, seed):
    t, x, v, u, _ = servo()
    logged = u + OFFSET + np.random.default_rng(seed).normal(0.0, NOISE, u.size)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    np.savetxt(folder / "run0.csv", np.column_stack([t, x, v, logged]), delimiter=",", comments="", fmt="%.12g",
               header="time[s],position[rad],velocity[rad/s],command_torque[N*m]")
    (folder / "dataset.toml").write_text(tomli_w.dumps({"name": "servo", "experiment": [
        {"file": "run0.csv", "temperature": 25.0}]}))
    return folder


def covers(ci, truth):
    return ci[0] <= truth <= ci[1]


def test_delay_is_parsed_and_bad_values_are_refused():
    assert parse_delay("auto").kind == "auto" and parse_delay(None).kind == "none" and parse_delay("NONE").kind == "none"
    assert parse_delay(0.005) == DelaySpec("value", 0.005, 0.005)
    assert parse_delay("5ms") == DelaySpec("value", 0.005, 0.005) and parse_delay("500 us").lo == pytest.approx(5e-4)
    assert parse_delay("0:20ms") == DelaySpec("range", 0.0, 0.02) and parse_delay((0.001, 0.02)).hi == 0.02
    for bad, phrase in (("fast", "delay must be auto, none"), ("5 parsecs", "delay must be"), ((0.02, 0.01), "below"),
                        ("1:2:3", "MIN:MAX"), (math.inf, "finite"), ((1,), "pair"), (True, "delay must be")):
        with pytest.raises(InputError, match=phrase):
            parse_delay(bad)


def test_api_none_value_range_and_the_model_file(tmp_path):
    """The joint of test_identify_command (point samples, 8 ms: read as 7.5 ms, that module's docstring): none fits
    0, a value is held and travels in the model file, a range is searched within it and said; a range whose end
    holds the least residuals is refused."""
    data = make_command_dataset(tmp_path / "d", delay=0.008)
    with pytest.raises(InputError, match="delay must be"):
        tf.identify(data, method="base", starts=1, delay="soon")
    none = tf.identify(data, method="base", starts=1, delay="none")
    assert none.model.plant.delay == 0.0 and "none fitted" in none.details["plant"]["delay"]["note"]
    held = tf.identify(data, method="base", starts=1, delay="7ms")
    assert held.model.plant.delay == pytest.approx(0.007) and "held" in held.details["plant"]["delay"]["note"]
    held.model.save(tmp_path / "held.toml")
    assert tf.load_model(tmp_path / "held.toml").plant.delay == pytest.approx(0.007)
    ranged = tf.identify(data, method="base", starts=1, delay=(0.002, 0.02))
    d = ranged.details["plant"]["delay"]
    assert covers(d["ci95"], 0.008 - 0.5 * DT) and d["searched"]["min"] == pytest.approx(0.002) and "range given" in d["note"]
    with pytest.raises(ComputationError, match=r"end of the range given \(0ms:5ms"):
        tf.identify(data, method="base", starts=1, delay="0:5ms")
    with pytest.raises(InputError, match="delay applies to a drive's command"):
        tf.identify(_friction_data(tmp_path / "f"), method="base", starts=1, delay="5ms")


def _friction_data(folder):
    """A friction record (a torque sensor's): the delay does not apply."""
    folder.mkdir()
    t = np.arange(0.0, 2.0, DT)
    x, v, _ = reference(t)
    np.savetxt(folder / "run0.csv", np.column_stack([t, x, v, 0.2 * np.tanh(v / 0.01)]), delimiter=",",
               comments="", fmt="%.12g", header="time[s],position[rad],velocity[rad/s],friction_torque[N*m]")
    (folder / "dataset.toml").write_text(tomli_w.dumps({"name": "f", "experiment": [
        {"file": "run0.csv", "temperature": 25.0}]}))
    return tf.load_dataset(folder)


def test_cli_delay_option(tmp_path):
    """--delay VALUE is held and written into the model file; a bad value is one message naming --delay, exit 2;
    an automatic search says the range it searched and why."""
    data = tmp_path / "d"
    make_command_dataset(data, delay=0.008)
    fit = tmp_path / "fit.toml"
    r = run_cli("identify", data, "--method", "base", "--starts", "1", "--delay", "6ms", "-o", fit)
    assert r.returncode == 0, r.stderr
    assert tf.load_model(fit).plant.delay == pytest.approx(0.006)
    bad = run_cli("identify", data, "--method", "base", "--starts", "1", "--delay", "6 weeks", "-o", tmp_path / "x.toml")
    assert bad.returncode == 2 and "--delay" in bad.stderr and "Traceback" not in bad.stderr
    assert not (tmp_path / "x.toml").exists()
    auto = tf.identify(tf.load_dataset(data), method="base", starts=1)
    assert "half the motion's time scale" in auto.details["plant"]["delay"]["note"]
    assert "searched" in auto.report()
    both = make_command_dataset(tmp_path / "b", delay=0.008, validate=True)
    html = tf.report([tf.identify(both, method="base", starts=1)], both, tmp_path / "report.html")
    assert "inertia J" in html and "delay (fitted with the friction" in html and "half the motion" in html


def test_hold_relation_of_the_truth():
    """The truth's own check: the command is the mean of J a + F over its hold interval (the exact discrete
    relation, J dv/dt integrated), the relation the measurement compares at the transport delay (5 ms; as point
    samples the command would act 5.5 ms late on average)."""
    t, x, v, u, F = servo()
    k = HOLD_DELAY
    mean = J * (v[k + 1:] - v[k:-1]) / DT + 0.5 * (F[k + 1:] + F[k:-1])
    assert np.max(np.abs(u[:-k - 1] - mean)) < 1e-3 * np.ptp(u)
    assert np.ptp(v) > 3.0 and np.ptp(u) > 0.5


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_servo_with_a_held_command(tmp_path, seed):
    """From the data's own start (no --init): the delay (the transport delay, 5 ms), J and fc within a few % of the
    truth, and their 95 % intervals cover it. (Failed with the fixed 9-sample acceleration, which blurred the
    presliding ringing after reversals: 5.58-5.62 ms +- 0.025 for 5.5; the window chosen from the record, 3 samples
    on this noise-free velocity, gave 5.49-5.52 ms +- 0.009 for 5.5 with point samples of J a + F; their means over
    the hold give 4.99-5.02 ms +- 0.009 on seeds 0-4.)"""
    res = tf.identify(tf.load_dataset(servo_dataset(tmp_path / "d", seed)), method="base", starts=1)
    plant = res.details["plant"]
    d, inertia, fc = plant["delay"], plant["inertia"], res.parameters["fc"]
    assert abs(d["estimate"] - EFFECTIVE) < 0.03 * EFFECTIVE, d
    assert abs(inertia["value"] - J) < 0.02 * J and abs(fc.value - LUGRE["fc"]) < 0.02 * LUGRE["fc"]
    assert covers(d["ci95"], EFFECTIVE), d
    assert covers(inertia["ci95"], J), inertia
    assert covers(fc.ci95, LUGRE["fc"]), fc.ci95


#: the noise seeds of the presliding test, and the share of them whose 95 % intervals must cover the truth
SEEDS, COVERAGE = range(20), 0.9


def test_servo_presliding(tmp_path):
    """The presliding parameters sigma1 and sigma0 of the servo truth over 20 noise seeds: their 95 % intervals
    cover the truth in at least 90 % of the seeds, and every estimate lies within twice its interval's half-width
    of it. Issue 40 item 6: when the model compared point samples of J a + F with the held command (the bristles'
    fast change after a reversal, a time scale g/(sigma0 |v|) of a few ms, at point samples where the drive
    realises each sample's mean), sigma1 came out 0.042-0.049 (intervals covering 0.04 in 1 of 25 seeds) and sigma0
    59.1-59.9 (5 of 25). With the means over the hold: sigma1 0.038-0.044 (24 of 25), sigma0 59.6-60.4 (24 of 25),
    the delay 4.98-5.02 ms (covering 5 ms in 24 of 25), fc 25 of 25, J 21 of 25 (as before), on seeds 0-24; a fit
    takes 0.5 s, as before."""
    covered = {"sigma1": 0, "sigma0": 0}
    for seed in SEEDS:
        res = tf.identify(tf.load_dataset(servo_dataset(tmp_path / f"d{seed}", seed)), method="base", starts=1)
        for name in covered:
            p = res.parameters[name]
            half = 0.5 * (p.ci95[1] - p.ci95[0])
            assert math.isfinite(half) and abs(p.value - LUGRE[name]) <= 2 * half, (seed, name, p.value, p.ci95)
            covered[name] += covers(p.ci95, LUGRE[name])
    assert all(n >= COVERAGE * len(SEEDS) for n in covered.values()), covered
