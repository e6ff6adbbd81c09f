"""Cost of the online temperature estimator (estimator.h) against the real-time friction step (a script, not a test).

    .venv/bin/python benchmarks/bench_estimator.py [runs]

Per step, in nanoseconds, timed in C over 200 000 steps at dt = 1 ms of the stage-model-i preset (LuGre, Model I: four
laws) sliding back and forth at 0.3 m/s: tf_rt_step at a temperature that changes every step (its laws evaluated every
step, as the estimator's are) and tf_temperature_step (three friction steps -- the estimate and its +-0.01 K trials --,
the heat path's prediction and the Kalman updates), one node and two nodes with a housing proxy, each measurement
given every step. Both in the same run, alternated, ``runs`` times (default 15): the median and the 90th percentile
over the runs, and their ratio.
"""

import sys

import numpy as np

import thermofriction as tf
from thermofriction import control as C


def main(runs: int = 15):
    model = tf.load_model("stage-model-i")
    n, dt = 200_000, 1e-3
    t = dt * np.arange(n)
    v = 0.3 * np.tanh(5.0 * np.sin(np.pi * t))
    T = 30.0 + 10.0 * t / t[-1]  # a temperature that changes every step
    F = C.friction_steps(model, v, dt, temperature=T)[0]
    one = C.TemperatureEstimator(C_th=1.0, R_th=330.0, r_F=0.016, v_min=0.02)
    two = C.TemperatureEstimator(C_th=1.0, R_th=30.0, C_2=8.0, R_2=300.0, r_F=0.016, proxy="housing", tau_p=10.0,
                                 v_min=0.02)
    cases = {"tf_rt_step (T changing)": lambda: C.friction_steps(model, v, dt, temperature=T)[1],
             "estimator, one node": lambda: one.run(model, v, dt=dt, ambient=30.0, start=30.0,
                                                    measured_force=F).stats["seconds"],
             "estimator, two nodes + proxy": lambda: two.run(model, v, dt=dt, ambient=30.0, start=30.0,
                                                             measured_force=F, proxy_temperature=T).stats["seconds"]}
    times = {name: [] for name in cases}
    for _ in range(runs):
        for name, run in cases.items():
            times[name].append(run() / n * 1e9)
    base = np.median(times["tf_rt_step (T changing)"])
    print(f"{'ns per step':32s} {'median':>8s} {'p90':>8s} {'x tf_rt_step':>13s}")
    for name, ns in times.items():
        print(f"{name:32s} {np.median(ns):8.0f} {np.percentile(ns, 90):8.0f} {np.median(ns) / base:13.1f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 15)
