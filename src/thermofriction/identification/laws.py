"""Laws of temperature fitted through per-temperature estimates: linear and exponential by
weighted least squares with AICc to choose, and the two-segment (broken-line) fit of Model II."""

from __future__ import annotations

import copy
import math

import numpy as np

from .._lazy import lazy
from ..errors import InputError
from ..models.laws import RANGE_TOLERANCE
from ..models import PWL, Const, Exp, Linear
from ..models.friction import in_domain

optimize = lazy("scipy.optimize")

LOG_SPACE_BELOW = 0.3  # relative standard error below which a parameter's misfit is taken as quadratic in its log
LAWS_ON_INFORMATION_EVALUATIONS = 100  # the most evaluations of laws_on_information's least squares


def aicc(ssr, n, k):
    if ssr <= 0:
        ssr = 1e-300
    aic = n * math.log(ssr / n) + 2 * k
    return aic + 2 * k * (k + 1) / (n - k - 1) if n - k - 1 > 0 else aic


#: [degC] temperatures closer than this are one temperature to a fit (procedures.temperature_groups), and a law
#: holds within it of its range (models/laws.py: RANGE_TOLERANCE, the same number)
SAME_TEMPERATURE = RANGE_TOLERANCE


def fit_range(T) -> tuple:
    """The range a law fitted at temperatures ``T`` is written with: from the lowest to the highest, as fitted. (Widened
    by SAME_TEMPERATURE, a fitted constant fs beside a falling fc law fell below it at the widened end, and the fit
    could not start: the range stays what was fitted, and a law is taken to hold within RANGE_TOLERANCE of it, so
    that runs nominally at 24 and 45 C whose records average 24.0001 and 44.9995 C are inside.)"""
    T = np.asarray(T, float)
    return float(T.min()), float(T.max())


#: the law kinds fit_law fits (identify(laws={name: kind}), --law NAME=KIND)
FIT_LAW_KINDS = ("linear", "exp", "const")


#: the law kinds a Model I parameter's estimates choose from by AICc (unless the user names them; the initial model's
#: kind kept unless another is better by more than 2)
KINDS = ("linear", "exp")
#: the shape constants: the Stribeck velocity, which the initial model gives no law, may take a constant law too (it
#: must beat linear by more than 2 in AICc: identification/model_i.py, _laws_through)
SHAPE_CONSTANTS = ("vs", "vs_neg")
KINDS_OF_A_SHAPE_CONSTANT = ("linear", "exp", "const")


def law_kinds_for(name, prior, asked):
    """(the kinds ``name``'s law is chosen among, the kind kept over a constant or None): ``asked`` (a kind or
    kinds, the user's) as asked; else KINDS, and for a shape constant without a law in the initial model (``prior``
    None) KINDS_OF_A_SHAPE_CONSTANT with linear kept over the constant unless it is better by more than 2."""
    if asked:
        return ((asked,) if isinstance(asked, str) else tuple(asked)), None
    if name in SHAPE_CONSTANTS and not prior:
        return KINDS_OF_A_SHAPE_CONSTANT, "linear"
    return KINDS, None


def fit_law(T, values, stderr=None, kinds=("linear", "exp"), prefer=None, parameter=None, over_const=None):
    """Weighted least-squares fits of each law kind to (T, value +- stderr); the one with the
    lowest AICc wins, except that ``prefer`` (e.g. the initial model's kind) is kept unless another
    kind is better by more than 2 (a difference the data support). A law that leaves the physical
    domain of ``parameter`` (e.g. sigma1 < 0) anywhere in its range is not a candidate.

    Parameters
    ----------
    T : array_like
        The temperatures [C].
    values : array_like
        The per-temperature estimates, in the parameter's unit.
    stderr : array_like, optional
        Their standard errors (the weights); default equal weights.
    kinds : sequence of str, default ("linear", "exp")
        The law kinds tried.
    prefer : str, optional
        A kind kept unless another is better by more than 2 in AICc.
    over_const : str, optional
        A kind kept over a constant unless the constant is better by more than 2 in AICc (the other kinds
        compete by AICc alone): a constant wins only where the data say so, not where a slope is lost in noise.
    parameter : str, optional
        The parameter's name, for its physical domain.

    Returns
    -------
    tuple
        (the winning Law, {kind: {"aicc", "law", and "excluded" where it left the domain}}).

    Raises
    ------
    InputError
        An unknown law kind.
    """
    T, values = np.asarray(T, float), np.asarray(values, float)
    w = np.ones_like(values)
    if stderr is not None:
        se = np.asarray(stderr, float)
        ok = np.isfinite(se) & (se > 0)
        if ok.all():
            w = 1.0 / se
            w = w / w.mean()
    rng = fit_range(T)
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
            raise InputError(f"unknown law kind '{kind}' for a Model I parameter ({', '.join(FIT_LAW_KINDS)})")
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
    if best[0] == "const" and over_const is not None and prefer is None:
        prefer = over_const
    if (prefer in table and prefer != best[0] and "excluded" not in table[prefer]
            and table[prefer]["aicc"] - table[best[0]]["aicc"] <= 2.0):
        from ..models import law_from_dict
        return law_from_dict(table[prefer]["law"], "law"), table
    return best[1], table


def segmented_fit(T, values, weights=None):
    """Two linear segments meeting at an estimated breakpoint (the paper's Fig. 6): a grid
    search over the breakpoint, linear least squares at each.

    Parameters
    ----------
    T : array_like
        The temperatures [C]; at least 4.
    values : array_like
        The values at them.
    weights : array_like, optional
        The residuals' weights; default 1.

    Returns
    -------
    tuple
        (the breakpoint [C], the PWL law through the ends and the breakpoint, the weighted sum of squared
        residuals).

    Raises
    ------
    InputError
        Fewer than 4 temperatures.
    """
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
    return float(tb), PWL(knots, vals, range=fit_range(T)), best[0]


def laws_on_information(Ts, per_T, laws: dict) -> dict:
    """The laws' coefficients refitted to the per-temperature estimates weighted by each temperature's
    full covariance (in log space, where the fits were made), not by its standard errors alone: the
    per-temperature estimates are strongly correlated (sigma0 with fc), and the joint refinement then
    starts near its optimum instead of some standard errors away. The law kinds stay as chosen; a law
    is kept as it was if this fails or leaves its parameter's physical domain."""
    names = list(laws)
    blocks = []
    for T, res in per_T:
        varying = [p.name for p in res.parameters.varying]
        if not all(n in varying for n in names):
            return laws
        idx = [varying.index(n) for n in names]
        value = np.array([res.parameters[n].value for n in names])
        se = np.array([res.parameters[n].stderr for n in names], float)
        if np.any(value <= 0) or res.correlation.shape != (len(varying), len(varying)):
            return laws
        known = np.isfinite(se) & (se > 0)  # a parameter this temperature leaves open adds nothing
        corr = res.correlation[np.ix_(idx, idx)][np.ix_(known, known)]
        if not known.any() or not np.all(np.isfinite(corr)):
            continue
        # well-determined parameters in log space (where the fits were made), a poorly determined one
        # (sigma1, often) in its own: its misfit is nearer quadratic there
        log = se[known] < LOG_SPACE_BELOW * value[known]
        unit = np.where(log, value[known], 1.0)
        cov = corr * np.outer(se[known] / unit, se[known] / unit)
        try:
            root = np.linalg.cholesky(np.linalg.inv(cov))  # W = root root^T
        except np.linalg.LinAlgError:
            continue
        blocks.append((T, np.flatnonzero(known), log, np.where(log, np.log(value[known]), value[known]), root))
    if not blocks:
        return laws
    sizes = [len(laws[n].coefficients()) for n in names]
    c0 = np.concatenate([laws[n].coefficients() for n in names])

    def with_coefficients(c):
        out, k = {}, 0
        for n, size in zip(names, sizes):
            out[n] = laws[n].with_coefficients(c[k:k + size])
            k += size
        return out

    at = np.array([b[0] for b in blocks], float)

    def residuals(c):
        # each law evaluated once at every temperature (the same values as one temperature at a time: 0.5 s of
        # Python per Model I fit went to evaluating them one by one, in the thousands of calls this fit can take)
        trial = with_coefficients(c)
        values = [np.asarray(trial[n](at), float) for n in names]
        out = []
        for k, (T, known, log, estimate, root) in enumerate(blocks):
            predicted = np.array([values[i][k] for i in known])
            if np.any(~np.isfinite(predicted)) or np.any(predicted <= 0):
                return np.full(sum(len(b[1]) for b in blocks), 1e6)
            out.append(root.T @ (np.where(log, np.log(predicted), predicted) - estimate))
        return np.concatenate(out)

    try:
        # at most LAWS_ON_INFORMATION_EVALUATIONS: where it converges it takes 4-46 (20 fits of the independent-truths
        # study); where it does not (an exponential law chasing sigma1 estimates at zero, a valley to b -> -inf)
        # SciPy's default of 100 per coefficient took 0.5 s of a 0.9 s fit only to end unconverged, which keeps
        # the laws as they were -- as stopping sooner does
        res = optimize.least_squares(residuals, c0, x_scale=np.where(c0 != 0, np.abs(c0), 1.0),
                                     max_nfev=LAWS_ON_INFORMATION_EVALUATIONS)
    except (ValueError, np.linalg.LinAlgError):
        return laws
    if not res.success or 2 * res.cost >= float(np.sum(residuals(c0) ** 2)):
        return laws
    refined = with_coefficients(res.x)
    grid = np.linspace(float(np.min(Ts)), float(np.max(Ts)), 41)
    return {n: refined[n] if in_domain(n, refined[n](grid)).all() else laws[n] for n in names}


def at_shared(per_T, free, shared):
    """Each temperature's estimates where the freed plant parameters take their shared values (``shared``: the
    median of the per-temperature estimates) instead of that temperature's own: the conditional mean and covariance
    given them, from the fit's own covariance (each parameter in log space where its standard error is below
    LOG_SPACE_BELOW of its value, as the fits were made, else in its own). The per-temperature estimates of sigma0
    and fc move with that temperature's m_e; laws through them unmoved started the joint refinement far from its
    optimum (8 temperatures from a start 2-3x off: 17 evaluations to a fit 1.2 times the noise, not adequate).
    A temperature whose covariance is not usable is kept as it is."""
    out = []
    for T, res in per_T:
        varying = [p.name for p in res.parameters.varying]
        n = len(varying)
        se = np.array([res.parameters[v].stderr for v in varying], float)
        val = np.array([res.parameters[v].value for v in varying], float)
        corr = np.asarray(res.correlation, float)
        if corr.shape != (n, n) or not np.all(np.isfinite(se)) or not np.all(np.isfinite(corr)) \
                or np.any(val <= 0) or not all(x in varying for x in free):
            out.append((T, res))
            continue
        log = se < LOG_SPACE_BELOW * val
        unit = np.where(log, val, 1.0)
        cov = corr * np.outer(se / unit, se / unit)
        y = np.where(log, np.log(val), val)
        f = [varying.index(x) for x in free]
        o = [i for i in range(n) if i not in f]
        target = np.array([shared[x] for x in free])
        try:
            gain = cov[np.ix_(o, f)] @ np.linalg.inv(cov[np.ix_(f, f)])
        except np.linalg.LinAlgError:
            out.append((T, res))
            continue
        x = y[o] + gain @ (np.where(log[f], np.log(target), target) - y[f])
        c = cov[np.ix_(o, o)] - gain @ cov[np.ix_(f, o)]
        values = np.where(log[o], np.exp(np.minimum(x, 700.0)), x)
        if np.any(values <= 0) or not np.all(np.isfinite(values)):
            out.append((T, res))
            continue
        moved = copy.deepcopy(res)
        sd = np.sqrt(np.maximum(np.diag(c), 0.0))
        for k, i in enumerate(o):
            moved.parameters[varying[i]].value = float(values[k])
            moved.parameters[varying[i]].stderr = float(sd[k] * (values[k] if log[i] else 1.0))
        for k, i in enumerate(f):
            moved.parameters[varying[i]].value = float(target[k])
        moved.correlation = np.eye(n)
        moved.correlation[np.ix_(o, o)] = c / np.outer(np.where(sd > 0, sd, 1.0), np.where(sd > 0, sd, 1.0))
        out.append((T, moved))
    return out


__all__ = ["fit_law", "law_kinds_for", "KINDS", "SHAPE_CONSTANTS", "FIT_LAW_KINDS", "segmented_fit", "aicc", "laws_on_information", "at_shared", "LOG_SPACE_BELOW"]
