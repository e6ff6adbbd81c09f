"""The static Stribeck map; its parameters and its
description (docs/models.md#friction-models)."""

from __future__ import annotations

from dataclasses import dataclass

from .base import Description, _Friction, friction_model


@friction_model(Description(
    name="stribeck", title="Stribeck", c_id="stribeck", smoothed_sign=True,
    fitted={"displacement": ("fc", "vs", "sigma2"), "force": ("fc", "fs", "vs", "sigma2")}))
@dataclass(frozen=True)
class Stribeck(_Friction):
    """Static Stribeck map: ``F = g(v) s(v) + sigma2 v``, g the Stribeck curve of docs/models.md#friction-models and
    ``s(v) = tanh(v / v_smooth)``.

    Parameters
    ----------
    fc : float or None
        The Coulomb level [N], > 0; None where a Model I law gives it.
    fs : float or None, optional
        The static (breakaway) level [N], >= fc; default fc (no Stribeck effect).
    vs : float or None, optional
        The Stribeck velocity [m/s], > 0; needed where fs > fc.
    delta : float or None, default 2.0
        The Stribeck curve's exponent [-].
    sigma2 : float or None, default 0.0
        The viscous coefficient [N s/m], >= 0.
    v_smooth : float or None, default 1e-6
        The smoothed sign's velocity band [m/s].
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

    fc: float | None
    fs: float | None = None
    vs: float | None = None
    delta: float | None = 2.0
    sigma2: float | None = 0.0
    v_smooth: float | None = 1e-6
    fc_neg: float | None = None
    fs_neg: float | None = None
    vs_neg: float | None = None
    sigma2_neg: float | None = None


__all__ = ["Stribeck"]
