"""The classical LuGre experiments of Canudas de Wit, Olsson, Astrom and Lischinsky, "A new model
for control of systems with friction", IEEE TAC 40(3), 1995, with the paper's parameters:

    sigma0 = 1e5 N/m, sigma1 = sqrt(1e5) N s/m, sigma2 = 0.4 N s/m,
    fc = 1 N, fs = 1.5 N, vs = 0.001 m/s (Stribeck exponent 2), m = 1 kg.

(a) stick-slip      a 1 kg mass pulled through a 2 N/m spring at 0.1 m/s;
(b) presliding      a force cycled slowly well below fs: spring-like micro-displacement, x ~ F/sigma0
                    for small F, and its hysteresis loop;
(c) frictional lag  the sliding velocity prescribed as v(t) = 1e-3 (cos(omega t) + 1.5) m/s, through the
                    Stribeck region, at omega = 1, 10 and 25 rad/s: the friction-velocity loops widen
                    with frequency;
(d) break-away      a force ramped at different rates: the break-away force depends on the rate.

Each experiment is a function that returns a small dict of key figures, next to the figure the
physics predicts for it (derived in the function's docstring). Run:

    python examples/canudas1995.py                 # prints the key figures
    python examples/canudas1995.py --plot DIR      # and saves PNGs in DIR (needs matplotlib)

The paper's parameter set is not dissipative at high sliding speed (sigma1 = 316 N s/m is large
against sigma2 fc/(fs - fc) = 0.8 N s/m), and tf.simulate says so with a PassivityWarning for every
run. That warning is expected here and silenced (only that one) around each simulation.
"""

from __future__ import annotations

import argparse
import math
import warnings
from pathlib import Path

import numpy as np

import thermofriction as tf

# --- the paper's parameters ------------------------------------------------------------------
SIGMA0 = 1e5               # N/m
SIGMA1 = math.sqrt(1e5)    # N s/m
SIGMA2 = 0.4               # N s/m
FC = 1.0                   # N
FS = 1.5                   # N
VS = 1e-3                  # m/s
MASS = 1.0                 # kg
K_SPRING = 2.0             # N/m, stick-slip experiment
V_PULL = 0.1               # m/s, stick-slip experiment


def lugre() -> tf.LuGre:
    """LuGre with the paper's parameters (constant sigma1, Stribeck exponent 2)."""
    return tf.LuGre(sigma0=SIGMA0, sigma1=SIGMA1, sigma2=SIGMA2, fc=FC, fs=FS, vs=VS)


def stribeck_curve(v):
    """g(v) = fc + (fs - fc) exp(-(v/vs)^2)."""
    return FC + (FS - FC) * np.exp(-(np.asarray(v, float) / VS) ** 2)


def steady_friction(v):
    """LuGre's steady-state friction at constant velocity v > 0: g(v) + sigma2 v."""
    return stribeck_curve(v) + SIGMA2 * np.asarray(v, float)


def _simulate(model, duration=None, **kw):
    with warnings.catch_warnings():
        # expected for this parameter set (see the module docstring); every other warning stays
        warnings.filterwarnings("ignore", category=tf.PassivityWarning)
        return tf.simulate(model, duration, **kw)


# ---------------------------------------------------------------------------------------------
# (a) stick-slip
# ---------------------------------------------------------------------------------------------

def run_stick_slip(duration=60.0, sample_rate=1000.0, **options):
    """``options`` (solver=, controller=) go to tf.simulate, here and in the other run_* functions."""
    model = tf.Model(tf.MassPlant(MASS, spring_stiffness=K_SPRING, pull_velocity=V_PULL), lugre())
    return _simulate(model, duration, sample_rate=sample_rate, **options)


def slip_prediction(f_spring, v_start=0.0):
    """The slip phase predicted from the spring force f_spring at which the mass moves at v_start,
    with the friction of gross sliding taken as Coulomb + viscous, F = fc + sigma2 v (LuGre's
    steady state beyond the Stribeck band, v >> vs = 1 mm/s). Relative to the pulling point,
    w = x' - v0 obeys the damped oscillator m w'' + sigma2 w' + k_s w = 0, starting at
    w = v_start - v0 with m w' = f_spring - fc - sigma2 v_start. The slip ends when x' = v0 + w is
    back at zero. Returns (peak velocity, slip duration, spring force at the end of the slip)."""
    wn = math.sqrt(K_SPRING / MASS)
    zeta = SIGMA2 / (2 * math.sqrt(K_SPRING * MASS))
    wd = wn * math.sqrt(1 - zeta ** 2)
    w0, dw0 = v_start - V_PULL, (f_spring - FC - SIGMA2 * v_start) / MASS
    t = np.linspace(0.0, 2 * math.pi / wd, 200_001)
    a, b = w0, (dw0 + zeta * wn * w0) / wd
    v = V_PULL + np.exp(-zeta * wn * t) * (a * np.cos(wd * t) + b * np.sin(wd * t))
    end = int(np.argmax(v[1:] <= 0)) + 1  # first sample where the mass is back at rest
    # the spring force k_s (v0 t - x) rises by k_s v0 t and falls by k_s x
    x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    f_end = f_spring + K_SPRING * (V_PULL * t[end] - x[end])
    return float(v[:end].max()), float(t[end]), float(f_end)


def stick_slip(run=None) -> dict:
    """Key figures of the stick-slip limit cycle.

    Cycles run from one slip onset (x' rising through 10 vs, where the Stribeck drop is complete)
    to the next; the first one, which starts from rest with a relaxed spring, is left out. The
    stick phase of a cycle is its longest run of |x'| < vs (the mass creeps there, in presliding,
    at micrometres per second); the slip phase runs from the onset to the stick phase.

    What the physics predicts:
    - a periodic orbit: the same period every cycle, and a displacement per cycle of v0 T (the
      spring force returns to the same value, so x - v0 t does too): the mean velocity is v0;
    - the largest friction force of a cycle is the break-away force for the spring's force rate
      k_s v0 = 0.2 N/s (break_away(): between fc and fs, just below fs at such a slow rate);
    - from the spring force at the onset, slip_prediction() gives the peak velocity, the slip
      duration and the spring force where the mass sticks again; the stick phase then lasts until
      the spring force is back at its onset value, (f_onset - f_after_slip) / (k_s v0), and the
      period is slip + stick.
    """
    r = run if run is not None else run_stick_slip()
    t, x, v, F = r.time, r.displacement, r.velocity, r.friction_force
    spring = K_SPRING * (V_PULL * t - x)
    onsets = np.flatnonzero((v[1:] > 10 * VS) & (v[:-1] <= 10 * VS)) + 1
    if onsets.size < 3:
        raise RuntimeError("fewer than two full stick-slip cycles were simulated")
    periods = np.diff(t[onsets])
    mean_velocity = (x[onsets[-1]] - x[onsets[0]]) / (t[onsets[-1]] - t[onsets[0]])
    peaks_v, peaks_F, sticks, slips, creep, f_after = [], [], [], [], [], []
    for i0, i1 in zip(onsets[:-1], onsets[1:]):
        peaks_v.append(v[i0:i1].max())
        peaks_F.append(F[i0 + (i1 - i0) // 2:i1 + 1].max())  # the break-away ending this cycle
        # the stick phase: the longest run of |v| < vs in the cycle, samples a .. b-1
        edges = np.diff(np.concatenate([[0], (np.abs(v[i0:i1]) < VS).astype(int), [0]]))
        starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
        j = int(np.argmax(stops - starts))
        a, b = i0 + starts[j], i0 + stops[j]
        sticks.append(t[b] - t[a])
        slips.append(t[a] - t[i0])
        quarter = (b - a) // 4
        creep.append(np.abs(v[a + quarter:b - quarter]).max())
        f_after.append(spring[a])
    f_onset = float(spring[onsets[1:]].mean())
    v_pred, slip_pred, f_after_pred = slip_prediction(f_onset, 10 * VS)
    stick_pred = (f_onset - f_after_pred) / (K_SPRING * V_PULL)
    return {
        "period": float(periods.mean()),
        "period_predicted": slip_pred + stick_pred,
        "period_spread": float(np.ptp(periods)),
        "cycles": int(periods.size),
        "mean_velocity": float(mean_velocity),
        "break_away_force": float(np.mean(peaks_F)),
        "spring_force_at_onset": f_onset,
        "peak_velocity": float(np.mean(peaks_v)),
        "peak_velocity_predicted": v_pred,
        "slip_duration": float(np.mean(slips)),
        "slip_duration_predicted": slip_pred,
        "spring_force_after_slip": float(np.mean(f_after)),
        "spring_force_after_slip_predicted": f_after_pred,
        "stick_duration": float(np.mean(sticks)),
        "stick_duration_predicted": stick_pred,
        "max_creep_velocity": float(np.max(creep)),
    }


# ---------------------------------------------------------------------------------------------
# (b) presliding displacement
# ---------------------------------------------------------------------------------------------

def run_presliding(f_max=1.2, frequency=0.02, sample_rate=1000.0, **options):
    """The mass (no spring) under F(t) = f_max sin(2 pi f t) for 1.25 periods: the virgin loading
    0 -> f_max, then a full loop f_max -> -f_max -> f_max. At most 2 pi f f_max = 0.15 N/s."""
    model = tf.Model(tf.MassPlant(MASS), lugre())
    return _simulate(model, 1.25 / frequency, input=tf.Sine(f_max, frequency), sample_rate=sample_rate, **options)


def presliding_quasistatic(F, f_max, branch):
    """The quasi-static LuGre loop for slow forcing: inertia and damping negligible, F = sigma0 z
    and |v| << vs so g(v) = fs. From z' = v (1 - sgn(v) sigma0 z / fs), along a branch of one sign
    dx = dF / (sigma0 (1 - sgn(v) F / fs)), which integrates to (x0 = fs / sigma0):
      virgin     x = x0 ln(fs / (fs - F))
      descending x = x_top - x0 ln((fs + f_max) / (fs + F)),  x_top = x0 ln(fs / (fs - f_max))
      ascending  x = x_bot + x0 ln((fs + f_max) / (fs - F)),  x_bot = -x0 ln((fs + f_max) / fs)
    (the ascending branch ends exactly at x_top: the loop closes after one cycle)."""
    x0 = FS / SIGMA0
    F = np.asarray(F, float)
    if branch == "virgin":
        return x0 * np.log(FS / (FS - F))
    if branch == "descending":
        return x0 * np.log(FS / (FS - f_max)) - x0 * np.log((FS + f_max) / (FS + F))
    return -x0 * np.log((FS + f_max) / FS) + x0 * np.log((FS + f_max) / (FS - F))


def presliding(run=None, f_max=1.2, frequency=0.02) -> dict:
    """Key figures of presliding: the stiffness at the origin, and the hysteresis loop.

    Predicted (presliding_quasistatic): the initial stiffness dF/dx at F = 0 is sigma0 (the
    bristles are springs: x ~ F/sigma0 for F << fs); the loading curve softens as F nears fs
    (dF/dx = sigma0 (1 - F/fs)) and the unloading one stiffens (sigma0 (1 + F/fs)), so the
    loop is a hysteresis loop with a residual displacement x0 ln(fs^2 / (fs^2 - f_max^2)) at F = 0
    and an energy loss per cycle (its area) computed from the same branches.
    """
    r = run if run is not None else run_presliding(f_max, frequency)
    t, u, x = r.time, r.input, r.displacement
    quarter, three_q = 0.25 / frequency, 0.75 / frequency
    i1, i2 = np.searchsorted(t, quarter), np.searchsorted(t, three_q)
    # stiffness at the origin: x = a F + b F^2 fitted on the virgin branch, F <= 0.1 N
    sel = u[:i1 + 1] <= 0.1
    b, a, _ = np.polyfit(u[:i1 + 1][sel], x[:i1 + 1][sel], 2)
    errors = [np.abs(x[:i1 + 1] - presliding_quasistatic(u[:i1 + 1], f_max, "virgin")).max(),
              np.abs(x[i1:i2 + 1] - presliding_quasistatic(u[i1:i2 + 1], f_max, "descending")).max(),
              np.abs(x[i2:] - presliding_quasistatic(u[i2:], f_max, "ascending")).max()]
    j0 = i1 + np.argmin(np.abs(u[i1:i2]))  # F = 0 on the way down
    # loop area: the work the force does over the closed loop (i1 -> end), = energy dissipated
    area = float(np.sum(0.5 * (u[i1 + 1:] + u[i1:-1]) * np.diff(x[i1:])))
    Fq = np.linspace(-f_max, f_max, 20_001)
    gap = presliding_quasistatic(Fq, f_max, "descending") - presliding_quasistatic(Fq, f_max, "ascending")
    area_pred = float(np.sum(0.5 * (gap[1:] + gap[:-1]) * np.diff(Fq)))
    x0 = FS / SIGMA0
    return {
        "stiffness": float(1.0 / a),
        "stiffness_predicted": SIGMA0,
        "displacement_at_fmax": float(x[i1]),
        "displacement_at_fmax_predicted": float(presliding_quasistatic(f_max, f_max, "virgin")),
        "residual_displacement": float(x[j0]),
        "residual_displacement_predicted": float(x0 * np.log(FS ** 2 / (FS ** 2 - f_max ** 2))),
        "loop_closure_error": float(abs(x[-1] - x[i1])),
        "loop_energy": area,
        "loop_energy_predicted": area_pred,
        "max_error_vs_quasistatic": float(max(errors)),
        "f_max": f_max,
    }


# ---------------------------------------------------------------------------------------------
# (c) frictional lag
# ---------------------------------------------------------------------------------------------

LAG_MEAN, LAG_AMPLITUDE = 1.5e-3, 1e-3  # v(t) = LAG_AMPLITUDE cos(omega t) + LAG_MEAN


def simulate_frictional_lag(omega, periods=3, knots_per_period=4000, **options):
    """Prescribed motion with v(t) = 1e-3 (cos(omega t) + 1.5) m/s, i.e. the displacement
    x(t) = 1.5e-3 t + 1e-3 sin(omega t) / omega. No waveform has that shape (a sine on a ramp), so
    it is given as tf.Sampled knots; its slope between two knots is the exact mean velocity there,
    and the output is taken at the midpoints, where that equals v(t) to O(dt^2). The whole run."""
    T = 2 * math.pi / omega
    tk = np.arange(periods * knots_per_period + 1) * (T / knots_per_period)
    xk = LAG_MEAN * tk + LAG_AMPLITUDE * np.sin(omega * tk) / omega
    t_out = np.concatenate([[0.0], 0.5 * (tk[1:] + tk[:-1])])
    model = tf.Model(tf.PrescribedMotion(), lugre())
    return _simulate(model, input=tf.Sampled(tk, xk), t_eval=t_out, **options)


def run_frictional_lag(omega, periods=3, knots_per_period=4000, **options):
    """simulate_frictional_lag's last period (the start-up transient has died out): time, velocity,
    friction force."""
    r = simulate_frictional_lag(omega, periods, knots_per_period, **options)
    last = r.time >= (periods - 1) * 2 * math.pi / omega
    return r.time[last], r.velocity[last], r.friction_force[last]


def lag_width_predicted(omega, v=LAG_MEAN):
    """First-order (small omega tau) loop width at velocity v, where the velocity changes at
    |v'| = a omega (a = 1e-3 m/s; at v = 1.5e-3 m/s, cos = 0 and |sin| = 1).
    For v > 0, z' = (z_ss - z) / tau with z_ss = g(v)/sigma0 and tau = g(v)/(sigma0 v): the
    bristles lag their steady state, sigma0 z ~ g(v) - tau g'(v) v', and the damping term adds
    sigma1 z' = sigma1 (z_ss - z)/tau = sigma1 g'(v) v' / sigma0. On the accelerating branch
    (g' < 0, v' > 0) friction is higher than steady, on the decelerating one lower, by
    |g'(v)| |v'| (tau - sigma1/sigma0) each: width = 2 |g'(v)| a omega (tau - sigma1/sigma0)."""
    g = float(stribeck_curve(v))
    dg = -(FS - FC) * 2 * v / VS ** 2 * math.exp(-(v / VS) ** 2)
    tau = g / (SIGMA0 * v)
    return 2 * abs(dg) * LAG_AMPLITUDE * omega * (tau - SIGMA1 / SIGMA0)


def frictional_lag(omegas=(1.0, 10.0, 25.0), runs=None) -> dict:
    """Key figures of the friction-velocity loops, per frequency omega [rad/s]:
    - width: friction on the accelerating branch minus on the decelerating one, at v = 1.5 mm/s
      (positive: friction lags the velocity); predicted by lag_width_predicted() for slow variation;
    - area: the loop's area in the F-v plane [N m/s];
    - max deviation of the friction from the steady-state curve g(v) + sigma2 v [N].
    Predicted: as omega -> 0 the loop collapses onto the steady-state (Stribeck) curve; it widens
    with omega (linearly while omega tau << 1, tau = g/(sigma0 v) ~ 7 ms at 1.5 mm/s)."""
    out = {"omega": [], "width": [], "width_predicted": [], "area": [], "max_deviation": []}
    for i, w in enumerate(omegas):
        t, v, F = runs[i] if runs is not None else run_frictional_lag(w)
        accelerating = np.sin(w * t) < 0  # v' = -a omega sin(omega t)

        def at(mask):
            o = np.argsort(v[mask])
            return float(np.interp(LAG_MEAN, v[mask][o], F[mask][o]))

        out["omega"].append(float(w))
        out["width"].append(at(accelerating) - at(~accelerating))
        out["width_predicted"].append(lag_width_predicted(w))
        out["area"].append(float(abs(np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(v)))))
        out["max_deviation"].append(float(np.abs(F - steady_friction(v)).max()))
    return out


# ---------------------------------------------------------------------------------------------
# (d) varying break-away force
# ---------------------------------------------------------------------------------------------

RAMP_TO = 1.6  # N: the applied force ramps from 0 to above fs


def run_break_away(rate, samples=20_000, **options):
    """The mass (no spring) under an applied force ramp u = rate t, up to RAMP_TO."""
    T = RAMP_TO / rate
    model = tf.Model(tf.MassPlant(MASS), lugre())
    return _simulate(model, T, input=tf.Step(RAMP_TO, time=0.0, slew=T), sample_rate=samples / T, **options)


def _creep_rate_max(u, v):
    """h_max(u) = max over v of sigma0 v (1 - u / g(v)) (see break_away_quasistatic)."""
    return (SIGMA0 * v * (1 - u / stribeck_curve(v))).max()


_V_GRID = np.logspace(-10, -1, 9001)


def break_away_quasistatic(rate):
    """The break-away force for a slow ramp, massless and undamped (m x'' and sigma1 z', sigma2 v
    negligible): friction follows the applied force, F = sigma0 z = u, while the mass creeps at the
    velocity v that makes z' = u'/sigma0, i.e. rate = h(v) = sigma0 v (1 - u / g(v)).
    For fc < u < fs, h is positive only below the velocity where g(v) = u and has a maximum
    h_max(u), which falls from h_max(fc) = critical_rate() at u = fc to 0 at u = fs. Once
    h_max(u) < rate, no creep velocity can keep up with the ramp: the mass breaks away. So
    F_ba(rate) = h_max^{-1}(rate): between fc and fs, and DEcreasing with the rate (a faster ramp
    needs a faster creep, which is further down the Stribeck curve). Above critical_rate() the
    creep branch is gone altogether: the elastic loading alone crosses the Stribeck band, there is
    no peak, and this returns fc."""
    lo, hi = FC, FS
    for _ in range(60):
        u = 0.5 * (lo + hi)
        if _creep_rate_max(u, _V_GRID) > rate:
            lo = u
        else:
            hi = u
    return 0.5 * (lo + hi)


def critical_rate():
    """h_max(fc) = max_v sigma0 v (1 - fc / g(v)) [N/s]: the fastest ramp with a break-away peak
    in the quasi-static picture (16.7 N/s for the paper's parameters, near v = vs / sqrt(2))."""
    return float(_creep_rate_max(FC, _V_GRID))


def break_away(rates=(0.03, 0.1, 0.3, 1.0, 3.0, 10.0), runs=None) -> dict:
    """Break-away force per force rate [N/s]: the largest friction force before gross sliding
    (the friction peaks there, then falls along the Stribeck curve as the mass accelerates; the
    search stops where the velocity first exceeds 10 vs). Also the applied force at that instant
    and the quasi-static prediction (break_away_quasistatic), which the simulation approaches
    from above as the rate falls (above it because the mass needs time to accelerate through the
    Stribeck band while the force keeps rising). Rates are kept below critical_rate() = 16.7 N/s,
    above which there is no creep branch and no peak to speak of: the elastic presliding velocity
    rate/sigma0 alone approaches the Stribeck band (at 100 N/s it is vs itself)."""
    out = {"rate": [], "break_away_force": [], "applied_force": [], "predicted": [], "displacement": []}
    for i, rate in enumerate(rates):
        r = runs[i] if runs is not None else run_break_away(rate)
        sliding = np.flatnonzero(r.velocity > 10 * VS)
        end = sliding[0] if sliding.size else r.time.size
        k = int(np.argmax(r.friction_force[:end]))
        out["rate"].append(float(rate))
        out["break_away_force"].append(float(r.friction_force[k]))
        out["applied_force"].append(float(r.input[k]))
        out["displacement"].append(float(r.displacement[k]))
        out["predicted"].append(float(break_away_quasistatic(rate)))
    return out


# ---------------------------------------------------------------------------------------------
# main
# ---------------------------------------------------------------------------------------------

def _plot(outdir: Path, ss_run, pre_run, lag_runs, omegas, ba_runs, ba):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    outdir.mkdir(parents=True, exist_ok=True)
    paths = []

    fig, ax = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    t = ss_run.time
    ax[0].plot(t, ss_run.displacement, label="mass x")
    ax[0].plot(t, V_PULL * t, "--", label="pulling point v0 t")
    ax[0].set_ylabel("position [m]")
    ax[0].legend()
    ax[1].plot(t, ss_run.velocity)
    ax[1].set_ylabel("velocity [m/s]")
    ax[2].plot(t, ss_run.friction_force)
    ax[2].set_ylabel("friction [N]")
    ax[2].set_xlabel("time [s]")
    fig.suptitle("(a) stick-slip: 1 kg pulled through 2 N/m at 0.1 m/s")
    paths.append(outdir / "canudas1995_stick_slip.png")
    fig.savefig(paths[-1], dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 5))
    f_max = float(pre_run.input.max())
    ax.plot(pre_run.displacement * 1e6, pre_run.input, label="simulated")
    for name, F in (("virgin", np.linspace(0, f_max, 200)), ("descending", np.linspace(f_max, -f_max, 200)),
                    ("ascending", np.linspace(-f_max, f_max, 200))):
        ax.plot(presliding_quasistatic(F, f_max, name) * 1e6, F, "k:", lw=1,
                label="quasi-static" if name == "virgin" else None)
    xs = np.linspace(-5, 5, 3)
    ax.plot(xs, SIGMA0 * xs * 1e-6, "r--", lw=0.8, label="F = sigma0 x")
    ax.set_xlabel("displacement [um]")
    ax.set_ylabel("applied force [N]")
    ax.set_title("(b) presliding displacement")
    ax.legend()
    paths.append(outdir / "canudas1995_presliding.png")
    fig.savefig(paths[-1], dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 5))
    for w, (_, v, F) in zip(omegas, lag_runs):
        ax.plot(v * 1e3, F, label=f"omega = {w:g} rad/s")
    vv = np.linspace(0.4e-3, 2.6e-3, 200)
    ax.plot(vv * 1e3, steady_friction(vv), "k:", label="steady state g(v) + sigma2 v")
    ax.set_xlabel("velocity [mm/s]")
    ax.set_ylabel("friction [N]")
    ax.set_title("(c) frictional lag")
    ax.legend()
    paths.append(outdir / "canudas1995_frictional_lag.png")
    fig.savefig(paths[-1], dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(1, 2, figsize=(10, 4.5))
    for rate, r in zip(ba["rate"], ba_runs):
        ax[0].plot(r.input, r.friction_force, label=f"{rate:g} N/s")
    ax[0].set_xlim(1.0, RAMP_TO)
    ax[0].set_ylim(0.95, 1.55)
    ax[0].set_xlabel("applied force [N]")
    ax[0].set_ylabel("friction [N]")
    ax[0].legend(fontsize=8)
    rr = np.logspace(np.log10(min(ba["rate"])), np.log10(max(ba["rate"])), 50)
    ax[1].semilogx(ba["rate"], ba["break_away_force"], "o-", label="simulated (peak friction)")
    ax[1].semilogx(rr, [break_away_quasistatic(x) for x in rr], "k:", label="quasi-static prediction")
    ax[1].axhline(FS, color="gray", lw=0.8)
    ax[1].axhline(FC, color="gray", lw=0.8)
    ax[1].set_xlabel("force rate [N/s]")
    ax[1].set_ylabel("break-away force [N]")
    ax[1].legend()
    fig.suptitle("(d) varying break-away force")
    paths.append(outdir / "canudas1995_break_away.png")
    fig.savefig(paths[-1], dpi=120)
    plt.close(fig)
    return paths


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--plot", metavar="DIR", type=Path, help="save the figures as PNGs in DIR")
    args = ap.parse_args(argv)

    print("LuGre, Canudas de Wit et al. (1995): sigma0 = 1e5 N/m, sigma1 = sqrt(1e5) N s/m, sigma2 = 0.4 N s/m, "
          "fc = 1 N, fs = 1.5 N, vs = 1 mm/s, m = 1 kg\n")

    ss_run = run_stick_slip()
    ss = stick_slip(ss_run)
    print("(a) stick-slip, k_s = 2 N/m, v0 = 0.1 m/s (60 s simulated)        simulated      predicted")
    rows = [("period [s]", "period", "period_predicted"),
            ("mean velocity [m/s]", "mean_velocity", None),
            ("break-away (peak friction) [N]", "break_away_force", None),
            ("spring force at slip onset [N]", "spring_force_at_onset", None),
            ("peak slip velocity [m/s]", "peak_velocity", "peak_velocity_predicted"),
            ("slip duration [s]", "slip_duration", "slip_duration_predicted"),
            ("spring force after slip [N]", "spring_force_after_slip", "spring_force_after_slip_predicted"),
            ("stick duration [s]", "stick_duration", "stick_duration_predicted")]
    for label, key, pkey in rows:
        pred = ss[pkey] if pkey else (V_PULL if key == "mean_velocity" else None)
        print(f"    {label:58s} {ss[key]:10.5f}" + (f"     {pred:10.5f}" if pred is not None else ""))
    print(f"    {'period spread over ' + str(ss['cycles']) + ' cycles [s]':58s} {ss['period_spread']:10.1e}")
    print(f"    {'max creep velocity, middle half of the stick phases [m/s]':58s} {ss['max_creep_velocity']:10.2e}")

    pre_run = run_presliding()
    pre = presliding(pre_run)
    print(f"\n(b) presliding, applied force {pre['f_max']:g} N sin(2 pi 0.02 t), no spring"
          f"{'':21s}simulated      predicted")
    rows = [("stiffness at F = 0 [N/m]", "stiffness", 1.0, "10.5g"),
            ("displacement at F max, virgin loading [um]", "displacement_at_fmax", 1e6, "10.4f"),
            ("residual displacement at F = 0, unloading [um]", "residual_displacement", 1e6, "10.4f"),
            ("loop area = energy dissipated per cycle [uJ]", "loop_energy", 1e6, "10.4f")]
    for label, key, scale, fmt in rows:
        print(f"    {label:58s} {pre[key] * scale:{fmt}}     {pre[key + '_predicted'] * scale:{fmt}}")
    print(f"    {'max |x - quasi-static x| over the whole run [nm]':58s} {pre['max_error_vs_quasistatic'] * 1e9:10.3f}")
    print(f"    {'loop closure error [nm]':58s} {pre['loop_closure_error'] * 1e9:10.3f}")

    omegas = (1.0, 10.0, 25.0)
    lag_runs = [run_frictional_lag(w) for w in omegas]
    lag = frictional_lag(omegas, lag_runs)
    print("\n(c) frictional lag, v = 1e-3 (cos(omega t) + 1.5) m/s")
    print(f"    {'omega [rad/s]':>13s}  {'width at 1.5 mm/s [N]':>21s}  {'first-order prediction':>22s}  "
          f"{'loop area [N m/s]':>17s}  {'max |F - F_ss| [N]':>18s}")
    for i, w in enumerate(lag["omega"]):
        print(f"    {w:13g}  {lag['width'][i]:21.5f}  {lag['width_predicted'][i]:22.5f}  {lag['area'][i]:17.3e}  "
              f"{lag['max_deviation'][i]:18.4f}")

    rates = (0.03, 0.1, 0.3, 1.0, 3.0, 10.0)
    ba_runs = [run_break_away(r) for r in rates]
    ba = break_away(rates, ba_runs)
    print("\n(d) break-away force against the force rate (mass at rest, applied force u = rate t)")
    print(f"    quasi-static prediction: fs as the rate -> 0, falling to fc at the critical rate "
          f"{critical_rate():.1f} N/s")
    print(f"    {'rate [N/s]':>10s}  {'break-away [N]':>14s}  {'applied then [N]':>16s}  {'displacement [um]':>17s}  "
          f"{'quasi-static [N]':>16s}")
    for i, rate in enumerate(ba["rate"]):
        print(f"    {rate:10g}  {ba['break_away_force'][i]:14.4f}  {ba['applied_force'][i]:16.4f}  "
              f"{ba['displacement'][i] * 1e6:17.2f}  {ba['predicted'][i]:16.4f}")

    if args.plot:
        for p in _plot(args.plot, ss_run, pre_run, lag_runs, omegas, ba_runs, ba):
            print(f"wrote {p}")


if __name__ == "__main__":
    main()
