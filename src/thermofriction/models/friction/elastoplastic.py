"""Elasto-plastic friction (Dupont, Hayward, Armstrong and Altpeter 2002): LuGre without drift under small forces; its parameters and its
description (docs/models.md#friction-models)."""

from __future__ import annotations

from dataclasses import dataclass

from .base import Description, _Friction, friction_model


@friction_model(Description(
    name="elastoplastic", title="elasto-plastic", c_id="elastoplastic", states=(("z", "m"),), bristle=True,
    dissipativity=True,
    fitted={"displacement": ("sigma0", "sigma1", "fc"), "force": ("sigma0", "sigma1", "fc", "fs", "vs", "sigma2")}))
@dataclass(frozen=True)
class ElastoPlastic(_Friction):
    """Elasto-plastic friction (Dupont, Hayward, Armstrong and Altpeter 2002): LuGre with
    ``z' = v - alpha(z, v) sigma0 |v| z / g(v)``. alpha is 0 for |z| <= z_ba (and whenever z
    opposes v: purely elastic, so small oscillating forces cause no drift), 1 from the steady
    deflection g(v)/sigma0 on, and a half sine between. Needs 0 <= z_ba < fc/sigma0.

    Parameters
    ----------
    sigma0 : float or None
        The bristle stiffness [N/m], > 0; None where a Model I law gives it.
    sigma1 : float or None
        The bristle damping [N s/m], >= 0; None where a Model I law gives it.
    fc : float or None
        The Coulomb level [N], > 0; None where a Model I law gives it.
    z_ba : float or None
        The breakaway deflection [m], 0 <= z_ba < fc/sigma0; None where a Model I law gives it.
    sigma2 : float or None, default 0.0
        The viscous coefficient [N s/m], >= 0.
    fs : float or None, optional
        The static (breakaway) level [N], >= fc; default fc (no Stribeck effect).
    vs : float or None, optional
        The Stribeck velocity [m/s], > 0; needed where fs > fc.
    delta : float or None, default 2.0
        The Stribeck curve's exponent [-].
    vd : float or None, optional
        The velocity [m/s] over which the bristle damping decays,
        sigma1(v) = sigma1 exp(-(v/vd)^2); default none (constant sigma1).
    v_smooth : float or None, default 1e-6
        The velocity band [m/s] of Model II's smoothed sign.
    fc_neg, fs_neg, vs_neg, sigma2_neg : float or None, optional
        The values of fc, fs, vs, sigma2 [N, N, m/s, N s/m] in negative sliding (docs/models.md#direction-and-position);
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

    sigma0: float | None
    sigma1: float | None
    fc: float | None
    z_ba: float | None
    sigma2: float | None = 0.0
    fs: float | None = None
    vs: float | None = None
    delta: float | None = 2.0
    vd: float | None = None
    v_smooth: float | None = 1e-6
    fc_neg: float | None = None
    fs_neg: float | None = None
    vs_neg: float | None = None
    sigma2_neg: float | None = None


__all__ = ["ElastoPlastic"]
