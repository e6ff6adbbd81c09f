"""One domain rule per friction parameter (docs/models.md#friction-models): where a value is physical, written once
as data that the checks, the laws' ranges, identification and a test against the core's own table all read.

A rule is a code of a small fixed vocabulary (``RULES``), ``kind`` or ``kind:argument``:

- ``positive``: a finite number > 0;
- ``nonnegative``: a finite number >= 0;
- ``finite``: any finite number (either sign);
- ``ge:P``: a finite number at least parameter P's value (a static level over its Coulomb level);
- ``positive_if:A!=B``: a finite number, positive where A and B differ (the Stribeck velocity, where fs != fc);
- ``below:A/B``: a finite number >= 0 and below A/B (the elasto-plastic breakaway deflection, below fc/sigma0).
"""

from __future__ import annotations

import numpy as np

from .._bridge import PARAMETERS

#: The vocabulary of the rules: kind -> what it asks of a value.
RULES = {"positive": "a finite number > 0", "nonnegative": "a finite number >= 0", "finite": "any finite number",
         "ge": "a finite number >= another parameter's value", "positive_if": "a finite number, > 0 where two "
         "parameters differ", "below": "a finite number >= 0 and below a ratio of two parameters"}

#: Each friction parameter's rule, in the core's order (friction.h, TF_PARAMETERS).
PARAMETER_DOMAIN = {
    "sigma0": "positive", "sigma1": "nonnegative", "sigma2": "nonnegative", "fc": "positive", "fs": "ge:fc",
    "vs": "positive_if:fs!=fc", "delta": "positive", "vd": "positive", "v_smooth": "positive",
    "z_ba": "below:fc/sigma0", "C": "positive", "fc_neg": "positive", "fs_neg": "ge:fc_neg", "vs_neg": "positive",
    "sigma2_neg": "nonnegative", "ripple_period": "positive", "ripple_cos1": "finite", "ripple_sin1": "finite",
    "ripple_cos2": "finite", "ripple_sin2": "finite", "ripple_cos3": "finite", "ripple_sin3": "finite",
}
if set(PARAMETER_DOMAIN) != set(PARAMETERS) or any(r.partition(":")[0] not in RULES
                                                   for r in PARAMETER_DOMAIN.values()):  # pragma: no cover
    raise ImportError(f"every friction parameter needs one rule of {list(RULES)}: "
                      f"{sorted(set(PARAMETERS) ^ set(PARAMETER_DOMAIN))}")


def rule_of(name: str) -> tuple[str, str]:
    """(kind, argument) of parameter ``name``'s rule; ("finite", "") for a name that has none."""
    kind, _, arg = PARAMETER_DOMAIN.get(name, "finite").partition(":")
    return kind, arg


#: A value's own domain, without the other parameters (the words of the messages): None is "finite".
_OWN = {"positive": "positive", "nonnegative": "non-negative", "below": "non-negative"}


def own_domain(name: str) -> str | None:
    """The words of parameter ``name``'s own domain (``"positive"``, ``"non-negative"``), None where it is any
    finite number (a relation to other parameters aside)."""
    return _OWN.get(rule_of(name)[0])


def in_domain(name: str, values) -> np.ndarray:
    """Whether each value of parameter ``name`` is in its own physical domain (finite, where it has none).

    Parameters
    ----------
    name : str
        A friction parameter (``PARAMETER_DOMAIN``); another name is only asked to be finite.
    values : float or array_like
        The values.

    Returns
    -------
    numpy.ndarray
        Booleans, the shape of ``values``.

    Raises
    ------
    ValueError
        ``values`` that are not numbers.
    """
    values = np.asarray(values, float)
    domain = own_domain(name)
    if domain == "positive":
        return np.isfinite(values) & (values > 0)
    if domain == "non-negative":
        return np.isfinite(values) & (values >= 0)
    return np.isfinite(values)


#: The negative side's parameters (docs/models.md#direction-and-position), each with its positive one: the core's
#: ``*_neg`` parameters.
NEGATIVE_SIDE = {name: name.removesuffix("_neg") for name in PARAMETERS if name.endswith("_neg")}
#: Each side's static level and the Coulomb level it must not fall below (fs >= fc, fs_neg >= fc_neg): the
#: ``ge`` rules.
STATIC_LEVELS = tuple((name, rule_of(name)[1]) for name in PARAMETERS if rule_of(name)[0] == "ge")

__all__ = ["PARAMETER_DOMAIN", "RULES", "rule_of", "own_domain", "in_domain", "NEGATIVE_SIDE", "STATIC_LEVELS"]
