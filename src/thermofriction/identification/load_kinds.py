"""A law of load's kind chosen (docs/identification.md#laws-of-temperature-and-load): the candidates of a law of
temperature and load -- proportional to the load (a product), affine in it as a product or a sum, each with and
without an interaction term c T |L| -- fitted through per-condition estimates (or, where those are not determined,
through the given law's values at the fit conditions), ranked by AICc there, and the leaders then compared on all
experiments by AICc on the effective samples (the samples over the residuals' integrated autocorrelation time: on
correlated noise a difference of misfits is that much larger for the same evidence), as Model I's temperature kinds
are (identification/law_kinds.py).

The law's temperature kind (linear, exp, ...) is the model file's: along the load only the load term's form is
chosen. With a linear temperature law, "affine, product" and "affine, sum" with an interaction span the same
functions; the candidates are ordered with the given form first, so that such a tie keeps the user's.
"""

from __future__ import annotations

import math

import numpy as np

from .._lazy import lazy
from ..errors import InputError
from ..models.load_laws import LoadLaw, LoadTerm
from ..measurements.force_load import law_derivatives
from .laws import aicc

optimize = lazy("scipy.optimize")

#: the load terms' forms a law of load is chosen among: (kind, combine)
FORMS = (("proportional", "product"), ("affine", "product"), ("affine", "sum"))
#: the candidates of each law tried on all experiments besides the best on the per-condition estimates
CHECKED = 2


def form_of(law) -> str:
    """A law's form in words: ``"affine, sum, with interaction"``; ``"temperature only"`` for a temperature law."""
    if not isinstance(law, LoadLaw):
        return "temperature only"
    t = law.load
    return f"{t.kind}, {t.combine}" + (", with interaction" if t.interaction is not None else "")


def equation(name: str, law) -> str:
    """A law of temperature and load as one line: ``fc(T, L) = (-0.01 T + 1.5) + 0.05 |L| - 0.0002 T |L|``.

    Parameters
    ----------
    name : str
        The parameter.
    law : Law or LoadLaw
        Its law.

    Returns
    -------
    str
    """
    base = law.base if isinstance(law, LoadLaw) else law
    if base.kind == "linear":
        f = f"({base.a:.4g} T + {base.b:.4g})"
    elif base.kind == "const":
        f = f"{base.value:.4g}"
    elif base.kind == "exp":
        f = f"{base.a:.4g} exp({base.b:.4g} T)"
    else:
        f = f"{name}0(T) ({base.kind})"
    if not isinstance(law, LoadLaw):
        return f"{name}(T) = {f}"
    t = law.load
    s = "|L|" if t.saturation is None else f"{t.saturation:.4g} tanh(|L|/{t.saturation:.4g})"
    v = f"{f} {s}" if t.kind == "proportional" else f"{f} (1 + {t.k:.4g} {s})" if t.combine == "product" else \
        f"{f} + {t.k:.4g} {s}"
    if t.interaction is not None:
        v += f" {'-' if t.interaction < 0 else '+'} {abs(t.interaction):.4g} T {s}"
    return f"{name}(T, L) = {v}".replace("+ -", "- ")


def law_value(law, T, load):
    """The value of a law of temperature (and load) at (T, load), without a range warning."""
    return law.value(T, load, warn=False) if isinstance(law, LoadLaw) else float(law(T))


def candidates(law: LoadLaw, T_mid: float, load_mid: float) -> list:
    """The forms a law of load is chosen among: ``law`` itself first, then the other forms of FORMS with and without
    an interaction, each started at the given law's value at (T_mid, load_mid) (its temperature law scaled; k and the
    interaction from 0).

    Parameters
    ----------
    law : LoadLaw
        The given law.
    T_mid, load_mid : float
        The middle of the fit conditions' temperatures [C] and loads [N or N m].

    Returns
    -------
    list of LoadLaw
    """
    out = [law]
    target = law_value(law, T_mid, load_mid)
    for kind, combine in FORMS:
        for interaction in (None, 0.0):
            term = LoadTerm(kind, k=None if kind == "proportional" else 0.0, combine=combine,
                            interaction=interaction, saturation=law.load.saturation, range=law.load.range)
            if form_of(LoadLaw(law.base, term)) == form_of(law):
                continue
            level = float(law.base(T_mid)) * (float(term.magnitude(load_mid)) if kind == "proportional" else 1.0)
            base = law.base.scaled(target / level) if level != 0 and math.isfinite(target / level) else law.base
            out.append(LoadLaw(base, term))
    return out


def fit_through(law, T, L, values, stderr):
    """``law`` fitted through ``values`` at the conditions (T, L), weighted by 1/``stderr``: (the fitted law, its
    weighted sum of squares). The chain rule is the law's own derivatives (measurements/force_load.py).

    Parameters
    ----------
    law : Law or LoadLaw
        The law, its coefficients the start.
    T, L : numpy.ndarray
        The conditions' temperatures [C] and loads.
    values, stderr : numpy.ndarray
        The estimates there and their standard errors.

    Returns
    -------
    tuple
        (law, weighted sum of squares); the start and infinity where the fit fails.
    """
    w = 1.0 / np.asarray(stderr, float)

    def residuals(c):
        m = law.with_coefficients(c)
        return (np.array([law_value(m, t, x) for t, x in zip(T, L)]) - values) * w

    def jacobian(c):
        m = law.with_coefficients(c)
        return np.array([law_derivatives(m, t, x) for t, x in zip(T, L)]) * w[:, None]
    c0 = np.array(law.coefficients(), float)
    if c0.size == 0:
        r = residuals(c0)
        return law, float(r @ r)
    try:
        res = optimize.least_squares(residuals, c0, jac=jacobian, x_scale="jac", method="trf", max_nfev=200)
    except (InputError, ValueError, FloatingPointError):
        return law, math.inf
    return law.with_coefficients(res.x), float(res.fun @ res.fun)


def ranked(law, T, L, values, stderr) -> list:
    """The candidates of ``law`` (a law of load; a temperature law is its own only candidate) fitted through the
    estimates, best AICc first (ties: the given form first): [(aicc, fitted law)].

    Parameters
    ----------
    law : Law or LoadLaw
        The given law.
    T, L, values, stderr : numpy.ndarray
        As :func:`fit_through`.

    Returns
    -------
    list of tuple
    """
    T, L = np.asarray(T, float), np.asarray(L, float)
    pool = candidates(law, float(np.mean(T)), float(np.mean(np.abs(L)))) if isinstance(law, LoadLaw) and \
        len({round(abs(x), 9) for x in L}) > 1 else [law]
    out = []
    for cand in pool:
        fitted, ssr = fit_through(cand, T, L, values, stderr)
        score = aicc(ssr, len(T), len(fitted.coefficients())) if math.isfinite(ssr) else math.inf
        out.append((score, fitted))
    return sorted(out, key=lambda sl: sl[0])


def effective_aicc(rss: float, n: int, k: int, tau: float) -> float:
    """AICc on the effective samples: n / tau of them (tau the residuals' integrated autocorrelation time).

    Parameters
    ----------
    rss : float
        The residuals' sum of squares over the n samples.
    n : int
        The samples.
    k : int
        The fitted coefficients (offsets included).
    tau : float
        The integrated autocorrelation time [samples], at least 1.

    Returns
    -------
    float
    """
    n_eff = n / max(tau, 1.0)
    return aicc(rss * n_eff / n, n_eff, k)  # n_eff log(rss / n) + the correction on n_eff


__all__ = ["FORMS", "CHECKED", "form_of", "equation", "law_value", "candidates", "fit_through", "ranked", "effective_aicc"]
