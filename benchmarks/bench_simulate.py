"""Speed and memory of tf.simulate on this machine (a script, not a test).

    .venv/bin/python benchmarks/bench_simulate.py [--parts i,ii,iii] [--rounds 15]   (from the repository root)

(i)   The Li (2009) Model I preset at 35.7 C, sawtooth 30 V 5 Hz, 2 s simulated, output at 10 kHz:
      tf.simulate (default, Dopri5, Rodas4) against the near-limit baseline -- a plain C
      Dormand-Prince 5(4) with the workload's right-hand side inline (baseline_dopri5.c, compiled
      here with the system cc, called through ctypes) over a sweep of tolerances -- and SciPy's
      solve_ivp(method="LSODA", rtol=1e-7, the same per-state scaled atol) on the plain-Python
      reference right-hand side (tests/reference/). All timed in one process, in interleaved rounds
      (medians of this thread's CPU time), as ms per simulated second; accuracy as max |x_e error| in % of the range of x_e
      against a tight reference (DOP853, rtol 1e-10, piecewise); the ratios, the one to the plain
      integrator at matched accuracy (the loosest of its tolerances from which on it is at least
      as accurate as the default).
(ii)  tf.simulate for 1, 10 and 100 s simulated: CPU time of the calling thread (robust to the machine's other load) and per simulated second.
(iii) Peak memory of a 100 s run at 10 kHz (in a fresh interpreter): tracemalloc peak of Python
      allocations (NumPy arrays included) and the increase of the peak resident set size
      (VmHWM; ru_maxrss where /proc is missing), against the size of the output arrays.
(iv)  Start-up, as whole processes (interleaved, medians): the interpreter alone, `import numpy`
      (the floor: the package needs NumPy), `import thermofriction`, `thermofriction simulate
      --help`, and a whole `thermofriction simulate` of 0.1 s writing a CSV (target 0.3 s).
"""

from __future__ import annotations

import argparse
import ctypes
import json
import math
import os
import subprocess
import sys
import tempfile
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


def best_of(fn, n, clock=time.perf_counter):
    times, out = [], None
    for _ in range(n):
        t0 = clock()
        out = fn()
        times.append(clock() - t0)
    return min(times), out


def interleaved(runs: dict, rounds: int, clock=time.thread_time) -> dict:
    """Times every run once per round, the runs in turn (so that the machine's other load falls on
    all of them alike); returns name -> (median time [s], last result, median C-core time or None).
    A run is a function returning its result. The clock is this thread's CPU time by default: on a
    shared machine a few-millisecond run is often preempted, which wall time counts and CPU time
    does not (everything timed here, the C integrators included, runs on the calling thread)."""
    walls = {name: [] for name in runs}
    cores = {name: [] for name in runs}
    last = {}
    with core_timer(clock) as core_time:
        for _ in range(rounds):
            for name, fn in runs.items():
                core_time.clear()
                t0 = clock()
                last[name] = fn()
                walls[name].append(clock() - t0)
                cores[name].append(sum(core_time) if core_time else math.nan)
    return {name: (float(np.median(walls[name])), last[name],
                   float(np.median(cores[name])) if not math.isnan(cores[name][0]) else None) for name in runs}


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


class _BaselineParams(ctypes.Structure):
    _fields_ = [(n, ctypes.c_double) for n in ("m", "c", "k", "T_em", "m_e", "sigma0", "sigma1", "sigma2", "fc",
                                               "amplitude", "frequency", "rise", "offset")]


class _BaselineStats(ctypes.Structure):
    _fields_ = [(n, ctypes.c_long) for n in ("steps", "rejected", "rhs_evals")]


class PlainDopri5:
    """benchmarks/baseline_dopri5.c, compiled here with the system C compiler (the core's -O3) and
    called through ctypes: a plain Dormand-Prince 5(4) with this workload's right-hand side inline."""

    def __init__(self, model, temperature):
        self.tmp = tempfile.TemporaryDirectory()
        lib = Path(self.tmp.name) / "baseline_dopri5.so"
        cc = os.environ.get("CC", "cc")
        subprocess.run([cc, "-O3", "-shared", "-fPIC", "-o", str(lib), str(ROOT / "benchmarks" / "baseline_dopri5.c"),
                        "-lm"], check=True)
        self.lib = ctypes.CDLL(str(lib))
        dp = ctypes.POINTER(ctypes.c_double)
        self.lib.baseline_dopri5.argtypes = [ctypes.POINTER(_BaselineParams), ctypes.c_double, dp, dp, ctypes.c_long,
                                             dp, ctypes.c_long, ctypes.POINTER(_BaselineStats)]
        p = model.parameters_at(temperature)
        if model.friction.model != "lugre" or p["fs"] != p["fc"] or p.get("vd", 0.0) > 0:
            raise ValueError("the baseline's inline rhs is LuGre with fs = fc and a constant sigma1")
        c, k, T_em = model.plant.physical()
        w = model.input
        self.params = _BaselineParams(model.plant.mass, c, k, T_em, model.plant.end_effector_mass, p["sigma0"],
                                      p["sigma1"], p["sigma2"], p["fc"], w.amplitude, w.frequency, w.rise,
                                      getattr(w, "offset", 0.0))
        self.model, self.temperature = model, temperature
        self.stats = _BaselineStats()

    def __call__(self, t_eval, rtol):
        atol = np.ascontiguousarray(R.default_atol(self.model, self.temperature, rtol=rtol))
        out = np.empty((t_eval.size, 5))
        dp = ctypes.POINTER(ctypes.c_double)
        if self.lib.baseline_dopri5(ctypes.byref(self.params), rtol, atol.ctypes.data_as(dp),
                                    t_eval.ctypes.data_as(dp), t_eval.size, out.ctypes.data_as(dp), 10_000_000,
                                    ctypes.byref(self.stats)):
            raise RuntimeError("baseline: max_steps")
        return out


def part_i(rounds):
    print(f"(i) Model I preset at {T_C} C, sawtooth 30 V 5 Hz, {DURATION:g} s simulated, output at "
          f"{RATE / 1000:g} kHz ({int(DURATION * RATE) + 1} samples); times are CPU times of the calling thread, "
          f"medians of {rounds} interleaved rounds")
    model = tf.load_model("li2009-model-i")
    t_eval = np.arange(int(DURATION * RATE) + 1) / RATE
    t0 = time.perf_counter()
    ref = R.reference_simulate(model, t_eval, T_C, method="DOP853", rtol=1e-10)
    t_ref = time.perf_counter() - t0
    x_ref = ref.y[:, 2]
    span = np.ptp(x_ref)
    print(f"    tight reference: SciPy DOP853, rtol 1e-10, atol 1e-10 x state scale, piecewise between "
          f"{ref.segments} corner-to-corner segments: {t_ref:.2f} s; x_e range {span * 1e6:.4f} um")

    def err(x):  # max |x_e error| as % of the range of x_e
        return 100.0 * np.max(np.abs(x - x_ref)) / span

    def sim(solver=None, rtol=1e-6):
        return lambda: tf.simulate(model, DURATION, temperature=T_C, sample_rate=RATE, solver=solver,
                                   controller=tf.StepSizeController(rtol=rtol))

    runs = {"tf.simulate default (auto), rtol 1e-6": sim(),
            "tf.simulate default (auto), rtol 1e-7": sim(rtol=1e-7),
            "tf.simulate Dopri5, rtol 1e-6": sim(tf.Dopri5()),
            "tf.simulate Rodas4, rtol 1e-6": sim(tf.Rodas4())}
    try:
        plain = PlainDopri5(model, T_C)
    except (OSError, subprocess.CalledProcessError, ValueError) as e:
        plain = None
        print(f"    (the plain C baseline could not be built: {e})")
    plain_rtols = [10.0 ** (-k / 4) for k in range(20, 37)] if plain else []  # 1e-5 .. 1e-9

    def plain_name(rtol):
        return f"plain C Dormand-Prince 5(4), inline rhs, rtol {rtol:.1e}"

    for rtol in plain_rtols:
        runs[plain_name(rtol)] = (lambda r: lambda: plain(t_eval, r))(rtol)
    timed = interleaved(runs, rounds)
    t_l, x_l = best_of(lambda: lsoda(model, t_eval, 1e-7, False), 2, clock=time.thread_time)

    rows = []
    for name, (wall, res, core) in timed.items():
        x = res.displacement if hasattr(res, "displacement") else res[:, 2]
        note = (f"{res.stats['steps']} steps, {res.stats['rejected']} rejected, {res.stats['rhs_evals']} rhs, "
                f"{res.stats['solver']}" if hasattr(res, "stats") else "")
        rows.append((name, wall, core, err(x), note))
    rows.append(("SciPy LSODA, rtol 1e-7, whole interval (best of 2)", t_l, None, err(x_l), ""))
    w = max(len(r[0]) for r in rows)
    print(f"    {'run':{w}s}  {'ms per sim. s':>13s}  {'C core':>7s}  {'max err, % of range':>19s}")
    for name, t, core, e, note in rows:
        c = f"{1e3 * core / DURATION:7.2f}" if core is not None else " " * 7
        print(f"    {name:{w}s}  {1e3 * t / DURATION:13.2f}  {c}  {e:19.2e}  {note}")

    name = "tf.simulate default (auto), rtol 1e-6"
    t_tf, _, core_tf = timed[name]
    e_tf = next(r[3] for r in rows if r[0] == name)
    print(f"    LSODA rtol 1e-7 / tf.simulate default: {t_l / t_tf:.0f}x slower (errors {err(x_l):.1e} % and "
          f"{e_tf:.1e} %)")
    if plain:
        # matched accuracy: from the tightest tolerance down, the loosest plain-C run before its error first
        # exceeds the default's (its error is not monotone in rtol: a lucky loose run does not count)
        matched = None
        for rtol in sorted(plain_rtols):
            e = next(r[3] for r in rows if r[0] == plain_name(rtol))
            if e > e_tf:
                break
            matched = (timed[plain_name(rtol)][0], rtol, e)
        if matched:
            t_p, r_p, e_p = matched
            print(f"    at matched accuracy: tf.simulate default ({e_tf:.1e} %, {1e3 * t_tf / DURATION:.2f} ms/s) / "
                  f"plain C at rtol {r_p:.1e} ({e_p:.1e} %, {1e3 * t_p / DURATION:.2f} ms/s) = {t_tf / t_p:.2f}x  "
                  f"(C core alone: {core_tf / t_p:.2f}x; targets: <= 1.5x, <= 1.2 ms/s at <= 2e-4 %)")
        else:
            print("    the plain C integrator did not reach the default's accuracy down to rtol 1e-9")
        for solver in ("Dopri5", "Rodas4"):
            t_s = timed[f"tf.simulate {solver}, rtol 1e-6"][0]
            print(f"    tf.simulate {solver} / plain C, both at rtol 1e-6: {t_s / timed[plain_name(1e-6)][0]:.2f}x")
    return t_tf


def part_ii():
    print("\n(ii) cost against simulated time (Model I preset at 35.7 C, 10 kHz output, default solver)")

    model = tf.load_model("li2009-model-i")
    print(f"    {'simulated [s]':>13s}  {'CPU [s]':>9s}  {'per simulated s [ms]':>20s}  {'in C core [s]':>13s}  "
          f"{'C per sim. s [ms]':>17s}  {'steps':>8s}")
    per, per_c = [], []
    # CPU time of this thread (the C core runs on it): robust to the machine's other load
    with core_timer(time.thread_time) as core_time:  # the integration itself (C), apart from simulate()'s Python
        for d, n in ((1.0, 7), (10.0, 3), (100.0, 2)):
            walls = []
            for _ in range(n):
                core_time.clear()
                t0 = time.thread_time()
                res = tf.simulate(model, d, temperature=T_C, sample_rate=RATE)
                walls.append((time.thread_time() - t0, core_time[-1]))
            t, tc = min(walls)
            per.append(t / d)
            per_c.append(tc / d)
            print(f"    {d:13g}  {t:9.4f}  {1e3 * t / d:20.3f}  {tc:13.4f}  {1e3 * tc / d:17.3f}  "
                  f"{res.stats['steps']:8d}")
    print(f"    growth of the time per simulated second, 100 s / 1 s: whole call {per[2] / per[0]:.2f}, "
          f"C core {per_c[2] / per_c[0]:.2f} (1 = linear)")
    # the same 100 s with 100x fewer outputs: the integration alone, apart from writing 88 MB of fresh memory
    with core_timer(time.thread_time) as core_time:
        t0 = time.thread_time()
        res = tf.simulate(model, 100.0, temperature=T_C, sample_rate=RATE / 100)
        t, tc = time.thread_time() - t0, core_time[-1]
    print(f"    100 s at {RATE / 100:g} Hz output: {1e3 * t / 100:.3f} ms per simulated s (C core {1e3 * tc / 100:.3f}), "
          f"{res.stats['steps']} steps: against 1 s at {RATE / 1000:g} kHz, {t / 100 / per[0]:.2f} (C core "
          f"{tc / 100 / per_c[0]:.2f}); the rest of the growth above is the output block's first touch of fresh "
          f"memory (page faults)")


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


def part_iv(rounds=9):
    print(f"\n(iv) start-up as whole processes (medians of {rounds} interleaved rounds)")
    exe = Path(sys.executable).with_name("thermofriction")
    with tempfile.TemporaryDirectory() as tmp:
        cmds = {"python -c pass": [sys.executable, "-c", "pass"],
                "python -c 'import numpy'": [sys.executable, "-c", "import numpy"],
                "python -c 'import thermofriction'": [sys.executable, "-c", "import thermofriction"],
                "thermofriction simulate --help": [str(exe), "simulate", "--help"],
                "thermofriction simulate (0.1 s, -o CSV)": [str(exe), "simulate", "li2009-model-i", "--temperature",
                                                            "35.7", "--duration", "0.1", "-o",
                                                            str(Path(tmp) / "run.csv")]}
        times = {k: [] for k in cmds}
        for _ in range(rounds):
            for k, c in cmds.items():
                t0 = time.perf_counter()
                subprocess.run(c, stdout=subprocess.DEVNULL, check=True)
                times[k].append(time.perf_counter() - t0)
    floor = float(np.median(times["python -c 'import numpy'"]))
    for k, v in times.items():
        t = float(np.median(v))
        print(f"    {k:42s}  {t:6.3f} s  ({t - floor:+.3f} s over importing NumPy)")
    print("    target: the whole simulate process <= 0.3 s")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", default="i,ii,iii,iv", help="which parts to run (comma-separated; default all)")
    ap.add_argument("--rounds", type=int, default=15, help="interleaved rounds of part (i) (default 15)")
    args = ap.parse_args()
    parts = set(args.parts.split(","))
    print(f"thermofriction {getattr(tf, '__version__', '?')} from {Path(tf.__file__).parent}; "
          f"numpy {np.__version__}; {os.cpu_count()} CPU(s); load average {os.getloadavg()[0]:.1f}\n")
    if "i" in parts:
        part_i(args.rounds)
    if "ii" in parts:
        part_ii()
    if "iii" in parts:
        part_iii()
    if "iv" in parts:
        part_iv()


if __name__ == "__main__":
    main()
