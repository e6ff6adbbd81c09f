"""What the data allow without a model: a smooth map of friction over velocity, travel and position, fitted by linear least
squares on the fit runs and scored on the held-out ones. Where the noise cannot be estimated from the data (noise
correlated from sample to sample: fitting/quality.py), a fit's error has nothing to be held against; this map
is that yardstick. A friction model that predicts the held-out runs many times worse than such a map of the same
runs misses something the data show, whatever the noise.

The map, per direction of motion and shared by all runs: ``F = b + s_dir(|v|) + q_dir(d) + p(x)`` (+ ``m a`` for a
drive's command): cubic B-splines in the speed (knots at the fit runs' speed quantiles: Stribeck curve, viscous rise,
direction-dependent levels), in the distance ``d`` travelled since the last reversal (knots in octaves from the
slowest samples' travel: a presliding transition of any length, model-free), in the position (a slow ripple, a
position-dependent load); ``b`` the sensor offset as the fit has it (one shared, or each run's own). Held-out runs'
values beyond the fit runs' are held at the range's ends (no extrapolation). Its transition is additive, the same
after every reversal, where a real one depends on the speed at which it happens: a right dynamic model beats it, so
it is a bound a right model meets, not the noise.
"""

from __future__ import annotations

import math

import numpy as np

from .._lazy import lazy

# SciPy on first use: not at the package's import
interpolate, linalg, sparse = lazy("scipy.interpolate"), lazy("scipy.linalg"), lazy("scipy.sparse")

#: interior knots of each speed spline and of the position spline
KNOTS = 8
#: the most a model's held-out RMSE may exceed the baseline's and the fit be called adequate relative to it. The map
#: holds a right model's steady sliding and an additive presliding transition; a right dynamic model does better
#: (LuGre on the look-alike joint under AR(1) noise, tests/test_verdict_baseline.py: 0.31-0.37 times the map's), so
#: 1.5 leaves room for what a held-out run's different motion makes of the map, while a model that misses what the
#: map sees (a Coulomb level for a Stribeck curve, 1.7-1.9 times there) is caught
BASELINE_FACTOR = 1.5


def _basis(u, lo, hi, knots):
    """A cubic B-spline design matrix of ``u`` (clipped to [lo, hi]) with ``knots`` interior knots at ``u``'s
    quantiles (given as the array ``knots``), sparse (CSR: four entries a row)."""
    t = np.concatenate([[lo] * 4, knots, [hi] * 4])
    # extrapolate=True only skips SciPy's range check (Python's min and max over the array: most of the time here);
    # u is clipped to the knots' range, so nothing is extrapolated
    return interpolate.BSpline.design_matrix(np.clip(u, lo, hi), t, 3, extrapolate=True)


class _Axis:
    """One variable's spline: its range and knots from the fit runs' samples."""

    def __init__(self, u, n_knots=KNOTS):
        u = np.asarray(u, float)
        self.lo, self.hi = (float(u.min()), float(u.max())) if u.size else (0.0, 1.0)
        inner = np.unique(np.quantile(u, np.linspace(0, 1, n_knots + 2)[1:-1])) if u.size > 4 * n_knots else []
        self.knots = np.asarray([k for k in inner if self.lo < k < self.hi])
        self.ok = self.hi > self.lo

    def columns(self, u, mask=None):
        """The spline's columns at ``u`` (sparse; rows outside ``mask`` zero)."""
        if not self.ok:
            return sparse.csr_matrix((np.size(u), 0))
        B = _basis(np.asarray(u, float), self.lo, self.hi, self.knots)
        if mask is not None:  # four entries a row, in row order: the rows outside the mask zeroed in place
            B.data *= np.repeat(mask.astype(float), np.diff(B.indptr))
        return B


def since_reversal(v, x) -> np.ndarray:
    """The distance travelled since the motion last reversed (the last change of the velocity's sign, zeros
    skipped), from the run's start before the first reversal."""
    v, x = np.asarray(v, float), np.asarray(x, float)
    s = np.sign(v)
    idx = np.where(s != 0, np.arange(s.size), 0)
    last = s[np.maximum.accumulate(idx)]  # the sign of the last moving sample
    flips = np.flatnonzero(last[1:] * last[:-1] < 0) + 1
    start = np.zeros(s.size, int)
    start[flips] = flips
    return np.abs(x - x[np.maximum.accumulate(start)])


class _Travel(_Axis):
    """The distance since a reversal: knots in geometric steps from the slowest samples' travel to the longest
    distance, so that a presliding transition of any length between one sample and the stroke is resolved."""

    def __init__(self, d, step):
        d = np.asarray(d, float)
        self.lo, self.hi = 0.0, float(d.max()) if d.size else 0.0
        step = max(step, self.hi * 1e-6)
        n = int(math.floor(math.log2(self.hi / step))) if self.hi > step > 0 else 0
        self.knots = step * 2.0 ** np.arange(min(n, 3 * KNOTS))
        self.knots = self.knots[self.knots < self.hi]
        self.ok = self.hi > 0 and d.size > 4 * (self.knots.size + 4)


def _columns(axes, v, x, a):
    """The map's columns (without offsets, sparse) at velocity ``v``, position ``x`` and acceleration ``a`` (None: no
    inertia column): per direction a spline in the speed and one in the distance since the last reversal, a
    spline in the position."""
    pos, neg = v > 0, v < 0
    d = since_reversal(v, x)
    cols = [axes["v+"].columns(v, pos), axes["v-"].columns(-v, neg), axes["d"].columns(d, pos),
            axes["d"].columns(d, neg), axes["x"].columns(x)]
    if a is not None:
        cols.append(sparse.csr_matrix(np.asarray(a, float)[:, None]))
    return sparse.hstack(cols, format="csr")


def _design(axes, runs, own, inertia):
    """The fit runs' design (sparse): the map's columns and the offsets, each run's own (``own``) or one shared."""
    blocks = []
    for k, (vr, xr, _, ar) in enumerate(runs):
        X = _columns(axes, np.asarray(vr, float), np.asarray(xr, float), ar if inertia else None)
        off = sparse.csr_matrix((np.ones(X.shape[0]), (np.arange(X.shape[0]), np.full(X.shape[0], k if own else 0))),
                                shape=(X.shape[0], len(runs) if own else 1))
        blocks.append(sparse.hstack([X, off], format="csr"))
    return sparse.vstack(blocks, format="csr")


def _least_squares(X, F):
    """A least-squares solution of ``X c = F`` for the sparse, tall, rank-deficient design ``X`` (its columns are
    B-splines: those of one spline sum to one, as do the offsets'), by the normal equations of the column-scaled
    design: the Gram matrix (a sparse product, a few entries a row) factored by Cholesky with pivoting (LAPACK's
    ``pstrf``), which stops where the pivots fall below ``len(F)`` rounding units (the design's null space: no change
    in ``X c``; on the study's designs its pivots are below 1e-13, the others above 1e-3), the other columns'
    coefficients zero; then one step of iterative refinement on the residuals (what the squared condition number
    costs in accuracy, given back). The fitted values, and so both RMSEs, equal numpy's SVD ``lstsq`` of the dense
    design's to 1e-9 of the noise (tests/test_cost_paths5.py)."""
    XT = X.T.tocsr()
    G = (XT @ X).toarray()
    scale = np.sqrt(np.diag(G))
    scale[scale == 0] = 1.0
    L, piv, rank, _ = linalg.lapack.dpstrf(G / np.outer(scale, scale), lower=1, tol=np.finfo(float).eps * max(X.shape))
    kept = piv[:rank] - 1  # (LAPACK's pivots count from 1)
    factor = (np.tril(L[:rank, :rank]), True)

    def solve(rhs):
        c = np.zeros(X.shape[1])
        c[kept] = linalg.cho_solve(factor, ((XT @ rhs) / scale)[kept])
        return c / scale

    c = solve(F)
    return c + solve(F - X @ c)  # the refinement step


def baseline_map(fit_runs, held_runs, per_run_offset: bool) -> dict | None:
    """The model-free baseline: ``{"fit_rmse", "heldout_rmse", "columns", "samples"}`` for runs given as
    ``(velocity, position, force, acceleration or None)``; the offset shared by all runs (fitted on the fit runs,
    kept for the held-out ones) or, with ``per_run_offset``, each run's own (a held-out run's estimated on it, as
    validate scores it). None where the fit runs cannot determine the map (too few samples for its columns).
    The design is sparse (a few B-splines a row) and built once per run; its least squares by the normal
    equations (:func:`_least_squares`)."""
    if not fit_runs or not held_runs:
        return None
    v = np.concatenate([r[0] for r in fit_runs])
    x = np.concatenate([r[1] for r in fit_runs])
    d = np.concatenate([since_reversal(r[0], r[1]) for r in fit_runs])
    steps = np.concatenate([np.abs(np.diff(np.asarray(r[1], float))) for r in fit_runs])
    step = float(np.quantile(steps[steps > 0], 0.05)) if np.any(steps > 0) else 0.0  # the slow samples' travel
    axes = {"v+": _Axis(v[v > 0]), "v-": _Axis(-v[v < 0]), "d": _Travel(d, step), "x": _Axis(x)}
    inertia = all(r[3] is not None for r in fit_runs + held_runs)
    X = _design(axes, fit_runs, per_run_offset, inertia)
    F = np.concatenate([np.asarray(r[2], float) for r in fit_runs])
    if X.shape[0] < 5 * X.shape[1]:
        return None
    coef = _least_squares(X, F)
    fit_rmse = float(np.sqrt(np.mean((X @ coef - F) ** 2)))
    n_map = X.shape[1] - (len(fit_runs) if per_run_offset else 1)
    errors = []
    for vr, xr, Fr, ar in held_runs:
        pred = _columns(axes, np.asarray(vr, float), np.asarray(xr, float), ar if inertia else None) @ coef[:n_map]
        err = pred - np.asarray(Fr, float)
        err = err - err.mean() if per_run_offset else err + coef[n_map]  # the held-out run's own offset, or the fit's
        errors.append(err)
    err = np.concatenate(errors)
    return {"fit_rmse": fit_rmse, "heldout_rmse": float(np.sqrt(np.mean(err ** 2))), "columns": int(X.shape[1]),
            "samples": int(X.shape[0]), "factor": BASELINE_FACTOR}


def model_free(measurement, fit_exps, held_exps) -> dict | None:
    """:func:`baseline_map` on a measurement's experiments (force or a drive's command: their velocity, position,
    force and, for a command, the acceleration); None for other measurements."""
    if measurement.name not in ("force", "command"):
        return None
    if measurement.name == "command":
        from .command import acceleration
    else:
        acceleration = None

    def runs(exps):
        return [(np.asarray(e.drive_velocity, float), np.asarray(e.displacement, float), np.asarray(e.force, float),
                 acceleration(e) if acceleration else None) for e in exps]

    out = baseline_map(runs(fit_exps), runs(held_exps), measurement.offset == "per-experiment")
    if out is not None and not all(math.isfinite(out[k]) for k in ("fit_rmse", "heldout_rmse")):
        return None
    return out





def baseline_verdict(quality: dict, base: dict, model_heldout: float, n_held: int, unit: str) -> str | None:
    """The verdict where the noise cannot be estimated (``quality["adequate"]`` None): the model's held-out RMSE
    against the baseline's on the same runs, at most BASELINE_FACTOR times for "adequate relative to the baseline".
    Sets ``quality["adequate"]`` and ``quality["verdict_basis"] = "baseline"``, and returns the warning that says it
    with both numbers (None, nothing changed, where the noise was estimated or there is no baseline)."""
    from . import amount
    quality["baseline"] = dict(base, model_heldout_rmse=model_heldout,
                               ratio=model_heldout / base["heldout_rmse"] if base["heldout_rmse"] > 0 else math.inf)
    if quality["adequate"] is not None:
        return None
    r, f = quality["baseline"]["ratio"], base["factor"]
    quality["adequate"] = bool(r <= f)
    quality["verdict_basis"] = "baseline"
    both = (f"RMSE {amount(model_heldout, unit)} against {amount(base['heldout_rmse'], unit)} on the {n_held} "
            f"held-out experiment(s); the map: friction over the speed and the distance since the last reversal per "
            f"direction and over the position, fitted by least squares to the fit experiments")
    why = quality.get("why") or "the noise cannot be estimated from the data"
    if not quality["adequate"]:
        return (f"the fit is not adequate: it predicts the held-out experiments {r:.3g} times worse than a model-free "
                f"map of the same fit experiments ({both}; a right model does at most {f:g} times as badly as this map): the model misses what the data show; its residuals are not held against the "
                f"noise, which cannot be estimated ({why})")
    return (f"adequate relative to a model-free baseline: the model predicts the held-out experiments {r:.3g} times "
            f"as badly as a map of the same fit experiments ({both}; at most {f:g} times is adequate). The noise "
            f"cannot be estimated ({why}): this says the model does what a static map of these runs does, not that it "
            f"reaches the noise")
__all__ = ["baseline_map", "model_free", "baseline_verdict", "BASELINE_FACTOR"]
