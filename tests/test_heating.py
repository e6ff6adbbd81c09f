"""Self-heating (docs/models.md#self-heating): the lumped thermal model in the C core, against closed forms, a
conservation law and the independent reference implementation (tests/reference/). Each test's
docstring names its oracle."""

from __future__ import annotations

import dataclasses
import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import simpson
from scipy.optimize import brentq

import thermofriction as tf
from thermofriction import _bridge
from thermofriction.models import Coulomb, Exp, Heat, Linear, Model, ModelI, ModelII, PrescribedMotion

sys.path.insert(0, str(Path(__file__).resolve().parent))
import reference as R  # noqa: E402
from conftest import every_friction_model  # noqa: E402

V_SLIDE = 1e-3  # m/s
FC = 0.5        # N


def sliding(friction, thermal=None, heat=None, duration=100.0):
    """Prescribed sliding at constant speed V_SLIDE: x_r = V_SLIDE t."""
    model = Model(PrescribedMotion(), friction, thermal, heat=heat)
    return model, tf.Sampled(np.array([0.0, duration]), np.array([0.0, V_SLIDE * duration]))


HEAT = Heat(heat_capacity=0.01, thermal_resistance=200.0, heat_fraction=0.8, ambient_temperature=25.0)


def paper_heated(kind="I", heater=None, **heat):
    """The paper's actuator (li2009-model-i / -model-ii presets) with a lumped thermal model."""
    model = tf.load_model("li2009-model-i" if kind == "I" else "li2009-model-ii")
    h = dict(heat_capacity=1.5e-4, thermal_resistance=2e4, heat_fraction=0.5, external_heat=heater)
    h.update(heat)
    return dataclasses.replace(model, heat=Heat(**h))


def test_constant_speed_sliding_gives_the_exact_exponential():
    """Oracle (analytic, the issue's): constant-speed sliding with temperature-independent friction
    heats as T(t) = T_amb + R_th eta F v (1 - exp(-t / (R_th C_th))) exactly; the C core follows it
    to 1e-7 of the rise over five time constants at rtol 1e-10, and its frictional work is F v t."""
    model, motion = sliding(Coulomb(fc=FC, v_smooth=1e-7), heat=HEAT)
    res = tf.simulate(model, duration=10.0, sample_rate=100, input=motion,
                      controller=tf.StepSizeController(rtol=1e-10))
    F = FC * math.tanh(V_SLIDE / 1e-7)
    rise = HEAT.thermal_resistance * HEAT.heat_fraction * F * V_SLIDE
    exact = 25.0 + rise * (1 - np.exp(-res.time / HEAT.time_constant))
    assert np.max(np.abs(res.temperature - exact)) < 1e-7 * rise
    assert res.temperature[-1] - 25.0 > 0.99 * rise  # five time constants: nearly the full rise
    np.testing.assert_allclose(res.friction_work, F * V_SLIDE * res.time, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(res.friction_force, F, rtol=1e-12)


@pytest.mark.parametrize("thermal", ["model-i", "model-ii"])
def test_steady_state_is_the_fixed_point_of_the_heat_balance(thermal):
    """Oracle (analytic, the issue's): with temperature-dependent friction the temperature settles
    at the fixed point of T = T_amb + R_th eta F(T) v (found by brentq on the model's own law);
    after 25 time constants the C core is there to 1e-6 K. Model I: fc(T) = 2 exp(-0.05 T);
    Model II: F = fc (1 + dF(T)/fc) with dF(T) = -0.02 (T - 25)."""
    if thermal == "model-i":
        friction, th = Coulomb(fc=None, v_smooth=1e-7), ModelI({"fc": Exp(a=2.0, b=-0.05)})
        F_of_T = lambda T: 2.0 * math.exp(-0.05 * T)  # noqa: E731
    else:
        friction, th = Coulomb(fc=FC, v_smooth=1e-7), ModelII(Linear(a=-0.02, b=0.5))
        F_of_T = lambda T: FC - 0.02 * (T - 25.0)  # noqa: E731
    heat = dataclasses.replace(HEAT, thermal_resistance=2000.0, heat_capacity=0.002)
    model, motion = sliding(friction, th, heat)
    res = tf.simulate(model, duration=25 * heat.time_constant, sample_rate=10, input=motion,
                      controller=tf.StepSizeController(rtol=1e-10))
    R_eta_v = heat.thermal_resistance * heat.heat_fraction * V_SLIDE
    T_star = brentq(lambda T: T - 25.0 - R_eta_v * F_of_T(T), 25.0, 100.0, xtol=1e-14)
    assert T_star - 25.0 > 0.3  # a real rise, and a real dependence on T
    assert abs(res.temperature[-1] - T_star) < 1e-6
    assert abs(F_of_T(T_star) - F_of_T(25.0)) > 1e-3


def test_energy_balance_on_the_paper_actuator():
    """Oracle (conservation of energy): heat stored plus heat lost equals eta times the work done
    by friction plus the heater's energy, C_th (T(t) - T_0) + int (T - T_amb)/R_th dt =
    eta W(t) + int P_ext dt. The paper's actuator (Model I) at 500 Hz with a heater switched on
    at 0.1 s; the loss integral by Simpson's rule on a 2 MHz output grid; balance to 1e-6 of the
    heat stored."""
    heater = tf.Step(amplitude=2e-3, time=0.1, slew=1e-3)
    model = paper_heated("I", heater=heater)
    saw = tf.Sawtooth(amplitude=30, frequency=500, rise=0.999)
    res = tf.simulate(model, duration=0.3, sample_rate=2e6, input=saw, temperature=30.0,
                      controller=tf.StepSizeController(rtol=1e-9))
    h = model.heat
    stored = h.heat_capacity * (res.temperature - 30.0)
    lost = simpson((res.temperature - 30.0) / h.thermal_resistance, x=res.time)
    heater_energy = 2e-3 * (0.3 - 0.1 - 0.5e-3)
    balance = stored[-1] + lost - (h.heat_fraction * res.friction_work[-1] + heater_energy)
    assert res.friction_work[-1] > 0 and lost > 0
    assert abs(balance) < 1e-6 * stored[-1], (balance, stored[-1])


@pytest.mark.parametrize("kind", ["I", "II"])
def test_heated_actuator_matches_the_reference(kind):
    """Oracle: independent reference implementation (tests/reference/ ReferenceHeatedSystem,
    solve_ivp LSODA at rtol 1e-10): the paper's actuator (Model I or II) heating itself at 500 Hz
    for 0.1 s (a small C_th, so the temperature rises ~2 K) agrees in temperature to 1e-5 K, in
    end-effector displacement to 1e-4 of the stroke and in frictional work to 1e-5 relative."""
    model = paper_heated(kind, heat_capacity=1e-6, thermal_resistance=2e4)
    saw = tf.Sawtooth(amplitude=30, frequency=500, rise=0.999)
    t = np.linspace(0.0, 0.1, 2001)
    res = tf.simulate(model, t_eval=t, input=saw, temperature=30.0, controller=tf.StepSizeController(rtol=1e-9))
    _, ref = R.reference_simulate_heated(model, t, 30.0, saw, rtol=1e-10)
    assert res.temperature[-1] - 30.0 > 1.0
    stroke = np.ptp(res.stage_displacement)
    assert np.max(np.abs(res.temperature - ref[:, -2])) < 1e-5
    assert np.max(np.abs(res.displacement - ref[:, 2])) < 1e-4 * stroke
    np.testing.assert_allclose(res.friction_work, ref[:, -1], rtol=1e-5, atol=1e-9 * ref[-1, -1])


def test_heat_rows_and_temperature_column_of_the_jacobian():
    """Oracle: central finite differences of the independent reference's rhs
    (ReferenceHeatedSystem). The C Jacobian's temperature and work rows and its temperature
    column (itself a difference in T, h = 1e-3 K) agree to 1e-5 of each row's scale at 40 random
    sliding states, for Model I and Model II."""
    rng = np.random.default_rng(7)
    saw = tf.Sawtooth(amplitude=30, frequency=500, rise=0.999)
    for kind in ("I", "II"):
        model = paper_heated(kind, heater=tf.Step(amplitude=1e-3, time=0.0, slew=1.0))
        spec = _bridge.model_spec(model, 30.0, saw)
        for _ in range(40):
            t = float(rng.uniform(0, 2e-3))
            vp, ve = rng.normal(0, 1e-3, 2)
            z = rng.uniform(-1, 1) * 1e-6
            y = np.array([rng.normal(0, 1e-6), vp, rng.normal(0, 1e-6), ve, z, rng.uniform(30, 40), 1e-6])
            n = y.size
            dy, J = np.empty(n), np.empty((n, n))
            _bridge.rhs_jac(spec, t, y, dy, J)
            ref = R.ReferenceHeatedSystem(model, 30.0, saw)
            np.testing.assert_allclose(dy, ref.rhs(t, y), rtol=1e-10, atol=1e-12 * np.abs(dy).max())
            scale = np.array([1e-6, 1e-3, 1e-6, 1e-3, 1e-6, 1.0, 1e-6])  # x, v, x, v, z, T, W
            h = 1e-4 * scale
            h[[1, 3]] = min(h[1], abs(ve - vp) / 10)  # stay clear of |v_r|'s kink
            for j in range(n):
                yp, ym = y.copy(), y.copy()
                yp[j] += h[j]
                ym[j] -= h[j]
                fd = (np.array(ref.rhs(t, yp)) - np.array(ref.rhs(t, ym))) / (2 * h[j])
                for i in range(n) if j == 5 else (5, 6):
                    row = np.max(np.abs(J[i]) * scale)
                    assert abs(J[i, j] - fd[i]) * scale[j] <= 1e-5 * row + 1e-300, (kind, i, j, J[i, j], fd[i])


def test_heat_section_round_trip_and_state_outputs(tmp_path):
    """The [heat] section saves and loads unchanged (with a heater waveform), the temperature is
    a state starting at T_0, and the CSV gains friction_work[J]."""
    model = paper_heated("I", heater=tf.Step(amplitude=1e-3, time=0.01, slew=1e-3), initial_temperature=32.0)
    model.save(tmp_path / "m.toml")
    back = tf.load_model(tmp_path / "m.toml")
    assert back == model
    text = (tmp_path / "m.toml").read_text()
    assert "[heat]" in text and "C_th" in text and "R_th" in text and "P_ext" in text
    res = tf.simulate(back, duration=0.02, sample_rate=1e5, temperature=30.0,
                      input=tf.Sawtooth(amplitude=30, frequency=500, rise=0.999))
    assert res.temperature[0] == 32.0
    assert res.temperature[-1] != 32.0
    res.to_csv(tmp_path / "out.csv")
    header = (tmp_path / "out.csv").read_text().splitlines()[0].split(",")
    assert header[-1] == "friction_work[J]" and "temperature[C]" in header


@pytest.mark.parametrize("text, message", [
    ("C_th = -1.0\nR_th = 10.0", "'C_th' must be positive"),
    ("C_th = 1.0\nR_th = 0.0", "'R_th' must be positive"),
    ("C_th = 1.0\nR_th = 10.0\neta = 1.5", "'eta' must be between 0 and 1"),
    ("C_th = 1.0", "missing 'R_th'"),
    ("C_th = 1.0\nR_th = 10.0\nRth = 3", "Rth"),
    ("C_th = 1.0\nR_th = 10.0\nP_ext = { waveform = \"sawtooth\" }", "[heat] P_ext"),
])
def test_bad_heat_section_is_named(tmp_path, text, message):
    """Bad [heat] sections: one message naming the file and the key."""
    base = (Path(tf.models.preset_path("li2009-model-i"))).read_text()
    p = tmp_path / "bad.toml"
    p.write_text(base + "\n[heat]\n" + text + "\n")
    with pytest.raises(tf.InputError) as e:
        tf.load_model(p)
    assert str(p) in str(e.value) and message in str(e.value)


def test_heat_needs_an_ambient_temperature_and_refuses_a_signal():
    model = paper_heated("I")
    with pytest.raises(tf.InputError, match="ambient"):
        tf.simulate(model, duration=0.01)
    with pytest.raises(tf.InputError, match="temperature is a state"):
        tf.simulate(model, duration=0.01, temperature=([0.0, 1.0], [30.0, 31.0]))


def test_heating_out_of_the_calibrated_range_warns_and_out_of_the_valid_range_fails():
    """The temperature range is known after the run: heating past a law's calibrated range warns;
    heating to where a Model I parameter leaves its domain (sigma1(T) = -0.138 T + 6.445 < 0 above
    46.7 C) is a computation error that names the temperature."""
    saw = tf.Sawtooth(amplitude=30, frequency=500, rise=0.999)
    model = paper_heated("I", heat_capacity=1e-6, thermal_resistance=2e4)
    with pytest.warns(tf.TemperatureRangeWarning, match="outside the calibrated range"):
        res = tf.simulate(model, duration=0.1, sample_rate=1e4, temperature=41.0, input=saw)
    assert res.temperature.max() > 41.5
    model = paper_heated("I", heat_capacity=1e-7, thermal_resistance=1e5)
    with pytest.raises(tf.SolverError, match=r"self-heating took the temperature to 40\.\.4[6-9].*'sigma1'"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", tf.TemperatureRangeWarning)
            tf.simulate(model, duration=0.05, sample_rate=1e4, temperature=40.0, input=saw)


# ---------------------------------------------------------------------------------------------
# The two-time-scale method (thermofriction.heating)
# ---------------------------------------------------------------------------------------------

def test_two_time_scale_on_prescribed_sawtooth_sliding_is_the_exact_exponential():
    """Oracle (analytic): Coulomb friction under a prescribed sawtooth motion of amplitude A
    dissipates exactly 2 A F per cycle (F = fc tanh(v/v_smooth) on each flank), so the averaged
    heat balance is the exponential T_amb + R eta 2 A F f (1 - exp(-t/tau)); the method's table
    and its temperature agree to 1e-9 relative and 1e-6 of the rise."""
    from thermofriction.heating import TwoTimeScale, simulate_heating
    A, f = 1e-5, 50.0
    saw = tf.Sawtooth(amplitude=A, frequency=f, rise=0.5)
    heat = dataclasses.replace(HEAT, thermal_resistance=2000.0, heat_capacity=0.002)
    model = Model(PrescribedMotion(), Coulomb(fc=FC, v_smooth=1e-9), heat=heat, input=saw)
    res = simulate_heating(model, 20.0, solver=TwoTimeScale(points=5))
    v = 2 * A * f  # the slope on each flank: A / (rise / f) with rise 0.5
    F = FC * math.tanh(v / 1e-9)
    np.testing.assert_allclose(res.table.cycle_work, 2 * A * F, rtol=1e-9)
    rise = heat.thermal_resistance * heat.heat_fraction * 2 * A * F * f
    exact = 25.0 + rise * (1 - np.exp(-res.time / heat.time_constant))
    assert np.max(np.abs(res.temperature - exact)) < 1e-6 * rise
    np.testing.assert_allclose(res.friction_work, 2 * A * F * f * res.time, rtol=1e-6, atol=1e-15)


def test_two_time_scale_against_the_full_simulation():
    """Oracle: the full coupled simulation (method Full(), every cycle) of the li2009-self-heating
    preset at 500 Hz for 20 s (10,000 cycles, from 30 C). The two-time-scale method agrees to
    5e-3 K in temperature and 0.3 % in displacement, and simulates under 5 % of the cycles."""
    from thermofriction.heating import Full, simulate_heating
    model = tf.load_model("li2009-self-heating")
    saw = tf.Sawtooth(amplitude=30, frequency=500, rise=0.999)
    avg = simulate_heating(model, 20.0, input=saw)
    full = simulate_heating(model, 20.0, input=saw, solver=Full())
    np.testing.assert_array_equal(avg.time, full.time)
    assert full.temperature[-1] - 30.0 > 3.0  # it heats a lot in 20 s
    assert np.max(np.abs(avg.temperature - full.temperature)) < 5e-3
    assert abs(avg.displacement[-1] - full.displacement[-1]) < 3e-3 * abs(full.displacement[-1])
    assert np.max(np.abs(avg.step_size - full.step_size)[1:]) < 0.02 * np.max(np.abs(full.step_size))
    assert avg.stats["cycles_simulated"] < 0.05 * full.stats["cycles_simulated"]


def test_simulate_heating_refuses_what_it_cannot_average():
    from thermofriction.heating import simulate_heating
    with pytest.raises(tf.InputError, match=r"\[heat\] section"):
        simulate_heating(tf.load_model("li2009-model-i"), 1.0, temperature=30.0)
    with pytest.raises(tf.InputError, match="periodic input"):
        simulate_heating(tf.load_model("li2009-self-heating"), 1.0, input=tf.Step(amplitude=1.0))


# ---------------------------------------------------------------------------------------------
# Identification of the heat model (method "heat")
# ---------------------------------------------------------------------------------------------

def _heated_truth(heater):
    m = tf.load_model("li2009-self-heating")
    return dataclasses.replace(m, input=tf.Sawtooth(30, 500, rise=0.999), heat=dataclasses.replace(
        m.heat, heat_capacity=5e-5, thermal_resistance=1e4, external_heat=heater))


def _wrong_start(model):
    return dataclasses.replace(model, heat=dataclasses.replace(
        model.heat, heat_capacity=8e-5, thermal_resistance=1.5e4, heat_fraction=0.3))


def test_heat_identification_recovers_c_r_eta_with_a_known_heater():
    """Oracle: the true parameters of synthetic data (synthesize from a known model: 20 nm
    displacement noise, 0.02 K temperature noise; the paper's actuator at 500 Hz, tau = 0.5 s,
    a 0.3 mW heater switched on at 1 s). From 60 %, 50 % and 40 % off, the heat fit finds C_th,
    R_th, eta inside their 95 % intervals, within 1 % of the truth, with a residual at the noise."""
    heater = tf.Step(amplitude=3e-4, time=1.0, slew=0.01)
    truth = _heated_truth(heater)
    data = tf.synthesize(truth, [30.0], duration=2.0, sample_rate=5000, noise=20e-9, temperature_noise=0.02)
    fit = tf.identify(data, method="heat", init=_wrong_start(truth), starts=1)
    for name, true in (("C_th", 5e-5), ("R_th", 1e4), ("eta", 0.5)):
        p = fit.parameters[name]
        assert p.ci95[0] <= true <= p.ci95[1], (name, p)
        assert abs(p.value - true) < 0.01 * true, (name, p)
    assert fit.experiments[0]["rmse_offset_removed"] < 30e-9
    assert fit.experiments[0]["temperature_rmse"] < 0.03
    assert fit.model.heat.heat_capacity == pytest.approx(fit.parameters["C_th"].value)


def test_heat_identification_without_a_heater_reports_the_unidentifiable_scale():
    """Oracle (analytic): without a known heat input the heat balance is invariant under
    (eta, R_th, C_th) -> (a eta, R_th / a, a C_th), so the records fix only eta R_th and R_th C_th.
    The fit must say so -- an infinite interval and a warning -- instead of a falsely tight one,
    while the combinations it can determine come out right (to 2 %)."""
    truth = _heated_truth(None)
    data = tf.synthesize(truth, [30.0], duration=2.0, sample_rate=5000, noise=20e-9, temperature_noise=0.02)
    fit = tf.identify(data, method="heat", init=_wrong_start(truth), starts=1)
    assert any(not math.isfinite(fit.parameters[n].stderr) for n in ("C_th", "R_th", "eta"))
    assert any("not identifiable" in w for w in fit.warnings)
    v = {n: fit.parameters[n].value for n in ("C_th", "R_th", "eta")}
    assert v["eta"] * v["R_th"] == pytest.approx(0.5 * 1e4, rel=0.02)
    assert v["R_th"] * v["C_th"] == pytest.approx(0.5, rel=0.02)


def test_heat_identification_needs_a_temperature_record():
    truth = _heated_truth(None)
    data = tf.synthesize(truth, [30.0], duration=0.2, sample_rate=5000, record_temperature=False)
    with pytest.raises(tf.InputError, match="no temperature"):
        tf.identify(data, method="heat", init=truth, starts=1)


def test_heat_fit_through_the_command_line_and_validate(tmp_path):
    """End to end on the command line: synthesise a self-heating run (synth writes the temperature
    record), identify --method heat from a wrong start, validate the fitted model on the data."""
    from conftest import run_cli
    truth = _heated_truth(tf.Step(amplitude=3e-4, time=0.5, slew=0.01))
    tf.save_dataset(tf.synthesize(truth, [30.0], duration=1.0, sample_rate=5000, noise=20e-9,
                                  temperature_noise=0.02), tmp_path / "data")
    _wrong_start(truth).save(tmp_path / "init.toml")
    r = run_cli("identify", str(tmp_path / "data"), "--method", "heat", "--init", str(tmp_path / "init.toml"),
                "-o", str(tmp_path / "fit.toml"), "--json", str(tmp_path / "fit.json"), "--starts", "1")
    assert r.returncode == 0, r.stderr
    fitted = tf.load_model(tmp_path / "fit.toml")
    assert fitted.heat.heat_capacity == pytest.approx(5e-5, rel=0.02)
    v = tf.validate(fitted, tf.load_dataset(tmp_path / "data"))
    assert v.experiments[0]["max_error_pct"] < 0.1


def test_simulate_command_line_with_a_heat_model(tmp_path):
    """thermofriction simulate on the self-heating preset: --temperature is the ambient one, the
    summary says where the temperature went, the CSV has the temperature and friction_work columns."""
    from conftest import run_cli
    out = tmp_path / "run.csv"
    r = run_cli("simulate", "li2009-self-heating", "--temperature", "31", "--duration", "0.2", "--sample-rate",
                "5000", "--input", "sawtooth:amplitude=30,frequency=500,rise=0.999", "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert "self-heating from 31 C" in r.stdout and "ambient 31 C" in r.stdout
    header = out.read_text().splitlines()[0].split(",")
    assert header[-1] == "friction_work[J]"
    T = np.loadtxt(out, delimiter=",", skiprows=1)[:, header.index("temperature[C]")]
    assert T[0] == 31.0 and T[-1] > 31.05


EVERY_FRICTION = every_friction_model()


@pytest.mark.parametrize("kind", list(EVERY_FRICTION))
def test_every_friction_model_heats_with_its_energy_balanced(kind):
    """Oracle (conservation of energy) for every base model, with Model I (fc falling with T):
    the spring-pulled mass of Canudas de Wit et al. (1995) in stick-slip for 10 s heats its
    interface, and C_th (T - T_0) + int (T - T_amb)/R_th dt = eta W to 1e-5 of the stored heat
    (the loss integral by Simpson's rule on a 20 kHz grid)."""
    friction = dataclasses.replace(EVERY_FRICTION[kind], fc=None)
    law = ModelI({"fc": Exp(a=1.0 / math.exp(-0.01 * 25.0), b=-0.01)})  # 1 N at 25 C
    heat = Heat(heat_capacity=0.2, thermal_resistance=20.0, heat_fraction=0.9, ambient_temperature=25.0)
    model = Model(tf.MassPlant(1.0, 2.0, 0.1), friction, law, heat=heat)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tf.PassivityWarning)
        res = tf.simulate(model, duration=10.0, sample_rate=20_000, controller=tf.StepSizeController(rtol=1e-9))
    stored = heat.heat_capacity * (res.temperature[-1] - 25.0)
    lost = simpson((res.temperature - 25.0) / heat.thermal_resistance, x=res.time)
    assert stored > 0.1  # ~1 W of friction for 10 s into 0.2 J/K: a real rise
    assert abs(stored + lost - heat.heat_fraction * res.friction_work[-1]) < 1e-5 * stored
