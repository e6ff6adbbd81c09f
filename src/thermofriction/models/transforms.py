"""Model -> Model transforms (pure functions of a model): the model at one constant temperature, the model without
its thermal extension, and the model with another friction model built from its values. Identification, the
measurements' starting values and the fitting engine use them; none of them simulates or fits."""

from __future__ import annotations

import dataclasses

from ..errors import InputError
from .friction import FRICTION_MODELS
from .laws import Const
from .model import Model
from .thermal import ModelI, ModelII


def at_temperature(model: Model, T: float) -> Model:
    """The model at one constant temperature: Model I's laws' values there as plain parameters,
    Model II's dF as a constant."""
    if isinstance(model.thermal, ModelII):
        return dataclasses.replace(model, thermal=ModelII(Const(float(model.thermal.dF(T)))))
    values = model.parameters_at(T)
    return dataclasses.replace(model, friction=dataclasses.replace(model.friction, **{n: values[n] for n in model.laws}),
                               thermal=None)


def base_model(model: Model, temperature=None) -> Model:
    """The model without its thermal extension: a Model I's laws evaluated at ``temperature``.

    Parameters
    ----------
    model : Model
        The model.
    temperature : float, optional
        The temperature [C] Model I's laws are evaluated at; default the middle of their range (35 C without
        one).

    Returns
    -------
    Model

    Raises
    ------
    InputError
        A law whose value is outside the parameter's physical domain there.
    """
    if isinstance(model.thermal, ModelI):
        if temperature is None:
            lo_hi = model.temperature_range()
            temperature = 0.5 * (lo_hi[0] + lo_hi[1]) if lo_hi else 35.0
        p = model.parameters_at(temperature)
        fr = dataclasses.replace(model.friction, **{k: p[k] for k in model.laws})
        return dataclasses.replace(model, friction=fr, thermal=None)
    return dataclasses.replace(model, thermal=None)


def with_friction_model(model: Model, kind: str) -> Model:
    """``model`` with a ``kind`` friction model (docs/identification.md#friction-models), built from
    its own friction's values where the two share a parameter (a Model I law goes with its
    parameter; laws of parameters the new model lacks are dropped). What the new model requires
    and the old one lacks is derived from the level fc and the presliding stiffness sigma0 (a GMS
    model's sum of k_i; else fc over 1 um): sigma1 = 1e-6 s x sigma0, z_ba = fc / (2 sigma0),
    C = 1e4 /s x fc, and GMS elements k_i proportional to 1/i summing to sigma0, w_i = 1/4 (four
    elements breaking loose one after the other).

    Parameters
    ----------
    model : Model
        The model.
    kind : str
        The friction model wanted (``FRICTION_MODELS``: lugre, dahl, elastoplastic, gms, stribeck, coulomb).

    Returns
    -------
    Model

    Raises
    ------
    InputError
        An unknown friction model.
    """
    if kind not in FRICTION_MODELS:
        raise InputError(f"unknown friction model '{kind}' (one of: {', '.join(FRICTION_MODELS)})")
    if model.friction.model == kind:
        return model
    cls = FRICTION_MODELS[kind]
    names = set(cls.law_targets)
    laws = {k: v for k, v in model.laws.items() if k in names}
    kw = {k: v for k, v in model.friction.values().items() if k in names}
    kw.update({k: None for k in laws})
    at = base_model(model).friction.values()  # numbers (laws at mid-range), to derive the rest from
    fc = at["fc"]
    sigma0 = at.get("sigma0") or (sum(at["k"]) if "k" in at else fc / 1e-6)
    h = sum(1.0 / i for i in range(1, 5))
    derived = {"sigma0": sigma0, "sigma1": 1e-6 * sigma0, "z_ba": 0.5 * fc / sigma0, "C": 1e4 * fc,
               "k": tuple(sigma0 / (i * h) for i in range(1, 5)), "w": (0.25,) * 4}
    for name in cls.required:
        if name not in kw:
            kw[name] = derived[name]
    thermal = model.thermal
    if isinstance(thermal, ModelI):
        thermal = ModelI(laws) if laws else None
    return dataclasses.replace(model, friction=cls(**kw), thermal=thermal)


__all__ = ["at_temperature", "base_model", "with_friction_model"]
