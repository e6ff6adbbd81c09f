"""Generalized Maxwell-slip friction (Al-Bender, Lampaert and Swevers 2005): N elementary blocks; its parameters and its
description (docs/models.md#friction-models)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...errors import InputError
from .._parse import num_array
from .base import Array, Description, _Friction, friction_model


@friction_model(Description(
    name="gms", title="GMS", c_id="gms",
    arrays={"k": Array("N/m", "stiffness of GMS element {e}", "gms_k"),
            "w": Array("", "capacity fraction of GMS element {e} (the fractions sum to 1)", "gms_w")},
    fitted={"displacement": ("C", "fc"), "force": ("C", "fc", "fs", "vs", "sigma2")}))
@dataclass(frozen=True)
class GMS(_Friction):
    """Generalized Maxwell-slip (Al-Bender, Lampaert and Swevers 2005): N elementary blocks with
    stiffnesses ``k`` [N/m] and capacity fractions ``w`` (summing to one), ``F = sum F_i + sigma2 v``.

    A stuck element follows the motion, ``F_i' = k_i v``, until |F_i| reaches its capacity
    ``w_i g(v)``; then it slips, ``F_i' = C (sgn(v) w_i - F_i / g(v))`` (rate ``C`` [N/s]), until
    the motion reverses and it sticks again. The switches are events the integrator locates and
    restarts at -- no regularisation -- so presliding hysteresis keeps its return-point memory.
    (docs/models.md#friction-models prints the slip law as ``sgn(v) C (w_i - F_i/g)``; that is the same for v > 0 and
    unstable for v < 0, so the sign is applied to the capacity instead.)

    Parameters
    ----------
    k : sequence of float
        The elements' stiffnesses [N/m], each > 0; 1 to 64 elements.
    w : sequence of float
        The elements' capacity fractions [-], each > 0, summing to one; as many as ``k``.
    C : float or None
        The slip rate [N/s], > 0; None where a Model I law gives it.
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

    k: tuple
    w: tuple
    C: float | None
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

    _MAX_ELEMENTS = 64

    def __post_init__(self):
        super().__post_init__()
        k, w = (tuple(float(x) for x in num_array(a, "[friction]", name)) for name, a in (("k", self.k), ("w", self.w)))
        if len(k) != len(w) or not 1 <= len(k) <= self._MAX_ELEMENTS:
            raise InputError(f"[friction]: 'k' and 'w' must have the same length, 1 to {self._MAX_ELEMENTS} "
                             f"elements (got {len(k)} and {len(w)})")
        for name, arr in (("k", k), ("w", w)):
            for i, x in enumerate(arr):
                if not (math.isfinite(x) and x > 0):
                    raise InputError(f"[friction]: '{name}[{i}]' must be positive, got {x!r}")
        if abs(sum(w) - 1.0) > 1e-9:
            raise InputError(f"[friction]: the GMS weights 'w' must sum to one, got {sum(w):.12g}")
        object.__setattr__(self, "k", k)
        object.__setattr__(self, "w", w)

    @property
    def nstate(self):
        return len(self.k)

    @property
    def state_names(self):
        return tuple(f"F_{i + 1}" for i in range(len(self.k)))

    @property
    def state_units(self):
        return ("N",) * len(self.k)


__all__ = ["GMS"]
