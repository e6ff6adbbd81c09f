"""Simulation: analytic oracles, published findings, and the result object.

Each test names its oracle: an analytic solution, a definition, or the paper's findings.
The differential tests against the independent NumPy/SciPy reference are in test_differential.py."""

import math

import numpy as np
import pytest

import thermofriction as tf

PAPER_PLANT = tf.StickSlipPlant(mass=0.05, end_effector_mass=0.05, damping_ratio=0.2488,
                                natural_frequency=6685.5, gain=0.096e-6)


def ramp_for_velocity(v, gain=0.096e-6, duration=1.0):
    """A voltage ramp that moves the stage at v [m/s] (x_p = K u in steady state)."""
    return tf.Sampled([0.0, duration], [0.0, v / gain * duration])


def sliding_plant():
    """A stage that moves at the ramp's speed whatever the friction, and an end effector too
    heavy to follow it: the contact slides steadily at v_r = -v_stage."""
    return tf.StickSlipPlant(mass=0.05, end_effector_mass=1e14, damping_ratio=0.7, natural_frequency=2e4,
                             gain=0.096e-6)


@pytest.mark.parametrize("v_stage", [2e-4, 1e-3, -5e-3, 2e-2])
def test_lugre_steady_sliding_force_is_stribeck_curve_plus_viscous__analytic(v_stage):
    """Analytic: in steady sliding z' = 0, so F = g(v) sgn(v) + sigma2 v."""
    fr = tf.LuGre(sigma0=1e6, sigma1=300.0, fc=1.0, sigma2=40.0, fs=1.5, vs=1e-3, vd=5e-3)
    model = tf.Model(sliding_plant(), fr)
    # z relaxes at sigma0 |v| / g (133/s at the slowest speed): 0.3 s is 40 time constants
    res = tf.simulate(model, 0.3, input=ramp_for_velocity(v_stage), sample_rate=2000,
                      controller=tf.StepSizeController(rtol=1e-9))
    v = res.relative_velocity[-1]
    assert v == pytest.approx(-v_stage, rel=1e-6)
    g = 1.0 + 0.5 * math.exp(-(v / 1e-3) ** 2)
    expected = g * np.sign(v) + 40.0 * v
    assert res.friction_force[-1] == pytest.approx(expected, rel=1e-6)
    assert res.states[-1, 0] == pytest.approx(g * np.sign(v) / 1e6, rel=1e-6)


@pytest.mark.parametrize("T", [31.0, 36.0, 40.0, 41.5])
@pytest.mark.parametrize("v_stage", [1e-3, -3e-3])
def test_model_ii_scale_equals_eq12_in_steady_sliding__analytic(T, v_stage, model_ii):
    """Eq. (12): |F'| = |F_L| + dF(T) along the sliding direction, i.e. fc + dF(T) for the
    paper's LuGre (no Stribeck, sigma2 = 0) once sliding is steady."""
    model = tf.Model(sliding_plant(), model_ii.friction, model_ii.thermal)
    res = tf.simulate(model, 0.05, temperature=T, input=ramp_for_velocity(v_stage), sample_rate=2000,
                      controller=tf.StepSizeController(rtol=1e-9))
    fc = model_ii.friction.fc
    dF = model_ii.thermal.dF(T)
    assert np.sign(res.friction_force[-1]) == np.sign(res.relative_velocity[-1])
    assert abs(res.friction_force[-1]) == pytest.approx(fc + dF, rel=1e-6)


def test_model_ii_offset_form_adds_dF_along_the_sliding_direction__analytic(model_ii):
    th = tf.ModelII(model_ii.thermal.dF, form="offset")
    model = tf.Model(sliding_plant(), model_ii.friction, th)
    res = tf.simulate(model, 0.05, temperature=40.0, input=ramp_for_velocity(2e-3), sample_rate=2000,
                      controller=tf.StepSizeController(rtol=1e-9))
    assert abs(res.friction_force[-1]) == pytest.approx(model_ii.friction.fc + th.dF(40.0), rel=1e-6)


@pytest.mark.parametrize("solver", [tf.Dopri5(), tf.Rodas4(), tf.AutoSwitch()])
def test_frictionless_stage_step_response_is_exact_second_order__analytic(solver):
    """Analytic: with friction removed (forces of 1e-12 N) the stage is m x'' + c x' + k x = T_em u,
    whose response to a step of u is the textbook underdamped second-order response."""
    fr = tf.LuGre(sigma0=1e-12, sigma1=0.0, fc=1e-12)
    model = tf.Model(PAPER_PLANT, fr)
    res = tf.simulate(model, 0.004, input=tf.Step(10.0, time=5e-4), sample_rate=100_000, solver=solver,
                      controller=tf.StepSizeController(rtol=1e-9))
    xi, wn, K = 0.2488, 6685.5, 0.096e-6
    wd = wn * math.sqrt(1 - xi ** 2)
    tau = np.clip(res.time - 5e-4, 0, None)
    exact = 10 * K * (1 - np.exp(-xi * wn * tau) * (np.cos(wd * tau) + xi / math.sqrt(1 - xi ** 2) * np.sin(wd * tau)))
    assert np.max(np.abs(res.stage_displacement - exact)) < 1e-6 * 10 * K


def test_model_i_is_the_base_model_with_parameters_at_T__definition(model_i):
    """Definition (docs/models.md#model-i): Model I at a constant T is LuGre with its laws evaluated at T."""
    T = 36.2
    p = model_i.parameters_at(T)
    base = tf.Model(model_i.plant, tf.LuGre(sigma0=p["sigma0"], sigma1=p["sigma1"], fc=p["fc"]), input=model_i.input)
    a = tf.simulate(model_i, 0.5, temperature=T)
    b = tf.simulate(base, 0.5)
    np.testing.assert_allclose(a.displacement, b.displacement, rtol=0, atol=1e-15)
    assert p["sigma0"] == pytest.approx(115072e3 * math.exp(-0.136 * T))
    assert p["sigma1"] == pytest.approx(-0.138 * T + 6.445)
    assert p["fc"] == pytest.approx(106.04 * math.exp(-0.159 * T))


def test_constant_sampled_temperature_equals_constant_temperature__definition(model_i):
    """A sampled signal that stays at 35 C is the constant 35 C, to the last bit when it adds no
    corner, and to the solver's tolerance when its knots add corners (other step sequences)."""
    a = tf.simulate(model_i, 0.4, temperature=35.0)
    b = tf.simulate(model_i, 0.4, temperature=([0.0, 0.4], [35.0, 35.0]))
    np.testing.assert_array_equal(a.displacement, b.displacement)
    c = tf.simulate(model_i, 0.4, temperature=([0.0, 0.1, 0.4], [35.0, 35.0, 35.0]))
    np.testing.assert_allclose(a.displacement, c.displacement, rtol=0, atol=1e-3 * np.ptp(a.displacement))
    assert np.all(c.temperature == 35.0)


@pytest.mark.parametrize("T", [30.8, 35.7, 41.5])
def test_default_tolerances_reproduce_a_tight_run_to_0p1_percent_of_range__convergence(T, model_i):
    """Convergence: the default controller (rtol 1e-6, scaled atol) against a run at rtol 1e-11."""
    tight = tf.simulate(model_i, 2.0, temperature=T, solver=tf.Dopri5(),
                        controller=tf.StepSizeController(rtol=1e-11))
    res = tf.simulate(model_i, 2.0, temperature=T)
    err = np.max(np.abs(res.displacement - tight.displacement)) / np.ptp(tight.displacement)
    assert err < 1e-3


def test_dense_output_is_consistent_across_output_grids__consistency(model_ii):
    """Dense output: a 1 kHz grid reads the same trajectory as a 20 kHz grid at common times."""
    fine = tf.simulate(model_ii, 0.6, temperature=38.0, sample_rate=20_000)
    coarse = tf.simulate(model_ii, 0.6, temperature=38.0, sample_rate=1_000)
    np.testing.assert_allclose(coarse.displacement, fine.displacement[::20], rtol=0,
                               atol=1e-4 * np.ptp(fine.displacement))


def test_step_sizes_add_up_to_the_displacement_over_whole_cycles__conservation(model_i):
    res = tf.simulate(model_i, 1.03, temperature=35.7, sample_rate=997)
    assert len(res.cycle_times) == 6 and np.allclose(res.cycle_times, np.arange(6) * 0.2)
    full = tf.simulate(model_i, 1.0, temperature=35.7, sample_rate=1000)
    assert res.step_sizes.sum() == pytest.approx(full.displacement[-1] - full.displacement[0], rel=1e-6)
    assert res.mean_velocity == pytest.approx(res.step_sizes.mean() * 5.0)


@pytest.mark.parametrize("preset", ["li2009-model-i", "li2009-model-ii"])
def test_paper_findings_end_effector_advances_more_at_higher_temperature__published(preset):
    """Li et al. (2009): under the 30 V, 5 Hz sawtooth the end effector advances, and the
    displacement over a fixed time grows with temperature over 30.8-41.5 C (Figs. 6, 9, 10)."""
    model = tf.load_model(preset)
    temps = [30.8, 33.9, 35.7, 38.4, 40.0, 41.5]
    disp = [tf.simulate(model, 1.0, temperature=T, sample_rate=1000).displacement[-1] for T in temps]
    assert all(d > 0 for d in disp)
    assert all(b > a for a, b in zip(disp, disp[1:])), disp
    assert disp[-1] > 1.5 * disp[0]


def test_mirrored_sawtooth_drives_the_end_effector_backwards__physics(model_i):
    fwd = tf.simulate(model_i, 1.0, temperature=38.0, sample_rate=1000)
    back = tf.simulate(model_i, 1.0, temperature=38.0, sample_rate=1000,
                       input=tf.Sawtooth(30, 5, rise=0.999, direction=-1))
    assert fwd.displacement[-1] > 0 > back.displacement[-1]


def test_end_effector_feels_minus_F__sign_convention(model_i):
    """docs/models.md#conventions: the end effector feels -F (m_e a_e = -F), where F resists the sliding v_r = v_e - v_p
    (its steady-sliding sign is checked by the analytic tests above)."""
    res = tf.simulate(model_i, 0.4, temperature=38.0, sample_rate=200_000)
    accel = np.gradient(res.velocity, res.time)
    sliding = np.nonzero(np.abs(res.relative_velocity) > 1e-3)[0]
    assert sliding.size > 10
    np.testing.assert_allclose(model_i.plant.end_effector_mass * accel[sliding], -res.friction_force[sliding],
                               rtol=0.02, atol=0.02 * np.max(np.abs(res.friction_force)))


def test_stiff_bristles_and_light_end_effector_finish_quickly_and_agree_across_solvers__convergence():
    """The issue's stiff case: sigma0 = 1e8 N/m with m_e = 1 g."""
    import time
    plant = tf.StickSlipPlant(mass=0.05, end_effector_mass=0.001, damping_ratio=0.2488, natural_frequency=6685.5,
                              gain=0.096e-6)
    model = tf.Model(plant, tf.LuGre(sigma0=1e8, sigma1=2.3, fc=0.9), input=tf.Sawtooth(30, 5, rise=0.999))
    t0 = time.perf_counter()
    res = tf.simulate(model, 2.0)
    assert time.perf_counter() - t0 < 5.0
    stiff = tf.simulate(model, 2.0, solver=tf.Rodas4(), controller=tf.StepSizeController(rtol=1e-9))
    assert np.max(np.abs(res.displacement - stiff.displacement)) < 1e-3 * np.ptp(stiff.displacement)


def test_result_dataframe_and_csv_follow_spec7(tmp_path, model_i):
    res = tf.simulate(model_i, 0.01, temperature=35.0, sample_rate=1000)
    df = res.to_dataframe()
    assert list(df.columns[:4]) == ["time", "input", "stage_displacement", "stage_velocity"]
    assert "z" in df.columns and len(df) == 11
    path = tmp_path / "out.csv"
    res.to_csv(path)
    header = path.read_text().splitlines()[0].split(",")
    assert header == ["time[s]", "input[V]", "stage_displacement[m]", "displacement[m]", "velocity[m/s]",
                      "friction_force[N]", "temperature[C]", "z[m]"]
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    np.testing.assert_allclose(data[:, 3], res.displacement, rtol=1e-11, atol=1e-20)


def test_solver_failure_says_when_and_where():
    model = tf.load_model("li2009-base")
    with pytest.raises(tf.SolverError) as e:
        tf.simulate(model, 1.0, controller=tf.StepSizeController(max_steps=50))
    assert e.value.time is not None and 0 <= e.value.time < 1.0
    assert "x_e =" in str(e.value) and "max_steps" in str(e.value)


def test_model_ii_lambda_not_positive_is_an_error_not_a_clamp(model_ii):
    with pytest.raises(tf.InputError, match="lambda"):
        tf.simulate(model_ii, 0.1, temperature=46.0)


def test_law_outside_its_range_warns(model_i):
    with pytest.warns(tf.TemperatureRangeWarning, match="sigma0"):
        tf.simulate(model_i, 0.01, temperature=25.0)


def test_thermal_model_without_temperature_is_an_input_error(model_i):
    with pytest.raises(tf.InputError, match="temperature"):
        tf.simulate(model_i, 0.1)


def test_anti_damped_offset_form_warns_and_passive_one_does_not(model_ii):
    """The paper's dF < 0 in the offset form is a negative damping dF/v_smooth near v = 0 far
    stronger than sigma1 (the differential tests show default tolerances miss 0.1 % there); a
    positive dF is passive and must not warn."""
    import warnings as _w
    from thermofriction.models import ModelII
    offset = tf.Model(model_ii.plant, model_ii.friction, ModelII(model_ii.thermal.dF, "offset"), model_ii.input)
    with pytest.warns(tf.ConditioningWarning, match="anti-damped"):
        tf.simulate(offset, 0.01, temperature=40.0)
    passive = tf.Model(model_ii.plant, model_ii.friction, ModelII(tf.Const(0.3), "offset"), model_ii.input)
    with _w.catch_warnings():
        _w.simplefilter("error", tf.ConditioningWarning)
        tf.simulate(passive, 0.01, temperature=40.0)
    with _w.catch_warnings():
        _w.simplefilter("error", tf.ConditioningWarning)
        tf.simulate(model_ii, 0.01, temperature=40.0)  # the scale form


CANUDAS = dict(sigma0=1e5, sigma1=1e5 ** 0.5, fc=1.0, fs=1.5, vs=1e-3, sigma2=0.4)


def test_lugre_passivity_condition_warns_for_large_sigma1_and_not_with_vd_or_the_paper():
    """Oracle: the dissipativity inequality F v >= d/dt(sigma0 z^2/2) on |z| <= fs/sigma0 --
    at high speed it reduces to sigma1 <= sigma2 fc/(fs - fc) (0.8 N s/m for the Canudas de Wit
    1995 set, whose sigma1 = 316 violates it); a velocity-dependent sigma1 (vd) restores it, and
    the paper's LuGre (fs = fc) satisfies it."""
    import warnings as _w
    spring = tf.MassPlant(1.0, 2.0, 0.1)
    with pytest.warns(tf.PassivityWarning, match=r"sigma1 <= sigma2 fc/\(fs - fc\) = 0\.8"):
        tf.simulate(tf.Model(spring, tf.LuGre(**CANUDAS)), 0.01)
    from thermofriction.models import dissipativity_violation
    v_bad, _ = dissipativity_violation("lugre", CANUDAS)
    # the quadratic's minimum at the edge |z| = fs/sigma0 turns negative where fs^2/g + v (sigma1 + sigma2 -
    # sigma1 fs / g) = 0, g ~ fc: v = fs^2 / (fc (sigma1 (fs - fc)/fc - sigma2)) = 0.01428 m/s
    assert v_bad == pytest.approx(1.5 ** 2 / (1e5 ** 0.5 * 0.5 - 0.4), rel=0.02)
    just_passive = dict(CANUDAS, sigma1=0.8 * 0.999)
    assert dissipativity_violation("lugre", just_passive) is None
    assert dissipativity_violation("lugre", dict(CANUDAS, sigma1=0.8 * 1.2)) is not None
    with _w.catch_warnings():
        _w.simplefilter("error", tf.PassivityWarning)
        tf.simulate(tf.Model(spring, tf.LuGre(**CANUDAS, vd=1e-3)), 0.01)
        tf.simulate(tf.load_model("li2009-base"), 0.01)
        tf.simulate(tf.load_model("li2009-model-i"), 0.01, temperature=35.0)


def test_identification_and_datasets_refuse_what_they_cannot_do_with_a_clear_message():
    """Identification is implemented on the stick-slip actuator (any friction model: see
    tests/test_identify_friction.py); datasets record that actuator. Other plants simulate, and say
    so when asked for more."""
    base = tf.load_model("li2009-base")
    synthetic_experiments = tf.synthesize(base, [30.0], duration=0.2, sample_rate=2000)
    mass = tf.Model(tf.MassPlant(1.0, 2.0, 0.1), tf.LuGre(**CANUDAS))
    with pytest.raises(tf.InputError, match="'mass' plant"):
        tf.identify(synthetic_experiments, method="base", init=mass)
    with pytest.raises(tf.InputError, match="stick-slip actuator"):
        tf.synthesize(mass, [30.0], input=tf.Sine(1.0, 1.0))


def test_prescribed_motion_needs_a_continuous_displacement():
    model = tf.Model(tf.PrescribedMotion(), tf.Dahl(sigma0=1e5, fc=1.0))
    with pytest.raises(tf.InputError, match="needs an input waveform"):
        tf.simulate(model, 0.1)
    with pytest.raises(tf.InputError, match="slew"):
        tf.simulate(model, 0.1, input=tf.Step(1e-6, time=0.05))


def test_static_map_under_prescribed_motion_needs_no_integration():
    """Oracle: the Coulomb map itself, F = fc tanh(v/v_smooth) + sigma2 v, at the prescribed
    sine's analytic velocity (no state: the samples are evaluated directly)."""
    import numpy as np
    model = tf.Model(tf.PrescribedMotion(), tf.Coulomb(fc=2.0, sigma2=0.5, v_smooth=1e-4), input=tf.Sine(1e-3, 2.0))
    res = tf.simulate(model, 1.0, sample_rate=1000)
    v = 1e-3 * 2 * np.pi * 2.0 * np.cos(2 * np.pi * 2.0 * res.time)
    np.testing.assert_allclose(res.velocity, v, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(res.friction_force, 2.0 * np.tanh(v / 1e-4) + 0.5 * v, rtol=1e-12, atol=1e-12)
    assert res.stats["steps"] == 0 and res.stage_displacement is None
    assert "stage_displacement[m]" not in res.columns() and "input[m]" in res.columns()
