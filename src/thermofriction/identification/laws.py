"""Laws of temperature fitted through per-temperature estimates: linear and exponential by
weighted least squares with AICc to choose, and the two-segment (broken-line) fit of Model II."""

from __future__ import annotations

import math

import numpy as np

from .._lazy import lazy
from ..errors import InputError
from ..models import PWL, Const, Exp, Linear
from ..models.friction import in_domain

optimize = lazy("scipy.optimize")

def aicc(ssr, n, k):
    if ssr <= 0:
        ssr = 1e-300
    aic = n * math.log(ssr / n) + 2 * k
    return aic + 2 * k * (k + 1) / (n - k - 1) if n - k - 1 > 0 else aic


def fit_law(T, values, stderr=None, kinds=("linear", "exp"), prefer=None, parameter=None):
    """Weighted least-squares fits of each law kind to (T, value +- stderr); the one with the
    lowest AICc wins, except that ``prefer`` (e.g. the initial model's kind) is kept unless another
    kind is better by more than 2 (a difference the data support). A law that leaves the physical
    domain of ``parameter`` (e.g. sigma1 < 0) anywhere in its range is not a candidate. Returns
    (law, table)."""
    T, values = np.asarray(T, float), np.asarray(values, float)
    w = np.ones_like(values)
    if stderr is not None:
        se = np.asarray(stderr, float)
        ok = np.isfinite(se) & (se > 0)
        if ok.all():
            w = 1.0 / se
            w = w / w.mean()
    rng = (float(T.min()), float(T.max()))
    table, best = {}, None
    for kind in kinds:
        if kind == "linear":
            A = np.column_stack([T, np.ones_like(T)]) * w[:, None]
            coef, *_ = np.linalg.lstsq(A, values * w, rcond=None)
            law = Linear(float(coef[0]), float(coef[1]), range=rng)
            k = 2
        elif kind == "exp":
            if np.any(values <= 0) or len(T) < 2:
                continue
            b0, la0 = np.polyfit(T, np.log(values), 1, w=w)
            res = optimize.least_squares(lambda c: (c[0] * np.exp(c[1] * T) - values) * w,
                                         [math.exp(la0), b0], x_scale=[math.exp(la0), max(abs(b0), 1e-3)])
            law = Exp(float(res.x[0]), float(res.x[1]), range=rng)
            k = 2
        elif kind == "const":
            law = Const(float(np.average(values, weights=w ** 2)), range=rng)
            k = 1
        else:
            raise InputError(f"unknown law kind '{kind}' for a Model I parameter (linear, exp, const)")
        ssr = float(np.sum(((law(T) - values) * w) ** 2))
        table[kind] = {"aicc": aicc(ssr, len(T), k), "law": law.to_dict()}
        if parameter is not None and not in_domain(parameter, law(np.linspace(rng[0], rng[1], 41))).all():
            table[kind]["excluded"] = f"leaves the physical domain of {parameter} within {rng[0]:g}..{rng[1]:g} C"
            continue
        if best is None or table[kind]["aicc"] < table[best[0]]["aicc"]:
            best = (kind, law)
    if best is None and parameter is not None and "const" not in table:
        # every shape left the physical domain (e.g. sigma1 estimates at zero and above): a constant,
        # the weighted mean kept inside the domain, is the law the data support without leaving it
        value = float(np.average(values, weights=w ** 2))
        positive = values[values > 0]
        if not in_domain(parameter, value):
            value = float(positive.min()) if positive.size else 0.0
        if in_domain(parameter, value):
            law = Const(value, range=rng)
            ssr = float(np.sum(((law(T) - values) * w) ** 2))
            table["const"] = {"aicc": aicc(ssr, len(T), 1), "law": law.to_dict(),
                              "note": "the fallback: every other kind left the physical domain"}
            best = ("const", law)
    if best is None:
        raise InputError("no law could be fitted" + (f" that keeps {parameter} physical over "
                                                       f"{rng[0]:g}..{rng[1]:g} C" if parameter else ""))
    if (prefer in table and prefer != best[0] and "excluded" not in table[prefer]
            and table[prefer]["aicc"] - table[best[0]]["aicc"] <= 2.0):
        from ..models import law_from_dict
        return law_from_dict(table[prefer]["law"], "law"), table
    return best[1], table


def segmented_fit(T, values, weights=None):
    """Two linear segments meeting at an estimated breakpoint (the paper's Fig. 6): a grid
    search over the breakpoint, linear least squares at each. Returns (breakpoint, law)."""
    T, values = np.asarray(T, float), np.asarray(values, float)
    w = np.ones_like(T) if weights is None else np.asarray(weights, float)
    order = np.argsort(T)
    T, values, w = T[order], values[order], w[order]
    best = None
    for tb in np.linspace(T[1], T[-2], 200) if len(T) >= 4 else []:
        A = np.column_stack([np.ones_like(T), T - tb, np.maximum(T - tb, 0.0)]) * w[:, None]
        coef, *_ = np.linalg.lstsq(A, values * w, rcond=None)
        ssr = float(np.sum((A @ coef - values * w) ** 2))
        if best is None or ssr < best[0]:
            best = (ssr, tb, coef)
    if best is None:
        raise InputError("a segmented fit needs at least 4 temperatures")
    _, tb, (c0, c1, c2) = best
    knots = np.array([T[0], tb, T[-1]])
    vals = c0 + c1 * (knots - tb) + c2 * np.maximum(knots - tb, 0.0)
    return float(tb), PWL(knots, vals, range=(float(T[0]), float(T[-1]))), best[0]


__all__ = ["fit_law", "segmented_fit", "aicc"]
