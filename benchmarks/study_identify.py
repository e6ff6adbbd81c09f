"""Identification on independent truths (a study, not a test): random Model I and Model II truths drawn
away from the presets (masses, laws, break temperatures and slopes; tests/truths.py), 5 temperatures of
0.4 s at 5 kHz with 20 nm noise and 1 nm quantisation, identified from a model file that gives only the
plant. Prints, per method: the identification time, how often the fit is adequate, the recovered laws'
largest relative errors over the fit temperatures, and how often their 95 % intervals cover the truth.

Run: python benchmarks/study_identify.py [--seeds N] [--method model-i|model-ii|both]
"""

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from truths import study_model_i, study_model_ii  # noqa: E402


def summarise(label, outcomes):
    times = np.array([o.wall_time for o in outcomes])
    adequate = sum(o.adequate for o in outcomes)
    covered = sum(o.covered for o in outcomes)
    points = sum(o.points for o in outcomes)
    print(f"{label}: {len(outcomes)} truths")
    print(f"  time per identification: median {np.median(times):.2f} s, max {times.max():.2f} s")
    print(f"  adequate fits (RMSE within 2x the noise): {adequate} of {len(outcomes)}")
    for name in outcomes[0].errors:
        errs = np.array([o.errors[name] for o in outcomes])
        ok = np.array([o.adequate for o in outcomes])
        print(f"  {name}: largest relative error over the fit temperatures, median {np.median(errs):.2g}, "
              f"90th percentile {np.quantile(errs, 0.9):.2g}; among adequate fits median "
              f"{np.median(errs[ok]) if ok.any() else float('nan'):.2g}")
    print(f"  95 % intervals of the law values covering the truth: {covered} of {points} "
          f"({100 * covered / max(points, 1):.0f} %)")
    for name in outcomes[0].errors:
        base = name.split("/")[0]
        n_missed = sum(1 for o in outcomes for m in o.missed if m[0] == base)
        print(f"    {base}: {n_missed} points not covered")
    for o in outcomes:
        if not o.adequate:
            print(f"    seed {o.seed}: not adequate ({o.wall_time:.1f} s)")
        if o.missed:
            print(f"    seed {o.seed}: not covered at " + ", ".join(f"{n} {T:g} C" for n, T in o.missed))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--method", choices=("model-i", "model-ii", "both"), default="both")
    args = ap.parse_args()
    if args.method in ("model-i", "both"):
        summarise("Model I (sigma0, fc exponential; sigma1 linear)", [study_model_i(s) for s in range(args.seeds)])
    if args.method in ("model-ii", "both"):
        summarise("Model II (dF with a break between 34 and 39 C; dF relative to the lowest temperature, in units "
                  "of fc)", [study_model_ii(s) for s in range(args.seeds)])


if __name__ == "__main__":
    main()
