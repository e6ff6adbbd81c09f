"""The optimiser's two stops of issue 42's third round, each against the same fit without it (the reference: the
optimiser as it was, run apart from the change by switching the stop off): a start of the multi-start that lands
within LANDED standard errors of the first run's optimum stops there, and a run whose cost stalls (STALL_COST of
the misfit's variance in STALL_EVALUATIONS evaluations) stops at its best point. On look-alike force data
(tests/lookalike.py: no model reaches the noise, so the multi-start always runs) both must end where the reference
ends, to a small fraction of each parameter's standard error, and spend no more evaluations."""

import sys
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.fitting import optimiser
from thermofriction.models import PrescribedMotion

sys.path.insert(0, str(Path(__file__).resolve().parent))
from lookalike import Truth, lookalike_experiments  # noqa: E402

NAMES = ["sigma0", "sigma1", "fc", "fc_neg", "fs", "fs_neg", "vs", "sigma2"]


def _fit(data):
    """LuGre with asymmetric levels from a start 2-3x off the look-alike's truth, per-run offsets."""
    start = tf.LuGre(sigma0=120.0, sigma1=0.9, fc=0.15, fs=0.26, vs=0.25, sigma2=0.04)
    return tf.identify(data, init=tf.Model(PrescribedMotion(motion="rotary"), start), method="base",
                       parameters=NAMES, offset="per-experiment")


@pytest.mark.parametrize("seed", [1, 4])
def test_landing_and_stall_stops_end_where_the_fit_without_them_ends(seed, monkeypatch):
    truth = Truth(fc_pos=0.4, fc_neg=0.45, fs_pos=0.55, fs_neg=0.6, vs=0.08, sigma0=250.0, sigma1=0.4,
                  sigma2=0.1, ripple=0.0)
    data, _ = lookalike_experiments(truth=truth, motion="position", offsets=(0.03, -0.05, 0.02), duration=10.0,
                                    rate=250.0, noise=0.01, seed=seed)
    fit = _fit(data)
    assert fit.starts > 1  # the multi-start ran (look-alike data never reach the noise)
    monkeypatch.setattr(optimiser, "LANDED", 0.0)
    monkeypatch.setattr(optimiser, "STALL_COST", 0.0)
    reference = _fit(data)
    for n in NAMES:
        p, q = fit.parameters[n], reference.parameters[n]
        assert abs(p.value - q.value) <= 0.1 * q.stderr, (n, p.value, q.value, q.stderr)
    assert fit.nfev < reference.nfev  # (the stops were taken)
    assert fit.cost == pytest.approx(reference.cost, rel=1e-3)
