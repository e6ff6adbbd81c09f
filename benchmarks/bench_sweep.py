"""Sweep throughput: simulations per second in this process (the sequential baseline) and on a
local Dask cluster of 1 and 2 worker processes, in the same run, with the ratios; the cluster's
start-up, and the scheduler's overhead per task (empty tasks, and a sweep of one point per task).

    python benchmarks/bench_sweep.py [--points N] [--duration S]
"""

from __future__ import annotations

import argparse
import logging
import os
import time

import numpy as np

import thermofriction as tf


def _noop(x):
    return x


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=600)
    ap.add_argument("--duration", type=float, default=1.0)
    args = ap.parse_args()
    from distributed import Client, LocalCluster

    model = tf.load_model("li2009-model-i")
    n_amp = 6
    temps = np.linspace(30.0, 41.5, max(args.points // n_amp, 1))
    grid = {"temperature": temps, "amplitude": np.linspace(10, 35, n_amp)}
    n = temps.size * n_amp
    opts = dict(duration=args.duration, sample_rate=1000.0)
    print(f"sweep: li2009-model-i, {n} points (temperature x amplitude), {args.duration:g} s each at 1 kHz; "
          f"{os.cpu_count()} cores")

    t0 = time.perf_counter()
    ref = tf.sweep(model, grid, scheduler="sequential", **opts)
    t_seq = time.perf_counter() - t0
    rate_seq = n / t_seq
    print(f"  sequential (this process)     {t_seq:7.2f} s  {rate_seq:8.1f} simulations/s")

    rows = []
    for workers in (1, 2):
        t0 = time.perf_counter()
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                          silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
            client.wait_for_workers(workers)
            t_start = time.perf_counter() - t0
            t0 = time.perf_counter()
            res = tf.sweep(model, grid, scheduler=client, **opts)
            t_run = time.perf_counter() - t0
            for name in ref.columns:
                assert np.array_equal(res[name], ref[name], equal_nan=True), name
            rate = n / t_run
            print(f"  local cluster, {workers} worker(s)    {t_run:7.2f} s  {rate:8.1f} simulations/s  "
                  f"({rate / rate_seq:.2f}x sequential; start-up {t_start:.1f} s, "
                  f"{n / (t_run + t_start):.1f}/s with it)")
            rows.append((workers, rate))
            if workers == 2:
                k = 400
                t0 = time.perf_counter()
                futures = client.map(_noop, range(k), pure=False)
                client.gather(futures)
                per_task = (time.perf_counter() - t0) / k
                small = min(n, 120)
                sub = {"temperature": temps[:max(small // n_amp, 1)], "amplitude": grid["amplitude"]}
                m = sub["temperature"].size * n_amp
                t0 = time.perf_counter()
                tf.sweep(model, sub, scheduler=client, batch_size=1, **opts)
                t_one = time.perf_counter() - t0
                t0 = time.perf_counter()
                tf.sweep(model, sub, scheduler=client, **opts)
                t_batched = time.perf_counter() - t0
                print(f"  scheduler overhead: {per_task * 1e3:.2f} ms per empty task (2 workers); a {m}-point "
                      f"sweep takes {t_one:.2f} s at 1 point per task, {t_batched:.2f} s batched")
    print(f"ratio 2 workers / sequential: {rows[-1][1] / rate_seq:.2f}x; 2 workers / 1 worker: "
          f"{rows[-1][1] / rows[0][1]:.2f}x")


if __name__ == "__main__":
    main()
