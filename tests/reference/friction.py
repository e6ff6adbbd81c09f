"""The friction models (docs/models.md#friction-models) and the thermal extensions
(docs/models.md#thermal-extensions), written again from their definitions. This is the only place
the friction equations are written: every plant, the self-heating model and the LuGre actuator
of the C core's first differential tests (ReferenceModel) evaluate them here.

    FrictionParams, friction_params(model, T)      parameters at T (Model I laws applied)
    stribeck_g, elastoplastic_alpha                the Stribeck curve, the elasto-plastic alpha
    base_friction(kind, p, v, z, modes)            (F, [z_i']) of the friction model alone
    thermal_friction(kind, p, v, z, modes, x)      (F', [z_i']) with the position ripple and Model II
    on_side(p, direction), ripple(p, x)            direction-dependent levels, the position ripple
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from thermofriction.models import ModelI, ModelII

from .laws import law_value

#: friction parameters a model may carry (the C core's list, read here by name from the model)
_ALL_PARAMS = ("sigma0", "sigma1", "sigma2", "fc", "fs", "vs", "delta", "vd", "v_smooth", "z_ba", "C")


@dataclass(frozen=True)
class FrictionParams:
    """One friction model's parameters at one temperature (Model I laws applied), plus Model II's
    scale factor ``lam`` and offset force ``dF_offset``."""

    sigma0: float
    sigma1: float
    sigma2: float
    fc: float
    fs: float
    vs: float | None
    delta: float
    vd: float | None
    v_smooth: float
    z_ba: float
    C: float
    k: tuple
    w: tuple
    lam: float
    dF_offset: float
    #: the negative side's levels (None: the positive one) and the position ripple
    fc_neg: float | None = None
    fs_neg: float | None = None
    vs_neg: float | None = None
    sigma2_neg: float | None = None
    ripple_period: float | None = None
    ripple_cos: tuple = ()
    ripple_sin: tuple = ()


def friction_params(model, T, load=None) -> FrictionParams:
    """The friction parameters of ``model`` at temperature T [degC] (NaN without a thermal model) and ``load``
    (read by laws of the load only), read from the friction object's attributes and the thermal model's laws."""
    fr, th = model.friction, model.thermal
    p = {n: getattr(fr, n, None) for n in _ALL_PARAMS}
    laws = th.laws if isinstance(th, ModelI) else {}
    for name, law in laws.items():
        p[name] = law_value(law, T, load)
    if p["fs"] is None:
        p["fs"] = p["fc"]  # no Stribeck effect; fs follows fc (and fc's law)
    defaults = {"sigma2": 0.0, "delta": 2.0, "sigma0": math.nan, "sigma1": 0.0, "z_ba": 0.0, "C": math.nan,
                "v_smooth": 1e-6}
    for name, value in defaults.items():
        if p[name] is None:
            p[name] = value
    lam, off = 1.0, 0.0
    if isinstance(th, ModelII):
        dF = law_value(th.dF, T)
        if th.form == "scale":
            lam = 1.0 + dF / float(fr.fc)  # F_ref: the base model's steady sliding level, fc
        else:
            off = dF
    f = {n: (None if p[n] is None else float(p[n])) for n in _ALL_PARAMS}
    k = tuple(float(x) for x in getattr(fr, "k", ()))
    w = tuple(float(x) for x in getattr(fr, "w", ()))
    # direction and position (written here from docs/models.md#direction-and-position, by name)
    extra = {}
    for n in ("fc_neg", "fs_neg", "vs_neg", "sigma2_neg", "ripple_period"):
        value = law_value(laws[n], T, load) if n in laws else getattr(fr, n, None)
        extra[n] = None if value is None else float(value)
    for f_ in ("cos", "sin"):
        amps = []
        for h in (1, 2, 3):
            n = f"ripple_{f_}{h}"
            value = law_value(laws[n], T, load) if n in laws else getattr(fr, n, None)
            amps.append(0.0 if value is None else float(value))
        extra[f"ripple_{f_}"] = tuple(amps)
    return FrictionParams(**f, k=k, w=w, lam=lam, dF_offset=off, **extra)


def on_side(p: FrictionParams, direction) -> FrictionParams:
    """The parameters acting in sliding direction ``direction`` (< 0: negative): each given
    negative-side level in place of its positive one; fs_neg not given is fs, except where the
    positive side has no Stribeck effect (fs = fc) and fc_neg is given: then fc_neg."""
    if not direction < 0:
        return p
    fc = p.fc if p.fc_neg is None else p.fc_neg
    if p.fs_neg is not None:
        fs = p.fs_neg
    elif p.fc_neg is not None and p.fs == p.fc:
        fs = fc
    else:
        fs = p.fs
    vs = p.vs if p.vs_neg is None else p.vs_neg
    sigma2 = p.sigma2 if p.sigma2_neg is None else p.sigma2_neg
    return dataclasses.replace(p, fc=fc, fs=fs, vs=vs, sigma2=sigma2)


def ripple(p: FrictionParams, x):
    """sum_k a_k cos(2 pi k x / P) + b_k sin(2 pi k x / P), k = 1, 2, ... (0 without a period)."""
    if not p.ripple_period:
        return 0.0
    q = 2.0 * math.pi * x / p.ripple_period
    return sum(a * math.cos((k + 1) * q) for k, a in enumerate(p.ripple_cos)) + \
        sum(b * math.sin((k + 1) * q) for k, b in enumerate(p.ripple_sin))


def stribeck_g(p: FrictionParams, v):
    """g(v) = fc + (fs - fc) exp(-|v/vs|^delta) (fc when fs == fc)."""
    if p.fs == p.fc:
        return p.fc
    r = abs(v) / p.vs
    return p.fc + (p.fs - p.fc) * (math.exp(-(r ** p.delta)) if r < 1e30 else 0.0)


def elastoplastic_alpha(p: FrictionParams, z, v, g):
    """Dupont et al. (2002): 0 while z and v have opposite signs or |z| <= z_ba; 1 for |z| at or
    beyond the steady deflection z_ss = g(v)/sigma0; a half sine rising from 0 to 1 between."""
    if not (z * v > 0.0):
        return 0.0
    az, z_ss = abs(z), g / p.sigma0
    if az <= p.z_ba:
        return 0.0
    if az >= z_ss:
        return 1.0
    mid, half = 0.5 * (z_ss + p.z_ba), z_ss - p.z_ba
    return 0.5 + 0.5 * math.sin(math.pi * (az - mid) / half)


def base_friction(kind, p: FrictionParams, v, z, modes=()):
    """(F, [z_i']) of the friction model alone (no thermal extension) at sliding velocity v and
    internal states z. GMS ``modes``: 0 stuck, +1/-1 slipping in that direction. Direction-
    dependent levels: the side of v's sign (on_side)."""
    p = on_side(p, v)
    if kind == "coulomb":
        return p.fc * math.tanh(v / p.v_smooth) + p.sigma2 * v, []
    if kind == "stribeck":
        return stribeck_g(p, v) * math.tanh(v / p.v_smooth) + p.sigma2 * v, []
    if kind == "dahl":
        return p.sigma0 * z[0], [v - p.sigma0 * abs(v) * z[0] / p.fc]
    if kind in ("lugre", "elastoplastic"):
        g = stribeck_g(p, v)
        alpha = 1.0 if kind == "lugre" else elastoplastic_alpha(p, z[0], v, g)
        zd = v - alpha * p.sigma0 * abs(v) * z[0] / g
        s1 = p.sigma1 * math.exp(-((v / p.vd) ** 2)) if p.vd is not None else p.sigma1
        return p.sigma0 * z[0] + s1 * zd + p.sigma2 * v, [zd]
    if kind == "gms":
        g = stribeck_g(p, v)
        F, rates = p.sigma2 * v, []
        for Fi, ki, wi, mi in zip(z, p.k, p.w, modes):
            F += Fi
            # stuck: a spring moving with the surface; slipping (direction mi = sgn v while it lasts):
            # relaxes towards its capacity mi w_i g(v) at rate C
            rates.append(ki * v if mi == 0 else p.C * (mi * wi - Fi / g))
        return F, rates
    raise TypeError(f"reference: unknown friction model {kind!r}")



def thermal_friction(kind, p: FrictionParams, v, z, modes=(), x=0.0):
    """(F', [z_i']): the friction model, the position ripple at sliding position x added to the
    base force, and Model II's thermal term (docs/models.md#model-ii): the base force scaled by
    lam = 1 + dF(T)/fc, or dF(T) tanh(v/v_smooth) added (the offset form). Model I needs nothing
    here: its laws are in p already."""
    F, zd = base_friction(kind, p, v, z, modes)
    F += ripple(p, x)
    F = p.lam * F
    if p.dF_offset != 0.0:
        F += p.dF_offset * math.tanh(v / p.v_smooth)
    return F, zd
