"""What the tool says and how well it predicts on look-alike joint logs (tests/lookalike.py: the character of the
public OpenArm and CICESE logs measured in tests/data/README.md: irregular 66.7 Hz samples, a quantised
encoder and firmware velocity, AR(1) torque noise, per-run sensor offsets, direction-dependent friction, position
ripple). Prints, per way of fitting, the fit time, the held-out RMSE, the generalisation ratio and what the tool
says about adequacy -- the earlier behaviour (velocity column as it is, one shared offset) beside the new
defaults (motion auto, offsets per experiment), in one run.

Run: python benchmarks/bench_real_measurements.py [--lag 0.07] [--seed 0]
"""

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from lookalike import lookalike_dataset  # noqa: E402

import thermofriction as tf  # noqa: E402


def run(folder, *, motion, offset, friction="lugre"):
    data = tf.load_dataset(folder, motion=motion)
    t0 = time.perf_counter()
    fit = tf.identify(data, "base", friction=friction, offset=offset)
    seconds = time.perf_counter() - t0
    v = tf.validate(fit.model, data, offset=None if offset == "shared" else offset)
    held = [p.rmse for p in v.predictions if p.role == "validate"]
    q = fit.fit_quality
    verdict = "unknown" if q["adequate"] is None else "adequate" if q["adequate"] else "NOT adequate"
    gen = q.get("generalisation", {}).get("ratio", float("nan"))
    return seconds, fit.nfev, float(np.sqrt(np.mean(np.square(held)))), gen, verdict, fit


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lag", type=float, default=0.07, help="the firmware velocity's lag [s]")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    folder = Path(tempfile.mkdtemp()) / "joint"
    lookalike_dataset(folder, offsets=(0.02, -0.35, 0.4, -0.25), lag=args.lag, seed=args.seed, rho=0.8,
                      duration=20.0)
    rows = [("velocity column, shared offset (before)", "velocity", "shared"),
            ("position, shared offset", "position", "shared"),
            ("auto motion, offsets per experiment (now)", None, "per-experiment")]
    print(f"look-alike joint: 3 fit runs + 1 held out, 20 s each at 66.7 Hz, velocity lag {args.lag * 1e3:g} ms, "
          f"offsets re-zeroed per run, AR(1) noise 0.8")
    print(f"{'fit':45s} {'time [s]':>9s} {'evals':>6s} {'held-out RMSE [N m]':>20s} {'held/fit':>9s}  adequacy")
    for label, motion, offset in rows:
        seconds, nfev, heldout, gen, verdict, _ = run(folder, motion=motion, offset=offset)
        print(f"{label:45s} {seconds:9.2f} {nfev:6d} {heldout:20.4f} {gen:9.3g}  {verdict}")


if __name__ == "__main__":
    main()
