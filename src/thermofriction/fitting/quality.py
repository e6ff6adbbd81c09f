"""Is a fit as good as the data allow? The measurement noise estimated from the data alone, and the
fit's residuals compared with it.

The noise comes from the record's second differences, ``x[i+1] - 2 x[i] + x[i-1]``: for white noise
of standard deviation s they scatter with standard deviation ``sqrt(6) s``, while a smooth motion
sampled fast contributes almost nothing; their median absolute deviation ignores the few samples where
the motion itself jumps (a stick-slip actuator's slips). No model is involved, so a fit can be held
against it: a fit whose residuals are several times the noise misses something the data show.
"""

from __future__ import annotations

import math

import numpy as np

#: The most a fit's RMSE may exceed the noise estimated from the data and the fit be called adequate (few samples).
ADEQUATE_RATIO = 2.0
#: What a right model may leave above the noise whatever the number of samples: the noise estimate's own bias on
#: a stick-slip record (its slips), the solver's tolerance. Right models on the suite's data give 0.96-1.04.
MODEL_ALLOWANCE = 0.1
#: standard deviations of the ratio's sampling scatter allowed above that (one-sided, ~3e-5 per experiment)
ADEQUACY_Z = 4.0
#: n times the variance of noise_level's relative error on white noise (measured: 1.39^2 at 10^3 and 10^4 samples)
NOISE_ESTIMATE_VARIANCE = 1.93
#: ... or when its RMSE is below this fraction of the record's range (noise-free or nearly noise-free
#: data: the noise estimate is then the signal's own curvature, and the solver's accuracy the floor).
RESOLUTION = 1e-4

_MAD_TO_SIGMA = 1.0 / 0.6744897501960817  # for a normal distribution


def noise_level(x) -> float:
    """Standard deviation of white measurement noise in the record ``x`` (same unit), from the median
    absolute deviation of its second differences. NaN for fewer than 5 samples."""
    x = np.asarray(x, float)
    if x.size < 5:
        return math.nan
    d2 = x[2:] - 2.0 * x[1:-1] + x[:-2]
    mad = float(np.median(np.abs(d2 - np.median(d2))))
    return mad * _MAD_TO_SIGMA / math.sqrt(6.0)


#: noise_check's limit on the wide estimate over the narrow one (plus 3/sqrt(n), the ratio's sampling scatter):
#: white noise on a stick-slip record gives 1.0-1.13 (the signal's curvature shows more at two samples' spacing),
#: noise with a lag-1 autocorrelation of 0.5 1.29, of 0.8-0.9 1.39-1.4
WIDE_TO_NARROW = 1.2


def noise_check(x) -> tuple:
    """Whether :func:`noise_level` can be trusted on the record ``x``: (reliable, why not). The noise is estimated
    again from second differences two samples apart: for white noise the two estimates agree (both see the same
    noise), for noise correlated from sample to sample (an estimator's output, a filtered velocity, a command
    minus a filtered J a) the wider one is larger (1.29 times at a lag-1 autocorrelation of 0.5, 1.4 at 0.9) and
    the estimate a fraction of the real noise (a quarter at 0.9); for a record smooth at the sample scale it is
    four times larger (curvature); a quantised record has mostly zero differences. Sparse features (a
    stick-slip actuator's slips) move neither median."""
    x = np.asarray(x, float)
    if x.size < 20:
        return False, "the record is too short to estimate its noise"
    narrow, wide = _spread(x, 1), _spread(x, 2)
    if narrow == 0.0:
        return False, ("most of the record's second differences are zero (a quantised or held signal): its noise "
                       "cannot be estimated from it")
    ratio = wide / narrow
    if ratio > WIDE_TO_NARROW + 3.0 / math.sqrt(x.size):
        return False, (f"the record's noise is not white at the sample scale (estimated from samples two apart it "
                       f"is {ratio:.2f} times the estimate from neighbours; white noise gives 1): a filtered or "
                       f"estimated signal, or one smooth at the sample scale, whose noise the data cannot tell")
    return True, ""


def _spread(x, k) -> float:
    """The noise level from second differences ``k`` samples apart (k = 1: :func:`noise_level`)."""
    d2 = x[2 * k:] - 2.0 * x[k:-k] + x[:-2 * k]
    return float(np.median(np.abs(d2 - np.median(d2)))) * _MAD_TO_SIGMA / math.sqrt(6.0)


def lag1_autocorrelation(r) -> float:
    r = np.asarray(r, float)
    r = r - r.mean()
    den = float(r @ r)
    return float(r[1:] @ r[:-1]) / den if r.size > 2 and den > 0 else math.nan


def adequacy_threshold(n: int, autocorrelation: float = 0.0) -> float:
    """The largest rmse/noise ratio a right model gives on ``n`` samples whose residuals have this lag-1
    autocorrelation: 1 + MODEL_ALLOWANCE + ADEQUACY_Z standard deviations of the ratio's scatter, from the noise
    estimate's (NOISE_ESTIMATE_VARIANCE / n) and the residuals' mean square's (tau / 2n, tau = (1 + rho)/(1 - rho),
    their integrated autocorrelation time as an AR(1) series); at most ADEQUATE_RATIO. About 1.14 at 10^4 white
    samples, 1.11 at 10^5."""
    rho = min(max(autocorrelation if math.isfinite(autocorrelation) else 0.0, 0.0), 0.99)
    tau = (1.0 + rho) / (1.0 - rho)
    sd = math.sqrt((NOISE_ESTIMATE_VARIANCE + tau / 2.0) / max(n, 1))
    return min(ADEQUATE_RATIO, 1.0 + MODEL_ALLOWANCE + ADEQUACY_Z * sd)


def fit_quality(residuals, measured, noise: float | None = None) -> dict:
    """``{"rmse", "noise", "ratio", "autocorrelation", "adequate", "noise_reliable", "why"}`` for residuals
    (prediction minus measurement, offset already removed) of the record ``measured``; ``noise`` overrides the
    estimate (e.g. one pooled over several records). ``adequate`` is None (unknown, ``why`` says why) where the
    noise cannot be estimated from the record (:func:`noise_check`): a ratio to a wrong noise level says
    nothing about the model."""
    r = np.asarray(residuals, float)
    rmse = float(np.sqrt(np.mean(r ** 2))) if r.size else math.nan
    reliable, why = (True, "") if noise is not None else noise_check(measured)
    noise = noise_level(measured) if noise is None else float(noise)
    span = float(np.ptp(measured)) if np.size(measured) else 0.0
    ratio = rmse / noise if noise > 0 else math.inf
    rho = lag1_autocorrelation(r)
    threshold = adequacy_threshold(r.size, rho)
    if rmse <= RESOLUTION * span:
        adequate = True
    elif not reliable:
        adequate = None
    else:
        adequate = bool(ratio <= threshold)
    return {"rmse": rmse, "noise": noise, "ratio": ratio, "threshold": threshold, "autocorrelation": rho,
            "adequate": adequate, "noise_reliable": reliable, "why": why}


def pooled(qualities, sizes) -> dict:
    """The fit as a whole: RMSE and noise pooled over the experiments (by their numbers of samples); adequate
    when every experiment is, not adequate when one is not, else unknown (None, with the first reason)."""
    n = np.asarray(sizes, float)
    rmse = float(np.sqrt(np.sum(n * np.array([q["rmse"] for q in qualities]) ** 2) / n.sum()))
    noise = float(np.sqrt(np.sum(n * np.array([q["noise"] for q in qualities]) ** 2) / n.sum()))
    ac = float(np.sum(n * np.array([q["autocorrelation"] for q in qualities])) / n.sum())
    verdicts = [q["adequate"] for q in qualities]
    adequate = False if False in verdicts else None if None in verdicts else True
    why = next((q.get("why", "") for q in qualities if q["adequate"] is None), "")
    return {"rmse": rmse, "noise": noise, "ratio": rmse / noise if noise > 0 else math.inf,
            "threshold": min((q.get("threshold", ADEQUATE_RATIO) for q in qualities), default=ADEQUATE_RATIO),
            "autocorrelation": ac,
            "adequate": adequate, "noise_reliable": all(q.get("noise_reliable", True) for q in qualities),
            "why": why}


__all__ = ["noise_level", "noise_check", "lag1_autocorrelation", "fit_quality", "pooled", "adequacy_threshold",
           "ADEQUATE_RATIO", "RESOLUTION"]
