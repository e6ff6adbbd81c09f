"""A position ripple the residuals hold, found and tried before it is said (docs/force-data.md, "A ripple the
residuals hold"). A joint's cogging or gear mesh is a torque periodic in its angle; a model without a ripple leaves
it in the residuals, where no statistic of the fit names it. After a force fit whose model has no ripple, the
residuals of each fit run are searched over the recorded angle (a Lomb-Scargle periodogram, SciPy's definition,
the runs' powers summed, so runs whose angles do not line up still add up); the strongest period is then tried: a
short refit from the optimum with that period and its first harmonic's amplitudes (started where the data put them:
measurements/ripple.py ``started``), scored on the fit runs and, where the dataset holds runs out, on those. Only
a refit that lowers the error by MATERIAL of the misfit (and does not raise the held-out error) is said, with its
measured gains; the period is then one a user can give (``ripple_period``)."""

from __future__ import annotations

import copy
import math

import numpy as np

from ..errors import ThermofrictionError
from ..fitting.optimiser import fit
from ..fitting.problem import Problem, counting
from ..fitting.parameters import get_value, unit_of, with_values
from ..measurements import amount, make_traces
from ..measurements.ripple import additive, has_ripple, started
from ..validation import heldout_score


#: the share of the misfit a tried ripple must remove to be said (as a freed held value must: advice.py)
MATERIAL = 0.05
#: a tried ripple that removes this share of the misfit makes the fit not adequate, whatever else said it was
INADEQUATE = 0.25
#: the most evaluations the tried refit may take (it starts at the optimum with the amplitudes solved)
TRY_EVALUATIONS = 12
#: periods searched: from this many samples' travel (a period the sampling resolves) to half the travel
SAMPLES_PER_PERIOD = 4
#: at most this many periods on the log-spaced grid (fewer where the travel holds fewer cycles)
PERIODS = 3000
#: the periodogram runs on the residuals averaged in bins of the angle this many to the shortest period
BINS_PER_PERIOD = 8
AMPLITUDES = ("ripple_cos1", "ripple_sin1")


def _at(model, traces):
    """The residuals of ``model`` on ``traces`` as the fit forms them (the exact stepping, offsets as the policy fits
    them), split per trace; None where the model cannot be run."""
    r, _ = Problem(model, [], traces, parallel=len(traces) > 1).evaluate(np.array([]), jac=False)
    if r is None:
        return None
    edges = np.cumsum([0] + [tr.n_residuals for tr in traces])
    return [r[i:j] for i, j in zip(edges[:-1], edges[1:])]


def _runs(traces, residuals):
    """[(angle, residual about its mean)] of each trace with a recorded angle."""
    out = []
    for tr, r in zip(traces, residuals):
        x = getattr(tr, "angle", None)
        if x is None or np.size(x) != np.size(r):
            continue
        ok = np.isfinite(r) & np.isfinite(x)
        if ok.sum() > 8:
            out.append((np.asarray(x, float)[ok], r[ok] - r[ok].mean()))
    return out


def _rms(residuals) -> float:
    r = np.concatenate(residuals)
    return float(np.sqrt(np.mean(r ** 2)))


def _binned(x, r, width):
    """(bin, mean): the residuals averaged in bins of the angle ``width`` wide (the bins a run visits, numbered from
    the run's least angle, bin k centred at least + (k + 1/2) ``width``): a run that passes the same angles again and
    again adds its samples to the same bins, so the periodogram's cost is the travel's, not the record's (a bin an
    eighth of the shortest period searched changes no peak)."""
    k = np.floor((x - x.min()) / width).astype(np.int64)
    n = np.bincount(k)
    seen = n > 0
    return np.nonzero(seen)[0], (np.bincount(k, weights=r)[seen] / n[seen])


#: the angular frequencies of one block of the periodogram (its matrices: samples x this, bounded memory)
BLOCK = 512


def lombscargle(x, y, omega):
    """The Lomb-Scargle periodogram of ``y`` at the angular frequencies ``omega`` (SciPy's ``lombscargle``, its
    classic "power" normalisation: half the squared projections on the cosine and sine shifted by the phase that
    makes them orthogonal over ``x``). The same sums, but each shifted projection from the unshifted ones by the
    angle-addition formulas: two trigonometric matrices instead of SciPy 1.17's four, and sums instead of its
    matrix products of them (on a joint's two 10,000-sample runs, 2.3 s of a 6 s fit was SciPy's periodogram).

    Parameters
    ----------
    x : array_like
        The sample positions (here the binned angles).
    y : array_like
        The values at ``x`` (about their mean).
    omega : array_like
        The angular frequencies [rad per unit of ``x``].

    Returns
    -------
    numpy.ndarray
        The power at each of ``omega``.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    out = np.empty(len(omega))
    n = float(x.size)
    tiny = np.finfo(float).epsneg * n
    for k in range(0, len(omega), BLOCK):
        w = np.asarray(omega[k:k + BLOCK], float)
        phase = np.multiply.outer(x, w)
        c, s = np.cos(phase), np.sin(phase)
        cc, cs = np.einsum("ij,ij->j", c, c), np.einsum("ij,ij->j", c, s)
        tau = 0.5 * np.arctan2(2.0 * cs, 2.0 * cc - n)  # cc - ss, ss = n - cc
        ct, st = np.cos(tau), np.sin(tau)
        yc, ys = y @ c, y @ s
        YC, YS = ct * yc + st * ys, ct * ys - st * yc
        CC = np.maximum(ct * ct * cc + 2.0 * ct * st * cs + st * st * (n - cc), tiny)
        SS = np.maximum(n - CC, tiny)
        out[k:k + BLOCK] = 0.5 * (YC * YC / CC + YS * YS / SS)
    return out


def grid_lombscargle(k, y, width, omega):
    """:func:`lombscargle` of ``y`` at positions ``width * k``, ``k`` whole numbers (the bins' centres, shifted: the
    periodogram does not change with a shift), by products instead of a sine and a cosine per sample and frequency:
    with k = B a + b, exp(i omega width k) = exp(i omega width B a) exp(i omega width b), so the sums over the samples
    are a matrix product over b and a sum over a (the trigonometric matrices have 2 sqrt(max k) rows, not one per
    sample). The same power to rounding (tests/test_cost_paths.py); 10-20 times faster on a joint's binned runs.

    Parameters
    ----------
    k : array_like of int
        The positions in units of ``width``, nonnegative, each once.
    y : array_like
        The values at the positions (about their mean).
    width : float
        The positions' unit.
    omega : array_like
        The angular frequencies [rad per unit of ``width``'s].

    Returns
    -------
    numpy.ndarray
        The power at each of ``omega``.
    """
    k, y = np.asarray(k, np.int64), np.asarray(y, float)
    B = int(math.isqrt(int(k.max()))) + 1
    a, b = np.divmod(k, B)
    rows = int(a.max()) + 1
    Y, M = np.zeros((rows, B)), np.zeros((rows, B))
    Y[a, b], M[a, b] = y, 1.0
    n = float(k.size)
    tiny = np.finfo(float).epsneg * n
    out = np.empty(len(omega))
    for j in range(0, len(omega), BLOCK):
        theta = np.asarray(omega[j:j + BLOCK], float) * width
        fine = np.exp(1j * np.multiply.outer(np.arange(B), theta))  # exp(i theta b)
        coarse = np.exp(1j * np.multiply.outer(B * np.arange(rows), theta))  # exp(i theta B a)
        z = np.einsum("af,af->f", coarse, Y @ fine)  # sum y exp(i theta k) = yc + i ys
        z2 = np.einsum("af,af->f", coarse * coarse, M @ (fine * fine))  # sum exp(2 i theta k)
        cc, cs = 0.5 * (n + z2.real), 0.5 * z2.imag
        yc, ys = z.real, z.imag
        tau = 0.5 * np.arctan2(2.0 * cs, 2.0 * cc - n)
        ct, st = np.cos(tau), np.sin(tau)
        YC, YS = ct * yc + st * ys, ct * ys - st * yc
        CC = np.maximum(ct * ct * cc + 2.0 * ct * st * cs + st * st * (n - cc), tiny)
        SS = np.maximum(n - CC, tiny)
        out[j:j + BLOCK] = 0.5 * (YC * YC / CC + YS * YS / SS)
    return out


def strongest_period(runs) -> float | None:
    """The period (in the angle's unit) with the most summed Lomb-Scargle power over ``runs`` [(angle,
    residual)], searched between SAMPLES_PER_PERIOD samples' median travel and half the largest run's travel;
    None where the runs do not move enough to see two periods."""
    steps = np.concatenate([np.abs(np.diff(x)) for x, _ in runs])
    steps = steps[steps > 0]
    travel = max(float(np.ptp(x)) for x, _ in runs)
    if steps.size == 0 or not travel > 0:
        return None
    shortest, longest = SAMPLES_PER_PERIOD * float(np.median(steps)), travel / 2
    if not shortest < longest:
        return None
    # a peak is 1/(cycles over the travel) wide, relatively: four points across the narrowest one (the shortest's)
    count = int(np.clip(math.ceil(4 * travel / shortest * math.log(longest / shortest)), 200, PERIODS))
    periods = np.geomspace(shortest, longest, count)
    width = shortest / BINS_PER_PERIOD
    binned = [_binned(x, r, width) for x, r in runs]
    best = None
    for _ in range(2):  # the grid, then a finer one between the best point's neighbours
        power = sum(grid_lombscargle(k, r, width, 2 * math.pi / periods) for k, r in binned)
        k = int(np.argmax(power))
        best = float(periods[k])
        periods = np.linspace(periods[max(k - 1, 0)], periods[min(k + 1, periods.size - 1)], 201)
    return best


def _share(runs, period) -> float:
    """The share of the residuals' sum of squares one harmonic of ``period`` explains, each run with its own phase
    (a linear least-squares fit per run: the test that decides whether a refit is worth trying)."""
    total = explained = 0.0
    for x, r in runs:
        w = 2 * math.pi * x / period
        A = np.column_stack([np.cos(w), np.sin(w), np.ones_like(w)])
        fitted = A @ np.linalg.lstsq(A, r, rcond=None)[0]
        total += float(r @ r)
        explained += float(r @ r) - float((r - fitted) @ (r - fitted))
    return explained / total if total > 0 else 0.0


def with_ripple_advice(res, experiments, held, measurement, rtol=1e-8):
    """``res`` with a tried position ripple said where its residuals hold one (``fit_quality["ripple"]``: the period,
    the gains measured; a warning), for force data fitted without a ripple; ``held``: the dataset's held-out runs."""
    model = res.model
    if res.fit_quality is None or res.method not in ("base", "model-i") or has_ripple(model) or \
            getattr(measurement, "ripple_phase", None) is None or not res.rmse > 0 or not experiments:
        return res
    if not additive(model.with_friction(ripple_period=1.0)):  # Model II scales a ripple: not a plain term here
        return res
    with counting() as spent:  # the search's and the refit's evaluations are the fit's too
        try:
            out = _tried(res, experiments, held, measurement, rtol)
        except ThermofrictionError:
            out = None
    res.nfev, res.njev = res.nfev + spent.nfev, res.njev + spent.njev
    if out is None:
        return res
    gain = out["gain"]
    res.fit_quality["ripple"] = out
    out["said"] = gain >= MATERIAL and not (held and not out["heldout_after"] < out["heldout_before"])
    if out["said"]:
        message = _message(out, res.unit, measurement, bool(getattr(experiments[0], "rotary", False)))
        q = res.fit_quality
        if gain >= INADEQUATE and q["adequate"] is not False:  # one verdict: the model misses what the data hold
            q["adequate"], q["verdict_basis"] = False, "ripple"
            res.warnings[:] = [w for w in res.warnings if not w.startswith(("adequacy unknown", "adequate relative"))]
            res.warnings.insert(0, "the fit is not adequate: " + message)
        else:
            res.warnings.append(message)
    return res


def _tried(res, experiments, held, measurement, rtol):
    """The strongest period of ``res``'s residuals over the recorded angle, tried by a refit: {period, gain, RMSE
    before and after, evaluations, and on the held-out runs ``held`` where there are any}; None where no period
    is worth a refit."""
    model = res.model
    traces = make_traces(experiments, model, measurement)
    residuals = _at(model, traces)
    runs = _runs(traces, residuals) if residuals is not None else []
    period = strongest_period(runs) if runs else None
    if period is None or _share(runs, period) < MATERIAL:  # not worth a refit: nothing to say
        return None
    refit, after, nfev = _refit(res, experiments, measurement, period, rtol)
    before = _rms(residuals)
    out = {"period": period, "gain": max(1.0 - (after / before) ** 2, 0.0), "rmse_before": before,
           "rmse_after": after, "evaluations": nfev}
    if held:
        out.update(heldout_before=heldout_score(model, held, held, measurement)[0],
                   heldout_after=heldout_score(refit, held, held, measurement)[0])
    return out


def _refit(res, experiments, measurement, period, rtol):
    """(the refit model, its RMSE on the fit runs, evaluations): the fit's varying parameters and the first harmonic
    of a ripple of ``period`` fitted from the optimum, the amplitudes solved first (ripple.started)."""
    start = started(measurement, res.model.with_friction(ripple_period=period), experiments, AMPLITUDES)
    params = copy.deepcopy(res.parameters)
    for p in params.values():  # from the optimum's values
        try:
            p.value = get_value(start, p.name)
        except ThermofrictionError:
            pass
    for n in AMPLITUDES:
        params.add(n, get_value(start, n), unit=unit_of(start, n))
    names = [p.name for p in params.varying]
    outcome = fit(start, params, make_traces(experiments, start, measurement), rtol=rtol, starts=1, near=True,
                  max_nfev=TRY_EVALUATIONS)
    rmse = float(np.sqrt(np.mean(outcome.r ** 2)))
    return with_values(start, dict(zip(names, outcome.theta))), rmse, int(outcome.nfev)


def _message(out, unit, measurement, rotary) -> str:
    per_turn = f" rad ({2 * math.pi / out['period']:.4g} a turn)" if rotary else " m"
    held = (f"; on the held-out runs {amount(out['heldout_before'], unit)} -> {amount(out['heldout_after'], unit)}"
            if "heldout_after" in out else "; no held-out runs to confirm it")
    return (f"the residuals hold a position ripple of period {out['period']:.5g}{per_turn} in the "
            f"{'recorded angle' if measurement.ripple_phase == 'recorded' else 'angle of each run'}: a refit with it "
            f"(ripple_period = {out['period']:.5g}, ripple_cos1 and ripple_sin1 fitted; {out['evaluations']} "
            f"evaluations) lowers the RMSE {amount(out['rmse_before'], unit)} -> {amount(out['rmse_after'], unit)} "
            f"({100 * out['gain']:.2g} % of the misfit){held}")


__all__ = ["with_ripple_advice", "strongest_period", "lombscargle", "grid_lombscargle", "MATERIAL"]
