"""The cheaper held-out check of issue 42's fifth round, each against an independent reference: the model-free map's
least squares by the normal equations of its sparse design against numpy's SVD ``lstsq`` of the dense design (the
fourth round's solve), and the held-out runs predicted by the exact stepping of the prescribed motion against the
adaptive simulation that ``validate`` runs."""

import sys
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.measurements import baseline, measurement_of
from thermofriction.validation import heldout_score

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import study_cost as S  # noqa: E402

NOISE = 0.01  # the study's force data: AR(1) torque noise of 0.01 N m (study_cost.force_case)


def _runs(exps):
    return [(np.asarray(e.drive_velocity, float), np.asarray(e.displacement, float), np.asarray(e.force, float), None)
            for e in exps]


def _dense_reference(fit, held, own):
    """The map as the fourth round solved it: the same columns, made dense, by numpy's SVD least squares."""
    v = np.concatenate([r[0] for r in fit])
    x = np.concatenate([r[1] for r in fit])
    d = np.concatenate([baseline.since_reversal(r[0], r[1]) for r in fit])
    steps = np.concatenate([np.abs(np.diff(r[1])) for r in fit])
    step = float(np.quantile(steps[steps > 0], 0.05))
    axes = {"v+": baseline._Axis(v[v > 0]), "v-": baseline._Axis(-v[v < 0]), "d": baseline._Travel(d, step),
            "x": baseline._Axis(x)}
    X = baseline._design(axes, fit, own, False).toarray()
    F = np.concatenate([r[2] for r in fit])
    scale = np.sqrt(np.sum(X ** 2, axis=0))
    scale[scale == 0] = 1.0
    coef = np.linalg.lstsq(X / scale, F, rcond=None)[0] / scale
    n_map = X.shape[1] - (len(fit) if own else 1)
    errs = []
    for vr, xr, Fr, _ in held:
        err = baseline._columns(axes, vr, xr, None).toarray() @ coef[:n_map] - Fr
        errs.append(err - err.mean() if own else err + coef[n_map])
    return float(np.sqrt(np.mean((X @ coef - F) ** 2))), float(np.sqrt(np.mean(np.concatenate(errs) ** 2)))


@pytest.mark.parametrize("kind,seed", [("force", 0), ("force-ripple", 1)])
@pytest.mark.parametrize("own", [True, False])
def test_the_maps_normal_equations_give_the_dense_lstsq(kind, seed, own):
    """baseline_map (the sparse design's normal equations, its null space dropped, one refinement step) against
    numpy's SVD lstsq of the same design made dense, on the cost study's look-alike joint data (its quick records):
    both RMSEs equal to 1e-9 of the noise. The design is rank-deficient (each spline's columns sum to one, as do
    the offsets'), so a solve that kept a null direction or lost the range's accuracy would differ."""
    data = S.force_case(kind, seed, True)[0]
    fit, held = _runs(data.fit), _runs(data.validate)
    out = baseline.baseline_map(fit, held, own)
    fit_rmse, heldout_rmse = _dense_reference(fit, held, own)
    assert abs(out["fit_rmse"] - fit_rmse) < 1e-9 * NOISE
    assert abs(out["heldout_rmse"] - heldout_rmse) < 1e-9 * NOISE
    assert out["fit_rmse"] > NOISE  # the map does not reach the noise on these data: a number worth comparing


def test_the_least_squares_of_a_rank_deficient_design_is_exact():
    """baseline._least_squares on a random sparse design with two exactly dependent columns (a column repeated, a
    column the sum of two others) and a right-hand side in its range: the fitted values equal it to 1e-10 of its
    size (analytic: the residual of a consistent system is zero), and for a right-hand side outside the range the
    residual equals numpy's lstsq's to 1e-12 relative."""
    from scipy import sparse
    rng = np.random.default_rng(5)
    A = sparse.random(3000, 20, density=0.2, random_state=7, format="csr")
    X = sparse.hstack([A, A[:, 3], A[:, 4] + A[:, 5]], format="csr")
    F = X @ rng.normal(size=X.shape[1])
    assert np.max(np.abs(X @ baseline._least_squares(X, F) - F)) < 1e-10 * np.max(np.abs(F))
    G = F + rng.normal(size=F.size)
    ref = np.linalg.lstsq(X.toarray(), G, rcond=None)[0]
    ours = baseline._least_squares(X, G)
    assert np.linalg.norm(X @ ours - G) == pytest.approx(np.linalg.norm(X @ ref - G), rel=1e-12)


@pytest.mark.parametrize("kind,seed", [("force", 3), ("force-ripple", 4)])
def test_the_heldout_score_by_the_exact_stepping_is_validates(kind, seed):
    """heldout_score (force data by the C core's exact stepping of the prescribed motion, what a fit evaluates)
    against validate's adaptive simulation of the same held-out run (rtol 1e-8), with the look-alike's truth as the
    model (a ripple scored per run): the same RMSE to 1e-6 of the noise, the same run scored."""
    data, truth, _, opts = S.force_case(kind, seed, True)
    m = measurement_of(list(data.fit), offset=opts["offset"])
    ours, v = heldout_score(truth, data, list(data.validate), m)
    ref = tf.validate(truth, data, list(data.validate), offset=opts["offset"])
    assert [p.file for p in v.predictions] == [p.file for p in ref.predictions]
    assert abs(ours - np.sqrt(np.mean([p.rmse ** 2 for p in ref.predictions]))) < 1e-6 * NOISE
    assert ours > NOISE  # the truth's prediction at the noise's level: a real comparison, not of zeros
