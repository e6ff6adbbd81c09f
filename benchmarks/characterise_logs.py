"""Measures what public joint logs look like (the numbers of tests/data/README.md): sample rate, the
quantisation of position, velocity and torque, the velocity column's lag and scale against the position's
derivative, and the noise colour of the torque (lag-1 autocorrelation after a cubic Savitzky-Golay fit).

The logs are not in this repository; give the git directories of local clones (read with ``git show``):

    .venv/bin/python benchmarks/characterise_logs.py \\
        --openarm PATH/Friction-Identification-for-Manipulators/.git \\
        --cicese PATH/Friction-Identification/.git

OpenArm: github.com/YIZHIXIAOCANGSHU/Friction-Identification-for-Manipulators (results/*.npz); CICESE:
github.com/jorgevchin/Friction-Identification (text columns, deg, deg/s, N m).
"""

from __future__ import annotations

import argparse
import io
import subprocess

import numpy as np
from scipy.signal import savgol_filter

from thermofriction.data.force import check_motion, quantum


def _show(gitdir, path) -> bytes:
    return subprocess.run(["git", f"--git-dir={gitdir}", "show", f"HEAD:{path}"], check=True,
                          capture_output=True).stdout


def _colour(tau, window):
    r = tau - savgol_filter(tau, window, 3)
    r = r[window:-window]
    return float(np.corrcoef(r[:-1], r[1:])[0, 1])


def _line(label, t, x, v, tau, window):
    c = check_motion(t, x, v)
    dt = np.diff(t)
    steps = ", ".join(f"{name} {q:.4g}" if q is not None else f"{name} -"
                      for name, q in (("x", quantum(x)), ("v", quantum(v)), ("tau", quantum(tau))))
    print(f"{label}: n {t.size}, {1 / np.median(dt):.1f} Hz (intervals {np.percentile(dt, 5) * 1e3:.1f}-"
          f"{np.percentile(dt, 95) * 1e3:.1f} ms, 5-95 %), lag {c.lag * 1e3:.1f} ms ({c.lag_samples:.2f} intervals), "
          f"scale {c.scale:.3f}, r {c.correlation:.3f}; steps {steps}; torque lag-1 autocorrelation "
          f"{_colour(tau, window):.2f}")


def openarm(gitdir):
    for joint in (1, 3, 4, 6, 7):
        d = np.load(io.BytesIO(_show(gitdir, f"results/real_uart_capture_collect_joint_{joint}.npz")))
        k = joint - 1
        _line(f"OpenArm joint {joint}", d["time"], d["q"][:, k], d["qd"][:, k], d["tau_measured"][:, k], 21)


def cicese(gitdir):
    runs = [("Test 3/sig1_{v}1_6_exp1_gan.t", "presliding q1"), ("Test 3/sig1_{v}2_08_exp1_gan.t", "presliding q2")]
    runs += [(f"Test 2/cin_{{v}}{j}_{s}_exp_gan.t", f"{s} deg/s q{j}") for s in ("40", "n40", "03") for j in "12"]
    for pattern, label in runs:
        cols = {v: np.loadtxt(io.BytesIO(_show(gitdir, pattern.format(v=v)))) for v in ("pos", "vel", "tau")}
        t = cols["pos"][:, 0]
        _line(f"CICESE {label}", t, cols["pos"][:, 1], cols["vel"][:, 1], cols["tau"][:, 1], 31)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--openarm", help="git directory of Friction-Identification-for-Manipulators")
    ap.add_argument("--cicese", help="git directory of jorgevchin/Friction-Identification")
    args = ap.parse_args(argv)
    if args.openarm:
        openarm(args.openarm)
    if args.cicese:
        cicese(args.cicese)


if __name__ == "__main__":
    main()
