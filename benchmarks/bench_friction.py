"""Cost of the friction models on this machine (a script, not a test).

    .venv/bin/python benchmarks/bench_friction.py          (from the repository root)

Every model runs on the spring-pulled mass of Canudas de Wit et al. (1995): m = 1 kg, k_s = 2 N/m,
v_0 = 0.1 m/s, with the paper's LuGre parameters (sigma0 = 1e5 N/m, sigma1 = sqrt(1e5) N s/m,
sigma2 = 0.4 N s/m, fc = 1 N, fs = 1.5 N, vs = 1 mm/s) and, for the other models, the same values
where they have the parameter: Coulomb (fc, sigma2), Stribeck (fc, fs, vs, sigma2), Dahl (sigma0,
fc), elasto-plastic (LuGre's plus z_ba = 5 um, half of fc/sigma0), GMS with N = 4, 10, 50 elements
(equal capacities w_i = 1/N, stiffnesses k_i proportional to 1/i summing to sigma0, so that the
initial presliding stiffness is LuGre's; C = 20 N/s; fc, fs, vs, sigma2 as LuGre).

(i)  One right-hand-side evaluation (plant + friction) in the C core, timed in C by
     thermofriction._bridge.time_rhs over 2 million calls, best of 7, in nanoseconds, with the ratio
     to LuGre, at two sliding velocities: v = vs = 1 mm/s (inside the Stribeck band) and
     v = 0.1 m/s (gross sliding, where exp(-(v/vs)^2) underflows to zero; most of a stick-slip
     cycle's slip phase is there). LuGre, Dahl: z = fc/(2 sigma0); elasto-plastic:
     z = 0.8 fc/sigma0 (inside its transition band, where alpha is a sine); GMS: F_i = w_i fc/2,
     timed with every element stuck (mode 0) and with every element slipping (mode +1).
(ii) tf.simulate of 10 s of the stick-slip benchmark, output at 1 kHz, default solver and
     tolerances: wall time (best of 5), of it the time inside the C core's integrator, steps,
     rejected steps, rhs evaluations, Jacobian evaluations (Rodas4 steps: the automatic choice
     may probe Rodas4 and go back), located events (GMS stick/slip switches), the solver the
     automatic choice ended on, and the ratio of wall times to LuGre. The first slip, the peak
     friction force and the peak velocity say what the run did.

(iii) GMS only, 30 s (long enough for the automatic solver choice to probe Rodas4): wall time with
     AutoSwitch, Dopri5 and Rodas4; Rodas4 factorises the dense (N + 2) x (N + 2) iteration
     matrix at every step.

The LuGre-type models with these parameters warn (PassivityWarning: not dissipative above
14.5 mm/s); that warning is expected and silenced here.
"""

from __future__ import annotations

import math
import os
import time
import warnings
from pathlib import Path

import numpy as np

import thermofriction as tf
from thermofriction import _bridge

from _timing import core_timer  # benchmarks/ is the script's folder, first on sys.path

SIGMA0, SIGMA1, SIGMA2 = 1e5, math.sqrt(1e5), 0.4
FC, FS, VS = 1.0, 1.5, 1e-3
PLANT = tf.MassPlant(1.0, spring_stiffness=2.0, pull_velocity=0.1)
V_STATES = (1e-3, 0.1)  # m/s: in the Stribeck band (v = vs), and gross sliding


def gms(n):
    w = np.full(n, 1.0 / n)
    k = 1.0 / np.arange(1, n + 1)
    k = SIGMA0 * k / k.sum()
    return tf.GMS(k=tuple(k), w=tuple(w), C=20.0, fc=FC, fs=FS, vs=VS, sigma2=SIGMA2)


MODELS = {
    "LuGre": tf.LuGre(sigma0=SIGMA0, sigma1=SIGMA1, sigma2=SIGMA2, fc=FC, fs=FS, vs=VS),
    "Coulomb": tf.Coulomb(fc=FC, sigma2=SIGMA2),
    "Stribeck": tf.Stribeck(fc=FC, fs=FS, vs=VS, sigma2=SIGMA2),
    "Dahl": tf.Dahl(sigma0=SIGMA0, fc=FC),
    "elasto-plastic": tf.ElastoPlastic(sigma0=SIGMA0, sigma1=SIGMA1, sigma2=SIGMA2, fc=FC, fs=FS, vs=VS,
                                       z_ba=5e-6),
    "GMS, 4 elements": gms(4),
    "GMS, 10 elements": gms(10),
    "GMS, 50 elements": gms(50),
}


def state(friction, v):
    """[x, v, friction states...] for the rhs timings."""
    if isinstance(friction, tf.GMS):
        z = 0.5 * FC * np.asarray(friction.w)
    elif isinstance(friction, tf.ElastoPlastic):
        z = np.array([0.8 * FC / SIGMA0])
    elif friction.nstate:
        z = np.array([0.5 * FC / SIGMA0])
    else:
        z = np.empty(0)
    return np.concatenate([[0.0, v], z])


def time_rhs(spec, y, n_evals=2_000_000, repeats=7):
    return min(_bridge.time_rhs(spec, 1.0, y, n_evals)[0] for _ in range(repeats))


def part_i():
    print("(i) one right-hand-side evaluation in the C core (plant + friction), best of 7 x 2e6 calls, "
          "at two sliding velocities")
    rows = []
    for name, friction in MODELS.items():
        model = tf.Model(PLANT, friction)
        spec = _bridge.model_spec(model, None, None)
        variants = [(name, spec)]
        if isinstance(friction, tf.GMS):
            n = len(friction.k)
            variants = [(f"{name}, all {label}", {**spec, "gms_mode": np.full(n, mode)})
                        for label, mode in (("stuck", 0.0), ("slipping", 1.0))]
        for label, sp in variants:
            rows.append((label, [time_rhs(sp, state(friction, v)) for v in V_STATES], 2 + friction.nstate))
    ref = rows[0][1]
    w = max(len(r[0]) for r in rows)
    head = "  ".join(f"{f'v = {v:g} m/s [ns]':>18s}  {'/ LuGre':>7s}" for v in V_STATES)
    print(f"    {'model':{w}s}  {'states':>6s}  {head}")
    for name, secs, n in rows:
        cols = "  ".join(f"{sec * 1e9:18.1f}  {sec / r:7.2f}" for sec, r in zip(secs, ref))
        print(f"    {name:{w}s}  {n:6d}  {cols}")
    return rows


def part_ii(duration=10.0, rate=1000.0, repeats=5):
    print(f"\n(ii) tf.simulate, {duration:g} s of stick-slip (k_s = 2 N/m, v0 = 0.1 m/s), output at "
          f"{rate / 1000:g} kHz, default solver and tolerances; best of {repeats}")

    rows = []
    with core_timer() as core_time:  # the integration itself (C), apart from simulate()'s Python
        for name, friction in MODELS.items():
            model = tf.Model(PLANT, friction)
            runs = []
            for _ in range(repeats):
                core_time.clear()
                t0 = time.perf_counter()
                res = tf.simulate(model, duration, sample_rate=rate)
                runs.append((time.perf_counter() - t0, core_time[-1]))
            wall, c = min(runs)
            v = res.velocity
            onset = np.flatnonzero(v > 10 * VS)
            rows.append((name, wall, c, res.stats, res.time[onset[0]] if onset.size else math.nan,
                         float(res.friction_force.max()), float(v.max())))
    ref = rows[0][1]
    w = max(len(r[0]) for r in rows)
    print(f"    {'model':{w}s}  {'wall [ms]':>9s}  {'C core [ms]':>11s}  {'steps':>6s}  {'rejected':>8s}  "
          f"{'rhs evals':>9s}  {'jac evals':>9s}  {'events':>6s}  {'ended on':>8s}  {'/ LuGre':>7s}  "
          f"{'1st slip [s]':>12s}  {'peak F [N]':>10s}  {'peak v [m/s]':>12s}")
    for name, wall, c, st, slip, Fmax, vmax in rows:
        print(f"    {name:{w}s}  {wall * 1e3:9.2f}  {c * 1e3:11.2f}  {st['steps']:6d}  {st['rejected']:8d}  "
              f"{st['rhs_evals']:9d}  {st['jac_evals']:9d}  {st['events']:6d}  {st['solver']:>8s}  {wall / ref:7.2f}  "
              f"{slip:12.3f}  {Fmax:10.4f}  {vmax:12.4f}")
    return rows


def part_iii(duration=30.0, rate=1000.0, repeats=5):
    print(f"\n(iii) GMS and the solver choice: {duration:g} s of stick-slip, output at {rate / 1000:g} kHz, "
          f"best of {repeats}")
    rows = []
    for name in ("GMS, 4 elements", "GMS, 10 elements", "GMS, 50 elements"):
        model = tf.Model(PLANT, MODELS[name])
        for solver in (tf.AutoSwitch(), tf.Dopri5(), tf.Rodas4()):
            best, res = math.inf, None
            for _ in range(repeats):
                t0 = time.perf_counter()
                res = tf.simulate(model, duration, sample_rate=rate, solver=solver)
                best = min(best, time.perf_counter() - t0)
            rows.append((name, solver.name, best, res.stats))
    w = max(len(r[0]) for r in rows)
    print(f"    {'model':{w}s}  {'solver':>6s}  {'wall [ms]':>9s}  {'steps':>6s}  {'jac evals':>9s}  {'events':>6s}  "
          f"{'ended on':>8s}  {'switched at [s]':>15s}")
    for name, solver, wall, st in rows:
        sw = f"{st['switch_time']:15.3f}" if st["switch_time"] >= 0 else f"{'-':>15s}"
        print(f"    {name:{w}s}  {solver:>6s}  {wall * 1e3:9.2f}  {st['steps']:6d}  {st['jac_evals']:9d}  "
              f"{st['events']:6d}  {st['solver']:>8s}  {sw}")
    return rows


def main():
    print(f"thermofriction {getattr(tf, '__version__', '?')} from {Path(tf.__file__).parent}; "
          f"numpy {np.__version__}; {os.cpu_count()} CPU(s)\n")
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=tf.PassivityWarning)
        part_i()
        part_ii()
        part_iii()


if __name__ == "__main__":
    main()
