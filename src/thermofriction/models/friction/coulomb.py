"""Coulomb + viscous friction, a static map through a smoothed sign; its parameters and its
description (docs/models.md#friction-models)."""

from __future__ import annotations

from dataclasses import dataclass

from .base import Description, _Friction, friction_model


@friction_model(Description(
    name="coulomb", title="Coulomb", c_id="coulomb", smoothed_sign=True,
    fitted={"displacement": ("fc", "sigma2"), "force": ("fc", "sigma2")}))
@dataclass(frozen=True)
class Coulomb(_Friction):
    """Coulomb + viscous friction, a static map: ``F = fc s(v) + sigma2 v`` with the sign smoothed
    over ``v_smooth`` [m/s], ``s(v) = tanh(v / v_smooth)`` (no sticking: below v_smooth the
    force is viscous-like, fc/v_smooth N s/m).

    Parameters
    ----------
    fc : float or None
        The Coulomb level [N], > 0; None where a Model I law gives it.
    sigma2 : float or None, default 0.0
        The viscous coefficient [N s/m], >= 0.
    v_smooth : float or None, default 1e-6
        The smoothed sign's velocity band [m/s].
    fc_neg, sigma2_neg : float or None, optional
        The values of fc [N] and sigma2 [N s/m] in negative sliding (docs/models.md#direction-and-position);
        default the positive side's.
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

    fc: float | None
    sigma2: float | None = 0.0
    v_smooth: float | None = 1e-6
    fc_neg: float | None = None
    sigma2_neg: float | None = None


__all__ = ["Coulomb"]
