"""One display of a fitted parameter's standard error and interval, for every table that shows one: the CLI's fit
report and notebook table (identification/result.py), the HTML report's parameter rows (reporting/entries.py,
reporting/force.py) and the docs (docs/identification.md#parameters-at-a-bound-or-undetermined).

A parameter at a bound shows "at lower bound" (or upper) and its one-sided interval only where that is finite and
within REL_SHOWN; a standard error that is infinite (the data do not determine it) shows "not determined"; one above
REL_SHOWN of the value shows "> 1000 %"; in those cases the interval is "—": the linearized interval then says
nothing a reader can use (it spanned 1e-317 to 1e291)."""

from __future__ import annotations

import math

#: the relative standard error above which neither the percentage nor the interval is shown (10 = 1000 %)
REL_SHOWN = 10.0
NONE = "—"


def _float(x):
    """A number from the results JSON ("inf", "-inf", "nan" strings included); None for None or anything else."""
    if isinstance(x, bool) or x is None:
        return None
    try:
        return float(x)
    except (TypeError, ValueError):
        return None


def shown(p: dict) -> tuple:
    """(value, standard error, relative error, 95 % interval) as text, for a parameter as the results JSON holds
    it (``value``, ``stderr``, ``ci95``, ``vary``, ``at_bound``; Parameter.to_dict())."""
    value, se = _float(p.get("value")), _float(p.get("stderr"))
    ci = p.get("ci95") or (None, None)
    lo, hi = _float(ci[0]), _float(ci[1])
    v = NONE if value is None or not math.isfinite(value) else f"{value:.6g}"
    if not p.get("vary", True):
        return v, "", "fixed", ""
    if se is None:
        return v, "", "", ""
    rel = se / abs(value) if value and math.isfinite(se) else (math.inf if value else math.nan)
    readable = math.isfinite(se) and not rel > REL_SHOWN
    side = p.get("at_bound")
    if side:
        far = hi if side == "lower" else lo
        one = (f"{'<=' if side == 'lower' else '>='} {far:.5g} (one-sided)"
               if readable and far is not None and math.isfinite(far) else NONE)
        return v, NONE, f"at {side} bound", one
    if not math.isfinite(se):
        return v, NONE, "not determined", NONE
    if rel > REL_SHOWN:
        return v, f"{se:.4g}", f"> {100 * REL_SHOWN:.0f} %", NONE
    pct = f"{100 * rel:.2g} %" if math.isfinite(rel) else ""
    interval = NONE if lo is None or hi is None else f"[{lo:.5g}, {hi:.5g}]"
    return v, f"{se:.4g}", pct, interval


def cells(p: dict) -> tuple:
    """(value, standard error, 95 % interval) for a table without a relative-error column (the HTML report's): a
    word in place of the percentage (at a bound, not determined, > 1000 %, fixed) goes with the standard error."""
    v, se, rel, ci = shown(p)
    note = rel if rel and not rel[0].isdigit() else ""
    err = note if note and se in ("", NONE) else (f"{se} ({note})" if note else se)
    return v, err, ci


__all__ = ["shown", "cells", "REL_SHOWN"]
