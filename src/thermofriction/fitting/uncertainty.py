"""Uncertainty (the layer above the optimiser): standard errors, intervals and correlations of a fit from the
Jacobian at its optimum."""

from __future__ import annotations

import math

import numpy as np

from .._lazy import lazy
from ..models import Model
from .identifiability import groups, no_information, scaled_svd
from .optimiser import UNDETERMINED, FitOutcome
from .parameters import Parameters, unit_of
from .shown import REL_SHOWN

special = lazy("scipy.special")


def uncertainty(params: Parameters, outcome: FitOutcome, traces, model: Model):
    """Standard errors, 95 % intervals and correlations from the Jacobian at the optimum.

    cov = s^2 (J^T J)^-1 by SVD of the column-scaled Jacobian; a direction the data do not
    determine (singular value below 1e-9 of the largest) gives the parameters on it an infinite
    error instead of a falsely tight one. Correlated residuals carry less information than as many
    independent ones: s^2 is inflated by the residuals' integrated autocorrelation time (n over the
    effective sample size, :func:`inflation_of`), and the t quantile takes the effective number of degrees of
    freedom. Returns the correlation matrix and warnings.

    Parameters
    ----------
    params : Parameters
        The fitted parameters; their stderr, ci95 and at_bound are set here.
    outcome : FitOutcome
        ``fit``'s optimum with its residuals and Jacobian.
    traces : list of Trace
        The runs fitted.
    model : Model
        The fitted model (the parameters' units).

    Returns
    -------
    tuple
        (correlation matrix, warnings, statistics: dof, residual_std, autocorrelation, variance_inflation,
        effective_samples, identifiability).

    Raises
    ------
    None
        Nothing is checked: the arguments come from ``fit``.
    """
    varying = params.varying
    theta, r, J = outcome.theta, outcome.r, outcome.J
    n, p = J.shape
    dof = max(n - p - traces[0].measurement.offsets_in(traces), 1)
    s2 = float(r @ r) / dof
    inflation, rho = inflation_of(r, [tr.n_residuals for tr in traces])
    dof_eff = max(n / inflation - p - traces[0].measurement.offsets_in(traces), 1.0)
    why_not = no_information([par.name for par in varying], np.linalg.norm(J, axis=0))
    S, Vt, col, bad, cov1 = scaled_svd(J, UNDETERMINED)
    cov = cov1 * (s2 * inflation)
    var = np.diag(cov).copy()
    se = np.sqrt(var)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    corr[~np.isfinite(corr)] = np.nan
    np.fill_diagonal(corr, 1.0)
    tq = float(special.stdtrit(dof_eff, 0.975))  # Student's t quantile (scipy.stats takes 0.3 s to import)
    found = groups(S, Vt, col, [par.name for par in varying], theta, se, s2 * inflation, bad=bad)
    warnings = [g["warning"] for g in found]
    for i, par in enumerate(varying):
        par.value = float(theta[i])
        par.stderr = float(se[i])
        side = outcome.at_bound[i] if outcome.at_bound else None
        if side:
            par.at_bound, par.ci95 = side, _one_sided(par, side, float(theta[i]), float(se[i]), outcome, i, dof_eff)
            far = par.ci95[1 if side == "lower" else 0]
            said = (f"the data put it {'below' if side == 'lower' else 'above'} {far:.4g} (one-sided 95 %)"
                    if math.isfinite(far) and se[i] <= REL_SHOWN * abs(theta[i]) else  # (shown.py's rule)
                    "the data do not bound it on the other side either")
            warnings.append(f"'{par.name}' ended at its {side} bound ({par.value:.4g}): {said}, not at a value; "
                            f"hold it, or fit another model")
            continue
        if not math.isfinite(se[i]):
            par.ci95 = (0.0 if par.positive else -math.inf, math.inf)
            warnings.append(f"'{par.name}' is not identifiable from these data (its interval is infinite)"
                            + (f": {why_not[par.name]}" if par.name in why_not else ""))
            continue
        if par.positive:  # (beyond e^700 the factor is infinite: (0, inf), not the cap's 1e-302 to 1e306)
            f = math.exp(tq * se[i] / theta[i]) if tq * se[i] / theta[i] < 700.0 else math.inf
            par.ci95 = (float(theta[i]) / f, float(theta[i]) * f)  # (Python floats: inf, not an overflow warning)
        else:
            par.ci95 = (theta[i] - tq * se[i], theta[i] + tq * se[i])
        if se[i] > 0.5 * abs(theta[i]):
            rel = (f"> {100 * REL_SHOWN:.0f} %" if se[i] > REL_SHOWN * abs(theta[i]) else
                   f"{100 * se[i] / abs(theta[i]):.0f} %") + " of its value" if theta[i] else f"{se[i]:.3g} around 0"
            warnings.append(f"'{par.name}' is poorly determined by these data (standard error {rel})")
    for par in params.values():
        if not par.vary:
            par.stderr, par.ci95 = 0.0, (par.value, par.value)
        if not par.unit:
            par.unit = unit_of(model, par.name)
    return corr, warnings, {"dof": dof, "residual_std": math.sqrt(s2), "autocorrelation": rho,
                            "variance_inflation": inflation, "effective_samples": n / inflation,
                            "identifiability": found}


def _one_sided(par, side, value, se, outcome, i, dof) -> tuple:
    """The one-sided 95 % interval of a parameter that ended at a bound: from the bound to the value plus (or
    minus) the one-sided t quantile times its standard error (in log for a positive parameter)."""
    bound = float(outcome.bounds[0][i] if side == "lower" else outcome.bounds[1][i])
    if not math.isfinite(se):
        return (bound, math.inf) if side == "lower" else (-math.inf if not par.positive else 0.0, bound)
    tq = float(special.stdtrit(dof, 0.95))
    if par.positive:
        far = value * math.exp(min(tq * se / value, 700.0) * (1 if side == "lower" else -1))
    else:
        far = value + tq * se * (1 if side == "lower" else -1)
    return (bound, far) if side == "lower" else (far, bound)


def residual_variance(outcome) -> float:
    """The residuals' variance at an optimum (sum of squares over the residuals less the fitted parameters)."""
    return float(outcome.r @ outcome.r) / max(outcome.r.size - outcome.J.shape[1], 1)


def integrated_autocorrelation(x) -> float:
    """The integrated autocorrelation time of the series ``x`` (1 for independent values; (1 + rho)/(1 - rho)
    for an AR(1) series), by Geyer's initial positive sequence: the autocorrelations summed in pairs
    rho_2k + rho_2k+1 while the pairs stay positive (past that they are the estimate's own noise)."""
    x = np.asarray(x, float)
    x = x - x.mean()
    n = x.size
    var = float(x @ x)
    if n < 4 or var <= 0:
        return 1.0
    spectrum = np.fft.rfft(x, 2 * n)
    acf = np.fft.irfft(spectrum * np.conj(spectrum))[:n] / var
    tau, k = -1.0, 0
    while 2 * k + 1 < n:
        pair = acf[2 * k] + acf[2 * k + 1]
        if pair <= 0:
            break
        tau += 2.0 * pair
        k += 1
    return max(tau, 1.0)


def inflation_of(r, sizes):
    """(the variance inflation, the mean lag-1 autocorrelation) of residuals ``r`` made of runs of ``sizes``:
    each run's integrated autocorrelation time, averaged over the runs by their lengths."""
    taus, rhos, weights, start = [], [], [], 0
    for size in sizes:
        seg = r[start:start + size]
        start += size
        if len(seg) > 3 and np.dot(seg, seg) > 0:
            taus.append(integrated_autocorrelation(seg))
            rhos.append(float(np.dot(seg[1:], seg[:-1]) / np.dot(seg, seg)))
            weights.append(len(seg))
    if not taus:
        return 1.0, 0.0
    return float(np.average(taus, weights=weights)), float(np.mean(rhos))


__all__ = ["uncertainty", "residual_variance", "integrated_autocorrelation", "inflation_of"]
