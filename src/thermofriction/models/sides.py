"""Direction-dependent friction levels and the position ripple (docs/models.md#direction-and-position):
the names, the model file's ripple table, the values that act in negative sliding, and their checks. Every
friction model of models/friction/ takes them; the sides and static levels are the domain rules' (models/domains.py)."""

from __future__ import annotations

import math

from ..errors import InputError, shorten
from ._parse import num, num_array
from .domains import NEGATIVE_SIDE, STATIC_LEVELS, own_domain

#: The ripple's harmonics (friction.h, TF_RIPPLE_ORDER) and its amplitudes' names, in N or N m.
RIPPLE_ORDER = 3
RIPPLE_AMPLITUDES = tuple(f"ripple_{f}{k}" for k in range(1, RIPPLE_ORDER + 1) for f in ("cos", "sin"))
#: Parameters that may take either sign (fitted as they are, not in log space).
SIGNED = frozenset(RIPPLE_AMPLITUDES)


def ripple_keys(table, where="[friction]") -> dict:
    """``ripple = { period = P, cos = [a1, ...], sin = [b1, ...] }`` as the flat parameters
    ``ripple_period``, ``ripple_cos1`` ... (up to RIPPLE_ORDER harmonics)."""
    if not isinstance(table, dict):
        raise InputError(f"{where}: 'ripple' must be a table {{ period = ..., cos = [...], sin = [...] }}, "
                         f"got {shorten(table)}")
    unknown = set(table) - {"period", "cos", "sin"}
    if unknown:
        raise InputError(f"{where}: 'ripple' has unknown keys {sorted(unknown)} (period, cos, sin)")
    if "period" not in table:
        raise InputError(f"{where}: 'ripple' needs its 'period' (one revolution, a screw pitch, ... in m or rad)")
    out = {"ripple_period": num(table["period"], where, "ripple.period")}
    if not out["ripple_period"] > 0:
        raise InputError(f"{where}: 'ripple.period' must be positive (one revolution, a screw pitch, ... in m or rad), "
                         f"got {out['ripple_period']!r}")
    for f in ("cos", "sin"):
        if f not in table:  # absent: no amplitudes of that kind (each 0), as docs/models.md says
            continue
        amps = list(num_array(table[f], where, f"ripple.{f}"))
        if len(amps) > RIPPLE_ORDER:
            raise InputError(f"{where}: 'ripple.{f}' has {len(amps)} amplitudes; at most {RIPPLE_ORDER} harmonics")
        out.update({f"ripple_{f}{k + 1}": float(a) for k, a in enumerate(amps)})
    return out


def with_ripple_table(d: dict, where="[friction]") -> dict:
    """A [friction] section with its ``ripple`` table (if any) as the flat keys; a key given both ways is refused
    (the table would silently replace the flat value)."""
    if "ripple" not in d:
        return d
    d = dict(d)
    flat = ripple_keys(d.pop("ripple"), where)
    both = sorted(set(flat) & set(d))
    if both:
        raise InputError(f"{where}: '{both[0]}' is given both as a key and in the 'ripple' table; give it once")
    return {**d, **flat}


def needs_period(names, values: dict, where: str):
    """Ripple amplitudes (among ``names``: given or to be fitted) need the ripple's period, which is given, not
    fitted: InputError naming ``where`` (the model) where it has none."""
    amps = [n for n in names if n in RIPPLE_AMPLITUDES]
    if amps and values.get("ripple_period") is None:
        raise InputError(f"{where}: ripple amplitudes ({', '.join(amps)}) need the ripple's period in the model "
                         f"([friction] ripple = {{ period = ..., cos = [...], sin = [...] }}: one revolution, a screw "
                         f"pitch, ... in m or rad)")


def side_values(values: dict) -> dict:
    """The parameter values that act in negative sliding: each given ``*_neg`` in its positive
    slot (fs_neg absent: fs, or fc_neg where fs = fc)."""
    out = dict(values)
    (level, coulomb), (level_neg, coulomb_neg) = STATIC_LEVELS
    no_stribeck = values.get(level) is None or values.get(level) == values.get(coulomb)
    for neg, pos in NEGATIVE_SIDE.items():
        if values.get(neg) is not None:
            out[pos] = values[neg]
    if values.get(level_neg) is None and values.get(coulomb_neg) is not None and no_stribeck:
        out[level] = out[coulomb]
    return out


def check_sides(values: dict, where: str, check_side):
    """The negative side's values checked as the positive ones are (``check_side(values, where, note)``), fs_neg
    against fc_neg, and the ripple: finite amplitudes, none without a period."""
    if any(values.get(n) is not None for n in NEGATIVE_SIDE):
        for name in (*(n for n in NEGATIVE_SIDE if own_domain(n) is None), *RIPPLE_AMPLITUDES):
            v = values.get(name)
            if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise InputError(f"{where}: '{name}' must be a number and finite, got {shorten(v)}")
        neg = side_values(values)
        (level, coulomb), (level_neg, coulomb_neg) = STATIC_LEVELS
        if neg.get(level) is not None and neg.get(coulomb) is not None and neg[level] < neg[coulomb]:
            raise InputError(f"{where}: the negative side's static level {level_neg} ({neg[level]!r}; {level} where not "
                             f"given) must be at least its Coulomb level {coulomb_neg} ({neg[coulomb]!r})")
        check_side(neg, where, f" (negative side: {', '.join(NEGATIVE_SIDE)})")
    amps = [n for n in RIPPLE_AMPLITUDES if values.get(n) is not None]
    for name in amps:
        if not (isinstance(values[name], (int, float)) and math.isfinite(values[name])):
            raise InputError(f"{where}: '{name}' must be a number and finite, got {shorten(values[name])}")
    needs_period(amps, values, where)
