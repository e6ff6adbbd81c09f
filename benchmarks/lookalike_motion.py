"""The motion that drives a force model, on look-alike joint data (tests/lookalike.py, tests/data/README.md):
three runs whose firmware velocity is 70 ms late (4.7 sampling intervals at 66.7 Hz), fitted (LuGre, method
base) once driven by the velocity column and once by the position, then validated. Prints, per motion, the
wall time, the fit's evaluations and RMSE, and each run's RMSE (the last one held out).

    .venv/bin/python benchmarks/lookalike_motion.py [--lag 0.07] [--seed 0]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import thermofriction as tf  # noqa: E402
import lookalike as L  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lag", type=float, default=0.070, help="the velocity column's lag [s]")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        folder, _ = L.lookalike_dataset(Path(tmp) / "data", lag=args.lag, seed=args.seed)
        for motion in ("velocity", "position"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                data = tf.load_dataset(folder, motion=motion)
                t0 = time.perf_counter()
                fit = tf.identify(data, "base")
                wall = time.perf_counter() - t0
                v = tf.validate(fit.model, data)
            lines = [s.strip() for s in fit.report().splitlines() if "evaluations" in s or s.strip().startswith("rmse")]
            print(f"driven by the {motion}: {wall:.1f} s; " + "; ".join(lines))
            print("    " + ", ".join(f"{p.file} ({p.role}) {p.rmse:.4f} {p.unit}" for p in v.predictions))


if __name__ == "__main__":
    main()
