"""Cost of the online temperature estimator (estimator.h) against the real-time friction step (a script, not a test).

    .venv/bin/python benchmarks/bench_estimator.py [runs]

Per step, in nanoseconds, timed in C over 200 000 steps at dt = 1 ms of the stage-model-i preset (LuGre, Model I: four
laws) sliding back and forth at 0.3 m/s: tf_rt_step at a temperature that changes every step (its laws evaluated every
step, as the estimator's are) and tf_temperature_step (three friction steps -- the estimate and its +-0.01 K trials --,
the heat path's prediction and the Kalman updates), one node and two nodes with a housing proxy, each measurement
given every step; and the two-node estimator on the same stage with its fc and fs made laws of the load
(fc0(T) (1 + 0.01 |N|)), told a normal force that switches between 20 and 80 N every second (a load-free model is
stepped at NaN, which it ignores). All in the same run, alternated, ``runs`` times (default 15): the median and the
90th percentile over the runs, and their ratio.
"""

import sys

import numpy as np

import thermofriction as tf
from thermofriction import control as C
from thermofriction.models.load_laws import LoadLaw, LoadTerm


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
    laws = {name: LoadLaw(law, LoadTerm("affine", k=0.01)) if name in ("fc", "fs") else law
            for name, law in model.laws.items()}
    loaded = tf.Model(model.plant, model.friction, tf.ModelI(laws))
    N = np.where((t % 2.0) < 1.0, 20.0, 80.0)
    cases = {"tf_rt_step (T changing)": lambda: C.friction_steps(model, v, dt, temperature=T)[1],
             "estimator, one node": lambda: one.run(model, v, dt=dt, ambient=30.0, start=30.0,
                                                    measured_force=F).stats["seconds"],
             "estimator, two nodes + proxy": lambda: two.run(model, v, dt=dt, ambient=30.0, start=30.0,
                                                             measured_force=F, proxy_temperature=T).stats["seconds"],
             "two nodes + proxy, load law": lambda: two.run(loaded, v, dt=dt, ambient=30.0, start=30.0,
                                                            measured_force=F, proxy_temperature=T,
                                                            load=N).stats["seconds"]}
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
