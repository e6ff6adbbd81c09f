"""Force data's result completed at the optimum (``Force.complete``): the sensor offset estimated with its standard
error as the policy says (:func:`estimate_offset`; the linear terms of a drive's command too, :func:`estimate_linear`),
written into the fitted model, and a rotary joint's parameters in its units (:func:`completed`). The force
measurement's class is passed in (``force``): this module sits below measurements/force.py, which calls it."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._lazy import lazy
from ..fitting.identifiability import OFFSET, groups, scaled_svd, with_groups
from ..fitting.optimiser import UNDETERMINED
from ..fitting.parameters import get_value
from ..fitting.problem import Problem, counting
from ..models import Model
from ..models.plants import rotary_unit
from .base import FD_RTOL

stats = lazy("scipy.stats")


def force_finish(res, experiments, init, measurement, *, force):
    """The fit completed for force data (``Force.complete``; ``force`` the force measurement's class): the sensor offset estimated at the optimum ("shared": one, written into
    the fitted model; "per-experiment": one per run, their mean written into the model; "none": the initial
    model's); a rotary joint's parameters in its units."""
    traces = [measurement.make_trace(e, res.model) for e in experiments]
    unit = traces[0].unit
    names = [p.name for p in res.parameters.varying] if res.n_points else []
    inflation = res.statistics.get("variance_inflation", 1.0)
    found = []
    with counting() as spent:  # the evaluations at the optimum are the fit's too (its nfev)
        if measurement.offset == "shared":
            est = estimate_offset(res.model, names, traces, inflation, found, force=force)
        elif measurement.offset == "per-experiment":
            runs = [dict(estimate_offset(res.model, names, [tr], inflation, found, force=force), file=tr.name)
                    for tr in traces]
            est = {"value": float(np.mean([r["value"] for r in runs])), "stderr": None, "ci95": None,
                   "per_experiment": runs}
        else:
            est = {"value": init.plant.sensor_offset, "stderr": 0.0, "ci95": (init.plant.sensor_offset,) * 2}
    res.nfev, res.njev = res.nfev + spent.nfev, res.njev + spent.njev
    model = dataclasses.replace(res.model, plant=dataclasses.replace(res.model.plant, sensor_offset=est["value"]))
    est.update(unit=unit, fitted=measurement.offset != "none", policy=measurement.offset)
    if names and measurement.offset != "none":  # the offset's column seen: these groups replace the fit's own
        res = with_groups(res, found)
    return completed(res, model, est, unit)


def completed(res, model, offset: dict, unit: str):
    """A force fit's result with its model, its offset's estimate and its unit; a rotary joint's parameters in
    its units."""
    if unit == "N m":  # the equations are the same, the numbers mean angles and torques
        for p in res.parameters.values():
            if p.unit and "C" != p.unit:
                p.unit = rotary_unit(p.unit)
    for e in res.experiments:
        q = e.get("fit_quality") or {}
        e["rmse"] = q.get("rmse", e.get("rmse_offset_removed"))
        e["unit"] = unit
    return dataclasses.replace(res, model=model, sensor_offset=offset, unit=unit)


def estimate_offset(model: Model, names, traces, variance_inflation=1.0, found=None, *, force) -> dict:
    """The shared offset at ``model`` (``names`` the fitted parameters): the mean of ``F_meas - F_sim`` over
    all traces, and its standard error from the Jacobian augmented with the offset's column of ones (so that
    the parameters' uncertainty is in it); ``found``, ``force``: as estimate_linear's."""
    return estimate_linear(model, names, traces, None, variance_inflation, found=found, force=force)[0][0]


def estimate_linear(model: Model, names, traces, columns=None, variance_inflation=1.0, at=None, found=None, *,
                    force):
    """The linear parameters profiled out of a fit, at ``model`` (``names`` the fitted parameters): the least
    squares ``F_sim + columns beta = F_meas`` (``columns`` None: one column of ones, the shared offset), and
    their standard errors from the Jacobian augmented with those columns (so that the parameters' uncertainty
    is in them); ``at(r, J)``, where given, transforms the residuals and Jacobian first (a delay's shift).
    ``found``, a list where given, gets the undetermined groups (identifiability.groups) the columns (offsets) are
    members of. ``force``: the force measurement's class (the traces' forces, no offset). Returns (one dict per
    column: value, stderr, ci95; the residuals at the estimate)."""
    plain = [dataclasses.replace(tr, measurement=force("none"), held_offset=0.0) for tr in traces]
    problem = Problem(model, names, plain, rtol=FD_RTOL, parallel=len(plain) > 1)
    theta = np.array([get_value(model, n) for n in names], float)
    r, J = problem.evaluate(theta, jac=bool(names))
    if at is not None and r is not None:
        r, J = at(r, J)
    X = np.ones((sum(tr.n_residuals for tr in traces), 1)) if columns is None else columns
    if r is None:
        return [{"value": math.nan, "stderr": math.nan, "ci95": (math.nan, math.nan)}] * X.shape[1], None
    beta = np.linalg.lstsq(X, -r, rcond=None)[0]
    res = r + X @ beta
    A = np.column_stack([J, X]) if names else X
    dof = max(r.size - A.shape[1], 1)
    s2 = float(res @ res) / dof * variance_inflation
    S, Vt, col, bad, cov1 = scaled_svd(A, UNDETERMINED)  # an offset the data do not determine: infinite error
    cov = cov1 * s2
    if found is not None and names:  # the groups the offset is part of (it is profiled out of the fit's own)
        se = np.sqrt(np.diag(cov))
        found += groups(S, Vt, col, list(names) + [OFFSET] * X.shape[1], np.concatenate([theta, beta]), se, s2,
                        nuisance={OFFSET}, bad=bad)
    tq = float(stats.t.ppf(0.975, dof))
    out = []
    for k, value in enumerate(beta):
        se = math.sqrt(max(float(cov[A.shape[1] - X.shape[1] + k, A.shape[1] - X.shape[1] + k]), 0.0))
        out.append({"value": float(value), "stderr": se, "ci95": (float(value) - tq * se, float(value) + tq * se)})
    return out, res


__all__ = ["force_finish", "completed", "estimate_offset", "estimate_linear"]
