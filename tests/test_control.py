"""The real-time C API (realtime.h, control.h) and thermofriction.control. Each test names its oracle."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest

pytestmark = pytest.mark.filterwarnings("ignore::thermofriction.PassivityWarning")  # Canudas' set, known

import sys
from pathlib import Path

import thermofriction as tf
from thermofriction import control as C

sys.path.insert(0, str(Path(__file__).resolve().parent))
import reference as R  # noqa: E402
from conftest import every_friction_model  # noqa: E402

MODELS = every_friction_model()
A, W = 20e-6, 2 * math.pi * 5.0  # prescribed motion x = A sin(W t): +-0.63 mm/s, 5 Hz


def prescribed(kind, thermal=None):
    friction = MODELS[kind]
    if thermal == "I":
        friction = dataclasses.replace(friction, fc=None)
        return tf.Model(tf.PrescribedMotion(), friction, tf.ModelI({"fc": tf.Exp(a=1.0 / math.exp(-0.159 * 30),
                                                                                 b=-0.159)}))
    if thermal == "II":
        return tf.Model(tf.PrescribedMotion(), friction, tf.ModelII(tf.Linear(a=-0.02, b=0.6)))
    return tf.Model(tf.PrescribedMotion(), friction)


@pytest.mark.parametrize("thermal", [None, "I", "II"])
@pytest.mark.parametrize("kind", list(MODELS))
def test_fixed_step_converges_to_the_adaptive_solver(kind, thermal):
    """Oracle: the adaptive solver (tf.simulate, prescribed motion, rtol 1e-10). The real-time step at
    dt = 1e-4, 1e-5, 1e-6 s (velocity held at each step's midpoint value) approaches its friction
    force over two periods of a 5 Hz sine: the max error falls at first order with dt (measured
    10x per decade) and is below 0.1 % of fc at 1e-6 s; at 35 C for the thermal models."""
    model = prescribed(kind, thermal)
    T = 35.0 if thermal else None
    errors = []
    for dt in (1e-4, 1e-5, 1e-6):
        n = int(round(0.4 / dt))
        t_mid = (np.arange(n) + 0.5) * dt
        F, _ = C.friction_steps(model, A * W * np.cos(W * t_mid), dt, temperature=T)
        t_end = (np.arange(n) + 1) * dt
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", tf.TemperatureRangeWarning)
            ref = tf.simulate(model, t_eval=np.concatenate([[0.0], t_end]), temperature=T,
                              input=tf.Sine(amplitude=A, frequency=5.0),
                              controller=tf.StepSizeController(rtol=1e-10)).friction_force[1:]
        errors.append(float(np.max(np.abs(F - ref))))
    assert errors[2] < 1e-3, errors  # fc = 1 N
    assert errors[1] <= errors[0] / 5 or errors[0] < 1e-6, errors  # first order (10x per decade) or at the floor


def test_large_steps_stay_stable_and_land_on_the_sliding_force():
    """Oracle (analytic): LuGre sliding at constant v tends to F = g(v) + sigma2 v. At dt = 10 ms
    (100x the bristle time constant g / (sigma0 |v|) = 0.1 ms at 0.1 m/s) the real-time step lands
    there at the first step, where explicit Euler would diverge (its limit is dt < 2 g / (sigma0 |v|))."""
    model = prescribed("lugre")
    v = 0.1
    F, _ = C.friction_steps(model, np.full(50, v), 1e-2)
    g = 1.0 + 0.5 * math.exp(-(v / 1e-3) ** 2)
    np.testing.assert_allclose(F, g + 0.4 * v, rtol=1e-9)


def test_compensation_table_shows_what_temperature_awareness_buys():
    """The issue's comparison on the stage-model-i preset (PID at 10 kHz; slow sine, 1 mm at 0.5 Hz):
    at 30 C both compensations cut the RMS error >= 20x and blind = aware (the model is calibrated
    there); at 41.5 C the blind compensation (told 30 C) over-compensates a friction that fell by
    ~84 % and is worse than none, while the aware one keeps its 30 C performance. Regression
    oracle: these orderings, not the digits."""
    stage = tf.load_model("stage-model-i")
    ref = C.sine_reference(1e-3, 0.5, 2.0)
    rows = {(r["temperature"], r["compensation"]): r["rms_error"] for r in C.compare_compensation(stage, [ref])}
    for comp in ("feed-forward", "observer"):
        assert rows[(30.0, f"{comp}, aware")] < rows[(30.0, "none")] / 20
        assert rows[(30.0, f"{comp}, blind")] == pytest.approx(rows[(30.0, f"{comp}, aware")], rel=1e-12)
        assert rows[(41.5, f"{comp}, blind")] > rows[(41.5, "none")]
        assert rows[(41.5, f"{comp}, aware")] < rows[(41.5, "none")] / 10
        assert rows[(41.5, f"{comp}, aware")] < 2 * rows[(30.0, f"{comp}, aware")]


def test_observer_estimate_converges_to_the_plant_friction_in_closed_loop():
    """Oracle: the plant's own friction. With a perfect model (temperature-aware) the observer's
    estimate F^ follows the true friction force of the plant in closed loop: after the first
    0.2 s, max |F^ - F| < 2 % of fc on the sine reference, from an estimate started at rest."""
    stage = tf.load_model("stage-model-i")
    ref = C.sine_reference(1e-3, 0.5, 2.0)
    res = C.simulate_loop(stage, ref, temperature=41.5, compensation=C.Observer(stage, 100.0))
    v = np.gradient(res.position, res.time)
    # the plant's friction at each period start: the same real-time model driven by the plant's velocity
    F_true, _ = C.friction_steps(stage, v, ref.time[1] - ref.time[0], temperature=41.5)
    fc = stage.parameters_at(41.5)["fc"]
    late = res.time > 0.2
    assert np.max(np.abs(res.compensation[late] - F_true[late])) < 0.02 * fc


def test_loop_refuses_a_plant_it_cannot_drive():
    with pytest.raises(tf.InputError, match="single-mass"):
        C.simulate_loop(tf.load_model("li2009-model-i"), C.sine_reference(1e-3, 0.5, 0.1), temperature=30.0)


def test_closed_loop_matches_the_plain_python_reference():
    """Oracle: independent reference implementation (tests/reference/ reference_closed_loop: the
    same loop as scalar Python, laws evaluated by the reference). The C loop's positions agree to
    1e-15 m over 1 s of the sine at 41.5 C with the observer (the same algorithm: rounding only)."""
    stage = tf.load_model("stage-model-i")
    ref = C.sine_reference(1e-3, 0.5, 1.0)
    res = C.simulate_loop(stage, ref, temperature=41.5, compensation=C.Observer(stage, 100.0))
    xs = R.reference_closed_loop(stage, ref, 41.5, C.DEFAULT_PID, gain=100.0)
    assert np.max(np.abs(res.position - xs)) < 1e-15


# ---------------------------------------------------------------------------------------------
# Issue 17: the real-time API and the compensation layer check their inputs. Oracle: the
# documented refusal (the package's error naming the argument), never a crash or a wrong number.
# ---------------------------------------------------------------------------------------------

def mass_stage(kind):
    return tf.Model(tf.MassPlant(mass=1.0), MODELS[kind])


@pytest.mark.parametrize("kind", ["gms", "coulomb", "stribeck"])
def test_observer_refuses_a_model_without_one_bristle_state(kind):
    """The issue's reproduction: simulate_loop(gms_model, ref, temperature=35,
    compensation=Observer(gms_model)) read past a one-double buffer in C (one `extra` for every GMS
    element). The observer estimates a bristle deflection: LuGre, Dahl and elasto-plastic have one;
    the others are refused with a message that says what to use instead."""
    stage = mass_stage(kind)
    ref = C.sine_reference(1e-3, 0.5, 0.1)
    with pytest.raises(tf.InputError, match=f"bristle state.*{kind} model.*FeedForward"):
        C.simulate_loop(stage, ref, temperature=35, compensation=C.Observer(stage))


def test_the_core_refuses_the_observer_on_gms_even_past_the_python_check():
    """Defence in depth: an Observer whose model was swapped after construction reaches the C core,
    which refuses it (tf_observer_step_status / tf_loop_run) instead of overflowing its stack."""
    obs = C.Observer(mass_stage("lugre"))
    object.__setattr__(obs, "model", mass_stage("gms"))
    with pytest.raises(tf.InputError, match="C core refused.*compensation.*LuGre, Dahl or elasto-plastic"):
        C.simulate_loop(mass_stage("lugre"), C.sine_reference(1e-3, 0.5, 0.1), temperature=35, compensation=obs)


@pytest.mark.parametrize("kind", C.OBSERVED_MODELS)
def test_observer_runs_on_every_bristle_model(kind):
    """Oracle: the observer's estimate of a perfect model follows the plant's friction (as for
    the preset above), here for each model it accepts: after 0.2 s within 5 % of fc = 1 N."""
    stage = mass_stage(kind)
    ref = C.sine_reference(1e-3, 0.5, 1.0)
    res = C.simulate_loop(stage, ref, temperature=35, compensation=C.Observer(stage, 100.0))
    F_true, _ = C.friction_steps(stage, np.gradient(res.position, res.time), ref.time[1] - ref.time[0])
    late = res.time > 0.2
    assert np.all(np.isfinite(res.compensation))
    assert np.max(np.abs(res.compensation[late] - F_true[late])) < 0.05


def law_i_model():
    """fc = fs = 2.5 - 0.05 T: positive below 50 C, negative above (the issue's F = -1.6e17 N at 60 C)."""
    friction = dataclasses.replace(MODELS["lugre"], fc=None, fs=None)
    law = tf.Linear(a=-0.05, b=2.5)
    return tf.Model(tf.PrescribedMotion(), friction, tf.ModelI({"fc": law, "fs": law}))


def test_friction_steps_refuses_a_model_i_law_out_of_its_domain():
    model = law_i_model()
    v = np.full(4, 1e-3)
    F, _ = C.friction_steps(model, v, 1e-4, temperature=35.0)
    assert np.all(np.isfinite(F)) and np.all(F > 0)
    with pytest.raises(tf.InputError, match="fc.*positive"):
        C.friction_steps(model, v, 1e-4, temperature=60.0)
    # one temperature per step: the core checks the model at each new one and names the step
    with pytest.raises(tf.InputError, match=r"invalid at step 2 \(T = 60 C\): 'fc' is out of its domain"):
        C.friction_steps(model, v, 1e-4, temperature=np.array([35.0, 40.0, 60.0, 35.0]))


def test_friction_steps_refuses_a_model_ii_that_reverses_friction():
    """Model II's lambda = 1 + dF/fc <= 0 reverses friction: refused (it gave negative forces)."""
    model = tf.Model(tf.PrescribedMotion(), MODELS["lugre"], tf.ModelII(tf.Linear(a=-0.1, b=0.6)))
    v = np.full(3, 1e-3)
    assert np.all(C.friction_steps(model, v, 1e-4, temperature=5.0)[0] > 0)
    with pytest.raises(tf.InputError, match="lambda.*reverse friction"):
        C.friction_steps(model, v, 1e-4, temperature=35.0)
    with pytest.raises(tf.InputError, match=r"step 1 \(T = 35 C\): 'dF' is out of its domain"):
        C.friction_steps(model, v, 1e-4, temperature=np.array([5.0, 35.0, 5.0]))


@pytest.mark.parametrize("velocity, dt, temperature, match", [
    ([1e-3, math.nan, 1e-3], 1e-4, None, r"velocity\[1\] is nan"),
    ([1e-3, math.inf], 1e-4, None, r"velocity\[1\] is inf"),
    ([1e-3], 0.0, None, "dt must be a positive finite number"),
    ([1e-3], math.nan, None, "dt must be a positive finite number"),
    ([1e-3], "1e-4", None, "dt must be a number"),
    ([1e-3], 1e-4, math.nan, "temperature must be a finite number"),
    ([1e-3, 1e-3], 1e-4, [35.0, math.inf], r"temperature\[1\] is inf"),
    ([1e-3, 1e-3], 1e-4, [35.0], "temperature must be one-dimensional with 2 values"),
    ("fast", 1e-4, None, "velocity must be an array of numbers"),
])
def test_friction_steps_refuses_bad_arguments(velocity, dt, temperature, match):
    with pytest.raises(tf.InputError, match=f"friction_steps: {match}"):
        C.friction_steps(prescribed("lugre"), velocity, dt, temperature=temperature)


def test_friction_steps_needs_a_temperature_for_a_thermal_model_and_a_model():
    with pytest.raises(tf.InputError, match="depends on temperature"):
        C.friction_steps(law_i_model(), [1e-3], 1e-4)
    with pytest.raises(tf.InputError, match="model must be a thermofriction Model"):
        C.friction_steps("li2009-model-i", [1e-3], 1e-4)


def test_an_overflowing_step_is_a_solver_error():
    """v = 1e308: sigma1 z' overflows. The core refuses the step (TF_ERR_NONFINITE) and keeps the
    state; the package reports it as a SolverError naming the step."""
    with pytest.raises(tf.SolverError, match="step 1: force or state not finite"):
        C.friction_steps(prescribed("lugre"), [1e-3, 1e308], 1e-4)


def test_simulate_loop_refuses_bad_arguments():
    stage = tf.load_model("stage-model-i")
    ref = C.sine_reference(1e-3, 0.5, 0.1)
    bad_ref = C.Reference("bad", ref.time, ref.position.copy(), ref.velocity)
    bad_ref.position[7] = math.nan
    cases = [
        (dict(stage="stage-model-i"), "stage must be a thermofriction Model"),
        (dict(reference="sine"), "reference must be a Reference"),
        (dict(reference=bad_ref), r"reference.position\[7\] is nan"),
        (dict(reference=C.Reference("one", ref.time[:1], ref.position[:1], ref.velocity[:1])), "two samples"),
        (dict(temperature=math.nan), "temperature must be a finite number"),
        (dict(temperature="35"), "temperature must be a number"),
        (dict(substeps=0), "substeps must be a positive whole number"),
        (dict(substeps=1.5), "substeps must be a positive whole number"),
        (dict(pid=(1, 2, 3)), "pid must be a PID"),
        (dict(compensation="observer"), "compensation must be FeedForward, Observer or None"),
        (dict(temperature=80.0), "the stage.*Model I at 80 C"),
    ]
    for change, match in cases:
        kw = dict(stage=stage, reference=ref, temperature=41.5)
        kw.update(change)
        with pytest.raises(tf.InputError, match=match):
            C.simulate_loop(kw.pop("stage"), kw.pop("reference"), **kw)


def test_compensation_and_pid_check_their_arguments():
    stage = tf.load_model("stage-model-i")
    for make, match in [
        (lambda: C.PID(kp=math.nan, ki=0, kd=0), "PID: kp must be a finite number"),
        (lambda: C.PID(kp=1, ki=0, kd=0, tau_d=-1e-3), "PID: tau_d must be a finite number of 0 or more"),
        (lambda: C.Observer(stage, gain=-1.0), "Observer: gain must be a finite number of 0 or more"),
        (lambda: C.Observer(stage, temperature=math.inf), "Observer: temperature must be a finite number"),
        (lambda: C.FeedForward("stage-model-i"), "FeedForward: model must be a thermofriction Model"),
    ]:
        with pytest.raises(tf.InputError, match=match):
            make()
    # a compensation told a temperature where its model is invalid
    with pytest.raises(tf.InputError, match="feed-forward compensation's model: Model I at 80 C"):
        C.simulate_loop(stage, C.sine_reference(1e-3, 0.5, 0.1), temperature=41.5,
                        compensation=C.FeedForward(stage, temperature=80.0))


def test_an_unstable_loop_is_a_solver_error():
    """Positive feedback (kp < 0) diverges: the core stops at the first non-finite state."""
    with pytest.raises(tf.SolverError, match="unstable"):
        C.simulate_loop(tf.load_model("stage-model-i"), C.sine_reference(1e-3, 0.5, 0.2), temperature=41.5,
                        pid=C.PID(kp=-1e12, ki=0.0, kd=0.0))


def test_loop_work_is_bounded_substeps_int_max_refused_at_once():
    """Issue 32, item 8: tf_loop_run put no bound on n x substeps, and substeps = 2**31 - 1 (INT_MAX) ran
    for hours. The core now refuses more than 1e8 plant substeps in one run (TF_LOOP_MAX_SUBSTEPS) before
    it starts, which the package reports as an InputError naming substeps; values beyond a C int too.
    A loop at the bound's scale but below it still runs."""
    import time

    stage = tf.load_model("stage-model-i")
    ref = C.sine_reference(1e-3, 0.5, 0.1)  # 0.1 s at 10 kHz: 1001 periods
    for substeps in (2**31 - 1, 10**5 + 1, 10**30):
        start = time.monotonic()
        with pytest.raises(tf.InputError, match="substeps"):
            C.simulate_loop(stage, ref, temperature=41.5, substeps=substeps)
        assert time.monotonic() - start < 2.0
    res = C.simulate_loop(stage, ref, temperature=41.5, substeps=20)
    assert np.isfinite(res.position).all()
