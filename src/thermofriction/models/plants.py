"""Plants (docs/models.md#plants): what the friction acts in. The stick-slip actuator, a single
mass, and prescribed motion."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, unknown_keys
from ._parse import by_symbol, num


@dataclass(frozen=True)
class StickSlipPlant:
    """Piezoelectric stick-slip actuator (docs/models.md#stick-slip-actuator): a stage (equivalent ``mass``, ``damping``,
    ``stiffness``, driven through ``transducer_ratio`` T_em by the voltage) carrying, by friction,
    an end effector of ``end_effector_mass``.

    Give either the modal form (``damping_ratio`` xi, ``natural_frequency`` wn [rad/s], ``gain``
    K [m/V]) or the physical one (``damping`` c, ``stiffness`` k, ``transducer_ratio`` T_em);
    the other is derived (k = m wn^2, c = 2 xi wn m, T_em = K k). The form given is the form saved.

    Parameters
    ----------
    mass : float
        The stage's equivalent mass m [kg], > 0.
    end_effector_mass : float
        The end effector's mass m_e [kg], > 0.
    damping_ratio : float, optional
        The modal form's damping ratio xi [-].
    natural_frequency : float, optional
        The modal form's natural frequency wn [rad/s].
    gain : float, optional
        The modal form's static gain K [m/V].
    damping : float, optional
        The physical form's damping c [N s/m].
    stiffness : float, optional
        The physical form's stiffness k [N/m].
    transducer_ratio : float, optional
        The physical form's transducer ratio T_em [N/V].

    Raises
    ------
    InputError
        Neither form complete, or both given; a value that is not a number, a mass, wn or k that is not
        positive, a negative xi or c, named.
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
            v = num(getattr(self, name), where, sym)
            if name in ("mass", "end_effector_mass", "natural_frequency", "stiffness") and v <= 0:
                raise InputError(f"{where}: '{sym}' must be positive, got {v!r}")
            if name in ("damping_ratio", "damping") and v < 0:
                raise InputError(f"{where}: '{sym}' must not be negative, got {v!r}")
            object.__setattr__(self, name, v)
        # the derived form must exist too: m = 1e308 or wn = 1e200 overflow k = m wn^2 (and the
        # solver could not resolve such a time scale anyway)
        with np.errstate(over="ignore", invalid="ignore"):
            m = np.float64(self.mass)
            if all(modal):
                xi, wn, K = (np.float64(getattr(self, n)) for n in self._MODAL)
                k = m * wn * wn
                c, T_em = 2 * xi * wn * m, K * k
            else:
                c, k, T_em = (np.float64(getattr(self, n)) for n in self._PHYSICAL)
                wn = np.sqrt(k / m)
        derived = {"c": c, "k": k, "T_em": T_em, "wn": wn}
        for sym, v in derived.items():
            if not np.isfinite(v):
                given = ", ".join(f"{self._SYMBOLS[n]} = {getattr(self, n)!r}" for n in
                                  ("mass", "end_effector_mass", *(self._MODAL if self.modal else self._PHYSICAL)))
                raise InputError(f"{where}: the derived '{sym}' overflows ({given}): the values are beyond "
                                 f"what can be computed")

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
        return cls(**by_symbol(cls, d, where, ("m", "m_e"), extra=("type",)))


@dataclass(frozen=True)
class MassPlant:
    """Single-mass stage (docs/models.md#mass-plant): ``m x'' = f(t) + k_s (v_0 t - x) - F``, v_r = x'.

    f(t) is the input waveform, a force [N] (none: zero). With ``spring_stiffness`` k_s [N/m] and
    ``pull_velocity`` v_0 [m/s] a spring pulled at constant speed drives the mass (the stick-slip
    benchmark of Canudas de Wit et al. 1995); both forces add when both are given.

    Parameters
    ----------
    mass : float
        The mass m [kg], > 0.
    spring_stiffness : float, default 0.0
        The pulling spring's stiffness k_s [N/m], >= 0.
    pull_velocity : float, default 0.0
        The speed v_0 [m/s] the spring's end is pulled at.

    Raises
    ------
    InputError
        A value that is not a number, a mass that is not positive, a negative k_s, v_0 without k_s, named.
    """

    mass: float
    spring_stiffness: float = 0.0
    pull_velocity: float = 0.0

    type = "mass"
    _SYMBOLS = {"mass": "m", "spring_stiffness": "k_s", "pull_velocity": "v_0"}

    def __post_init__(self):
        for name, sym in self._SYMBOLS.items():
            v = num(getattr(self, name), "[plant]", sym)
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
    """Prescribed motion (docs/models.md#prescribed-motion): the relative displacement x_r(t) is the input waveform [m]
    and v_r its slope; the friction model is driven by it (hysteresis loops, Stribeck curves,
    break-away tests). The waveform must be continuous (a step needs a slew time).

    ``motion = "rotary"``: a joint, the same equations read in angles: the input is an angle [rad], the
    friction a torque [N m], and the parameters' units follow (N m/rad, N m s/rad, N m, rad/s;
    :func:`rotary_unit`). ``sensor_offset`` [N or N m]: the constant bias of the force (torque) sensor, fitted
    with the friction from measured force (docs/force-data.md) and added to the predicted measurement; it is
    not part of the friction. ``inertia`` [kg, or kg m^2 for a joint] and ``delay`` [s]: what a drive's
    command adds to the friction (docs/force-data.md#drives-without-a-torque-sensor): the command recorded at
    ``t - delay`` is ``F + inertia * a + sensor_offset`` at ``t`` -- with ``command_hold = "zero-order"`` (a
    drive that holds each command for a sample) its mean over the sample from ``t``, with ``"none"`` (point
    samples of a continuous torque) its value at ``t``; inertia and delay are fitted from command data and used
    to predict a command; a simulation of prescribed motion does not use them.

    Parameters
    ----------
    motion : {"linear", "rotary"}, default "linear"
        A linear contact (m, N) or a rotary joint (rad, N m).
    sensor_offset : float, default 0.0
        The force (torque) sensor's constant bias [N, or N m for a joint].
    inertia : float, default 0.0
        A drive's moved inertia J [kg, or kg m^2 for a joint], for command data.
    delay : float, default 0.0
        A drive's command delay [s], for command data.
    command_hold : {"zero-order", "none"}, default "zero-order"
        How a drive's command data are read: held for a sample (its mean over it) or point samples.

    Raises
    ------
    InputError
        An unknown ``motion`` or ``command_hold``; a value that is not a finite number, or a negative inertia,
        named.
    """

    motion: str = "linear"
    sensor_offset: float = 0.0
    inertia: float = 0.0
    delay: float = 0.0
    command_hold: str = "zero-order"

    type = "prescribed"
    MOTIONS = ("linear", "rotary")
    #: how a drive's command is read (docs/force-data.md#drives-without-a-torque-sensor)
    COMMAND_HOLDS = ("zero-order", "none")

    def __post_init__(self):
        if self.motion not in self.MOTIONS:
            raise InputError(f"[plant]: 'motion' must be \"linear\" or \"rotary\", got {self.motion!r}")
        if self.command_hold not in self.COMMAND_HOLDS:
            raise InputError(f"[plant]: 'command_hold' must be \"zero-order\" or \"none\", got "
                             f"{self.command_hold!r}")
        for key in ("sensor_offset", "inertia", "delay"):
            object.__setattr__(self, key, num(getattr(self, key), "[plant]", key))
        if self.inertia < 0:
            raise InputError(f"[plant]: 'inertia' must not be negative, got {self.inertia!r}")

    @property
    def rotary(self) -> bool:
        return self.motion == "rotary"

    def unit(self, unit: str) -> str:
        """A linear unit as this motion reads it (unchanged for linear motion)."""
        return rotary_unit(unit) if self.rotary else unit

    def to_dict(self) -> dict:
        d = {"type": self.type}
        if self.rotary:
            d["motion"] = self.motion
        for key in ("sensor_offset", "inertia", "delay"):
            if getattr(self, key):
                d[key] = getattr(self, key)
        if self.command_hold != "zero-order":
            d["command_hold"] = self.command_hold
        return d

    @classmethod
    def from_dict(cls, d: dict, where="[plant]"):
        keys = ["type", "motion", "sensor_offset", "inertia", "delay", "command_hold"]
        unknown = set(d) - set(keys)
        if unknown:
            raise InputError(f"{where}: {unknown_keys(unknown, keys, 'prescribed motion')}")
        return cls(**{k: d[k] for k in keys[1:] if k in d})


def rotary_unit(unit: str) -> str:
    """A unit of linear motion read for a rotary joint: a force N becomes a torque N m, a length m an angle
    rad (``N/m`` -> ``N m/rad``, ``N s/m`` -> ``N m s/rad``, ``m/s`` -> ``rad/s``, ``N/m/C`` -> ``N m/rad/C``).
    The equations are the same; only what the numbers mean changes."""
    if not unit:
        return unit
    parts = unit.split("/")
    out = []
    for i, part in enumerate(parts):
        words = []
        for w in part.split(" "):
            if w == "N" and i == 0:
                words += ["N", "m"]
            elif w == "m":
                words.append("rad")
            else:
                words.append(w)
        out.append(" ".join(words))
    return "/".join(out)


PLANTS = {"stick-slip": StickSlipPlant, "mass": MassPlant, "prescribed": PrescribedMotion}


def plant_from_dict(d: dict, where="[plant]"):
    """A plant from a model file's ``[plant]`` table (docs/formats.md#model-files).

    Parameters
    ----------
    d : dict
        The parsed table: ``type`` and the plant's keys (``m``, ``m_e``, ``xi``, ``wn``, ``K``, ...).
    where : str, default "[plant]"
        The table's place, for the messages.

    Returns
    -------
    StickSlipPlant or MassPlant or PrescribedMotion

    Raises
    ------
    InputError
        An unknown ``type`` or key, a missing or bad value, named with ``where``.
    """
    kind = d.get("type")
    if not isinstance(kind, str) or kind not in PLANTS:
        raise InputError(f"{where}: 'type' must be one of {', '.join(repr(k) for k in PLANTS)}, got {kind!r}")
    return PLANTS[kind].from_dict(d, where)


__all__ = ["StickSlipPlant", "MassPlant", "PrescribedMotion", "PLANTS", "plant_from_dict", "rotary_unit"]
