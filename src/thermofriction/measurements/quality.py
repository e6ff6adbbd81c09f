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

#: A fit is adequate when its RMSE is at most this many times the noise estimated from the data.
ADEQUATE_RATIO = 2.0
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


def lag1_autocorrelation(r) -> float:
    r = np.asarray(r, float)
    r = r - r.mean()
    den = float(r @ r)
    return float(r[1:] @ r[:-1]) / den if r.size > 2 and den > 0 else math.nan


def fit_quality(residuals, measured, noise: float | None = None) -> dict:
    """``{"rmse", "noise", "ratio", "autocorrelation", "adequate"}`` for residuals (prediction minus
    measurement, offset already removed) of the record ``measured``; ``noise`` overrides the
    estimate (e.g. one pooled over several records)."""
    r = np.asarray(residuals, float)
    rmse = float(np.sqrt(np.mean(r ** 2))) if r.size else math.nan
    noise = noise_level(measured) if noise is None else float(noise)
    span = float(np.ptp(measured)) if np.size(measured) else 0.0
    ratio = rmse / noise if noise > 0 else math.inf
    adequate = bool(ratio <= ADEQUATE_RATIO or rmse <= RESOLUTION * span)
    return {"rmse": rmse, "noise": noise, "ratio": ratio, "autocorrelation": lag1_autocorrelation(r),
            "adequate": adequate}


def pooled(qualities, sizes) -> dict:
    """The fit as a whole: RMSE and noise pooled over the experiments (by their numbers of samples),
    adequate only when every experiment is."""
    n = np.asarray(sizes, float)
    rmse = float(np.sqrt(np.sum(n * np.array([q["rmse"] for q in qualities]) ** 2) / n.sum()))
    noise = float(np.sqrt(np.sum(n * np.array([q["noise"] for q in qualities]) ** 2) / n.sum()))
    ac = float(np.sum(n * np.array([q["autocorrelation"] for q in qualities])) / n.sum())
    return {"rmse": rmse, "noise": noise, "ratio": rmse / noise if noise > 0 else math.inf, "autocorrelation": ac,
            "adequate": all(q["adequate"] for q in qualities)}


__all__ = ["noise_level", "fit_quality", "pooled", "ADEQUATE_RATIO", "RESOLUTION"]
