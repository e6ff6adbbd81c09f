"""Fit parameters as objects (value, bounds, ``vary``, and after a fit ``stderr`` and ``ci95``),
and their mapping onto a model: a friction parameter given as a number (``sigma0``), a
coefficient of a Model I law (``sigma0.a``, ``fc.values[2]``) or of Model II's ``dF`` (``dF.values[1]``),
or the temperature of one of dF's inner breakpoints (``dF.T[1]``)."""

from __future__ import annotations

import dataclasses
import math
import re


from .. import _bridge
from ..errors import InputError
from ..models import PARAMETER_UNITS, PARAMETERS, Model, ModelI, ModelII
from ..models.sides import NEGATIVE_SIDE, RIPPLE_AMPLITUDES, SIGNED, side_values

TARGET_PARAM, TARGET_LAW, TARGET_DF, TARGET_HEAT, TARGET_PLANT = (
    _bridge.TARGET_CODES[k] for k in ("param", "law", "dF", "heat", "plant"))
#: Not a C core target: a breakpoint temperature of a piecewise-linear dF. Its sensitivity is the chain
#: rule on the knot values' sensitivities (fitting/problem.py), exact on constant-temperature runs.
KNOT = -1
#: Not a parameter of the model: the Stribeck excess fs - fc, fitted in place of fs (in log space, so that fs >= fc
#: holds by construction, never as a refused step); setting it sets fs = fc + excess.
EXCESS = "fs_excess"
#: The plant's fittable parameters by their model-file symbols, with units: one value shared by all
#: experiments (the masses above all, which the paper does not give).
PLANT_UNITS = {"m": "kg", "m_e": "kg", "xi": "", "wn": "rad/s", "K": "m/V", "c": "N s/m", "k": "N/m", "T_em": "N/V",
               "k_s": "N/m"}
#: The lumped thermal model's fittable parameters (docs/models.md#self-heating): symbol -> (Heat
#: field, unit, the C core's index)
HEAT_PARAMETERS = {sym: (field, unit, _bridge.HEAT_PARAMETER_INDEX[sym]) for sym, field, unit in (
    ("C_th", "heat_capacity", "J/K"), ("R_th", "thermal_resistance", "K/W"), ("eta", "heat_fraction", ""),
    ("T_0", "initial_temperature", "C"))}


@dataclasses.dataclass
class Parameter:
    """One parameter of a fit, like lmfit's: its value, bounds, and after the fit its standard error and interval.

    Parameters
    ----------
    name : str
        The parameter's name: a friction parameter (``sigma0``), a law coefficient (``sigma0.b``), a plant's
        (``m_e``), a heat model's (``C_th``) or Model II's (``dF.values[1]``).
    value : float
        The value, in ``unit``.
    min, max : float, default -inf, inf
        The bounds; a lower bound >= 0 fits the parameter in log space.
    vary : bool, default True
        Fitted (True) or held (False).
    unit : str, default ""
        The value's SI unit.
    stderr : float, optional
        The standard error after the fit, in ``unit``; None where not computed.
    ci95 : tuple of float, optional
        The 95 % interval (low, high) after the fit, in ``unit``.
    init_value : float, optional
        The starting value.
    at_bound : {"lower", "upper"}, optional
        Where the fit ended at a bound (its own, or the fit's e^+-30 around the start): the interval is then
        one-sided, from the bound.
    """

    name: str
    value: float
    min: float = -math.inf
    max: float = math.inf
    vary: bool = True
    unit: str = ""
    stderr: float | None = None
    ci95: tuple | None = None
    init_value: float | None = None
    #: "lower" or "upper" where the fit ended at a bound (its own, or the fit's e^+-30 around the start): the
    #: interval is then one-sided, from the bound
    at_bound: str | None = None

    @property
    def positive(self) -> bool:
        """Fitted in log space (so it stays positive) when its lower bound is >= 0."""
        return self.min >= 0 and self.value > 0

    def to_dict(self):
        def f(x):
            return None if x is None else (float(x) if math.isfinite(x) else ("inf" if x > 0 else "-inf"))
        ci = None if self.ci95 is None else [f(self.ci95[0]), f(self.ci95[1])]
        out = {"value": f(self.value), "stderr": f(self.stderr), "ci95": ci, "unit": self.unit, "vary": self.vary}
        if self.at_bound:
            out["at_bound"] = self.at_bound
        return out

    def __repr__(self):
        err = "" if self.stderr is None else f" +/- {self.stderr:.3g}"
        fixed = "" if self.vary else " (fixed)"
        return f"<Parameter {self.name!r} = {self.value:.6g}{err} {self.unit}{fixed}>"


class Parameters(dict):
    """An ordered set of :class:`Parameter`, like lmfit's."""

    def add(self, name, value, *, min=-math.inf, max=math.inf, vary=True, unit=""):
        if not (min <= value <= max):
            raise InputError(f"initial value of '{name}' ({value!r}) is outside its bounds [{min!r}, {max!r}]")
        self[name] = Parameter(name, float(value), float(min), float(max), bool(vary), unit, init_value=float(value))
        return self[name]

    @property
    def varying(self):
        return [p for p in self.values() if p.vary]

    def valuesdict(self):
        return {k: p.value for k, p in self.items()}

    def to_dict(self):
        return {k: p.to_dict() for k, p in self.items()}


# -- names <-> model ----------------------------------------------------------------------------

def split_name(name):
    m = re.fullmatch(r"([A-Za-z_0-9]+)(?:\.(.+))?", name)
    if not m:
        raise InputError(f"not a parameter name: '{name}'")
    return m.group(1), m.group(2)


def _plant_field(model: Model, base: str):
    """The plant's dataclass field for a model-file symbol (m, m_e, xi, ...), or None."""
    symbols = getattr(model.plant, "_SYMBOLS", {})
    return {sym: f for f, sym in symbols.items()}.get(base)


def _plant_target(model: Model, name: str):
    field = _plant_field(model, name)
    if field is None or name not in PLANT_UNITS:
        return None
    if getattr(model.plant, field) is None:
        form = "modal (xi, wn, K)" if getattr(model.plant, "modal", False) else "physical (c, k, T_em)"
        raise InputError(f"'{name}': the plant is given in its {form} form; free those parameters instead")
    if name == "m" and getattr(model.plant, "modal", False):
        return (TARGET_PLANT, _bridge.PLANT_PARAMETER_INDEX["m (modal)"], 0)
    return (TARGET_PLANT, _bridge.PLANT_PARAMETER_INDEX[name], 0)


def target_of(model: Model, name: str):
    """(kind, parameter index, coefficient index) of the C core's sensitivity target."""
    base, coef = split_name(name)
    if coef is None and base not in PARAMETERS:
        plant = _plant_target(model, base)
        if plant is not None:
            return plant
    if base in HEAT_PARAMETERS and coef is None:
        if model.heat is None:
            raise InputError(f"'{name}': the model has no [heat] section")
        return (TARGET_HEAT, HEAT_PARAMETERS[base][2], 0)
    if base == "dF":
        if not isinstance(model.thermal, ModelII):
            raise InputError(f"'{name}': the model has no Model II dF law")
        knot = re.fullmatch(r"T\[(\d+)\]", coef or "")
        if knot:
            law = model.thermal.dF
            k = int(knot.group(1))
            if law.kind != "pwl" or not 0 < k < len(law.T) - 1:
                raise InputError(f"'{name}': only an inner breakpoint of a 'pwl' dF law can be fitted"
                                 + (f" (dF.T[1] .. dF.T[{len(law.T) - 2}])" if law.kind == "pwl" and len(law.T) > 2
                                    else ""))
            return (KNOT, 0, k)
        names = model.thermal.dF.coefficient_names()
        if coef not in names:
            raise InputError(f"'{name}': dF ({model.thermal.dF.kind}) has coefficients {', '.join(names) or 'none'}")
        return (TARGET_DF, 0, names.index(coef))
    if name == EXCESS:  # fs - fc: its sensitivity is fs's (fc held); fc's column gains it (Problem.in_names)
        if "fs" in model.laws:
            raise InputError(f"'{name}': 'fs' follows a law in this model: fit its coefficients")
        return (TARGET_PARAM, PARAMETERS.index("fs"), 0)
    if base not in PARAMETERS:
        raise InputError(f"'{name}' is not a parameter ({', '.join(PARAMETERS)}, 'dF', or 'p.coefficient')")
    idx = PARAMETERS.index(base)
    if coef is None:
        if base in model.laws:
            raise InputError(f"'{base}' follows a law in this model: fit its coefficients "
                             f"({', '.join(base + '.' + c for c in model.laws[base].coefficient_names())})")
        return (TARGET_PARAM, idx, 0)
    if base not in model.laws:
        raise InputError(f"'{name}': '{base}' has no law in this model")
    names = model.laws[base].coefficient_names()
    if coef not in names:
        raise InputError(f"'{name}': the law of '{base}' has coefficients {', '.join(names) or 'none'}")
    return (TARGET_LAW, idx, names.index(coef))


def get_value(model: Model, name: str) -> float:
    if name == EXCESS:
        return get_value(model, "fs") - get_value(model, "fc")
    kind, idx, coef = target_of(model, name)
    if kind == TARGET_HEAT:
        return float(getattr(model.heat, HEAT_PARAMETERS[name][0]))
    if kind == TARGET_PLANT:
        return float(getattr(model.plant, _plant_field(model, name)))
    if kind == TARGET_DF:
        return float(model.thermal.dF.coefficients()[coef])
    if kind == KNOT:
        return float(model.thermal.dF.T[coef])
    if kind == TARGET_LAW:
        return float(model.laws[PARAMETERS[idx]].coefficients()[coef])
    values = model.friction.values()
    base = PARAMETERS[idx]
    if base == "fs" and "fs" not in values:
        return float(values["fc"])
    if base in NEGATIVE_SIDE and base not in values:  # a negative side starts from the positive one's value
        return float(side_values({**values, "fs": values.get("fs", values.get("fc"))})[NEGATIVE_SIDE[base]])
    if base in RIPPLE_AMPLITUDES and base not in values:
        return 0.0
    if base not in values:
        raise InputError(f"'{name}' has no value in this model")
    return float(values[base])


def fitted_positive(name: str) -> bool:
    """Whether ``name`` is fitted positive (in log space): not Model II's dF, not a law's coefficient, not a
    parameter that may take either sign (models/sides.py: SIGNED)."""
    return not name.startswith("dF") and "." not in name and name not in SIGNED


def with_values(model: Model, values: dict) -> Model:
    """A copy of ``model`` with the named parameters set."""
    friction = {}
    laws = dict(model.laws)
    dF = model.thermal.dF if isinstance(model.thermal, ModelII) else None
    heat, plant, knots = {}, {}, {}
    for name, v in values.items():
        kind, idx, coef = target_of(model, name)
        if kind == KNOT:
            knots[coef] = float(v)
        elif kind == TARGET_PLANT:
            plant[_plant_field(model, name)] = float(v)
        elif kind == TARGET_HEAT:
            heat[HEAT_PARAMETERS[name][0]] = float(v)
        elif name == EXCESS:
            friction["fs"] = float(values.get("fc", get_value(model, "fc"))) + float(v)
        elif kind == TARGET_PARAM:
            friction[PARAMETERS[idx]] = float(v)
        elif kind == TARGET_LAW:
            p = PARAMETERS[idx]
            c = laws[p].coefficients()
            c[coef] = v
            laws[p] = laws[p].with_coefficients(c)
        else:
            c = dF.coefficients()
            c[coef] = v
            dF = dF.with_coefficients(c)
    if knots:  # PWL refuses knots out of order: the step is then refused, like any rule-breaking step
        T = dF.T.copy()
        for k, v in knots.items():
            T[k] = v
        dF = dataclasses.replace(dF, T=T)
    thermal = model.thermal
    if isinstance(thermal, ModelI):
        thermal = ModelI(laws)
    elif isinstance(thermal, ModelII):
        thermal = dataclasses.replace(thermal, dF=dF)
    return dataclasses.replace(model, friction=dataclasses.replace(model.friction, **friction), thermal=thermal,
                               heat=dataclasses.replace(model.heat, **heat) if heat else model.heat,
                               plant=dataclasses.replace(model.plant, **plant) if plant else model.plant)


def unit_of(model: Model, name: str) -> str:
    base, coef = split_name(name)
    if base in HEAT_PARAMETERS:
        return HEAT_PARAMETERS[base][1]
    if coef is None and base not in PARAMETERS and base in PLANT_UNITS:
        return PLANT_UNITS[base]
    unit = "N" if base in ("dF", EXCESS) else PARAMETER_UNITS.get(base, "")
    if base == "dF" and coef and coef.startswith("T["):
        return "C"
    if coef is None:
        return unit
    law = model.thermal.dF if base == "dF" else model.laws.get(base)
    return unit if law is None else law.coefficient_unit(coef, unit)


def friction_parameters(model: Model, names, fixed=(), excess=False) -> Parameters:
    """``names`` of ``model`` as Parameters to fit (``fixed`` held): positive unless a Model II term, a law's
    coefficient or a ripple amplitude. ``excess``: fs fitted as the excess fs - fc (EXCESS, in log space: fs >= fc
    by construction) where the start has one (identification/procedures.py: stribeck_start)."""
    params = Parameters()
    for name in names:
        if name == "fs" and excess and get_value(model, EXCESS) > 0:
            name = EXCESS
        v = get_value(model, name)
        positive = fitted_positive(name)
        params.add(name, v, min=0.0 if positive else -math.inf, vary=name not in fixed,
                   unit=unit_of(model, name))
    return params


__all__ = ["EXCESS", "KNOT", "TARGET_PARAM", "TARGET_LAW", "TARGET_DF", "TARGET_HEAT", "TARGET_PLANT", "split_name", "PLANT_UNITS", "HEAT_PARAMETERS", "Parameter", "Parameters", "target_of", "get_value", "with_values", "unit_of", "fitted_positive", "friction_parameters"]
