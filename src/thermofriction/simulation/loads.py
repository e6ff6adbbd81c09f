"""The load a run is driven with (docs/models.md#laws-of-temperature-and-load): ``simulate(..., load=...)`` and the
real-time steps take a number, a waveform or (times, values), as the temperature; a model whose laws read the load
(a load term, models/load_laws.py) needs one, and is checked over the loads and temperatures the run reaches, as a
temperature-only model is over its temperatures (simulation/checks.py). A model without such a law ignores it.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError, PassivityWarning, TemperatureRangeWarning
from ..models import check_friction_values, dissipativity_violation
from ..models.load_laws import LoadRangeWarning, load_laws
from ..results import Finding
from ..waveforms import Sampled, Waveform

#: points per period (or over a step's transition) at which a periodic load's magnitude range is taken
_RANGE_POINTS = 513


def as_load(load, where: str = "load"):
    """A number, a waveform or a (times, values) pair -> a float or a Waveform (a pair as ``Sampled``).

    Parameters
    ----------
    load : float or Waveform or tuple of array_like or None
        The load [N or N m]; None passes.
    where : str, default "load"
        The argument's name, for the messages.

    Returns
    -------
    float or Waveform or None

    Raises
    ------
    InputError
        Not a number, a waveform or two arrays of one length; a value that is not finite.
    """
    if load is None or isinstance(load, Waveform):
        return load
    if isinstance(load, (tuple, list)) and len(load) == 2 and all(np.ndim(x) == 1 for x in load):
        try:
            return Sampled(np.asarray(load[0], float), np.asarray(load[1], float))
        except (TypeError, ValueError) as e:
            raise InputError(f"{where}: (times [s], values) must be two arrays of numbers ({e})") from None
    if isinstance(load, bool) or not isinstance(load, (int, float, np.integer, np.floating)):
        raise InputError(f"{where} must be a number [N or N m], a Waveform or (times, values), got {load!r}")
    if not math.isfinite(float(load)):
        raise InputError(f"{where} must be finite, got {load!r}")
    return float(load)


def load_magnitudes(load) -> tuple:
    """(lowest, highest) |load| a run reaches: the number's; a sampled load's samples; a periodic or step load on a
    fine grid of its first period (its transition) and its extremes.

    Parameters
    ----------
    load : float or Waveform
        The load [N or N m].

    Returns
    -------
    tuple of float
    """
    if not isinstance(load, Waveform):
        return abs(float(load)), abs(float(load))
    if isinstance(load, Sampled):
        a = np.abs(load.value)
    else:
        f = load.core_fields()
        span = 1.0 / f["frequency"] if f.get("frequency") else f.get("t0", 0.0) + f.get("slew", 0.0) + 1.0
        a = np.abs(load(np.linspace(0.0, span, _RANGE_POINTS)))
        if f.get("frequency"):  # the extremes between the grid's points
            a = np.concatenate([a, np.abs([f.get("offset", 0.0) + f.get("amplitude", 0.0)])])
    return float(a.min()), float(a.max())


def load_findings(model, temperatures, load) -> list:
    """What a run of a model with laws of the load at these temperatures and this load should say, as findings:
    a temperature or a load outside a law's calibrated range, a LuGre-type model that is not dissipative there;
    raises where the model is invalid at a corner of the (temperature, |load|) ranges (a law is linear in the
    load's magnitude s, so its domain rules hold in between where they hold at both ends).

    Parameters
    ----------
    model : Model
        A model holding laws of the load.
    temperatures : sequence of float
        The temperatures [C] of the run (the one; or its samples, whose range is checked on a grid of 65).
    load : float or Waveform or None
        The load.

    Returns
    -------
    list of Finding
        TemperatureRangeWarning, LoadRangeWarning and PassivityWarning findings.

    Raises
    ------
    InputError
        No load, naming the law; the model invalid at a corner, named with its temperature and load.
    """
    laws = load_laws(model)
    if load is None:
        name, law = next(iter(laws.items()))
        raise InputError(f"[thermal] {name}: a law of the load ({law.load.kind}, {law.load.combine} with the "
                         f"temperature law): give the run's load (load= a number [N or N m], a Waveform or "
                         f"(times, values))")
    lo, hi = load_magnitudes(load)
    Ts = np.unique(np.asarray(temperatures, float))
    if Ts.size > 2:  # a temperature signal: its range on a grid (as the core's check: model_check.c), not each sample
        Ts = np.unique(np.concatenate([[Ts[0], Ts[-1]], np.linspace(Ts[0], Ts[-1], 65)]))
    found = []
    outside_T = [f"'{n}' ({law.range[0]:g}..{law.range[1]:g} C)" for n, law in model.laws.items()
                 if not law.in_range(Ts)]
    if outside_T:
        span = f"{Ts[0]:g} C" if Ts.size == 1 else f"{Ts.min():g}..{Ts.max():g} C"
        found.append(Finding(TemperatureRangeWarning, f"temperature {span} is outside the calibrated range of the "
                                                      f"law(s) for {', '.join(outside_T)}"))
    outside = [f"'{n}' ({law.load.range[0]:.4g}..{law.load.range[1]:.4g})" for n, law in laws.items()
               if not law.load.in_range([lo, hi])]
    if outside:
        span = f"{lo:.4g}" if lo == hi else f"{lo:.4g}..{hi:.4g}"
        found.append(Finding(LoadRangeWarning, f"load {span} is outside the calibrated range of |load| of the law(s) "
                                               f"for {', '.join(outside)}: their values there are extrapolations"))
    for T in Ts:
        for L in sorted({lo, hi}):
            p = model.parameters_at(float(T), L)
            bad = [n for n, v in p.items() if v is not None and np.ndim(v) == 0 and not math.isfinite(float(v))]
            if bad:
                raise InputError(f"[thermal] {bad[0]}: the law gives {p[bad[0]]} at {T:g} C and load {L:.4g} (an "
                                 f"overflow): its coefficients are beyond what can be computed there")
            check_friction_values(p, f"Model I at {T:g} C and load {L:.4g}")
            violation = dissipativity_violation(model.friction.model, p)
            if violation and not any(f.category is PassivityWarning for f in found):
                found.append(Finding(PassivityWarning, f"{model.friction.model} at {T:g} C and load {L:.4g}: "
                                                       f"{violation[1]}"))
    return found


__all__ = ["as_load", "load_magnitudes", "load_findings"]
