"""Friction models (docs/models.md#friction-models): parameters as dataclass fields, their file
form, their state layout, and the physical checks on their values."""

from __future__ import annotations

import functools
import math
from dataclasses import KW_ONLY, dataclass, fields, replace

import numpy as np

from .._bridge import PARAMETER_UNITS, PARAMETERS
from ..errors import InputError, shorten, unknown_keys
from ._parse import num, num_array
from .sides import NEGATIVE_SIDE, check_sides, side_values, with_ripple_table

# PARAMETERS and PARAMETER_UNITS (the one table of units: files, reports and fit results use it) come
# from the core's parameter list (friction.h, TF_PARAMETERS).


@dataclass(frozen=True)
class _Ripple:
    """The position ripple every model takes (docs/models.md#direction-and-position), keyword-only."""

    _: KW_ONLY
    ripple_period: float | None = None
    ripple_cos1: float | None = None
    ripple_sin1: float | None = None
    ripple_cos2: float | None = None
    ripple_sin2: float | None = None
    ripple_cos3: float | None = None
    ripple_sin3: float | None = None


class _Friction(_Ripple):
    """What every friction model shares: parameters as dataclass fields (None where a Model I law
    gives the value), ``values()``, the file form, and the state layout."""

    model = ""
    required: tuple = ()
    nstate = 0
    state_names: tuple = ()
    state_units: tuple = ()
    #: parameters that are arrays, not numbers (never a law of temperature)
    arrays: tuple = ()

    def __post_init__(self):
        # checked at construction, so that LuGre(sigma0="1e5") fails here, naming the parameter,
        # not later inside a simulation (the physical checks need the whole model: Model does them)
        for f in fields(self):
            if f.name in self.arrays:
                continue
            v = getattr(self, f.name)
            if v is not None:
                object.__setattr__(self, f.name, num(v, f"{self.model} friction", f.name))

    def values(self) -> dict:
        """Parameters given as numbers (None-valued ones omitted)."""
        return {f.name: getattr(self, f.name) for f in sorted(fields(self), key=lambda f: f.name.startswith("ripple_"))
                if getattr(self, f.name) is not None}

    def to_dict(self) -> dict:
        d = {"model": self.model}
        for k, v in self.values().items():
            d[k] = [float(x) for x in v] if k in self.arrays else v
        return d

    def with_values(self, **values):
        return replace(self, **values)

    @classmethod
    def from_dict(cls, d: dict, where="[friction]"):
        d = with_ripple_table(dict(d), where)
        d.pop("model", None)
        allowed = [f.name for f in fields(cls)]
        unknown = set(d) - set(allowed)
        if unknown:
            raise InputError(f"{where}: {unknown_keys(unknown, ['model', *allowed], cls.model)}")
        for k, v in d.items():
            d[k] = tuple(num_array(v, where, k)) if k in cls.arrays else num(v, where, k)
        for k in cls.arrays:
            if k not in d:
                raise InputError(f"{where}: missing '{k}' (an array, one value per element)")
        kw = {k: d.get(k) for k in cls.required}
        kw.update({k: v for k, v in d.items() if k not in cls.required})
        return cls(**kw)


@dataclass(frozen=True)
class LuGre(_Friction):
    """LuGre friction (Canudas de Wit et al. 1995; docs/models.md#friction-models).

    The equations::

        z' = v - sigma0 |v| z / g(v),   F = sigma0 z + sigma1(v) z' + sigma2 v
        g(v) = fc + (fs - fc) exp(-|v/vs|^delta),   sigma1(v) = sigma1 exp(-(v/vd)^2) if vd

    A parameter that follows a Model I law is None here (the law lives in the thermal model).

    Parameters
    ----------
    sigma0 : float or None
        The bristle stiffness [N/m], > 0; None where a Model I law gives it.
    sigma1 : float or None
        The bristle damping [N s/m], >= 0; None where a Model I law gives it.
    fc : float or None
        The Coulomb level [N], > 0; None where a Model I law gives it.
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
    v_smooth : float, default 1e-6
        The velocity band [m/s] of the smoothed sign used by Model II's offset form.
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

    Examples
    --------
    >>> import thermofriction as tf
    >>> f = tf.LuGre(sigma0=1e5, sigma1=300.0, fc=0.5, fs=0.7, vs=1e-3)
    >>> f.model, f.delta
    ('lugre', 2.0)
    >>> f.with_values(fc=0.6).fc
    0.6
    """

    sigma0: float | None
    sigma1: float | None
    fc: float | None
    sigma2: float | None = 0.0
    fs: float | None = None
    vs: float | None = None
    delta: float | None = 2.0
    vd: float | None = None
    v_smooth: float = 1e-6
    fc_neg: float | None = None
    fs_neg: float | None = None
    vs_neg: float | None = None
    sigma2_neg: float | None = None

    model = "lugre"
    nstate = 1
    state_names = ("z",)
    state_units = ("m",)
    required = ("sigma0", "sigma1", "fc")


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

    model = "coulomb"
    required = ("fc",)


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

    model = "stribeck"
    required = ("fc",)


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

    model = "dahl"
    nstate = 1
    state_names = ("z",)
    state_units = ("m",)
    required = ("sigma0", "fc")


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

    model = "elastoplastic"
    nstate = 1
    state_names = ("z",)
    state_units = ("m",)
    required = ("sigma0", "sigma1", "fc", "z_ba")


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

    model = "gms"
    required = ("k", "w", "C", "fc")
    arrays = ("k", "w")
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


FRICTION_MODELS = {cls.model: cls for cls in (LuGre, Coulomb, Stribeck, Dahl, ElastoPlastic, GMS)}


#: Where each parameter is physical (fs, vs: relative to fc, checked below).
PARAMETER_DOMAIN = {"sigma0": "positive", "sigma1": "non-negative", "sigma2": "non-negative", "fc": "positive",
                    "delta": "positive", "vd": "positive", "v_smooth": "positive", "C": "positive",
                    "z_ba": "non-negative", "fc_neg": "positive", "vs_neg": "positive",
                    "sigma2_neg": "non-negative", "ripple_period": "positive"}


def in_domain(name: str, values) -> np.ndarray:
    """Whether each value of parameter ``name`` is in its physical domain (True where it has none)."""
    values = np.asarray(values, float)
    domain = PARAMETER_DOMAIN.get(name)
    if domain == "positive":
        return np.isfinite(values) & (values > 0)
    if domain == "non-negative":
        return np.isfinite(values) & (values >= 0)
    return np.isfinite(values)


def check_friction_values(values: dict, where: str):
    """Physical checks on a full set of parameter values (numbers and laws evaluated), on both
    sides of a direction-dependent model, and on the ripple.

    Parameters
    ----------
    values : dict
        Parameter name -> value, in the units of ``PARAMETER_UNITS``.
    where : str
        Where the values came from (a model file's section, ``"[friction]"``), for the messages.

    Returns
    -------
    None

    Raises
    ------
    InputError
        A value outside the physical domain (a stiffness that is not positive, fs < fc, vs <= 0 with a Stribeck
        effect, z_ba >= fc/sigma0, ...), named with ``where``.
    """
    _check_side(values, where, "")
    check_sides(values, where, _check_side)


def _check_side(values: dict, where: str, side: str):
    for name, domain in PARAMETER_DOMAIN.items():
        v = values.get(name)
        # finite first: a law that overflows (a exp(b T) with b = 100) gives inf, which is "positive"
        if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v) and in_domain(name, v)):
            raise InputError(f"{where}: '{name}' must be {domain} and finite, got {shorten(v)}")
    z_ba, sigma0, fc = values.get("z_ba"), values.get("sigma0"), values.get("fc")
    if z_ba is not None and sigma0 and fc and not z_ba < fc / sigma0:
        raise InputError(f"{where}: 'z_ba' ({z_ba!r} m) must be below the steady deflection fc/sigma0 "
                         f"({fc / sigma0:.6g} m): the elasto-plastic model breaks away before it")
    fs = values.get("fs")
    for name in ("fs", "vs"):  # no domain of their own (fs relative to fc, below), but finite
        v = values.get(name)
        if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v)):
            raise InputError(f"{where}: '{name}' must be a number and finite, got {shorten(v)}")
    if fs is not None and fc is not None and fs < fc:
        raise InputError(f"{where}: 'fs' ({fs!r}) must be at least 'fc' ({fc!r}){side}")
    if fs is not None and fc is not None and fs != fc:
        vs = values.get("vs")
        if vs is None or not vs > 0:
            raise InputError(f"{where}: 'vs' must be positive when fs != fc (the Stribeck velocity), got {vs!r}{side}")


def stribeck_curve(values: dict, v):
    """g(v) = fc + (fs - fc) exp(-|v/vs|^delta) (fs = fc: no Stribeck effect), NumPy, for checks and reports.

    Parameters
    ----------
    values : dict
        ``fc`` [N], and ``fs`` [N], ``vs`` [m/s], ``delta`` [-] where there is a Stribeck effect.
    v : float or array_like
        The sliding velocity [m/s].

    Returns
    -------
    numpy.ndarray
        g(v) [N], the shape of ``v``.

    Raises
    ------
    KeyError
        ``values`` without ``fc``, or without ``vs`` where fs differs from fc (the values are not checked here:
        ``check_friction_values`` does that).
    """
    fc = values["fc"]
    fs = values.get("fs", fc)
    fs = fc if fs is None else fs
    if fs == fc:
        return np.full_like(np.asarray(v, float), fc)
    return fc + (fs - fc) * np.exp(-np.abs(np.asarray(v, float) / values["vs"]) ** values.get("delta", 2.0))


def dissipativity_violation(model_name: str, values: dict):
    """Where a LuGre-type model (LuGre, elasto-plastic) may create energy, or None.

    Sufficient condition checked: with the bristle energy V = sigma0 z^2 / 2 as storage function,
    F v - V' = sigma0 a z^2 - sigma1(v) a v z + (sigma1(v) + sigma2) v^2 (a = sigma0 |v| / g(v))
    must be >= 0 for every |z| <= fs/sigma0 (the invariant set of z) at every velocity. It fails
    when sigma1 is large against sigma2 and the Stribeck drop (fs - fc)/fc -- at high speed it
    needs sigma1 <= sigma2 fc / (fs - fc) -- which is why a constant, large sigma1 makes LuGre
    non-passive (Barabanov and Ortega 2000) and a velocity-dependent sigma1(v) = sigma1
    exp(-(v/vd)^2) (Olsson 1996) restores it. (For the elasto-plastic model, alpha <= 1 only
    lowers the relaxation term, so the LuGre condition is checked as the stricter one.)

    Parameters
    ----------
    model_name : str
        The friction model's name (``"lugre"``, ``"elastoplastic"``; any other has no such test: None).
    values : dict
        Parameter name -> value (numbers, laws evaluated), in the units of ``PARAMETER_UNITS``; each side of a
        direction-dependent model is tested on its own.

    Returns
    -------
    tuple or None
        (velocity [m/s], message) for the lowest failing speed on a log grid from 1 nm/s to 100 m/s; None
        where the condition holds.

    Raises
    ------
    KeyError
        ``values`` without a parameter the model requires (the values are not checked here).
    """
    if model_name not in ("lugre", "elastoplastic"):
        return None
    if any(values.get(n) is not None for n in NEGATIVE_SIDE):  # each side on its own, the positive first
        return dissipativity_violation(model_name, {k: v for k, v in values.items() if k not in NEGATIVE_SIDE}) or \
            dissipativity_violation(model_name, {k: v for k, v in side_values(values).items()
                                                 if k not in NEGATIVE_SIDE})
    # extreme but finite values (sigma0 = 1e300) overflow the products below; the condition is
    # then decided by the terms that remain finite, and NumPy's warnings are not the user's business
    # the same values come back for every run of a model (simulate checks before each): decide once
    key = tuple(sorted((k, float(v)) for k, v in values.items() if isinstance(v, (int, float, np.floating))))
    return _dissipativity_violation_of(key)


@functools.lru_cache(maxsize=512)
def _dissipativity_violation_of(items: tuple):
    with np.errstate(over="ignore", invalid="ignore", under="ignore", divide="ignore"):
        return _dissipativity_violation(dict(items))


def _dissipativity_violation(values: dict):
    s0, s1, s2, fc = values["sigma0"], values["sigma1"], values.get("sigma2", 0.0) or 0.0, values["fc"]
    fs = values.get("fs") if values.get("fs") is not None else fc
    v = np.logspace(-9, 2, 1101)
    g = stribeck_curve(values, v)
    vd = values.get("vd")
    s1v = s1 * np.exp(-(v / vd) ** 2) if vd else np.full_like(v, s1)
    zmax = fs / s0
    a = s0 * v / g
    z_star = np.minimum(s1v * v / (2 * s0), zmax)  # the minimiser of the quadratic in z, within the set
    q = s0 * a * z_star ** 2 - s1v * a * v * z_star + (s1v + s2) * v ** 2
    bad = q < -1e-12 * (s1v + s2 + 1e-300) * v ** 2
    if not np.any(bad):
        return None
    v_bad = float(v[np.argmax(bad)])
    return v_bad, (f"not dissipative above |v| = {v_bad:.3g} m/s (condition: F v >= d/dt(sigma0 z^2/2) for "
                   f"|z| <= fs/sigma0; at high speed sigma1 <= sigma2 fc/(fs - fc) = "
                   f"{(s2 * fc / (fs - fc)) if fs > fc else float('inf'):.3g} N s/m, sigma1 = {s1:.3g}): the model "
                   f"can create energy; give vd (sigma1(v) = sigma1 exp(-(v/vd)^2)), or raise sigma2")


__all__ = ["PARAMETERS", "PARAMETER_UNITS", "LuGre", "Coulomb", "Stribeck", "Dahl", "ElastoPlastic", "GMS",
           "FRICTION_MODELS", "check_friction_values", "stribeck_curve", "dissipativity_violation"]
