"""Where the default's error on a random parameter set came from (docs/performance.md, "Where the
default's error came from"): replays AutoSwitch's Dormand-Prince phase after a flyback, step by step, as
it ran before its steps ended at reversals of the relative velocity, and compares each accepted step's
embedded error estimate with its true local error.

The replay starts from the reference solution (rtol 1e-11) at t0 and steps as the C core's Dormand-Prince
did in AutoSwitch's explicit phases: the same tableau, tolerances of 1/50 of the default's (per-state
absolute tolerances rtol x each state's scale, positions without the relative part), the same RMS
norm and PI control, from a first step of 1e-7 s (the core's own first step differs, so its steps fall
elsewhere: the run ends this window 1.7e-4 % off, the replay 1.1e-4 %). The true local error of a step is its result minus a DOP853 solution at rtol 1e-13
from the same start. Steps across a sign change of the relative velocity (the kink of LuGre's |v_r|)
are flagged. Default: the worst of `bench_accuracy.py --seed 11` (set 39), 0.200-0.206 s.

    python benchmarks/diagnose_accuracy.py [--seed 11] [--set 39] [--t0 0.2] [--t1 0.206]
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np
from scipy.integrate import solve_ivp

import thermofriction as tf
from thermofriction import _bridge
from thermofriction.simulation import input_of

from bench_accuracy import random_sets

EXPLICIT_TOL = 0.02  # AutoSwitch's explicit phases ran at 1/50 of the tolerances then (now 1/20: core/src/auto.c)
A = [[1 / 5], [3 / 40, 9 / 40], [44 / 45, -56 / 15, 32 / 9],
     [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729],
     [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656],
     [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]]
C = [0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1, 1]
E = [71 / 57600, 0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--set", type=int, default=39)
    ap.add_argument("--t0", type=float, default=0.2)
    ap.add_argument("--t1", type=float, default=0.206)
    args = ap.parse_args()
    warnings.simplefilter("ignore", tf.TemperatureRangeWarning)
    T, model = list(random_sets(args.set + 1, args.seed))[args.set]
    spec = _bridge.model_spec(model, T, input_of(model, None), False)
    scale = np.asarray(_bridge.state_scale(spec))
    rtol = 1e-6 * EXPLICIT_TOL
    atol = rtol * scale
    rtol_weight = np.array([0.0, 1.0, 0.0, 1.0, 1.0])  # x_p, v_p, x_e, v_e, z: positions to atol alone

    def f(t, y):
        dy = np.empty(5)
        _bridge.rhs_jac(spec, t, np.ascontiguousarray(y, float), dy)
        return dy

    grid = np.linspace(0.0, 2.0, 20001)
    ref = tf.simulate(model, duration=2.0, temperature=T, t_eval=grid, controller=tf.StepSizeController(rtol=1e-11))

    def state(j):
        return np.array([ref.stage_displacement[j], ref.stage_velocity[j], ref.displacement[j], ref.velocity[j],
                         ref.states[j, 0]])

    j0, j1 = int(round(args.t0 * 1e4)), int(round(args.t1 * 1e4))
    t, t1, y = grid[j0], grid[j1], state(j0)
    span = np.ptp(ref.displacement)
    h, facold, k0 = 1e-7, 1e-4, f(t, y)
    rows = []
    while t < t1 - 1e-15:
        h = min(h, t1 - t)
        k = [k0]
        for s in range(6):
            k.append(f(t + C[s + 1] * h, y + h * sum(a * kk for a, kk in zip(A[s], k))))
        y1 = y + h * sum(a * kk for a, kk in zip(A[5], k))
        sk = atol + rtol * rtol_weight * np.maximum(abs(y), abs(y1))
        err = np.sqrt(np.mean((h * sum(e * kk for e, kk in zip(E, k)) / sk) ** 2))
        if err > 1.0:
            h /= min(5.0, err ** 0.17 / 0.9)
            continue
        exact = solve_ivp(f, (t, t + h), y, method="DOP853", rtol=1e-13, atol=scale * 1e-16).y[:, -1]
        true = (y1 - exact) / sk
        reversal = (y[3] - y[1]) * (y1[3] - y1[1]) < 0
        rows.append((t, h, err, np.sqrt(np.mean(true ** 2)), true[4], reversal))
        fac = max(0.1, min(5.0, err ** 0.17 / facold ** 0.04 / 0.9))
        facold = max(err, 1e-4)
        t, y, k0, h = t + h, y1, k[6], h / fac
    print(f"seed {args.seed}, set {args.set} (T = {T:.2f} C), {args.t0:g}-{args.t1:g} s: {len(rows)} accepted steps")
    print(f"end effector off the reference at {args.t1:g} s by {(y[2] - ref.displacement[j1]) / span * 100:+.2e} % "
          "of its range")
    print("error norms in units of the tolerance (accepted: estimate <= 1)")
    print(f"{'t [s]':>10} {'h [s]':>9} {'estimate':>9} {'true':>8} {'true z/tol':>11}  across a reversal")
    for r in rows:
        if r[5] or r[3] > 1.0:
            print(f"{r[0]:10.6f} {r[1]:9.2e} {r[2]:9.2f} {r[3]:8.2f} {r[4]:11.1f}  {'yes' if r[5] else 'no'}")
    other = [r[3] for r in rows if not r[5]]
    print(f"the {len(other)} other steps: true error at most {max(other):.2f}")


if __name__ == "__main__":
    main()
