"""False alarms and detections of the adequacy verdict (issue 30, items 2-3) on random truths simulated by the
independent SciPy reference: random Model I truths (tests/truths.py: exponential sigma0 and fc, linear sigma1, random
masses), identified from a plant-only file (right model), and the same with the start's end-effector mass half the
truth's (a wrong held mass). Used by tests/test_adequacy_study.py (slow) and for the numbers in
docs/identification.md: ``python tests/adequacy_study.py N``."""

from __future__ import annotations

import dataclasses
import sys
import tempfile
import time

import numpy as np

import thermofriction as tf
from stribeck_truths import reference_experiments
from truths import model_i_truth, plant_only_file

TEMPERATURES = (31.0, 36.0, 41.0)


def one(seed, wrong_mass=False, duration=0.3, sample_rate=10_000.0) -> dict:
    truth = model_i_truth(np.random.default_rng(seed))
    data = reference_experiments(truth, TEMPERATURES, duration=duration, sample_rate=sample_rate, seed=seed)
    start = truth
    if wrong_mass:
        start = dataclasses.replace(truth, plant=dataclasses.replace(
            truth.plant, end_effector_mass=0.5 * truth.plant.end_effector_mass))
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        fit = tf.identify(data, "model-i", init=plant_only_file(start, d))
        wall = time.perf_counter() - t0
    q = fit.fit_quality
    held = [h["name"] for h in q.get("held") or [] if h["contradicted"]]
    return {"seed": seed, "wrong_mass": wrong_mass, "adequate": fit.adequate, "ratio": q["ratio"],
            "threshold": q["threshold"], "held_contradicted": held, "wall_time": wall}


def study(seeds, wrong_mass=False) -> list:
    return [one(s, wrong_mass) for s in seeds]


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 8
    for wrong in (False, True):
        rows = study(range(n), wrong)
        for r in rows:
            print(r, flush=True)
        flagged = sum(r["adequate"] is False for r in rows)
        unknown = sum(r["adequate"] is None for r in rows)
        print(f"wrong_mass={wrong}: not adequate {flagged}/{len(rows)}, unknown {unknown}, "
              f"ratios {min(r['ratio'] for r in rows):.3f}-{max(r['ratio'] for r in rows):.3f}", flush=True)
