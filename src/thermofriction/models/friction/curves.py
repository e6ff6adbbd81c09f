"""The Stribeck curve (for checks and reports) and the dissipativity test of the LuGre-type models
(docs/models.md#friction-models)."""

from __future__ import annotations

import functools

import numpy as np

from ..sides import NEGATIVE_SIDE, side_values
from .registry import FRICTION_MODELS


def stribeck_curve(values: dict, v):
    """g(v) = fc + (fs - fc) exp(-|v/vs|^delta) (fs = fc: no Stribeck effect), NumPy, for checks and reports.

    Parameters
    ----------
    values : dict
        ``fc`` [N], and ``fs`` [N], ``vs`` [m/s], ``delta`` [-] where there is a Stribeck effect.
    v : float or array_like
        The sliding velocity [m/s].

    Returns
    -------
    numpy.ndarray
        g(v) [N], the shape of ``v``.

    Raises
    ------
    KeyError
        ``values`` without ``fc``, or without ``vs`` where fs differs from fc (the values are not checked here:
        ``check_friction_values`` does that).
    """
    fc = values["fc"]
    fs = values.get("fs", fc)
    fs = fc if fs is None else fs
    if fs == fc:
        return np.full_like(np.asarray(v, float), fc)
    return fc + (fs - fc) * np.exp(-np.abs(np.asarray(v, float) / values["vs"]) ** values.get("delta", 2.0))


def dissipativity_violation(model_name: str, values: dict):
    """Where a LuGre-type model (LuGre, elasto-plastic) may create energy, or None.

    Sufficient condition checked: with the bristle energy V = sigma0 z^2 / 2 as storage function,
    F v - V' = sigma0 a z^2 - sigma1(v) a v z + (sigma1(v) + sigma2) v^2 (a = sigma0 |v| / g(v))
    must be >= 0 for every |z| <= fs/sigma0 (the invariant set of z) at every velocity. It fails
    when sigma1 is large against sigma2 and the Stribeck drop (fs - fc)/fc -- at high speed it
    needs sigma1 <= sigma2 fc / (fs - fc) -- which is why a constant, large sigma1 makes LuGre
    non-passive (Barabanov and Ortega 2000) and a velocity-dependent sigma1(v) = sigma1
    exp(-(v/vd)^2) (Olsson 1996) restores it. (For the elasto-plastic model, alpha <= 1 only
    lowers the relaxation term, so the LuGre condition is checked as the stricter one.)

    Parameters
    ----------
    model_name : str
        The friction model's name (those whose description says ``dissipativity``: ``"lugre"``,
        ``"elastoplastic"``; any other has no such test: None).
    values : dict
        Parameter name -> value (numbers, laws evaluated), in the units of ``PARAMETER_UNITS``; each side of a
        direction-dependent model is tested on its own.

    Returns
    -------
    tuple or None
        (velocity [m/s], message) for the lowest failing speed on a log grid from 1 nm/s to 100 m/s; None
        where the condition holds.

    Raises
    ------
    KeyError
        ``values`` without a parameter the model requires (the values are not checked here).
    """
    kind = FRICTION_MODELS.get(model_name)
    if kind is None or not kind.description.dissipativity:
        return None
    if any(values.get(n) is not None for n in NEGATIVE_SIDE):  # each side on its own, the positive first
        return dissipativity_violation(model_name, {k: v for k, v in values.items() if k not in NEGATIVE_SIDE}) or \
            dissipativity_violation(model_name, {k: v for k, v in side_values(values).items()
                                                 if k not in NEGATIVE_SIDE})
    # extreme but finite values (sigma0 = 1e300) overflow the products below; the condition is
    # then decided by the terms that remain finite, and NumPy's warnings are not the user's business
    # the same values come back for every run of a model (simulate checks before each): decide once
    key = tuple(sorted((k, float(v)) for k, v in values.items() if isinstance(v, (int, float, np.floating))))
    return _dissipativity_violation_of(key)


@functools.lru_cache(maxsize=512)
def _dissipativity_violation_of(items: tuple):
    with np.errstate(over="ignore", invalid="ignore", under="ignore", divide="ignore"):
        return _dissipativity_violation(dict(items))


def _dissipativity_violation(values: dict):
    s0, s1, s2, fc = values["sigma0"], values["sigma1"], values.get("sigma2", 0.0) or 0.0, values["fc"]
    fs = values.get("fs") if values.get("fs") is not None else fc
    v = np.logspace(-9, 2, 1101)
    g = stribeck_curve(values, v)
    vd = values.get("vd")
    s1v = s1 * np.exp(-(v / vd) ** 2) if vd else np.full_like(v, s1)
    zmax = fs / s0
    a = s0 * v / g
    z_star = np.minimum(s1v * v / (2 * s0), zmax)  # the minimiser of the quadratic in z, within the set
    q = s0 * a * z_star ** 2 - s1v * a * v * z_star + (s1v + s2) * v ** 2
    bad = q < -1e-12 * (s1v + s2 + 1e-300) * v ** 2
    if not np.any(bad):
        return None
    v_bad = float(v[np.argmax(bad)])
    return v_bad, (f"not dissipative above |v| = {v_bad:.3g} m/s (condition: F v >= d/dt(sigma0 z^2/2) for "
                   f"|z| <= fs/sigma0; at high speed sigma1 <= sigma2 fc/(fs - fc) = "
                   f"{(s2 * fc / (fs - fc)) if fs > fc else float('inf'):.3g} N s/m, sigma1 = {s1:.3g}): the model "
                   f"can create energy; give vd (sigma1(v) = sigma1 exp(-(v/vd)^2)), or raise sigma2")


__all__ = ["stribeck_curve", "dissipativity_violation"]
