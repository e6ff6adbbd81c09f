"""Speed and memory of tf.simulate on this machine (a script, not a test).

    /work/venv/bin/python benchmarks/bench_simulate.py          (from the repository root)

(i)   The Li (2009) Model I preset at 35.7 C, 2 s simulated, output at 10 kHz: tf.simulate (best of
      several runs) against SciPy's solve_ivp(method="LSODA", rtol=1e-6, atol=the same per-state
      scaled atol the C core uses by default) on the plain-Python reference right-hand side
      (tests/reference/), both across the whole interval in one call (what a SciPy user writes)
      and restarted at every corner of the sawtooth. Accuracy of each against a tight reference
      (DOP853, rtol 1e-10, piecewise), as max |x_e error| / (max x_e - min x_e); the speed ratio;
      and the ratio at matched accuracy (LSODA tightened until it is at least as accurate as we are).
(ii)  tf.simulate for 1, 10 and 100 s simulated: wall time and time per simulated second.
(iii) Peak memory of a 100 s run at 10 kHz (in a fresh interpreter): tracemalloc peak of Python
      allocations (NumPy arrays included) and the increase of the peak resident set size
      (VmHWM; ru_maxrss where /proc is missing), against the size of the output arrays.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import thermofriction as tf  # noqa: E402
import reference as R  # noqa: E402
from _timing import core_timer  # noqa: E402  (benchmarks/ is the script's folder, first on sys.path)

T_C = 35.7
DURATION = 2.0
RATE = 10_000.0


def best_of(fn, n):
    times, out = [], None
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def lsoda(model, t_eval, rtol, piecewise):
    """SciPy LSODA on the reference rhs with the C core's default scaled atol (rtol x state scale)."""
    atol = R.default_atol(model, T_C, rtol=rtol)
    if piecewise:
        return R.reference_simulate(model, t_eval, T_C, method="LSODA", rtol=rtol, atol=atol).y[:, 2]
    ref = R.ReferenceModel(model, T_C)
    sol = solve_ivp(ref.rhs, (t_eval[0], t_eval[-1]), np.zeros(5), method="LSODA", rtol=rtol, atol=atol,
                    t_eval=t_eval)
    if sol.status != 0:
        raise RuntimeError(sol.message)
    return sol.y[2]


def part_i():
    print(f"(i) Model I preset at {T_C} C, {DURATION:g} s simulated, output at {RATE / 1000:g} kHz "
          f"({int(DURATION * RATE) + 1} samples)")
    model = tf.load_model("li2009-model-i")
    t_eval = np.arange(int(DURATION * RATE) + 1) / RATE
    t0 = time.perf_counter()
    ref = R.reference_simulate(model, t_eval, T_C, method="DOP853", rtol=1e-10)
    t_ref = time.perf_counter() - t0
    x_ref = ref.y[:, 2]
    span = np.ptp(x_ref)
    print(f"    tight reference: SciPy DOP853, rtol 1e-10, atol 1e-10 x state scale, piecewise between "
          f"{ref.segments} corner-to-corner segments: {t_ref:.2f} s; x_e range {span * 1e6:.4f} um")

    def err(x):
        return np.max(np.abs(x - x_ref)) / span

    rows = []
    t_tf, res = best_of(lambda: tf.simulate(model, DURATION, temperature=T_C, sample_rate=RATE), 15)
    e_tf = err(res.displacement)
    rows.append(("tf.simulate (AutoSwitch, rtol 1e-6, default atol)", t_tf, e_tf, f"{res.stats['steps']} steps, "
                 f"{res.stats['rhs_evals']} rhs, {res.stats['solver']}"))
    for solver in (tf.Dopri5(), tf.Rodas4()):
        t_s, r_s = best_of(lambda: tf.simulate(model, DURATION, temperature=T_C, sample_rate=RATE, solver=solver), 5)
        rows.append((f"tf.simulate ({solver.name}, rtol 1e-6, default atol)", t_s, err(r_s.displacement),
                     f"{r_s.stats['steps']} steps, {r_s.stats['rhs_evals']} rhs"))
    lsoda_runs = {}
    for piecewise in (False, True):
        label = "piecewise between corners" if piecewise else "whole interval, one call"
        t_l, x_l = best_of(lambda: lsoda(model, t_eval, 1e-6, piecewise), 3)
        lsoda_runs[piecewise] = (t_l, err(x_l))
        rows.append((f"SciPy LSODA rtol 1e-6, same atol, {label}", t_l, err(x_l), ""))
    w = max(len(r[0]) for r in rows)
    print(f"    {'run':{w}s}  {'wall [s]':>9s}  {'max err / range':>15s}")
    for name, t, e, note in rows:
        print(f"    {name:{w}s}  {t:9.4f}  {e:15.2e}  {note}")
    for piecewise in (False, True):
        t_l, e_l = lsoda_runs[piecewise]
        print(f"    speed ratio, LSODA rtol 1e-6 ({'piecewise' if piecewise else 'whole interval'}) / tf.simulate: "
              f"{t_l / t_tf:.0f}x  (accuracy: LSODA {e_l:.1e}, tf.simulate {e_tf:.1e})")

    # matched accuracy: LSODA tightened until its error is at most ours
    print("    matched accuracy (LSODA across the whole interval, rtol tightened until its error <= tf.simulate's):")
    matched = None
    for rtol in (1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 1e-10):
        t_l, x_l = best_of(lambda: lsoda(model, t_eval, rtol, False), 1)
        e_l = err(x_l)
        print(f"      LSODA rtol {rtol:.0e}: {t_l:7.3f} s, error {e_l:.2e}")
        if e_l <= e_tf:
            matched = (rtol, t_l, e_l)
            break
    if matched:
        rtol, t_l, e_l = matched
        t_l, _ = best_of(lambda: lsoda(model, t_eval, rtol, False), 2)
        print(f"    speed ratio at matched accuracy: LSODA rtol {rtol:.0e} ({e_l:.1e}, {t_l:.3f} s) / tf.simulate "
              f"({e_tf:.1e}, {t_tf:.4f} s) = {t_l / t_tf:.0f}x")
    else:
        print("    LSODA did not reach tf.simulate's accuracy down to rtol 1e-10")
    return t_tf


def part_ii():
    print("\n(ii) cost against simulated time (Model I preset at 35.7 C, 10 kHz output, default solver)")

    model = tf.load_model("li2009-model-i")
    print(f"    {'simulated [s]':>13s}  {'wall [s]':>9s}  {'per simulated s [ms]':>20s}  {'in C core [s]':>13s}  "
          f"{'C per sim. s [ms]':>17s}  {'steps':>8s}")
    per, per_c = [], []
    with core_timer() as core_time:  # the integration itself (C), apart from simulate()'s Python
        for d, n in ((1.0, 7), (10.0, 3), (100.0, 2)):
            walls = []
            for _ in range(n):
                core_time.clear()
                t0 = time.perf_counter()
                res = tf.simulate(model, d, temperature=T_C, sample_rate=RATE)
                walls.append((time.perf_counter() - t0, core_time[-1]))
            t, tc = min(walls)
            per.append(t / d)
            per_c.append(tc / d)
            print(f"    {d:13g}  {t:9.4f}  {1e3 * t / d:20.3f}  {tc:13.4f}  {1e3 * tc / d:17.3f}  "
                  f"{res.stats['steps']:8d}")
    print(f"    growth of the time per simulated second, 100 s / 1 s: whole call {per[2] / per[0]:.2f}, "
          f"C core {per_c[2] / per_c[0]:.2f} (1 = linear)")


_MEMORY_CHILD = r"""
import json, resource, sys, tracemalloc
import numpy as np
import thermofriction as tf


def peak_rss_kb():
    # VmHWM belongs to this process image; ru_maxrss would carry the parent's peak over exec (Linux)
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


model = tf.load_model("li2009-model-i")
tf.simulate(model, 0.01, temperature=35.7)            # warm up imports and caches
rss0 = peak_rss_kb()
mode = sys.argv[1]
if mode == "tracemalloc":
    tracemalloc.start()
res = tf.simulate(model, 100.0, temperature=35.7, sample_rate=10_000)
out = {"rss_delta_kb": peak_rss_kb() - rss0}
if mode == "tracemalloc":
    out["tracemalloc_peak"] = tracemalloc.get_traced_memory()[1]
arrays = [getattr(res, n) for n in ("time", "input", "stage_displacement", "stage_velocity", "displacement",
          "velocity", "relative_displacement", "relative_velocity", "friction_force", "temperature", "states",
          "cycle_times", "step_sizes")]
out["output_bytes"] = int(sum(a.nbytes for a in arrays))
out["samples"] = int(res.time.size)
print(json.dumps(out))
"""


def part_iii():
    print("\n(iii) peak memory of a 100 s run at 10 kHz (fresh interpreter each)")
    runs = {}
    for mode in ("rss", "tracemalloc"):
        p = subprocess.run([sys.executable, "-c", _MEMORY_CHILD, mode], capture_output=True, text=True, check=True,
                           env={**os.environ, "PYTHONPATH": str(ROOT / "tests")})
        runs[mode] = json.loads(p.stdout.strip().splitlines()[-1])
    out_mb = runs["rss"]["output_bytes"] / 1e6
    rss_mb = runs["rss"]["rss_delta_kb"] * 1024 / 1e6
    tm_mb = runs["tracemalloc"]["tracemalloc_peak"] / 1e6
    print(f"    samples: {runs['rss']['samples']}; output arrays (all result fields): {out_mb:.1f} MB")
    print(f"    {'measure':44s}  {'MB':>8s}  {'/ output':>8s}")
    print(f"    {'tracemalloc peak (Python + NumPy allocations)':44s}  {tm_mb:8.1f}  {tm_mb / out_mb:8.2f}")
    print(f"    {'peak RSS increase (VmHWM, whole process)':44s}  {rss_mb:8.1f}  {rss_mb / out_mb:8.2f}")


def main():
    print(f"thermofriction {getattr(tf, '__version__', '?')} from {Path(tf.__file__).parent}; "
          f"numpy {np.__version__}; {os.cpu_count()} CPU(s)\n")
    part_i()
    part_ii()
    part_iii()


if __name__ == "__main__":
    main()
