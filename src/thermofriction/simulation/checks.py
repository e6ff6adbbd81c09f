"""Checks before (and, with self-heating, after) a run: the temperature against the laws'
ranges and the model's physical domain, dissipativity, and prescribed motion's continuity.
Findings (results.Finding: values) for what may be wrong, which ``simulate`` turns into warnings as it returns;
InputError for what is. The ``check_*`` functions emit the findings of their ``*_findings`` counterparts."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ConditioningWarning, InputError, PassivityWarning, SolverError, TemperatureRangeWarning
from ..models import Model, ModelI, ModelII, check_friction_values, dissipativity_violation
from ..plausible import check_temperature
from ..results import Finding, emit
from ..models.load_laws import load_laws
from ..waveforms import Sampled, Sawtooth, Step, Waveform, Zero
from .loads import load_findings


def as_temperature(temperature):
    """A number, a ``Sampled`` signal, or a (times, values) pair -> number or Sampled; a temperature
    that is not plausible in degC (e.g. one in kelvin) is refused, as in data files.

    Parameters
    ----------
    temperature : float or Sampled or tuple of array_like or None
        A temperature [C], a temperature signal, or (times [s], values [C]); None passes.

    Returns
    -------
    float or Sampled or None

    Raises
    ------
    InputError
        Not a number or a signal, not finite, or not plausible in C (a temperature in kelvin), named.
    """
    if temperature is None:
        return temperature
    if isinstance(temperature, Sampled):
        check_temperature(temperature.value, "temperature signal")
        return temperature
    if isinstance(temperature, (tuple, list)) and len(temperature) == 2:
        T = Sampled(np.asarray(temperature[0], float), np.asarray(temperature[1], float))
        check_temperature(T.value, "temperature signal")
        return T
    try:
        T = float(temperature)
    except (TypeError, ValueError):
        raise InputError(f"temperature must be a number [degC] or (times, values), got {temperature!r}") from None
    if not math.isfinite(T):
        raise InputError(f"temperature must be finite, got {temperature!r}")
    check_temperature(T, "temperature")
    return T


def check_prescribed_motion(waveform: Waveform):
    """Prescribed motion needs a continuous displacement: its slope is the sliding velocity.

    Parameters
    ----------
    waveform : Waveform
        The prescribed displacement x_r(t) [m] (an angle [rad] for a rotary joint).

    Returns
    -------
    None

    Raises
    ------
    InputError
        No waveform, an ideal step (no slew time), or a sawtooth with rise 0 or 1: a jump.
    """
    if isinstance(waveform, Zero):
        raise InputError("prescribed motion needs an input waveform, the displacement x_r(t) in metres "
                         "(e.g. --input sine:amplitude=1e-6,frequency=1)")
    if isinstance(waveform, Step) and waveform.slew <= 0:
        raise InputError("prescribed motion: an ideal step has no finite velocity; give the step a slew time")
    if isinstance(waveform, Sawtooth) and waveform.rise in (0.0, 1.0):
        raise InputError("prescribed motion: a sawtooth with rise 0 or 1 jumps; use 0 < rise < 1")


def passivity_findings(model: Model, temperatures=(math.nan,)) -> list:
    """A PassivityWarning finding where a LuGre-type model can create energy at these temperatures
    (``dissipativity_violation``): at the first such temperature, else none.

    Parameters
    ----------
    model : Model
        The model.
    temperatures : sequence of float, default (nan,)
        The temperatures [C] tested (a model without laws: any value).

    Returns
    -------
    list of Finding
        At most one.

    Raises
    ------
    KeyError
        A friction model without a parameter the test requires (the model is not checked here).
    """
    for T in temperatures:
        found = dissipativity_violation(model.friction.model, model.parameters_at(T))
        if found:
            where = f" at {T:g} C" if isinstance(model.thermal, ModelI) else ""
            return [Finding(PassivityWarning, f"{model.friction.model}{where}: {found[1]}")]
    return []


def check_passivity(model: Model, temperatures=(math.nan,)):
    """Warns (PassivityWarning) when a LuGre-type model can create energy at these temperatures
    (:func:`passivity_findings`).

    Parameters
    ----------
    model : Model
        The model.
    temperatures : sequence of float, default (nan,)
        The temperatures [C] tested (a model without laws: any value).

    Returns
    -------
    None

    Raises
    ------
    KeyError
        A friction model without a parameter the test requires (the model is not checked here).

    Warns
    -----
    PassivityWarning
        At the first temperature where the model may create energy.
    """
    emit(passivity_findings(model, temperatures))


def coverage_findings(temperature, t0: float, t1: float) -> list:
    """A finding when a temperature signal does not cover the run [t0, t1]: beyond its ends it is
    held constant, which is rarely what a file starting at t = 5 s for a 0-0.1 s run meant."""
    if not isinstance(temperature, Sampled):
        return []
    a, b = float(temperature.time[0]), float(temperature.time[-1])
    tol = 1e-9 * max(1.0, abs(t0), abs(t1))
    if a > t0 + tol or b < t1 - tol:
        where = f" ({temperature.file})" if temperature.file else ""
        return [Finding(TemperatureRangeWarning, f"the temperature signal{where} covers {a:g}..{b:g} s, the run "
                        f"{t0:g}..{t1:g} s: outside it the temperature is held at its first or last value")]
    return []


def check_temperature_coverage(temperature, t0: float, t1: float):
    """Warns (TemperatureRangeWarning) when a temperature signal does not cover the run [t0, t1]
    (:func:`coverage_findings`)."""
    emit(coverage_findings(temperature, t0, t1), stacklevel=3)


#: a model (frozen) keeps the findings of each constant temperature it was checked at, in its instance's own
#: dictionary (not a field: not compared, not copied by dataclasses.replace, gone with the model): a model run
#: again and again at one temperature (identification, sweeps, a benchmark) is checked once. Findings are values,
#: so a temperature with findings is cached as well as one without
_MEMO = "_thermofriction_findings"


def temperature_findings(model: Model, temperature) -> list:
    """What a run at ``temperature`` should say, as findings: temperatures outside a law's calibrated range, a
    LuGre-type model that is not dissipative there, Model II's offset form anti-damped; raises where the model is
    invalid there (Model II's lambda <= 0, a Model I parameter out of its physical domain). A constant
    temperature's are computed once per model.

    Parameters
    ----------
    model : Model
        The model.
    temperature : float or Sampled or None
        The temperature [C], or a temperature signal (its range is tested).

    Returns
    -------
    list of Finding
        TemperatureRangeWarning, PassivityWarning and ConditioningWarning findings, in that order.

    Raises
    ------
    InputError
        The model is invalid at the temperature, named with the parameter and the temperature.
    """
    memo = None if isinstance(temperature, Sampled) else model.__dict__.setdefault(_MEMO, {})
    if memo is not None and temperature in memo:
        return list(memo[temperature])
    found = []
    _check_temperatures(model, temperature, found)
    if memo is not None:
        memo[temperature] = tuple(found)
    return found


def check_temperatures(model: Model, temperature):
    """Warns for temperatures outside a law's calibrated range; raises where the model is
    invalid there (Model II's lambda <= 0, a Model I parameter out of its physical domain).
    Warns where a LuGre-type model is not dissipative (:func:`temperature_findings`, emitted).

    Parameters
    ----------
    model : Model
        The model.
    temperature : float or Sampled or None
        The temperature [C], or a temperature signal (its range is tested).

    Returns
    -------
    None

    Raises
    ------
    InputError
        The model is invalid at the temperature, named with the parameter and the temperature.

    Warns
    -----
    TemperatureRangeWarning
        A temperature outside a law's calibrated range.
    PassivityWarning
        A LuGre-type model that may create energy there.
    """
    emit(temperature_findings(model, temperature), stacklevel=3)  # (the caller's caller: simulate's, as before)


def _check_temperatures(model: Model, temperature, found: list):
    if model.thermal is None:
        found += passivity_findings(model)
        return
    if temperature is None:
        raise InputError("the model depends on temperature: give a temperature (e.g. --temperature 35)")
    if isinstance(temperature, Sampled):
        lo, hi = float(temperature.value.min()), float(temperature.value.max())
        Ts = np.unique(np.concatenate([temperature.value, np.linspace(lo, hi, 201)]))
    else:
        Ts = np.array([float(temperature)])
    laws = dict(model.laws)
    if isinstance(model.thermal, ModelII):
        laws["dF"] = model.thermal.dF
    for name, law in laws.items():  # an overflow (a exp(b T) with b = 100) is named as one
        vals = np.atleast_1d(law(Ts))
        if not np.all(np.isfinite(vals)):
            T_bad = Ts[np.argmax(~np.isfinite(vals))]
            raise InputError(f"[thermal] {name}: the '{law.kind}' law gives {vals[~np.isfinite(vals)][0]} at "
                             f"{T_bad:g} C (an overflow): its coefficients are beyond what can be computed there")
    outside = [f"'{name}' ({law.range[0]:g}..{law.range[1]:g} C)" for name, law in laws.items()
               if not law.in_range(Ts)]
    if outside:
        span = f"{Ts[0]:g} C" if len(Ts) == 1 else f"{Ts.min():g}..{Ts.max():g} C"
        found.append(Finding(TemperatureRangeWarning, f"temperature {span} is outside the calibrated range of the "
                                                      f"law(s) for {', '.join(outside)}"))
    if isinstance(model.thermal, ModelI):
        for T in (Ts.min(), Ts.max()) if len(Ts) > 1 else Ts:
            check_friction_values(model.parameters_at(T), f"Model I at {T:g} C")
        if len(Ts) > 2:
            for name, law in model.laws.items():
                vals = law(Ts)
                if name in ("sigma0", "fc") and np.any(vals <= 0):
                    T_bad = Ts[np.argmax(vals <= 0)]
                    raise InputError(f"Model I: '{name}' is not positive at {T_bad:g} C ({law(T_bad):g})")
    found += passivity_findings(model, (Ts.min(), Ts.max()) if isinstance(model.thermal, ModelI) else (math.nan,))
    if isinstance(model.thermal, ModelII) and model.thermal.form == "scale":
        lam = np.atleast_1d(model.thermal_factor(Ts))
        if np.any(lam <= 0):
            i = int(np.argmin(lam))
            raise InputError(f"Model II: lambda(T) = 1 + dF(T)/F_ref is {lam[i]:.4g} <= 0 at {Ts[i]:g} C "
                             f"(dF = {model.thermal.dF(Ts[i]):.4g} N, F_ref = fc = {model.reference_force():.4g} N): "
                             f"the thermal term would reverse friction")
    if isinstance(model.thermal, ModelII) and model.thermal.form == "offset":
        # dF(T) tanh(v / v_smooth) with dF < 0 is a negative damping dF/v_smooth near v = 0; stronger
        # than the bristles' own damping it makes the sticking state repelling (found by the
        # differential tests: the explicit solver needs rtol <= 1e-7 there, an L-stable one
        # finds another solution).
        dF = np.atleast_1d(model.thermal.dF(Ts))
        i = int(np.argmin(dF))
        p = model.parameters_at(Ts[i])
        # the base model's own damping at v = 0: bristle and viscous damping (models without
        # sigma1 have none), and for a static map the slope of its smoothed sign, fs / v_smooth
        damping = p.get("sigma1", 0.0) + p.get("sigma2", 0.0)
        what = "sigma1 + sigma2"
        if model.friction.description.smoothed_sign:
            damping += p["fs"] / p["v_smooth"]
            what = "sigma2 + fs/v_smooth"
        if dF[i] < 0 and -dF[i] / p["v_smooth"] > damping:
            found.append(Finding(ConditioningWarning, f"Model II offset form: dF = {dF[i]:.4g} N at {Ts[i]:g} C is "
                                 f"anti-damped near v = 0 (dF/v_smooth = {dF[i] / p['v_smooth']:.3g} N s/m against "
                                 f"{what} = {damping:.3g} N s/m); the solution is ill-conditioned: use Dopri5 with "
                                 f"rtol <= 1e-8, or the scale form"))


def heated_findings(model: Model, time, temperature, load=None) -> list:
    """With self-heating the temperature range is known only after the run: findings where it left a
    law's calibrated range; refuses a run that crossed a temperature where the model is invalid.

    Parameters
    ----------
    model : Model
        The model simulated.
    time : numpy.ndarray
        The run's output times [s].
    temperature : numpy.ndarray
        The run's temperature [C] at those times.
    load : float or Waveform, optional
        The run's load, for a model with a law of the load (simulation/loads.py: load_findings).

    Returns
    -------
    list of Finding
        As :func:`temperature_findings` (``load_findings``) over the range the run visited.

    Raises
    ------
    SolverError
        The temperature reached values where the model is invalid (Model II's factor <= 0, a Model I
        parameter out of its physical domain).
    """
    lo, hi = float(np.min(temperature)), float(np.max(temperature))
    try:
        if load_laws(model):
            return load_findings(model, [lo, hi], load)
        return temperature_findings(model, Sampled(np.array([0.0, 1.0]), np.array([lo, hi])) if hi > lo else lo)
    except InputError as e:
        raise SolverError(f"self-heating took the temperature to {lo:.4g}..{hi:.4g} C, where the model is "
                          f"invalid: {e}") from None


def check_heated_temperatures(model: Model, time, temperature):
    """With self-heating the temperature range is known only after the run: warn where it left a
    law's calibrated range, refuse a run that crossed a temperature where the model is invalid
    (:func:`heated_findings`, emitted).

    Parameters
    ----------
    model : Model
        The model simulated.
    time : numpy.ndarray
        The run's output times [s].
    temperature : numpy.ndarray
        The run's temperature [C] at those times.

    Returns
    -------
    None

    Raises
    ------
    SolverError
        The temperature reached values where the model is invalid (Model II's factor <= 0, a Model I
        parameter out of its physical domain).

    Warns
    -----
    TemperatureRangeWarning
        The temperature left a law's calibrated range.
    """
    emit(heated_findings(model, time, temperature))


__all__ = ["as_temperature", "check_temperature_coverage", "check_prescribed_motion", "check_passivity", "check_temperatures",
           "check_heated_temperatures", "temperature_findings", "passivity_findings", "coverage_findings",
           "heated_findings"]
