"""Dahl friction (1968): presliding hysteresis with a Coulomb level; its parameters and its
description (docs/models.md#friction-models)."""

from __future__ import annotations

from dataclasses import dataclass

from .base import Description, _Friction, friction_model


@friction_model(Description(
    name="dahl", title="Dahl", c_id="dahl", states=(("z", "m"),), bristle=True,
    fitted={"displacement": ("sigma0", "fc"), "force": ("sigma0", "fc")}))
@dataclass(frozen=True)
class Dahl(_Friction):
    """Dahl (1968): ``z' = v - sigma0 |v| z / fc``, ``F = sigma0 z`` -- presliding hysteresis
    with a Coulomb level, no Stribeck effect, no viscous term.

    Parameters
    ----------
    sigma0 : float or None
        The bristle stiffness [N/m], > 0; None where a Model I law gives it.
    fc : float or None
        The Coulomb level [N], > 0; None where a Model I law gives it.
    v_smooth : float or None, default 1e-6
        The velocity band [m/s] of Model II's smoothed sign.
    fc_neg : float or None, optional
        The Coulomb level [N] in negative sliding (docs/models.md#direction-and-position); default fc.
    ripple_period, ripple_cos1, ripple_sin1, ripple_cos2, ripple_sin2, ripple_cos3, ripple_sin3 : float or None, optional
        Keyword-only: the position ripple, a periodic force in the sliding position x added to the model's,
        R(x) = sum_k ripple_cosk cos(2 pi k x / P) + ripple_sink sin(2 pi k x / P), of period
        P = ``ripple_period`` [m] and amplitudes [N] (docs/models.md#direction-and-position); default none.

    Raises
    ------
    InputError
        A value that is not a number, named with the model (``lugre friction: 'sigma0' ...``). The physical checks
        (fs >= fc, positive stiffness, dissipativity) need the whole model: ``Model`` does them.
    """

    sigma0: float | None
    fc: float | None
    v_smooth: float | None = 1e-6
    fc_neg: float | None = None


__all__ = ["Dahl"]
