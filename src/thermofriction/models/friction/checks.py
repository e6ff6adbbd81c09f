"""The physical checks on a friction model's values, from the one domain rule per parameter (models/domains.py), on
both sides of a direction-dependent model and on the ripple."""

from __future__ import annotations

import math

from ..._bridge import PARAMETER_UNITS, PARAMETERS
from ...errors import InputError, shorten
from ..domains import in_domain, own_domain, rule_of
from ..sides import NEGATIVE_SIDE, check_sides


def check_friction_values(values: dict, where: str):
    """Physical checks on a full set of parameter values (numbers and laws evaluated), on both
    sides of a direction-dependent model, and on the ripple.

    Parameters
    ----------
    values : dict
        Parameter name -> value, in the units of ``PARAMETER_UNITS``.
    where : str
        Where the values came from (a model file's section, ``"[friction]"``), for the messages.

    Returns
    -------
    None

    Raises
    ------
    InputError
        A value outside the physical domain (a stiffness that is not positive, fs < fc, vs <= 0 with a Stribeck
        effect, z_ba >= fc/sigma0, ...), named with ``where``.
    """
    _check_side(values, where, "")
    check_sides(values, where, _check_side)


def _finite(v) -> bool:
    return isinstance(v, (int, float)) and math.isfinite(v)


def _check_side(values: dict, where: str, side: str):
    # each value in its own domain first (finite first: a law that overflows, a exp(b T) with b = 100, gives inf,
    # which is "positive"), then the rules between parameters
    for name in PARAMETERS:
        v, domain = values.get(name), own_domain(name)
        if domain is not None and v is not None and not (_finite(v) and in_domain(name, v)):
            raise InputError(f"{where}: '{name}' must be {domain} and finite, got {shorten(v)}")
    related = [(name, *rule_of(name)) for name in PARAMETERS if name not in NEGATIVE_SIDE]
    for name, kind, arg in related:  # 0 <= z_ba < fc/sigma0
        a, b = arg.partition("/")[::2]
        v, top, bottom = values.get(name), values.get(a), values.get(b)
        if kind == "below" and v is not None and bottom and top and not v < top / bottom:
            raise InputError(f"{where}: '{name}' ({v!r} {PARAMETER_UNITS[name]}) must be below the steady deflection "
                             f"{arg} ({top / bottom:.6g} {PARAMETER_UNITS[name]}): the elasto-plastic model breaks "
                             f"away before it")
    for name, kind, _ in related:  # no domain of their own (fs relative to fc, below), but finite
        v = values.get(name)
        if kind in ("ge", "positive_if") and v is not None and not _finite(v):
            raise InputError(f"{where}: '{name}' must be a number and finite, got {shorten(v)}")
    for name, kind, arg in related:  # fs >= fc
        v, least = values.get(name), values.get(arg)
        if kind == "ge" and v is not None and least is not None and v < least:
            raise InputError(f"{where}: '{name}' ({v!r}) must be at least '{arg}' ({least!r}){side}")
    for name, kind, arg in related:  # vs > 0 where fs != fc (a Stribeck effect)
        a, b = arg.partition("!=")[::2]
        if kind == "positive_if" and values.get(a) is not None and values.get(b) is not None and \
                values[a] != values[b] and not (values.get(name) is not None and values[name] > 0):
            raise InputError(f"{where}: '{name}' must be positive when {arg.replace('!=', ' != ')} (the Stribeck "
                             f"velocity), got {values.get(name)!r}{side}")


__all__ = ["check_friction_values"]
