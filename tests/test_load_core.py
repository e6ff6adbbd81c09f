"""The load as an input of the C core, the simulator and the real-time API (issue 43, the C side).

Truths: models/load_laws.py's LoadLaw.value (the one Python statement of the laws) for the C evaluation; central
differences for its partials and coefficient derivatives; the independent reference implementation (tests/reference,
its own load law written from the definition) for a preloaded stage under a load ramp; the adaptive simulator for
the real-time steps; the object files' symbols for the no-allocation rule."""

from __future__ import annotations

import dataclasses
import re
import shutil
import subprocess
import warnings

import numpy as np
import pytest

import reference as R
import thermofriction as tf
from thermofriction import _bridge
from thermofriction.control import friction_steps
from thermofriction.data.force import force_experiment
from thermofriction.drive import drive
from thermofriction.fmu_sources import sources_dir
from thermofriction.measurements.force_load import run_load
from thermofriction.models import PWL, Const, Exp, Linear, LoadLaw, LoadTerm, Poly

BASES = {"const": Const(value=0.45), "linear": Linear(a=-2.1e-3, b=0.52), "exp": Exp(a=0.61, b=-4.3e-3),
         "poly": Poly(c=(0.5, -1.1e-3, 7e-6)), "pwl": PWL(T=(10.0, 30.0, 55.0), values=(0.55, 0.47, 0.44))}
TERMS = {"proportional": LoadTerm("proportional"),
         "proportional-saturated-interaction": LoadTerm("proportional", saturation=90.0, interaction=-3e-5),
         "affine-product-interaction": LoadTerm("affine", k=0.018, interaction=1.2e-4),
         "affine-product-saturated": LoadTerm("affine", k=-2.5e-3, saturation=140.0),
         "affine-sum": LoadTerm("affine", k=6e-3, combine="sum"),
         "affine-sum-saturated-interaction": LoadTerm("affine", k=6e-3, combine="sum", saturation=60.0,
                                                      interaction=2e-5)}
T_GRID = np.array([-8.0, 12.5, 31.0, 58.0, 74.0])
L_GRID = np.array([-210.0, -3.5, 0.0, 17.25, 88.0, 400.0])


def _grid():
    T, L = np.meshgrid(T_GRID, L_GRID)
    return np.ascontiguousarray(T.ravel()), np.ascontiguousarray(L.ravel())


@pytest.mark.parametrize("base", list(BASES))
@pytest.mark.parametrize("term", list(TERMS))
def test_the_c_load_law_is_load_laws_value(base, term):
    """Truth: LoadLaw.value (models/load_laws.py), to 1e-14 relative (the same operations in the same order; the
    temperature laws' own evaluation, numpy against libm, differs by an ulp at most), for every base kind and every
    load kind, combination, saturation and interaction, at loads of both signs and zero."""
    law = LoadLaw(BASES[base], TERMS[term])
    T, L = _grid()
    v, _, _, _ = _bridge.law_eval_load(law, T, L)
    truth = law.value(T, L, warn=False)
    scale = np.maximum(np.abs(truth), 1e-300)
    assert np.max(np.abs(v - truth) / scale) <= 1e-14, np.max(np.abs(v - truth) / scale)


@pytest.mark.parametrize("base", ["linear", "exp", "poly", "pwl"])
@pytest.mark.parametrize("term", list(TERMS))
def test_the_c_partials_and_coefficient_derivatives_are_central_differences(base, term):
    """Truth: central differences -- of the C value in T and L (h = 1e-4 C, 1e-5 |L|), and of LoadLaw.value in
    each coefficient (LoadLaw.with_coefficients, h = 1e-6 of the coefficient): 1e-7 of the value's scale (their
    truncation and rounding are ~1e-9 here). Away from L = 0, where |L| has its kink."""
    law = LoadLaw(BASES[base], TERMS[term])
    T, L = _grid()
    keep = L != 0.0
    T, L = np.ascontiguousarray(T[keep]), np.ascontiguousarray(L[keep])
    v, dT, dL, dc = _bridge.law_eval_load(law, T, L)
    scale = float(np.max(np.abs(v)))
    ev = lambda T_, L_: _bridge.law_eval_load(law, np.ascontiguousarray(T_), np.ascontiguousarray(L_))[0]  # noqa
    fT = (ev(T + 1e-4, L) - ev(T - 1e-4, L)) / 2e-4
    hL = 1e-5 * np.abs(L)
    fL = (ev(T, L + hL) - ev(T, L - hL)) / (2 * hL)
    assert np.max(np.abs(dT - fT)) <= 1e-7 * scale / 10.0, np.max(np.abs(dT - fT))  # per C: ~the value over 10 C
    assert np.max(np.abs(dL - fL) * np.abs(L)) <= 1e-7 * scale, np.max(np.abs(dL - fL) * np.abs(L))
    c = np.array(law.coefficients(), float)
    assert dc.shape == (T.size, c.size) == (T.size, len(law.coefficient_names()))
    for k in range(c.size):
        h = 1e-6 * max(abs(c[k]), 1e-3)
        up, dn = c.copy(), c.copy()
        up[k] += h
        dn[k] -= h
        fd = (law.with_coefficients(up).value(T, L, warn=False) - law.with_coefficients(dn).value(T, L, warn=False)) \
            / (2 * h)
        assert np.max(np.abs(dc[:, k] - fd)) * max(abs(c[k]), 1e-3) <= 1e-7 * scale, (law.coefficient_names()[k],
                                                                                       np.max(np.abs(dc[:, k] - fd)))


def preloaded_stage(input=None):
    """A stage of 1 kg pulled through a spring (2 N/m at 0.1 m/s) over a LuGre contact whose levels follow its
    normal force N: fc = mu(T) |N| (proportional), fs = fc_0(T) (1 + k s) + c T s (affine, saturated, with an
    interaction)."""
    fc = LoadLaw(Linear(a=-1e-4, b=0.014), LoadTerm("proportional"))
    fs = LoadLaw(Linear(a=-2e-3, b=0.95), LoadTerm("affine", k=0.012, saturation=150.0, interaction=2e-5))
    friction = tf.LuGre(sigma0=1e5, sigma1=316.2, sigma2=0.4, fc=None, fs=None, vs=1e-3)
    return tf.Model(tf.MassPlant(mass=1.0, spring_stiffness=2.0, pull_velocity=0.1), friction,
                    tf.ModelI({"fc": fc, "fs": fs}), input=input)


RAMP = tf.Sampled(np.array([0.0, 1.0, 9.0, 12.0]), np.array([40.0, 40.0, 120.0, 120.0]))  # N


def test_a_preloaded_stage_under_a_load_ramp_matches_the_independent_reference():
    """Truth: the independent reference (tests/reference: its own load law, written from the definition, the
    plant's equations, SciPy's DOP853 at rtol 1e-11, restarted at the ramp's knots). The stage's displacement over
    12 s (sticking, breaking away near 7 s, slipping) while the normal force ramps 40 -> 120 N agrees to 1e-6 of
    its range (the issue's done-when; measured ~1e-11); the same run at a constant 40 N is far from it (the ramp is
    what the run is about), and matches the reference's at that constant load to 1e-6 as well."""
    model = preloaded_stage()
    t = np.linspace(0.0, 12.0, 1201)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tf.PassivityWarning)
        res = tf.simulate(model, t_eval=t, temperature=30.0, load=RAMP, solver="rodas4",
                          controller=tf.StepSizeController(rtol=1e-10))
        flat = tf.simulate(model, t_eval=t, temperature=30.0, load=40.0, solver="rodas4",
                           controller=tf.StepSizeController(rtol=1e-10))
    ref = R.reference_simulate_system(model, t, 30.0, load=RAMP, rtol=1e-11)
    x_range = float(np.ptp(ref.displacement))
    err = float(np.max(np.abs(res.displacement - ref.displacement))) / x_range
    print(f"load ramp: max |x error| / range = {err:.2e} (range {x_range:.4g} m), {res.stats['steps']} steps")
    assert x_range > 0.5 and err <= 1e-6
    assert np.max(np.abs(flat.displacement - ref.displacement)) > 1e-2 * x_range
    # a constant load: LuGre on a mass at one temperature and load takes the core's fast path (plant.c)
    ref_flat = R.reference_simulate_system(model, t, 30.0, load=40.0, rtol=1e-11)
    err_flat = float(np.max(np.abs(flat.displacement - ref_flat.displacement))) / np.ptp(ref_flat.displacement)
    print(f"constant load: max |x error| / range = {err_flat:.2e}")
    assert np.ptp(ref_flat.displacement) > 0.1 and err_flat <= 1e-6
    F = ref.friction_force
    assert np.max(np.abs(res.friction_force - F)) <= 1e-4 * np.ptp(F)


def test_a_model_with_a_law_of_the_load_needs_one_and_a_load_free_model_ignores_it(tmp_path):
    """The simulator names the law that needs a load; a load-free model gives the same run with or without one
    (the FMU, the loop and the sweeps take the load: tests/test_load_deploy.py)."""
    model = preloaded_stage()
    with pytest.raises(tf.InputError, match=r"\[thermal\] fc: a law of the load \(proportional.*give the run's load"):
        tf.simulate(model, 0.1, temperature=30.0)
    with pytest.raises(tf.InputError, match="load must be a number"):
        tf.simulate(model, 0.1, temperature=30.0, load="heavy")
    # fc = mu(T) |N| is 0 where the load ramp starts at 0 N: refused there before the run, naming both
    with pytest.raises(tf.InputError, match=r"Model I at 30 C and load 0: 'fc' must be positive"):
        tf.simulate(model, 0.1, temperature=30.0, load=(np.array([0.0, 1.0]), np.array([0.0, 50.0])))
    with warnings.catch_warnings():  # self-heating: the range it reached checked after the run at the load's
        warnings.simplefilter("ignore", tf.PassivityWarning)
        heated = tf.simulate(dataclasses.replace(model, heat=tf.models.Heat(heat_capacity=5.0, thermal_resistance=2.0,
                                                                             heat_fraction=1.0)),
                             12.0, sample_rate=100.0, temperature=25.0, load=RAMP)
    assert heated.temperature[-1] > 25.05 and np.ptp(heated.displacement) > 0.1
    # a zero waveform is the load 0 (an affine law's level at zero load), as the number 0 is
    affine = tf.Model(model.plant, tf.LuGre(sigma0=1e5, sigma1=316.2, sigma2=0.4, fc=0.5, fs=None, vs=1e-3),
                      tf.ModelI({"fs": model.laws["fs"]}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tf.PassivityWarning)
        zero = [tf.simulate(affine, 9.0, sample_rate=100.0, temperature=30.0, load=L)
                for L in (tf.waveforms.Zero(), 0.0, 60.0)]
    assert np.array_equal(zero[0].displacement, zero[1].displacement)
    assert np.max(np.abs(zero[2].displacement - zero[1].displacement)) > 1e-2
    free = tf.Model(tf.MassPlant(mass=1.0, spring_stiffness=2.0, pull_velocity=0.1),
                    tf.LuGre(sigma0=1e5, sigma1=316.2, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tf.PassivityWarning)
        a = tf.simulate(free, 1.0, sample_rate=100.0)
        b = tf.simulate(free, 1.0, sample_rate=100.0, load=RAMP)
    assert np.array_equal(a.displacement, b.displacement) and np.ptp(a.displacement) > 0


def prescribed_stage():
    model = preloaded_stage()
    return tf.Model(tf.PrescribedMotion(), model.friction, model.thermal)


def test_the_real_time_steps_with_a_load_converge_to_the_simulated_friction():
    """Truth: the adaptive simulator (prescribed motion, rtol 1e-10) under the same load waveform. tf_rt_step at
    dt = 1e-5 and 1e-6 s (velocity and load held at each step's midpoint) approaches its friction force over one
    period of a 2 Hz, 5 mm sine while the load swings 40..120 N at 1.5 Hz: to 1e-3 of the force's range at 1e-6 s,
    at first order in dt (as for the temperature, tests/test_control.py)."""
    model = prescribed_stage()
    A, f = 5e-3, 2.0
    load = tf.Sine(amplitude=40.0, frequency=1.5, offset=80.0)
    errors = []
    for dt in (1e-5, 1e-6):
        n = int(round(0.5 / dt))
        t_mid = (np.arange(n) + 0.5) * dt
        v = A * 2 * np.pi * f * np.cos(2 * np.pi * f * t_mid)
        L = 80.0 + 40.0 * np.sin(2 * np.pi * 1.5 * t_mid)
        F, _ = friction_steps(model, v, dt, temperature=30.0, load=L)
        t_end = (np.arange(n) + 1) * dt
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", tf.PassivityWarning)
            ref = tf.simulate(model, t_eval=np.concatenate([[0.0], t_end]), temperature=30.0,
                              input=tf.Sine(amplitude=A, frequency=f), load=load,
                              controller=tf.StepSizeController(rtol=1e-10)).friction_force[1:]
        errors.append(float(np.max(np.abs(F - ref)) / np.ptp(ref)))
    print("real-time steps with a load, error / force range at dt = 1e-5, 1e-6 s:", errors)
    assert errors[1] <= 1e-3 and errors[1] <= errors[0] / 5, errors
    with pytest.raises(tf.InputError, match=r"friction_steps: \[thermal\] fc: a law of the load"):
        friction_steps(model, v[:10], 1e-6, temperature=30.0)
    with pytest.raises(tf.InputError, match=r"friction_steps: load\[3\] is nan"):
        friction_steps(model, v[:10], 1e-6, temperature=30.0, load=np.where(np.arange(10) == 3, np.nan, 50.0))


def _varying_run():
    t = np.linspace(0.0, 4.0, 801)
    x = 2e-3 * np.sin(2 * np.pi * 0.5 * t)
    N = np.interp(t, [0.0, 1.0, 3.0, 4.0], [40.0, 40.0, 110.0, 110.0])
    cols = {"time": t, "position": x, "force": 0.6 * np.tanh(np.gradient(x, t) / 1e-3), "normal_force": N,
            "rotary": False, "headers": {"time": "time[s]", "position": "position[m]", "force": "friction_force[N]",
                                         "normal_force": "normal_force[N]"}}
    return force_experiment("ramp.csv", "ramp.csv", temperature=30.0, role="fit", description="",
                            from_zero=lambda t, i: (t, i), columns=cols), N


def test_a_varying_load_column_drives_the_simulation_and_a_force_fit_refuses_it():
    """A force run whose normal_force[N] column ramps 40 -> 110 N: its drive carries the column (per sample), and
    the simulation driven by it is the reference's under the same samples (truth: tests/reference, to 1e-4 of the
    force's range, the prescribed-motion differential tests' tolerance at rtol 1e-8 with margin); a force fit of
    the laws (a constant per run) refuses it, naming the file."""
    exp, N = _varying_run()
    model = prescribed_stage()
    d = drive(exp, model, start="record")
    assert isinstance(d.load, tf.Sampled) and np.array_equal(d.load.value, N)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tf.PassivityWarning)
        res = tf.simulate(model, t_eval=exp.time, temperature=d.temperature, input=d.waveform, load=d.load,
                          controller=tf.StepSizeController(rtol=1e-8))
    ref = R.reference_simulate_system(model, exp.time, 30.0, input=d.waveform, load=d.load, rtol=1e-10)
    F_range = np.ptp(ref.friction_force)
    assert np.max(np.abs(res.friction_force - ref.friction_force)) <= 1e-4 * F_range
    with pytest.raises(tf.InputError, match=r"ramp\.csv: the load column varies over the run \(40 to 110\)"):
        run_load(exp)


@pytest.mark.skipif(shutil.which("cc") is None or shutil.which("nm") is None, reason="needs cc and nm")
@pytest.mark.parametrize("source", ["realtime.c", "law.c", "thermal.c", "model_check.c"])
def test_the_step_path_allocates_nothing(tmp_path, source):
    """No allocation in the real-time step and what it calls with a load (the core's rule for step functions):
    each object file, compiled from the package's sources, calls no allocator (tests/test_estimator.py's check)."""
    root = sources_dir()
    obj = tmp_path / "step.o"
    subprocess.run(["cc", "-std=c99", "-O2", "-c", "-I", str(root), "-o", str(obj), str(root / source)],
                   check=True, capture_output=True)
    out = subprocess.run(["nm", "-u", str(obj)], check=True, capture_output=True, text=True).stdout
    undefined = {line.split()[-1] for line in out.splitlines() if line.strip()}
    assert undefined, "nm listed nothing: the check would prove nothing"
    assert not {s for s in undefined if re.search(r"alloc|free|^_?Znw|^_?Zdl", s)}, undefined


def _with_law(model, name, law):
    return tf.Model(model.plant, model.friction, tf.ModelI({**model.laws, name: law}), input=model.input)


def test_sensitivities_through_a_law_of_the_load_are_central_differences():
    """Truth: central differences (relative step 1e-4) of the stage's displacement simulated at rtol 1e-12 under
    the load ramp, over its breakaway and sliding. The core's forward sensitivities to fc's slope a (times the
    load's magnitude) and to fs's load gain k and interaction c (tf_law_coef_derivative at the run's (T, L)) agree
    to 1e-3 of the largest, times the coefficient (the displacement a 100 % change would make, to first order), as
    the parameters' do (tests/test_differential_friction.py); measured 1e-10 to 1e-5."""
    model = preloaded_stage()
    t = np.linspace(0.0, 12.0, 1201)  # through the breakaway (~7 s, where fs acts) and the sliding after it
    names = [("fc", 0), ("fs", 2), ("fs", 3)]  # fc: a; fs: load.k, load.interaction
    spec = _bridge.model_spec(model, 30.0, model.input, load=RAMP)
    theta = np.array([model.laws[n].coefficients()[k] for n, k in names])
    targets = np.array([_bridge.target("law", _bridge.PARAMETERS.index(n), k) for n, k in names], np.int32)
    atol_y = 1e-10 * _bridge.state_scale(spec)
    atol_s = atol_y[:, None] / np.abs(theta)[None, :]
    out = np.empty((t.size, _bridge.n_outputs(model, False)))
    sens = np.empty((t.size, atol_y.size, len(names)))
    _bridge.run_sensitivities(spec, targets, t, out, sens, rtol=1e-10, atol=np.concatenate([atol_y, atol_s.ravel()]),
                              max_steps=10_000_000)
    S = sens[:, _bridge.state_index(model, "x"), :] * theta  # per relative change
    scale = np.max(np.abs(S))
    for j, (n, k) in enumerate(names):
        xs = []
        for sign in (1.0, -1.0):
            c = np.array(model.laws[n].coefficients(), float)
            c[k] *= 1.0 + sign * 1e-4
            m = _with_law(model, n, model.laws[n].with_coefficients(c))
            o = np.empty((t.size, _bridge.n_outputs(m, False)))
            _bridge.run(_bridge.model_spec(m, 30.0, m.input, load=RAMP), t, o, method="dopri5", rtol=1e-12)
            xs.append(o[:, _bridge.OUTPUT_COLUMN["displacement"]])
        fd = (xs[0] - xs[1]) / 2e-4
        err = float(np.max(np.abs(S[:, j] - fd)))
        print(f"{n} coefficient {k}: max |S - FD| / max |S| = {err / scale:.2e}")
        assert np.max(np.abs(fd)) > 1e-3 * scale  # each coefficient moves the run
        assert err <= 1e-3 * scale, (n, k, err / scale)


def test_the_command_line_simulates_a_load_file_as_python_does(tmp_path):
    """`thermofriction simulate --load-file` (time[s], normal_force[mN]: converted to N) gives the run
    tf.simulate(load=Sampled) gives, to the CSV's 12 digits (the same core; checked against Python here, and Python
    against the independent reference above); `--load` a constant; a model with a law of the load and no load exits
    2 naming the law; a load file with another column name or unit exits 2 naming the file and line, writing
    nothing."""
    from conftest import run_cli
    model = preloaded_stage()
    model.save(tmp_path / "stage.toml")
    rows = "\n".join(f"{t:g},{1e3 * L:g}" for t, L in zip(RAMP.time, RAMP.value))
    (tmp_path / "load.csv").write_text("time[s],normal_force[mN]\n" + rows + "\n")
    r = run_cli("simulate", tmp_path / "stage.toml", "--temperature", 30, "--load-file", tmp_path / "load.csv",
                "--duration", 12, "--sample-rate", 100, "-o", tmp_path / "out.csv")
    assert r.returncode == 0, r.stderr
    out = np.loadtxt(tmp_path / "out.csv", delimiter=",", skiprows=1)
    assert (tmp_path / "out.csv").read_text().startswith("time[s],input[N],displacement[m],")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tf.PassivityWarning)
        py = tf.simulate(tf.load_model(tmp_path / "stage.toml"), 12.0, sample_rate=100.0, temperature=30.0,
                         load=RAMP)
    assert np.ptp(py.displacement) > 0.5
    assert np.allclose(out[:, 2], py.displacement, rtol=1e-11, atol=1e-12 * np.ptp(py.displacement))
    r = run_cli("simulate", tmp_path / "stage.toml", "--temperature", 30, "--load", 60, "--duration", 0.5)
    assert r.returncode == 0 and "at load 60" in r.stdout, r.stderr
    r = run_cli("simulate", tmp_path / "stage.toml", "--temperature", 30, "--duration", 0.5)
    assert r.returncode == 2 and "[thermal] fc: a law of the load" in r.stderr and "Traceback" not in r.stderr
    (tmp_path / "bad.csv").write_text("time[s],normal_force[kN]\n0,1\n1,2\n")
    r = run_cli("simulate", tmp_path / "stage.toml", "--temperature", 30, "--load-file", tmp_path / "bad.csv",
                "-o", tmp_path / "bad-out.csv")
    assert r.returncode == 2 and "bad.csv: line 1: unknown unit 'kN' of normal_force (use N, mN)" in r.stderr, r.stderr
    assert not (tmp_path / "bad-out.csv").exists()
    (tmp_path / "bad.csv").write_text("time[s],force[N]\n0,1\n1,2\n")
    r = run_cli("simulate", tmp_path / "stage.toml", "--temperature", 30, "--load-file", tmp_path / "bad.csv")
    assert r.returncode == 2 and "line 1: the value column must be normal_force[N] or load_torque[N*m]" in r.stderr


def test_the_temperature_estimator_needs_a_load_for_a_law_of_the_load_naming_it():
    """The online estimator steps its model at the load it is given (estimator.c): a model with a law of the load
    and no load is refused before any step, naming the law; a NaN load in the samples is refused naming it."""
    est = tf.control.TemperatureEstimator(C_th=1.0, R_th=1.0, r_F=0.01)
    with pytest.raises(tf.InputError, match=r"run: the model has a law of the load \(fc, fs\): give load="):
        est.run(preloaded_stage(), np.full(100, 0.01), dt=1e-3, ambient=25.0, start=25.0,
                measured_force=np.ones(100))
    bad = np.full(100, 60.0)
    bad[7] = np.nan
    with pytest.raises(tf.InputError, match=r"run: load\[7\] is nan"):
        est.run(preloaded_stage(), np.full(100, 0.01), dt=1e-3, ambient=25.0, start=25.0, load=bad)
