"""A Model I fit's value of a parameter at a temperature with the 95 % interval its law coefficients' intervals imply
(the delta method on the coefficients' covariance, which the fit reports as standard errors and correlations):
Model I reports intervals for the coefficients only, and two fits of one truth may choose different law kinds, whose
coefficients cannot be compared with the truth's, while their values at a temperature can."""

from __future__ import annotations

import math

import numpy as np


def law_interval(fit, name, T) -> tuple:
    """(value, half-width of its 95 % interval) of ``name`` at ``T`` [C] from ``fit``'s law and the covariance of
    its varying coefficients (central differences of the law in each coefficient); the half-width is 0 where the law
    has no varying coefficient (held)."""
    law = fit.model.thermal.laws[name]
    value = float(law(T))
    varying = [p.name for p in fit.parameters.varying]
    coef = np.array(law.coefficients(), float)
    idx = [varying.index(f"{name}.{c}") if f"{name}.{c}" in varying else None for c in law.coefficient_names()]
    if not idx or any(i is None for i in idx):
        return value, 0.0
    se = np.array([fit.parameters[varying[i]].stderr for i in idx], float)
    cov = np.asarray(fit.correlation, float)[np.ix_(idx, idx)] * np.outer(se, se)
    grad = np.empty(coef.size)
    for k in range(coef.size):
        h = 1e-6 * max(abs(coef[k]), 1e-9)
        up, down = coef.copy(), coef.copy()
        up[k] += h
        down[k] -= h
        grad[k] = (float(law.with_coefficients(up)(T)) - float(law.with_coefficients(down)(T))) / (2 * h)
    return value, 1.96 * math.sqrt(max(float(grad @ cov @ grad), 0.0))


def covers(fit, name, T, truth) -> bool:
    """Whether the 95 % interval of ``name`` at ``T`` (:func:`law_interval`) holds ``truth``."""
    value, half = law_interval(fit, name, T)
    return abs(value - truth) <= half
