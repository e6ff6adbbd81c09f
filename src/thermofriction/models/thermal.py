"""Thermal extensions (docs/models.md#thermal-extensions): Model I (parameters follow laws of
temperature), Model II (a thermal friction term dF(T)) and the lumped self-heating model."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from ..errors import InputError, shorten
from ..waveforms import Waveform, waveform_from_dict
from ._parse import by_symbol, num
from .laws import Law


@dataclass(frozen=True)
class ModelI:
    """Model I (docs/models.md#model-i): parameters of the base model follow laws of temperature.

    Parameters
    ----------
    laws : dict, default {}
        Parameter name -> ``Law``: each named friction parameter (``sigma0``, ``fc``, ...) is the law's value
        at the temperature, in the parameter's unit; the friction model holds None for it.

    Raises
    ------
    InputError
        ``laws`` not a dict of parameter names to Law objects.
    """

    laws: dict = field(default_factory=dict)
    model = "I"

    def __post_init__(self):
        if not (isinstance(self.laws, dict) and all(isinstance(k, str) and isinstance(v, Law)
                                                    for k, v in self.laws.items())):
            raise InputError(f"laws must be a dict of parameter name -> Law (e.g. {{'fc': tf.Linear(...)}}), got "
                             f"{type(self.laws).__name__} {shorten(self.laws)}")

    def to_dict(self):
        d = {"model": "I"}
        d.update({k: law.to_dict() for k, law in self.laws.items()})
        return d


@dataclass(frozen=True)
class ModelII:
    """Model II (docs/models.md#model-ii): base model plus thermal-induced friction dF(T) [N].

    ``form="scale"`` (default): F' = (1 + dF(T)/F_ref) F_base, F_ref the base model's steady
    sliding friction (fc) -- Eq. (12) in steady sliding, smooth and passive through v = 0.
    ``form="offset"``: F' = F_base + dF(T) s(v), s a sign smoothed over ``v_smooth``.

    Parameters
    ----------
    dF : Law
        The thermal-induced friction dF(T) [N] (N m for a joint).
    form : {"scale", "offset"}, default "scale"
        How dF enters the friction force (above).

    Raises
    ------
    InputError
        ``dF`` not a Law; an unknown ``form``.
    """

    dF: Law
    form: str = "scale"
    model = "II"

    def __post_init__(self):
        if not isinstance(self.dF, Law):
            raise InputError(f"dF must be a Law (e.g. tf.Linear(a, b)), got {type(self.dF).__name__} {shorten(self.dF)}")
        if not isinstance(self.form, str) or self.form not in ("scale", "offset"):
            raise InputError(f"[thermal]: 'form' must be \"scale\" or \"offset\", got {self.form!r}")

    def to_dict(self):
        return {"model": "II", "form": self.form, "dF": self.dF.to_dict()}



@dataclass(frozen=True)
class Heat:
    """Lumped thermal model of the friction interface (docs/models.md#self-heating).

    The temperature becomes a state::

        C_th T' = eta |F v_r| - (T - T_amb) / R_th + P_ext(t),    T(0) = T_0.

    ``heat_capacity`` C_th [J/K], ``thermal_resistance`` R_th [K/W] to ambient, ``heat_fraction``
    eta (0..1) of the friction power that heats the interface, ``ambient_temperature`` T_amb
    [degC] (None: the temperature given to ``simulate``), ``initial_temperature`` T_0 (None:
    T_amb), ``external_heat`` P_ext(t) [W] (a waveform, e.g. the paper's heater; None: none).

    Parameters
    ----------
    heat_capacity : float
        The interface's heat capacity C_th [J/K], > 0.
    thermal_resistance : float
        The thermal resistance R_th [K/W] to ambient, > 0.
    heat_fraction : float, default 1.0
        The fraction eta (0..1) of the friction power that heats the interface.
    ambient_temperature : float, optional
        T_amb [C]; None: the temperature given to ``simulate``.
    initial_temperature : float, optional
        T_0 [C]; None: T_amb.
    external_heat : Waveform, optional
        An external heat input P_ext(t) [W] (the paper's heater); None: none.

    Raises
    ------
    InputError
        A value that is not a number or out of its range, named.
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
            v = num(v, where, sym)
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
        kw = by_symbol(cls, d, where, ("C_th", "R_th"), what="the heat model")
        if "external_heat" in kw:
            kw["external_heat"] = waveform_from_dict(kw["external_heat"], f"{where} P_ext", base_dir)
        return cls(**kw)




__all__ = ["ModelI", "ModelII", "Heat"]
