"""Self-heating over a long run: the two-time-scale method against the full simulation (a script,
not a test).

    .venv/bin/python benchmarks/bench_heating.py [--minutes 10] [--frequency 500]

The li2009-self-heating preset (the paper's actuator, Model I, C_th = 1.5 mJ/K, R_th = 20 kK/W,
eta = 0.5, tau = 30 s) driven by the 30 V sawtooth (rise 0.999) from 30 C. Both methods run in
this process on the same grid of 2001 cycle starts: the full coupled simulation through every cycle
(the baseline: simulate with the [heat] model, default solver and tolerances) and the two-time-scale
method (17 temperatures x 10 cycles tabulated, then the slow heat balance alone). Printed: wall
times (best of 3 for the two-time-scale method, one full run), the speed-up ratio, fast cycles
simulated, and the two-time-scale method's error against the full run: max |dT| over the run,
the final displacement's relative error, and the largest step-size difference after the first
cycle.
"""

import argparse
import time

import numpy as np

import thermofriction as tf
from thermofriction.heating import Full, TwoTimeScale, simulate_heating


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--frequency", type=float, default=500.0)
    args = ap.parse_args(argv)
    model = tf.load_model("li2009-self-heating")
    saw = tf.Sawtooth(amplitude=30, frequency=args.frequency, rise=0.999)
    duration = 60.0 * args.minutes
    kw = dict(input=saw, temperature=30.0, samples=2000)

    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        avg = simulate_heating(model, duration, solver=TwoTimeScale(), **kw)
        best = min(best, time.perf_counter() - t0)
    t0 = time.perf_counter()
    full = simulate_heating(model, duration, solver=Full(), **kw)
    t_full = time.perf_counter() - t0

    n_cycles = full.stats["cycles_simulated"]
    print(f"li2009-self-heating, {args.minutes:g} min at {args.frequency:g} Hz ({n_cycles} cycles) from 30 C")
    print(f"{'method':16s} {'wall [s]':>9s} {'fast cycles':>12s} {'T end [C]':>10s} {'x end [mm]':>11s} "
          f"{'last step [um]':>15s}")
    for name, r, t in (("full", full, t_full), ("two-time-scale", avg, best)):
        print(f"{name:16s} {t:9.3f} {r.stats['cycles_simulated']:12d} {r.temperature[-1]:10.4f} "
              f"{r.displacement[-1] * 1e3:11.4f} {r.step_size[-1] * 1e6:15.5f}")
    print(f"speed-up (full / two-time-scale): {t_full / best:.0f}x")
    print(f"two-time-scale error: max |dT| {np.max(np.abs(avg.temperature - full.temperature)):.2e} K, "
          f"final displacement {abs(avg.displacement[-1] - full.displacement[-1]) / abs(full.displacement[-1]):.2e} "
          f"relative, max step difference after the first cycle "
          f"{np.max(np.abs(avg.step_size - full.step_size)[1:]) * 1e9:.3g} nm")


if __name__ == "__main__":
    main()
