"""Cost of the real-time C API and of the closed-loop simulation (a script, not a test).

    .venv/bin/python benchmarks/bench_control.py

(i)  tf_rt_step (realtime.h) per call, in nanoseconds, timed in C over 1 million steps at
     dt = 100 us (best of 5), through a 1 mm/s, 5 Hz sine of sliding velocity, for every friction
     model (the Canudas de Wit 1995 set; GMS with 4 and 50 elements), without a thermal model and
     with Model I (fc following exp(-0.159 T)) at a constant temperature (laws evaluated once) and
     at a temperature that changes every step (laws evaluated every step, the worst case). The
     budget is a 10 us control period (100 kHz); the share of it one step takes is printed.
(ii) The closed loop of thermofriction.control (stage-model-i preset, PID at 10 kHz with 10 plant
     substeps, observer compensation, 4 s of a 1 mm, 0.5 Hz sine): wall time in C through the binding,
     against the same loop written in plain Python (the LuGre exponential step, the PID and the
     observer as scalar Python, as a user would first write it: tests/reference/control.py
     reference_closed_loop), in the same process; ratio printed.
"""

import math
import sys
import time
from pathlib import Path

import numpy as np

import thermofriction as tf
from thermofriction import control as C

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import reference as R  # noqa: E402  (the plain-Python loop: the baseline)

CANUDAS = dict(sigma0=1e5, sigma1=math.sqrt(1e5), sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)


def models():
    k4 = [1e5 / (i + 1) for i in range(4)]
    k50 = [1.0 / (i + 1) for i in range(50)]
    k50 = [1e5 * k / sum(k50) for k in k50]
    yield "coulomb", tf.Coulomb(fc=1.0, sigma2=0.4, v_smooth=1e-4)
    yield "stribeck", tf.Stribeck(fc=1.0, fs=1.5, vs=1e-3, sigma2=0.4, v_smooth=1e-4)
    yield "dahl", tf.Dahl(sigma0=1e5, fc=1.0)
    yield "lugre", tf.LuGre(**CANUDAS)
    # z_ba < fc/sigma0 at every temperature of the sweep (fc falls to 0.16 N at 41.5 C)
    yield "elastoplastic", tf.ElastoPlastic(**CANUDAS, z_ba=1e-6)
    yield "gms (4)", tf.GMS(k=[k * 1e5 / sum(k4) for k in k4], w=[0.25] * 4, C=20.0, fc=1.0, fs=1.5, vs=1e-3)
    yield "gms (50)", tf.GMS(k=k50, w=[0.02] * 50, C=20.0, fc=1.0, fs=1.5, vs=1e-3)


def dataclasses_replace(obj, **kw):
    import dataclasses
    return dataclasses.replace(obj, **kw)


def step_ns(model, v, T):
    best = math.inf
    for _ in range(5):
        _, seconds = C.friction_steps(model, v, 1e-4, temperature=T)
        best = min(best, seconds)
    return best / v.size * 1e9


def main():
    n = 1_000_000
    t = np.arange(n) * 1e-4
    v = 1e-3 * np.sin(2 * math.pi * 5 * t)
    T_varying = 30.0 + 11.5 * (0.5 + 0.5 * np.sin(2 * math.pi * 0.1 * t))
    print("(i) tf_rt_step, ns per call (1 million steps at 100 us; best of 5)")
    print(f"{'model':15s} {'no thermal':>11s} {'Model I, T fixed':>17s} {'Model I, T varying':>19s} "
          f"{'share of 10 us':>15s}")
    for name, fr in models():
        base = tf.Model(tf.PrescribedMotion(), fr)
        mi = tf.Model(tf.PrescribedMotion(), dataclasses_replace(fr, fc=None),
                      tf.ModelI({"fc": tf.Exp(a=1.0 / math.exp(-0.159 * 30), b=-0.159)}))
        a = step_ns(base, v, None)
        b = step_ns(mi, v, 35.0)
        best = step_ns(mi, v, T_varying)  # a new temperature every step: laws evaluated every step
        worst = max(a, b, best)
        print(f"{name:15s} {a:11.1f} {b:17.1f} {best:19.1f} {worst / 1e4:14.2%}")

    stage = tf.load_model("stage-model-i")
    ref = C.sine_reference(1e-3, 0.5, 4.0)
    best = math.inf
    for _ in range(5):
        t0 = time.perf_counter()
        res = C.simulate_loop(stage, ref, temperature=41.5, compensation=C.Observer(stage, 100.0))
        best = min(best, time.perf_counter() - t0)
    t0 = time.perf_counter()
    xs = R.reference_closed_loop(stage, ref, 41.5, C.DEFAULT_PID, gain=100.0)
    t_py = time.perf_counter() - t0
    print(f"\n(ii) closed loop, 4 s at 10 kHz x 10 substeps (40,001 periods), observer compensation, 41.5 C")
    print(f"    C core through the binding: {best * 1e3:8.2f} ms  ({best / ref.time.size * 1e9:.0f} ns per period)")
    print(f"    plain Python, same loop:    {t_py * 1e3:8.2f} ms")
    print(f"    ratio: {t_py / best:.0f}x; max |x_C - x_Python| = {np.max(np.abs(res.position - xs)):.2e} m "
          f"(the same algorithm: rounding only)")


if __name__ == "__main__":
    main()
