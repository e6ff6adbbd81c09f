"""Parallel efficiency of the scale-out workloads on the embedded default (threads in this process), in
one run: each workload sequentially (``scheduler="sequential"``) and on the default, with

    parallel efficiency = t_sequential / (workers x t_parallel)

and the check that both give the same output to the last bit. Then, on a local Dask cluster of worker
processes (``scheduler="processes"``'s), the scheduler's overhead per task (empty tasks) against the
work of one chunk of the sweep: Dask's overhead share per chunk.

    python benchmarks/bench_scale.py [--workers N] [--runs N] [--only sweep,propagate,fleet,dask] [--quick]

- sweep: li2009-model-i, 1201 temperatures x 3 amplitudes = 3603 two-second runs at 10 kHz (the
  issue's design sweep);
- propagate: a fit's uncertainty, 1000 draws x 2 temperatures = 2000 two-second runs at 1 kHz;
- fleet: 8 identifications (li2009-base, 2 starts, 3 runs of 2 s each; an identification is hundreds of runs,
  so the fleet has fewer, longer tasks). tf.identify runs some of its own simulations side by side on
  a thread pool, so its "sequential" run already uses more than one core in part: the fleet's
  efficiency against it understates what the fleet's own parallelism adds.

The machine's load average (os.getloadavg) is printed before and after each measurement: on cores
shared with other jobs the wall-clock efficiency is depressed by the time the others take; the CPU
time of this process (sequential against parallel) is printed too, as the part of the overhead that
does not depend on the load.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import os
import time

import numpy as np

import thermofriction as tf
from _timing import core_timer  # noqa: E402  (benchmarks/ is the script's folder, first on sys.path)


def load() -> str:
    return "/".join(f"{x:.2f}" for x in os.getloadavg())


def timed(fn, one_core=False):
    """(result, wall [s], CPU of this process [s], load average before, after). ``one_core``: this process
    (all its threads) pinned to one core for the run."""
    cores = os.sched_getaffinity(0) if one_core else None
    if one_core:
        pin({min(cores)})
    try:
        before = load()
        c0, t0 = time.process_time(), time.perf_counter()
        out = fn()
        return out, time.perf_counter() - t0, time.process_time() - c0, before, load()
    finally:
        if one_core:
            pin(cores)


def pin(cores):
    """Every thread of this process (Linux: the affinity is a thread's; new threads inherit it) on ``cores``."""
    for tid in os.listdir("/proc/self/task"):
        try:
            os.sched_setaffinity(int(tid), cores)
        except OSError:  # a thread that has ended since
            pass


def best(runs, seq, par, one_core=False):
    """``runs`` alternating measurements of seq() and par(): the fastest of each (the machine's other jobs
    only ever add time)."""
    s = p = None
    for _ in range(runs):
        a = timed(seq, one_core)
        s = a if s is None or a[1] < s[1] else s
        b = timed(par)
        p = b if p is None or b[1] < p[1] else p
    return s, p


def row(name, n, unit, seq, par, workers, same, baseline="sequential"):
    _, t_s, c_s, l0, l1 = seq
    _, t_p, c_p, l2, l3 = par
    eff = t_s / (workers * t_p)
    print(f"{name:10s} {n:5d} {unit:12s} {baseline:14s} {t_s:7.2f} s  CPU {c_s:6.2f} s ({c_s / t_s:.2f} cores)  "
          f"load {l0} -> {l1}")
    print(f"{'':29s} {str(workers) + ' threads':14s} {t_p:7.2f} s  CPU {c_p:6.2f} s ({c_p / t_p:.2f} cores)  "
          f"load {l2} -> {l3}")
    print(f"{'':29s} parallel efficiency {eff:.2f} (speed-up {t_s / t_p:.2f}x on {workers}); CPU parallel / "
          f"sequential {c_p / c_s:.2f}; output identical: {same}")
    return eff


def same_sweep(a, b):
    return (all(np.array_equal(a[k], b[k], equal_nan=True) for k in a.columns) and a.errors == b.errors
            and a.warnings == b.warnings)


def same_bands(a, b):
    names = ("nominal", "median", "lower", "upper", "prediction_lower", "prediction_upper", "steps",
             "final_displacement", "parameters", "step_lower", "step_upper")
    return all(np.array_equal(getattr(a, k), getattr(b, k), equal_nan=True) for k in names) and a.failures == b.failures


def same_fleet(a, b):
    return a.names == b.names and a.failures == b.failures and all(
        a.fits[n].rmse == b.fits[n].rmse and all(a.fits[n].parameters[p].value == b.fits[n].parameters[p].value
                                                 for p in a.fits[n].parameters) for n in a.fits)


def _noop(x):
    return x


def gil_share(fn, workers):
    """Prints the share of fn()'s CPU time that holds the GIL (the Python around the C core, which runs one
    thread at a time) and the bound it sets on threads."""
    with core_timer(time.thread_time) as in_core:
        c0 = time.thread_time()
        fn()
        c_all = time.thread_time() - c0
    gil = 1.0 - sum(in_core) / c_all
    print(f"{'':29s} the GIL is held {100 * gil:.0f} % of a run's CPU time (outside the C core): on {workers} free "
          f"cores threads can reach at most {min(1.0, 1.0 / (workers * gil)):.2f}")


def cores_free(workers, n_evals=3_000_000):
    """The machine's parallel efficiency right now for work that is perfectly parallel: the C core's
    right-hand side (LuGre on a mass), timed in C without the GIL, n_evals on one thread against n_evals on
    each of ``workers`` threads at once (1.0 on free cores; the other jobs' share of the cores lowers it)."""
    from concurrent.futures import ThreadPoolExecutor

    from thermofriction import _bridge
    model = tf.Model(tf.MassPlant(1.0, spring_stiffness=2.0, pull_velocity=0.1),
                     tf.LuGre(sigma0=1e5, sigma1=300.0, sigma2=0.4, fc=1.0, fs=1.5, vs=0.001))
    spec, y = _bridge.model_spec(model, None, None), np.array([0.0, 1e-3, 5e-6])

    def one(_=None):
        t0 = time.perf_counter()
        _bridge.time_rhs(spec, 1.0, y, n_evals)
        return time.perf_counter() - t0
    t1 = one()
    with ThreadPoolExecutor(workers) as pool:
        t0 = time.perf_counter()
        list(pool.map(one, range(workers)))
        tw = time.perf_counter() - t0
    return t1 / tw


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--quick", action="store_true", help="a tenth of the work (a smoke test, not a measurement)")
    ap.add_argument("--only", default="sweep,propagate,fleet,dask", help="which of sweep,propagate,fleet,dask")
    ap.add_argument("--no-dask", action="store_true", help="skip the local Dask cluster")
    ap.add_argument("--runs", type=int, default=2, help="measurements of each, alternating; the fastest is shown")
    args = ap.parse_args()
    w = args.workers
    scale = 0.1 if args.quick else 1.0
    print(f"{os.cpu_count()} cores, {w} workers; best of {args.runs} alternating runs; load average (1/5/15 min) "
          f"{load()}; GIL-free C work on {w} threads runs at parallel efficiency {cores_free(w):.2f} now")

    only = set(args.only.split(",")) - ({"dask"} if args.no_dask else set())
    effs, free = {}, [cores_free(w)]
    model = tf.load_model("li2009-model-i")
    grid = {"temperature": np.linspace(30.0, 42.0, max(int(1201 * scale), 2)), "amplitude": [10.0, 20.0, 30.0]}
    opts = dict(duration=2.0)
    tf.sweep(model, {"temperature": [33.0, 36.0]}, scheduler="sequential", **opts)  # imports, caches: not timed
    ref_sweep = None
    if "sweep" in only:
        effs["sweep"], ref_sweep = bench_sweep(model, grid, opts, w, args.runs)
        free.append(cores_free(w))
    if "propagate" in only:
        effs["propagate"] = bench_propagate(w, args.runs, scale)
        free.append(cores_free(w))
    if "fleet" in only:
        effs["fleet"] = bench_fleet(w, args.runs, scale)
        free.append(cores_free(w))
    if "dask" in only:
        if ref_sweep is None:
            ref_sweep = timed(lambda: tf.sweep(model, grid, scheduler="sequential", **opts))
        bench_dask(model, grid, opts, w, ref_sweep)
    print("parallel efficiency (target >= 0.9): " + ", ".join(f"{k} {v:.2f}" for k, v in effs.items())
          + f"; load average now {load()}")
    print(f"the machine's own parallel efficiency for GIL-free C work on {w} threads, measured before the first "
          f"workload and after each: " + ", ".join(f"{x:.2f}" for x in free)
          + " (1.0 on free cores: what the other jobs leave of them)")


def bench_sweep(model, grid, opts, w, runs):
    """The issue's design sweep: 3603 two-second runs."""
    n_sweep = grid["temperature"].size * len(grid["amplitude"])
    chunks = []

    def par_sweep():
        chunks.clear()
        return tf.sweep(model, grid, workers=w, progress=chunks.append, **opts)
    seq, par = best(runs, lambda: tf.sweep(model, grid, scheduler="sequential", **opts), par_sweep)
    eff = row("sweep", n_sweep, "runs of 2 s", seq, par, w, same_sweep(seq[0], par[0]))
    print(f"{'':29s} {len(chunks)} chunks, {n_sweep / len(chunks):.0f} runs each on average")
    sub = {"temperature": grid["temperature"][::10], "amplitude": grid["amplitude"]}
    gil_share(lambda: tf.sweep(model, sub, scheduler="sequential", **opts), w)
    return eff, seq


def bench_propagate(w, runs, scale):
    """1000 draws x 2 temperatures of a fit's uncertainty."""
    base = tf.load_model("li2009-base")
    truth = dataclasses.replace(base, friction=dataclasses.replace(base.friction, fc=base.friction.fc * 0.85))
    data = tf.synthesize(truth, [35.0], duration=0.6, sample_rate=5000, noise=20e-9, seed=3)
    fit = tf.identify(data, "base", init="li2009-base", starts=2, parameters=["sigma0", "fc"])
    draws = max(int(1000 * scale), 2)
    popts = dict(temperatures=[33.0, 38.0], draws=draws, seed=1, duration=2.0)
    tf.propagate(fit, [35.0], draws=4, duration=0.2, scheduler="sequential")  # imports (SciPy's stats): not timed
    seq, par = best(runs, lambda: tf.propagate(fit, scheduler="sequential", **popts),
                    lambda: tf.propagate(fit, workers=w, **popts))
    eff = row("propagate", 2 * draws, "runs of 2 s", seq, par, w, same_bands(seq[0], par[0]))
    gil_share(lambda: tf.propagate(fit, **{**popts, "draws": max(draws // 10, 2)}, scheduler="sequential"), w)
    return eff


def bench_fleet(w, runs, scale):
    """8 identifications."""
    base = tf.load_model("li2009-base")
    fleet = []
    for k in range(max(int(8 * scale), 2)):
        fr = base.friction
        m = dataclasses.replace(base, friction=dataclasses.replace(fr, fc=fr.fc * (0.8 + 0.03 * k),
                                                                   sigma0=fr.sigma0 * (1.2 + 0.03 * k)))
        fleet.append(tf.synthesize(m, [33.0, 35.0, 38.0], duration=2.0, sample_rate=2500, noise=20e-9, seed=10 + k))
    seq, par = best(runs, lambda: tf.identify_fleet(fleet, "base", scheduler="sequential", starts=2),
                    lambda: tf.identify_fleet(fleet, "base", workers=w, starts=2))
    row("fleet", len(fleet), "fits", seq, par, w, same_fleet(seq[0], par[0]))
    # identify runs some simulations side by side on its own threads: its sequential run above may use more
    # than one core in part. The baseline of one core: the same run with every thread of this process pinned
    one, _ = best(1, lambda: tf.identify_fleet(fleet, "base", scheduler="sequential", starts=2), lambda: None,
                  one_core=True)
    return row("fleet", len(fleet), "fits", one, par, w, same_fleet(one[0], par[0]), baseline="one core")


def bench_dask(model, grid, opts, w, seq):
    """Dask's overhead per task (empty tasks) against the work of one of the sweep's chunks."""
    from distributed import Client, LocalCluster
    ref_sweep, t_sweep_seq = seq[0], seq[1]
    t0 = time.perf_counter()
    with LocalCluster(n_workers=w, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        client.wait_for_workers(w)
        t_start = time.perf_counter() - t0
        k = 400
        before = load()
        t0 = time.perf_counter()
        client.gather(client.map(_noop, range(k), pure=False))
        per_task = (time.perf_counter() - t0) / k
        chunks = []
        res, t_dask, _, l0, l1 = timed(lambda: tf.sweep(model, grid, scheduler=client, progress=chunks.append,
                                                        **opts))
        per_chunk = t_sweep_seq / len(chunks)
        print(f"local Dask cluster ({w} worker processes; start-up {t_start:.1f} s, not counted): "
              f"{per_task * 1e3:.2f} ms per empty task (load {before})")
        print(f"  sweep: {len(chunks)} chunks of {per_chunk * 1e3:.0f} ms of work on average: Dask's overhead "
              f"{100 * per_task / per_chunk:.1f} % of a chunk's work; {t_dask:.2f} s, parallel efficiency "
              f"{t_sweep_seq / (w * t_dask):.2f} (load {l0} -> {l1}); output identical: {same_sweep(res, ref_sweep)}")


if __name__ == "__main__":
    main()
