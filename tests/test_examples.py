"""The Canudas de Wit et al. (1995) experiments of examples/canudas1995.py against the physics.

Each experiment's key figures are checked against what the LuGre equations predict for them
(derived in the example's docstrings): closed-form quasi-static curves for presliding, the
first-order lag for slow velocity variation, the damped-oscillator slip phase and the v0 mean
velocity of the stick-slip limit cycle, and the fold of the creep solution for the break-away force.
Every simulation runs with all warnings as errors except the PassivityWarning that the paper's
parameter set is known to raise (the example silences that one only).
"""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
import canudas1995 as ex  # noqa: E402

pytestmark = pytest.mark.filterwarnings("error")


@pytest.fixture(scope="module")
def stick_slip():
    return ex.stick_slip()


@pytest.fixture(scope="module")
def presliding():
    return ex.presliding()


@pytest.fixture(scope="module")
def lag():
    return ex.frictional_lag((1.0, 10.0, 25.0))


@pytest.fixture(scope="module")
def break_away():
    return ex.break_away((0.03, 0.1, 0.3, 1.0, 3.0, 10.0))


def test_parameters_are_the_papers():
    f = ex.lugre()
    assert (f.sigma0, f.sigma2, f.fc, f.fs, f.vs, f.delta) == (1e5, 0.4, 1.0, 1.5, 1e-3, 2.0)
    assert f.sigma1 == pytest.approx(math.sqrt(1e5), rel=1e-15)
    assert f.vd is None  # constant sigma1, as in the paper
    # the set is not dissipative at high speed: simulate warns (and the example silences exactly that)
    with pytest.warns(tf.PassivityWarning, match="not dissipative"):
        tf.simulate(tf.Model(tf.MassPlant(1.0, 2.0, 0.1), f), 0.01)


# --- (a) stick-slip ---------------------------------------------------------------------------

def test_stick_slip_is_periodic_with_mean_velocity_v0(stick_slip):
    s = stick_slip
    assert s["cycles"] >= 7
    assert s["period_spread"] <= 2e-3          # two output samples at 1 kHz
    assert s["mean_velocity"] == pytest.approx(ex.V_PULL, rel=1e-4)


def test_stick_slip_has_stick_phases(stick_slip):
    s = stick_slip
    # the mass (nearly) stands still for more than half of every cycle: creep at ~1e-5 m/s,
    # against a peak slip velocity of ~0.37 m/s
    assert s["stick_duration"] > 0.5 * s["period"]
    assert s["max_creep_velocity"] < 0.05 * ex.VS
    assert s["peak_velocity"] > 100 * ex.VS


def test_stick_slip_break_away_is_the_ramp_break_away(stick_slip):
    s = stick_slip
    assert ex.FC < s["break_away_force"] < ex.FS
    # the spring loads the stuck mass at k_s v0 = 0.2 N/s: the same break-away as a 0.2 N/s force ramp
    ramp = ex.break_away((ex.K_SPRING * ex.V_PULL,))["break_away_force"][0]
    assert s["break_away_force"] == pytest.approx(ramp, abs=5e-3)


def test_stick_slip_cycle_matches_the_oscillator_prediction(stick_slip):
    s = stick_slip
    assert s["peak_velocity"] == pytest.approx(s["peak_velocity_predicted"], rel=5e-3)
    assert s["slip_duration"] == pytest.approx(s["slip_duration_predicted"], rel=1e-2)
    assert s["spring_force_after_slip"] == pytest.approx(s["spring_force_after_slip_predicted"], abs=5e-3)
    assert s["stick_duration"] == pytest.approx(s["stick_duration_predicted"], rel=1e-2)
    assert s["period"] == pytest.approx(s["period_predicted"], rel=2e-3)


# --- (b) presliding ---------------------------------------------------------------------------

def test_presliding_stiffness_is_sigma0(presliding):
    assert presliding["stiffness"] == pytest.approx(ex.SIGMA0, rel=0.02)


def test_presliding_follows_the_quasistatic_loop(presliding):
    p = presliding
    x_scale = p["displacement_at_fmax_predicted"]  # 24 um
    assert p["max_error_vs_quasistatic"] < 1e-3 * x_scale
    assert p["displacement_at_fmax"] == pytest.approx(p["displacement_at_fmax_predicted"], rel=1e-3)
    # micro-displacement: well below the presliding scale fs/sigma0 times a few, nowhere near sliding
    assert p["displacement_at_fmax"] < 2 * ex.FS / ex.SIGMA0
    # hysteresis: the force returns to zero with the mass displaced, the loop closes after one cycle
    assert p["residual_displacement"] == pytest.approx(p["residual_displacement_predicted"], rel=2e-3)
    assert p["residual_displacement"] > 0.5 * x_scale
    assert p["loop_closure_error"] < 1e-3 * x_scale
    assert p["loop_energy"] > 0
    assert p["loop_energy"] == pytest.approx(p["loop_energy_predicted"], rel=5e-3)


def test_quasistatic_loop_formulas():
    # the three branches join: virgin(f_max) = descending(f_max), descending(-f_max) = ascending(-f_max),
    # ascending(f_max) = virgin(f_max); and dF/dx at the origin is sigma0
    f = 1.2
    q = ex.presliding_quasistatic
    assert q(f, f, "descending") == pytest.approx(q(f, f, "virgin"), rel=1e-12)
    assert q(-f, f, "ascending") == pytest.approx(q(-f, f, "descending"), rel=1e-12)
    assert q(f, f, "ascending") == pytest.approx(q(f, f, "virgin"), rel=1e-12)
    assert 1e-6 / q(1e-6, f, "virgin") == pytest.approx(ex.SIGMA0, rel=1e-6)


# --- (c) frictional lag -----------------------------------------------------------------------

def test_frictional_lag_loops_widen_with_frequency(lag):
    w, area = np.array(lag["width"]), np.array(lag["area"])
    assert np.all(w > 0)                      # friction is higher while accelerating: it lags
    assert np.all(np.diff(w) > 0) and np.all(np.diff(area) > 0)
    assert w[-1] > 20 * w[0]


def test_frictional_lag_matches_first_order_theory(lag):
    # linear in omega while omega tau << 1 (tau ~ 7 ms): 1 and 10 rad/s; 25 rad/s is beyond it
    assert lag["width"][0] == pytest.approx(lag["width_predicted"][0], rel=0.05)
    assert lag["width"][1] == pytest.approx(lag["width_predicted"][1], rel=0.10)
    # slow variation: the loop lies on the steady-state Stribeck curve g(v) + sigma2 v
    assert lag["max_deviation"][0] < 0.01
    assert lag["max_deviation"][2] > 5 * lag["max_deviation"][0]


# --- (d) break-away ---------------------------------------------------------------------------

def test_break_away_force_falls_with_rate_between_fc_and_fs(break_away):
    F = np.array(break_away["break_away_force"])
    assert np.all((F > ex.FC) & (F < ex.FS))
    # the LuGre creep argument (break_away_quasistatic): a faster ramp needs a faster creep, further
    # down the Stribeck curve, so the mass breaks away at a lower force
    assert np.all(np.diff(F) < 0)
    assert F[0] > 1.49 and F[-1] < 1.3
    # the applied force leads the friction at the break-away (the mass is accelerating)
    assert np.all(np.array(break_away["applied_force"]) >= F)


def test_break_away_approaches_the_quasistatic_prediction(break_away):
    F, pred = np.array(break_away["break_away_force"]), np.array(break_away["predicted"])
    assert np.all(F >= pred - 1e-3)          # the fold is passed with a delay, never early
    gap = F - pred
    assert np.all(np.diff(gap) > 0)           # and the delay shrinks as the rate falls
    assert gap[0] < 5e-3 and gap[1] < 1e-2    # 0.03 and 0.1 N/s


def test_quasistatic_break_away_limits():
    # fs for an infinitely slow ramp, falling strictly to fc at the critical rate max_v sigma0 v (1 - fc/g(v))
    # (whose maximum lies near v = vs/sqrt(2), the maximum of v exp(-(v/vs)^2)), fc beyond
    r_crit = ex.critical_rate()
    v = np.linspace(0.1, 3, 29_001) * ex.VS
    assert r_crit == pytest.approx(np.max(ex.SIGMA0 * v * (1 - ex.FC / ex.stribeck_curve(v))), rel=1e-6)
    assert 10 < r_crit < 20
    assert ex.break_away_quasistatic(1e-6) == pytest.approx(ex.FS, abs=1e-3)
    assert ex.break_away_quasistatic(r_crit * 1.001) == pytest.approx(ex.FC, abs=1e-9)
    rates = np.logspace(-3, math.log10(0.99 * r_crit), 13)
    F = [ex.break_away_quasistatic(r) for r in rates]
    assert np.all(np.diff(F) < 0) and F[-1] > ex.FC


# --- the script -------------------------------------------------------------------------------

def test_main_prints_every_experiment(capsys, tmp_path):
    try:
        import matplotlib  # noqa: F401
        plot = True
    except ImportError:
        plot = False
    ex.main(["--plot", str(tmp_path)] if plot else [])
    out = capsys.readouterr().out
    for head in ("(a) stick-slip", "(b) presliding", "(c) frictional lag", "(d) break-away"):
        assert head in out
    if plot:
        assert len(list(tmp_path.glob("canudas1995_*.png"))) == 4


def test_self_heating_example_writes_its_report(tmp_path):
    """examples/self_heating.py end to end (shortened to 20 s): the HTML report holds its three
    figures and the summary, and the 500 Hz run heats far more than the 5 Hz one."""
    import self_heating
    out = tmp_path / "sh.html"
    self_heating.main(["-o", str(out), "--duration", "20", "--figures", str(tmp_path / "fig")])
    text = out.read_text()
    for name in ("heating_temperature", "heating_step_size", "heating_constant_temperature_error"):
        assert f'id="fig-{name}"' in text
        assert (tmp_path / "fig" / f"{name}.png").stat().st_size > 1000
    runs = [self_heating.run(f, 20.0, full=False) for f in (5.0, 500.0)]
    rise = [r["result"].temperature[-1] - 30.0 for r in runs]
    assert rise[1] > 20 * rise[0] > 0


def test_compensation_example_prints_its_table_and_writes_its_report(tmp_path):
    """examples/compensation.py end to end: 20 rows (2 references x 2 temperatures x 5 cases), the HTML
    report with its table and one figure per reference."""
    import compensation
    out = tmp_path / "c.html"
    rows = compensation.main(["-o", str(out), "--figures", str(tmp_path / "fig")])
    assert len(rows) == 20
    text = out.read_text()
    assert "observer, aware" in text and 'id="fig-control_error_0"' in text and 'id="fig-control_error_1"' in text
    assert (tmp_path / "fig" / "control_error_1.png").stat().st_size > 1000
