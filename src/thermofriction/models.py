"""Models: plants, friction models, temperature laws and thermal extensions (SPEC 3-5, 7).

A :class:`Model` is one actuator: a plant, a friction model, an optional thermal extension
and an optional input waveform. It loads from and saves to the model file (TOML) of SPEC 7;
``load_model`` also takes the name of a shipped preset (``li2009-model-i``, ...).
"""

from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass, field, fields, replace
from importlib import resources
from pathlib import Path

import numpy as np
import tomli_w

from . import _core
from ._io import atomic_write
from .errors import InputError, unknown_keys
from .waveforms import Waveform, waveform_from_dict

# ---------------------------------------------------------------------------------------------
# Temperature laws
# ---------------------------------------------------------------------------------------------

_LAW_CODES = {"const": 1, "linear": 2, "exp": 3, "poly": 4, "pwl": 5, "table": 6}


def _num(value, where, key):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{where}: '{key}' must be a number, got {value!r}")
    try:
        value = float(value)
    except OverflowError:  # an integer beyond the float range, e.g. 10**400
        raise InputError(f"{where}: '{key}' must be finite, got an integer too large for a number") from None
    if not math.isfinite(value):
        raise InputError(f"{where}: '{key}' must be finite, got {value!r}")
    return value


def _num_array(value, where, key, min_len=1):
    if not isinstance(value, (list, tuple, np.ndarray)) or len(value) < min_len:
        raise InputError(f"{where}: '{key}' must be an array of at least {min_len} number(s)")
    return np.array([_num(v, where, f"{key}[{i}]") for i, v in enumerate(value)], dtype=float)


@dataclass(frozen=True, eq=False)
class Law:
    """A function of temperature T [degC]. ``range`` is the calibrated interval (or None).

    Evaluated by the C core, the same code the simulator runs."""

    kind = ""

    def _core_tuple(self):
        raise NotImplementedError

    def __call__(self, T):
        return self.evaluate(T)[0]

    def evaluate(self, T):
        """(value, dvalue/dT) at T (scalars or arrays)."""
        T_arr = np.ascontiguousarray(np.atleast_1d(T), dtype=float)
        v, d = np.empty_like(T_arr), np.empty_like(T_arr)
        _core.law_eval(self._core_tuple(), T_arr, v, d)
        if np.ndim(T) == 0:
            return float(v[0]), float(d[0])
        return v, d

    def slope(self, T):
        return self.evaluate(T)[1]

    def in_range(self, T) -> bool:
        rng = getattr(self, "range", None)
        if rng is None:
            return True
        T = np.atleast_1d(T)
        return bool(np.all((T >= rng[0] - 1e-9) & (T <= rng[1] + 1e-9)))

    def to_dict(self) -> dict:
        d = {"law": self.kind}
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "range":
                if v is not None:
                    d["range"] = [float(v[0]), float(v[1])]
            elif isinstance(v, np.ndarray):
                d[f.name] = v.tolist()
            else:
                d[f.name] = v
        return d

    def __eq__(self, other):
        return type(self) is type(other) and self.to_dict() == other.to_dict()

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items() if k != "law")
        return f"{type(self).__name__}({args})"


def _check_range(rng, where):
    if rng is None:
        return None
    r = _num_array(rng, where, "range", 2)
    if len(r) != 2 or not r[0] < r[1]:
        raise InputError(f"{where}: 'range' must be [low, high] with low < high, got {list(rng)!r}")
    return (float(r[0]), float(r[1]))


@dataclass(frozen=True, eq=False, repr=False)
class Const(Law):
    value: float
    range: tuple | None = None
    kind = "const"

    def _core_tuple(self):
        return (1, float(self.value), 0.0, None, None)


@dataclass(frozen=True, eq=False, repr=False)
class Linear(Law):
    """a T + b"""

    a: float
    b: float
    range: tuple | None = None
    kind = "linear"

    def _core_tuple(self):
        return (2, float(self.a), float(self.b), None, None)


@dataclass(frozen=True, eq=False, repr=False)
class Exp(Law):
    """a exp(b T)"""

    a: float
    b: float
    range: tuple | None = None
    kind = "exp"

    def _core_tuple(self):
        return (3, float(self.a), float(self.b), None, None)


@dataclass(frozen=True, eq=False, repr=False)
class Poly(Law):
    """sum c[i] T^i"""

    c: np.ndarray
    range: tuple | None = None
    kind = "poly"

    def __post_init__(self):
        object.__setattr__(self, "c", np.ascontiguousarray(self.c, dtype=float))

    def _core_tuple(self):
        return (4, 0.0, 0.0, None, self.c)


@dataclass(frozen=True, eq=False, repr=False)
class PWL(Law):
    """Linear through (T[i], values[i]); extrapolated linearly with the end segments."""

    T: np.ndarray
    values: np.ndarray
    range: tuple | None = None
    kind = "pwl"

    def __post_init__(self):
        object.__setattr__(self, "T", np.ascontiguousarray(self.T, dtype=float))
        object.__setattr__(self, "values", np.ascontiguousarray(self.values, dtype=float))

    def _core_tuple(self):
        return (5, 0.0, 0.0, self.T, self.values)


@dataclass(frozen=True, eq=False, repr=False)
class Table(PWL):
    """Monotone cubic (PCHIP) through (T[i], values[i]); extrapolated linearly with the end slopes."""

    kind = "table"

    def _core_tuple(self):
        return (6, 0.0, 0.0, self.T, self.values)


_LAW_CLASSES = {"const": Const, "linear": Linear, "exp": Exp, "poly": Poly, "pwl": PWL, "table": Table}
_LAW_KEYS = {"const": ("value",), "linear": ("a", "b"), "exp": ("a", "b"), "poly": ("c",),
             "pwl": ("T", "values"), "table": ("T", "values")}


def law_from_dict(d, where: str) -> Law:
    """A law from its inline table, e.g. ``{ law = "exp", a = 1.15e8, b = -0.136 }``."""
    if not isinstance(d, dict):
        raise InputError(f"{where}: a law must be a table such as {{ law = \"linear\", a = ..., b = ... }}")
    kind = d.get("law")
    if not isinstance(kind, str) or kind not in _LAW_CLASSES:
        raise InputError(f"{where}: 'law' must be one of {', '.join(_LAW_CLASSES)}, got {kind!r}")
    keys = _LAW_KEYS[kind]
    unknown = set(d) - set(keys) - {"law", "range"}
    if unknown:
        raise InputError(f"{where}: {unknown_keys(unknown, [*keys, 'range'], f'law {kind!r}')}")
    missing = [k for k in keys if k not in d]
    if missing:
        raise InputError(f"{where}: law '{kind}' needs {', '.join(missing)}")
    rng = _check_range(d.get("range"), where)
    if kind in ("const", "linear", "exp"):
        return _LAW_CLASSES[kind](*(_num(d[k], where, k) for k in keys), range=rng)
    if kind == "poly":
        return Poly(_num_array(d["c"], where, "c"), range=rng)
    T = _num_array(d["T"], where, "T")
    values = _num_array(d["values"], where, "values")
    if len(T) != len(values):
        raise InputError(f"{where}: 'T' and 'values' must have the same length ({len(T)} != {len(values)})")
    if np.any(np.diff(T) <= 0):
        raise InputError(f"{where}: 'T' must increase strictly")
    return _LAW_CLASSES[kind](T, values, range=rng)


# ---------------------------------------------------------------------------------------------
# Plants
# ---------------------------------------------------------------------------------------------

def _by_symbol(cls, d: dict, where: str, required, what="", extra=()) -> dict:
    """A section keyed by the SPEC's symbols (``cls._SYMBOLS``: field -> symbol) as keyword
    arguments of ``cls``; unknown and missing keys are named."""
    names = {sym: name for name, sym in cls._SYMBOLS.items()}
    unknown = set(d) - set(names)
    if unknown:
        raise InputError(f"{where}: {unknown_keys(unknown, [*extra, *names], what)}")
    for req in required:
        if req not in d:
            raise InputError(f"{where}: missing '{req}'")
    return {names[k]: v for k, v in d.items()}


@dataclass(frozen=True)
class StickSlipPlant:
    """Piezoelectric stick-slip actuator (SPEC 3.1): a stage (equivalent ``mass``, ``damping``,
    ``stiffness``, driven through ``transducer_ratio`` T_em by the voltage) carrying, by friction,
    an end effector of ``end_effector_mass``.

    Give either the modal form (``damping_ratio`` xi, ``natural_frequency`` wn [rad/s], ``gain``
    K [m/V]) or the physical one (``damping`` c, ``stiffness`` k, ``transducer_ratio`` T_em);
    the other is derived (k = m wn^2, c = 2 xi wn m, T_em = K k). The form given is the form saved.
    """

    mass: float
    end_effector_mass: float
    damping_ratio: float | None = None
    natural_frequency: float | None = None
    gain: float | None = None
    damping: float | None = None
    stiffness: float | None = None
    transducer_ratio: float | None = None

    type = "stick-slip"
    _MODAL = ("damping_ratio", "natural_frequency", "gain")
    _PHYSICAL = ("damping", "stiffness", "transducer_ratio")
    _SYMBOLS = {"mass": "m", "end_effector_mass": "m_e", "damping_ratio": "xi", "natural_frequency": "wn",
                "gain": "K", "damping": "c", "stiffness": "k", "transducer_ratio": "T_em"}

    def __post_init__(self):
        where = "[plant]"
        modal = [getattr(self, n) is not None for n in self._MODAL]
        phys = [getattr(self, n) is not None for n in self._PHYSICAL]
        if all(modal) == all(phys) or (any(modal) and any(phys)):
            raise InputError(f"{where}: give either xi, wn and K (modal form) or c, k and T_em (physical form)")
        for name in ("mass", "end_effector_mass", *(self._MODAL if all(modal) else self._PHYSICAL)):
            sym = self._SYMBOLS[name]
            v = _num(getattr(self, name), where, sym)
            if name in ("mass", "end_effector_mass", "natural_frequency", "stiffness") and v <= 0:
                raise InputError(f"{where}: '{sym}' must be positive, got {v!r}")
            if name in ("damping_ratio", "damping") and v < 0:
                raise InputError(f"{where}: '{sym}' must not be negative, got {v!r}")
            object.__setattr__(self, name, v)

    @property
    def modal(self) -> bool:
        return self.damping_ratio is not None

    def physical(self):
        """(c, k, T_em) in SI units."""
        if self.modal:
            k = self.mass * self.natural_frequency ** 2
            return 2 * self.damping_ratio * self.natural_frequency * self.mass, k, self.gain * k
        return self.damping, self.stiffness, self.transducer_ratio

    def modal_parameters(self):
        """(xi, wn, K)."""
        if self.modal:
            return self.damping_ratio, self.natural_frequency, self.gain
        c, k, T_em = self.physical()
        wn = math.sqrt(k / self.mass)
        return c / (2 * wn * self.mass), wn, T_em / k

    def to_dict(self) -> dict:
        d = {"type": self.type}
        for name in ("mass", "end_effector_mass", *(self._MODAL if self.modal else self._PHYSICAL)):
            d[self._SYMBOLS[name]] = getattr(self, name)
        return d

    @classmethod
    def from_dict(cls, d: dict, where="[plant]"):
        d = dict(d)
        d.pop("type", None)
        return cls(**_by_symbol(cls, d, where, ("m", "m_e"), extra=("type",)))


@dataclass(frozen=True)
class MassPlant:
    """Single-mass stage (SPEC 3.2): ``m x'' = f(t) + k_s (v_0 t - x) - F``, v_r = x'.

    f(t) is the input waveform, a force [N] (none: zero). With ``spring_stiffness`` k_s [N/m] and
    ``pull_velocity`` v_0 [m/s] a spring pulled at constant speed drives the mass (the stick-slip
    benchmark of Canudas de Wit et al. 1995); both forces add when both are given."""

    mass: float
    spring_stiffness: float = 0.0
    pull_velocity: float = 0.0

    type = "mass"
    _SYMBOLS = {"mass": "m", "spring_stiffness": "k_s", "pull_velocity": "v_0"}

    def __post_init__(self):
        for name, sym in self._SYMBOLS.items():
            v = _num(getattr(self, name), "[plant]", sym)
            if name == "mass" and v <= 0:
                raise InputError(f"[plant]: 'm' must be positive, got {v!r}")
            if name == "spring_stiffness" and v < 0:
                raise InputError(f"[plant]: 'k_s' must not be negative, got {v!r}")
            object.__setattr__(self, name, v)
        if self.pull_velocity != 0 and self.spring_stiffness == 0:
            raise InputError("[plant]: 'v_0' pulls through a spring: give 'k_s' too")

    def to_dict(self) -> dict:
        d = {"type": self.type, "m": self.mass}
        if self.spring_stiffness:
            d.update(k_s=self.spring_stiffness, v_0=self.pull_velocity)
        return d

    @classmethod
    def from_dict(cls, d: dict, where="[plant]"):
        d = dict(d)
        d.pop("type", None)
        names = {sym: name for name, sym in cls._SYMBOLS.items()}
        unknown = set(d) - set(names)
        if unknown:
            raise InputError(f"{where}: {unknown_keys(unknown, ['type', *names], 'a mass plant')}")
        if "m" not in d:
            raise InputError(f"{where}: missing 'm'")
        return cls(**{names[k]: v for k, v in d.items()})


@dataclass(frozen=True)
class PrescribedMotion:
    """Prescribed motion (SPEC 3.3): the relative displacement x_r(t) is the input waveform [m]
    and v_r its slope; the friction model is driven by it (hysteresis loops, Stribeck curves,
    break-away tests). The waveform must be continuous (a step needs a slew time)."""

    type = "prescribed"

    def to_dict(self) -> dict:
        return {"type": self.type}

    @classmethod
    def from_dict(cls, d: dict, where="[plant]"):
        unknown = set(d) - {"type"}
        if unknown:
            raise InputError(f"{where}: {unknown_keys(unknown, ['type'], 'prescribed motion')}")
        return cls()


PLANTS = {"stick-slip": StickSlipPlant, "mass": MassPlant, "prescribed": PrescribedMotion}
PLANT_CODES = {"stick-slip": 0, "mass": 1, "prescribed": 2}


def plant_from_dict(d: dict, where="[plant]"):
    kind = d.get("type")
    if not isinstance(kind, str) or kind not in PLANTS:
        raise InputError(f"{where}: 'type' must be one of {', '.join(repr(k) for k in PLANTS)}, got {kind!r}")
    return PLANTS[kind].from_dict(d, where)


# ---------------------------------------------------------------------------------------------
# Friction models
# ---------------------------------------------------------------------------------------------

#: Parameter order of the C core (friction.h, tf_param).
PARAMETERS = ("sigma0", "sigma1", "sigma2", "fc", "fs", "vs", "delta", "vd", "v_smooth", "z_ba", "C")
PARAMETER_UNITS = {"sigma0": "N/m", "sigma1": "N s/m", "sigma2": "N s/m", "fc": "N", "fs": "N", "vs": "m/s",
                   "delta": "-", "vd": "m/s", "v_smooth": "m/s", "z_ba": "m", "C": "N/s"}


class _Friction:
    """What every friction model shares: parameters as dataclass fields (None where a Model I law
    gives the value), ``values()``, the file form, and the state layout."""

    model = ""
    core_code = -1
    required: tuple = ()
    nstate = 0
    state_names: tuple = ()
    state_units: tuple = ()
    #: parameters that are arrays, not numbers (never a law of temperature)
    arrays: tuple = ()

    def values(self) -> dict:
        """Parameters given as numbers (None-valued ones omitted)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) is not None}

    def to_dict(self) -> dict:
        d = {"model": self.model}
        for k, v in self.values().items():
            d[k] = [float(x) for x in v] if k in self.arrays else v
        return d

    def with_values(self, **values):
        return replace(self, **values)

    @classmethod
    def from_dict(cls, d: dict, where="[friction]"):
        d = dict(d)
        d.pop("model", None)
        allowed = [f.name for f in fields(cls)]
        unknown = set(d) - set(allowed)
        if unknown:
            raise InputError(f"{where}: {unknown_keys(unknown, ['model', *allowed], cls.model)}")
        for k, v in d.items():
            d[k] = tuple(_num_array(v, where, k)) if k in cls.arrays else _num(v, where, k)
        for k in cls.arrays:
            if k not in d:
                raise InputError(f"{where}: missing '{k}' (an array, one value per element)")
        kw = {k: d.get(k) for k in cls.required}
        kw.update({k: v for k, v in d.items() if k not in cls.required})
        return cls(**kw)


@dataclass(frozen=True)
class LuGre(_Friction):
    """LuGre friction (Canudas de Wit et al. 1995), SPEC 4::

        z' = v - sigma0 |v| z / g(v),   F = sigma0 z + sigma1(v) z' + sigma2 v
        g(v) = fc + (fs - fc) exp(-|v/vs|^delta),   sigma1(v) = sigma1 exp(-(v/vd)^2) if vd

    A parameter that follows a Model I law is None here (the law lives in the thermal model).
    ``fs`` defaults to ``fc`` (no Stribeck effect, the paper's case). ``v_smooth`` is the velocity
    band of the smoothed sign used by Model II's offset form.
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

    model = "lugre"
    core_code = 0
    nstate = 1
    state_names = ("z",)
    state_units = ("m",)
    required = ("sigma0", "sigma1", "fc")


@dataclass(frozen=True)
class Coulomb(_Friction):
    """Coulomb + viscous friction, a static map: ``F = fc s(v) + sigma2 v`` with the sign smoothed
    over ``v_smooth`` [m/s], ``s(v) = tanh(v / v_smooth)`` (no sticking: below v_smooth the
    force is viscous-like, fc/v_smooth N s/m)."""

    fc: float | None
    sigma2: float | None = 0.0
    v_smooth: float | None = 1e-6

    model = "coulomb"
    core_code = 1
    required = ("fc",)


@dataclass(frozen=True)
class Stribeck(_Friction):
    """Static Stribeck map: ``F = g(v) s(v) + sigma2 v``, g the Stribeck curve of SPEC 4 and
    ``s(v) = tanh(v / v_smooth)``."""

    fc: float | None
    fs: float | None = None
    vs: float | None = None
    delta: float | None = 2.0
    sigma2: float | None = 0.0
    v_smooth: float | None = 1e-6

    model = "stribeck"
    core_code = 2
    required = ("fc",)


@dataclass(frozen=True)
class Dahl(_Friction):
    """Dahl (1968): ``z' = v - sigma0 |v| z / fc``, ``F = sigma0 z`` -- presliding hysteresis
    with a Coulomb level, no Stribeck effect, no viscous term."""

    sigma0: float | None
    fc: float | None
    v_smooth: float | None = 1e-6

    model = "dahl"
    core_code = 3
    nstate = 1
    state_names = ("z",)
    state_units = ("m",)
    required = ("sigma0", "fc")


@dataclass(frozen=True)
class ElastoPlastic(_Friction):
    """Elasto-plastic friction (Dupont, Hayward, Armstrong and Altpeter 2002): LuGre with
    ``z' = v - alpha(z, v) sigma0 |v| z / g(v)``. alpha is 0 for |z| <= z_ba (and whenever z
    opposes v: purely elastic, so small oscillating forces cause no drift), 1 from the steady
    deflection g(v)/sigma0 on, and a half sine between. Needs 0 <= z_ba < fc/sigma0."""

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

    model = "elastoplastic"
    core_code = 4
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
    (SPEC 4 prints the slip law as ``sgn(v) C (w_i - F_i/g)``; that is the same for v > 0 and
    unstable for v < 0, so the sign is applied to the capacity instead.)"""

    k: tuple
    w: tuple
    C: float | None
    fc: float | None
    fs: float | None = None
    vs: float | None = None
    delta: float | None = 2.0
    sigma2: float | None = 0.0
    v_smooth: float | None = 1e-6

    model = "gms"
    core_code = 5
    required = ("k", "w", "C", "fc")
    arrays = ("k", "w")
    _MAX_ELEMENTS = 64

    def __post_init__(self):
        k, w = tuple(float(x) for x in self.k), tuple(float(x) for x in self.w)
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


def check_friction_values(values: dict, where: str):
    """Physical checks on a full set of parameter values (numbers and laws evaluated)."""
    def need(name, ok, what):
        v = values.get(name)
        if v is not None and not ok(v):
            raise InputError(f"{where}: '{name}' must be {what}, got {v!r}")
    need("sigma0", lambda v: v > 0, "positive")
    need("sigma1", lambda v: v >= 0, "non-negative")
    need("sigma2", lambda v: v >= 0, "non-negative")
    need("fc", lambda v: v > 0, "positive")
    need("delta", lambda v: v > 0, "positive")
    need("vd", lambda v: v > 0, "positive")
    need("v_smooth", lambda v: v > 0, "positive")
    need("C", lambda v: v > 0, "positive")
    need("z_ba", lambda v: v >= 0, "non-negative")
    z_ba, sigma0, fc = values.get("z_ba"), values.get("sigma0"), values.get("fc")
    if z_ba is not None and sigma0 and fc and not z_ba < fc / sigma0:
        raise InputError(f"{where}: 'z_ba' ({z_ba!r} m) must be below the steady deflection fc/sigma0 "
                         f"({fc / sigma0:.6g} m): the elasto-plastic model breaks away before it")
    fs = values.get("fs")
    if fs is not None and fc is not None and fs < fc:
        raise InputError(f"{where}: 'fs' ({fs!r}) must be at least 'fc' ({fc!r})")
    if fs is not None and fc is not None and fs != fc:
        vs = values.get("vs")
        if vs is None or not vs > 0:
            raise InputError(f"{where}: 'vs' must be positive when fs != fc (the Stribeck velocity), got {vs!r}")


def stribeck_curve(values: dict, v):
    """g(v) = fc + (fs - fc) exp(-|v/vs|^delta) (fs = fc: no Stribeck effect), NumPy, for checks and reports."""
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
    exp(-(v/vd)^2) (Olsson 1996) restores it. Returns (velocity, message) for the lowest failing
    speed on a log grid from 1 nm/s to 100 m/s. (For the elasto-plastic model, alpha <= 1 only
    lowers the relaxation term, so the LuGre condition is checked as the stricter one.)"""
    if model_name not in ("lugre", "elastoplastic"):
        return None
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


# ---------------------------------------------------------------------------------------------
# Thermal extensions
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class ModelI:
    """Model I (SPEC 5.1): parameters of the base model follow laws of temperature."""

    laws: dict = field(default_factory=dict)
    model = "I"

    def to_dict(self):
        d = {"model": "I"}
        d.update({k: law.to_dict() for k, law in self.laws.items()})
        return d


@dataclass(frozen=True)
class ModelII:
    """Model II (SPEC 5.2): base model plus thermal-induced friction dF(T) [N].

    ``form="scale"`` (default): F' = (1 + dF(T)/F_ref) F_base, F_ref the base model's steady
    sliding friction (fc) -- Eq. (12) in steady sliding, smooth and passive through v = 0.
    ``form="offset"``: F' = F_base + dF(T) s(v), s a sign smoothed over ``v_smooth``."""

    dF: Law
    form: str = "scale"
    model = "II"

    def __post_init__(self):
        if self.form not in ("scale", "offset"):
            raise InputError(f"[thermal]: 'form' must be \"scale\" or \"offset\", got {self.form!r}")

    def to_dict(self):
        return {"model": "II", "form": self.form, "dF": self.dF.to_dict()}


# ---------------------------------------------------------------------------------------------
# Self-heating
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Heat:
    """Lumped thermal model of the friction interface (SPEC 5.3): the temperature becomes a state,

        C_th T' = eta |F v_r| - (T - T_amb) / R_th + P_ext(t),    T(0) = T_0.

    ``heat_capacity`` C_th [J/K], ``thermal_resistance`` R_th [K/W] to ambient, ``heat_fraction``
    eta (0..1) of the friction power that heats the interface, ``ambient_temperature`` T_amb
    [degC] (None: the temperature given to ``simulate``), ``initial_temperature`` T_0 (None:
    T_amb), ``external_heat`` P_ext(t) [W] (a waveform, e.g. the paper's heater; None: none).
    """

    heat_capacity: float
    thermal_resistance: float
    heat_fraction: float = 1.0
    ambient_temperature: float | None = None
    initial_temperature: float | None = None
    external_heat: Waveform | None = None

    _SYMBOLS = {"heat_capacity": "C_th", "thermal_resistance": "R_th", "heat_fraction": "eta",
                "ambient_temperature": "T_amb", "initial_temperature": "T_0", "external_heat": "P_ext"}

    def __post_init__(self):
        where = "[heat]"
        for name in ("heat_capacity", "thermal_resistance", "heat_fraction", "ambient_temperature",
                     "initial_temperature"):
            v = getattr(self, name)
            if v is None and name in ("ambient_temperature", "initial_temperature"):
                continue
            sym = self._SYMBOLS[name]
            v = _num(v, where, sym)
            if name in ("heat_capacity", "thermal_resistance") and not v > 0:
                raise InputError(f"{where}: '{sym}' must be positive, got {v!r}")
            if name == "heat_fraction" and not 0 <= v <= 1:
                raise InputError(f"{where}: 'eta' must be between 0 and 1, got {v!r}")
            object.__setattr__(self, name, v)
        if self.external_heat is not None and not isinstance(self.external_heat, Waveform):
            raise InputError(f"{where}: 'P_ext' must be a waveform")

    @property
    def time_constant(self) -> float:
        """R_th C_th [s]."""
        return self.thermal_resistance * self.heat_capacity

    def resolved(self, temperature=None) -> "Heat":
        """This model with T_amb (``temperature`` overrides the file's) and T_0 filled in."""
        T_amb = self.ambient_temperature if temperature is None else float(temperature)
        if T_amb is None:
            raise InputError("[heat]: no ambient temperature: give 'T_amb' or a temperature (e.g. --temperature 30)")
        T_0 = self.initial_temperature if self.initial_temperature is not None else T_amb
        return replace(self, ambient_temperature=T_amb, initial_temperature=T_0)

    def to_dict(self) -> dict:
        d = {}
        for name, sym in self._SYMBOLS.items():
            v = getattr(self, name)
            if v is not None:
                d[sym] = v.to_dict() if isinstance(v, Waveform) else v
        return d

    @classmethod
    def from_dict(cls, d: dict, where="[heat]", base_dir=None):
        if not isinstance(d, dict):
            raise InputError(f"{where} must be a section")
        kw = _by_symbol(cls, d, where, ("C_th", "R_th"), what="the heat model")
        if "external_heat" in kw:
            kw["external_heat"] = waveform_from_dict(kw["external_heat"], f"{where} P_ext", base_dir)
        return cls(**kw)


# ---------------------------------------------------------------------------------------------
# The model
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Model:
    """One actuator: plant, friction model, thermal extension (or None), input (or None) and
    lumped thermal model of self-heating (or None)."""

    plant: StickSlipPlant | MassPlant | PrescribedMotion
    friction: LuGre | Coulomb | Stribeck | Dahl | ElastoPlastic | GMS
    thermal: ModelI | ModelII | None = None
    input: Waveform | None = None
    name: str | None = None
    description: str | None = None
    heat: Heat | None = None

    def __post_init__(self):
        laws = self.thermal.laws if isinstance(self.thermal, ModelI) else {}
        given = self.friction.values()
        for pname, law in laws.items():
            if pname not in PARAMETERS or pname not in [f.name for f in fields(self.friction)]:
                raise InputError(f"[thermal]: '{pname}' is not a parameter of {self.friction.model}")
            if pname in given:
                raise InputError(f"'{pname}' is given both as a number in [friction] and as a law in "
                                 f"[thermal]; give it once")
            if not isinstance(law, Law):
                raise InputError(f"[thermal]: '{pname}' must be a law")
        for pname in self.friction.required:
            if pname not in given and pname not in laws:
                raise InputError(f"[friction]: missing '{pname}' (a number here, or a law in [thermal])")
        check_friction_values(self._number_values(), "[friction]")
        if isinstance(self.thermal, ModelII):
            if not isinstance(self.thermal.dF, Law):
                raise InputError("[thermal]: 'dF' must be a law")
        if self.heat is not None and not isinstance(self.heat, Heat):
            raise InputError("'heat' must be a Heat model (the [heat] section)")

    def _number_values(self):
        v = self.friction.values()
        if "fs" not in v and "fc" in v:
            v["fs"] = v["fc"]
        return v

    # -- parameters at a temperature ------------------------------------------------------
    @property
    def laws(self) -> dict:
        return dict(self.thermal.laws) if isinstance(self.thermal, ModelI) else {}

    def parameters_at(self, T: float) -> dict:
        """Every friction parameter's value at temperature T (Model I laws applied)."""
        v = self.friction.values()
        for pname, law in self.laws.items():
            v[pname] = law(float(T))
        if "fs" not in v:
            v["fs"] = v["fc"]
        return v

    def reference_force(self) -> float:
        """F_ref of Model II's scale form: the base model's steady sliding friction level."""
        return float(self.friction.fc)

    def thermal_factor(self, T):
        """lambda(T) = 1 + dF(T)/F_ref of Model II's scale form (1 for other models)."""
        if not isinstance(self.thermal, ModelII) or self.thermal.form != "scale":
            return np.ones_like(np.asarray(T, float)) if np.ndim(T) else 1.0
        return 1.0 + self.thermal.dF(T) / self.reference_force()

    @property
    def depends_on_temperature(self) -> bool:
        return self.thermal is not None

    def temperature_range(self):
        """The intersection of the calibrated ranges of the model's laws (None if none)."""
        laws = list(self.laws.values())
        if isinstance(self.thermal, ModelII):
            laws.append(self.thermal.dF)
        ranges = [law.range for law in laws if law.range is not None]
        if not ranges:
            return None
        return (max(r[0] for r in ranges), min(r[1] for r in ranges))

    # -- files ---------------------------------------------------------------------------
    def to_dict(self) -> dict:
        d = {}
        if self.name:
            d["name"] = self.name
        if self.description:
            d["description"] = self.description
        d["plant"] = self.plant.to_dict()
        d["friction"] = self.friction.to_dict()
        d["thermal"] = self.thermal.to_dict() if self.thermal else {"model": "none"}
        if self.heat is not None:
            d["heat"] = self.heat.to_dict()
        if self.input is not None:
            d["input"] = self.input.to_dict()
        return d

    def to_toml(self) -> str:
        return tomli_w.dumps(self.to_dict())

    def save(self, path):
        """Writes the model file atomically (temporary file, then rename)."""
        text = self.to_toml()
        with atomic_write(path, "w") as fh:
            fh.write(text)

    def with_friction(self, **values) -> "Model":
        return replace(self, friction=self.friction.with_values(**values))


_TOP_KEYS = {"name", "description", "plant", "friction", "thermal", "heat", "input"}


def model_from_dict(d: dict, source: str = "<model>", base_dir=None) -> Model:
    """Builds a model from a parsed model file; errors name the file and the key."""
    try:
        unknown = set(d) - _TOP_KEYS
        if unknown:
            raise InputError(unknown_keys(unknown, sorted(_TOP_KEYS), "a model file"))
        for sec in ("plant", "friction"):
            if not isinstance(d.get(sec), dict):
                raise InputError(f"missing section [{sec}]")
        plant = plant_from_dict(d["plant"])
        fmodel = d["friction"].get("model")
        if not isinstance(fmodel, str) or fmodel not in FRICTION_MODELS:
            raise InputError(f"[friction]: 'model' must be one of {', '.join(FRICTION_MODELS)}, got {fmodel!r}")
        th = d.get("thermal", {"model": "none"})
        if not isinstance(th, dict):
            raise InputError("[thermal] must be a section")
        th = dict(th)
        tkind = th.pop("model", "none")
        if tkind == "I":
            laws = {}
            for k, v in th.items():
                if k in d["friction"]:
                    raise InputError(f"'{k}' is given both as a number in [friction] and as a law in "
                                     f"[thermal]; give it once")
                if k not in PARAMETERS:
                    raise InputError(f"[thermal]: {unknown_keys([k], ['model', *PARAMETERS], 'Model I')}")
                laws[k] = law_from_dict(v, f"[thermal] {k}")
            thermal = ModelI(laws)
        elif tkind == "II":
            unknown = set(th) - {"dF", "form"}
            if unknown:
                raise InputError(f"[thermal]: {unknown_keys(unknown, ['model', 'dF', 'form'], 'Model II')}")
            if "dF" not in th:
                raise InputError("[thermal]: Model II needs 'dF', a law of temperature")
            thermal = ModelII(law_from_dict(th["dF"], "[thermal] dF"), th.get("form", "scale"))
        elif tkind == "none":
            if th:
                raise InputError(f"[thermal]: {unknown_keys(th, ['model'], 'model none')}")
            thermal = None
        else:
            raise InputError(f"[thermal]: 'model' must be \"none\", \"I\" or \"II\", got {tkind!r}")
        friction = FRICTION_MODELS[fmodel].from_dict(d["friction"])
        if isinstance(thermal, ModelI):  # a law replaces the parameter's default (e.g. sigma2 = 0)
            names = [f.name for f in fields(friction)]
            friction = replace(friction, **{k: None for k in thermal.laws if k in names})
        inp = waveform_from_dict(d["input"], "[input]", base_dir) if "input" in d else None
        heat = Heat.from_dict(d["heat"], "[heat]", base_dir) if "heat" in d else None
        for key in ("name", "description"):
            if key in d and not isinstance(d[key], str):
                raise InputError(f"'{key}' must be a string")
        return Model(plant, friction, thermal, inp, d.get("name"), d.get("description"), heat)
    except InputError as e:
        raise InputError(f"{source}: {e}") from None


def require_actuator(model: Model, task: str):
    """Datasets (SPEC 7) record a stick-slip actuator: voltage in, end-effector displacement out."""
    if not isinstance(model.plant, StickSlipPlant):
        raise InputError(f"{task} works on the stick-slip actuator (datasets record its voltage and displacement); "
                         f"this model's plant is '{model.plant.type}'")


PRESETS = ("li2009-model-i", "li2009-model-ii", "li2009-base", "li2009-self-heating", "canudas1995", "stage-model-i")


def preset_path(name: str):
    return resources.files("thermofriction").joinpath("presets", f"{name}.toml")


def load_model(source) -> Model:
    """Loads a model file, or a shipped preset by name (see ``PRESETS``)."""
    source = os.fspath(source)
    p = Path(source)
    try:
        exists = p.exists()
    except (OSError, ValueError) as e:  # a name too long for the file system, a NUL byte
        raise InputError(f"{source[:200]!r}: not a usable file name ({getattr(e, 'strerror', None) or e})") from None
    if not exists and source in PRESETS:
        ref = preset_path(source)
        text = ref.read_text()
        base_dir = None
    else:
        if not exists:
            hint = f" (presets: {', '.join(PRESETS)})" if os.sep not in source and not source.endswith(".toml") else ""
            raise InputError(f"{source}: no such file{hint}")
        try:
            text = p.read_text()
        except (OSError, UnicodeDecodeError) as e:
            raise InputError(f"{source}: cannot read ({e})") from None
        base_dir = p.parent
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{source}: TOML syntax error: {e}") from None
    except RecursionError:  # tomllib recurses once per level of nested arrays or inline tables
        raise InputError(f"{source}: TOML nested too deeply") from None
    return model_from_dict(data, source, base_dir)


__all__ = ["Law", "Const", "Linear", "Exp", "Poly", "PWL", "Table", "law_from_dict", "StickSlipPlant", "MassPlant",
           "PrescribedMotion", "plant_from_dict", "LuGre", "Coulomb", "Stribeck", "Dahl", "ElastoPlastic", "GMS",
           "ModelI", "ModelII", "Heat", "Model", "load_model", "model_from_dict", "PARAMETERS", "PRESETS"]
