"""What every friction model shares: its description (``Description``: the facts the model file, the checks, the
reports, the FMU and identification derive from), its parameters as dataclass fields, their file form, and the
decorator that registers a description on its class (``friction_model``)."""

from __future__ import annotations

from dataclasses import KW_ONLY, MISSING, dataclass, field, fields, replace

from ..._bridge import FRICTION_CODES, PARAMETER_UNITS
from ...errors import InputError, unknown_keys
from .._parse import num, num_array
from ..domains import NEGATIVE_SIDE, PARAMETER_DOMAIN
from ..sides import with_ripple_table


@dataclass(frozen=True)
class Array:
    """A parameter that is an array, one value per element (GMS's ``k`` and ``w``): never a law of temperature.

    Parameters
    ----------
    unit : str
        Each element's unit (``"N/m"``; ``""``: dimensionless).
    element : str
        What element ``{e}`` (from 1) is, as the FMU's variable describes it.
    role : str
        The FMU binary's role of the array's values (core/fmu/fmu_common.c: ``gms_k``, ``gms_w``).
    """

    unit: str
    element: str
    role: str


@dataclass(frozen=True)
class Description:
    """One friction model's facts, written once (docs/architecture.md#adding-a-friction-model): the class it
    decorates (``friction_model``) adds its parameters, their defaults and which are required (the dataclass's
    fields); their units and domains are the core's and ``models/domains.py``'s, one per parameter.

    Parameters
    ----------
    name : str
        The model file's ``model`` (``"lugre"``).
    title : str
        The model's name in reports and figures (``"LuGre"``, ``"elasto-plastic"``).
    c_id : str
        The name of its code in the binding's constants (the friction group, ``_bridge.FRICTION_CODES``; friction.h,
        ``tf_friction_kind``).
    states : tuple of (str, str), default ()
        Its states' names and units, in the core's order (a model with a state per element, GMS, says so itself).
    arrays : dict, default {}
        Its parameters that are arrays (name -> ``Array``), in the model file's order.
    fitted : dict, default {}
        The parameters fitted by default, per measurement (``"displacement"``, ``"force"``): what those data
        determine.
    bristle : bool, default False
        One bristle deflection ``z`` as its state, which an observer can follow (control.py).
    smoothed_sign : bool, default False
        A static map through the smoothed sign ``tanh(v / v_smooth)`` (stiff below v_smooth).
    dissipativity : bool, default False
        A LuGre-type model whose passivity ``dissipativity_violation`` tests.
    """

    name: str
    title: str
    c_id: str
    states: tuple = ()
    arrays: dict = field(default_factory=dict)
    fitted: dict = field(default_factory=dict)
    bristle: bool = False
    smoothed_sign: bool = False
    dissipativity: bool = False


def friction_model(description: Description):
    """Registers ``description`` on a friction model's dataclass: its name (``model``), required parameters (the
    fields without a default), arrays, states, the parameters a law may target, its sides and domains.

    Parameters
    ----------
    description : Description
        The model's facts.

    Returns
    -------
    callable
        The class decorator (above ``@dataclass``).

    Raises
    ------
    ImportError
        A description the core does not know (its ``c_id``), or a field that is not a core parameter.
    """
    def register(cls):
        names = [f.name for f in fields(cls)]
        numbers = [n for n in names if n not in description.arrays]
        if description.c_id not in FRICTION_CODES or set(numbers) - set(PARAMETER_UNITS):  # pragma: no cover
            raise ImportError(f"{cls.__name__}: not the core's friction model or parameters ({description.c_id})")
        cls.description = description
        cls.model = description.name
        cls.required = tuple(f.name for f in fields(cls) if f.default is MISSING and f.default_factory is MISSING)
        cls.arrays = tuple(description.arrays)
        cls.law_targets = tuple(numbers)
        cls.sides = tuple(n for n in numbers if n in NEGATIVE_SIDE)
        cls.domains = {n: PARAMETER_DOMAIN[n] for n in numbers}
        if "nstate" not in cls.__dict__:  # (GMS: one state per element, its own properties)
            cls.nstate = len(description.states)
            cls.state_names = tuple(n for n, _ in description.states)
            cls.state_units = tuple(u for _, u in description.states)
        return cls
    return register


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
    gives the value), ``values()``, the file form, and the state layout (set by ``friction_model``)."""

    description: Description
    model = ""
    required: tuple = ()
    nstate = 0
    state_names: tuple = ()
    state_units: tuple = ()
    #: parameters that are arrays, not numbers (never a law of temperature)
    arrays: tuple = ()
    #: the parameters a Model I law may give (every number the model takes)
    law_targets: tuple = ()
    #: its negative side's parameters (docs/models.md#direction-and-position)
    sides: tuple = ()
    #: each parameter's domain rule (models/domains.py)
    domains: dict = {}

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


__all__ = ["Description", "Array", "friction_model"]
