"""Temperature laws (docs/models.md#model-i): a parameter, or Model II's dF, as a function of the
temperature T [degC].

Each law owns its coefficients: their names in the model file (``keys``), the ones that can be
fitted (``coefficient_names``), their values and units. Identification and the file reader ask the
law; nothing else knows what a law's coefficients are. Values are computed by the C core, the code
the simulator runs.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, fields

import numpy as np

from .. import _bridge
from ..errors import InputError, unknown_keys
from ._parse import num, num_array


#: [degC] a law holds within this of its calibrated range (in_range): the temperatures a fit groups as one
#: (identification's SAME_TEMPERATURE)
RANGE_TOLERANCE = 0.05


@dataclass(frozen=True, eq=False)
class Law:
    """A function of temperature T [degC]. ``range`` is the calibrated interval (or None)."""

    kind = ""
    #: the keys of the law's inline table in a model file, besides ``law`` and ``range``
    keys = ()

    def __post_init__(self):
        # checked at construction (Exp(a="1") or a NaN coefficient fail here, naming the coefficient)
        for k in self.keys:
            object.__setattr__(self, k, num(getattr(self, k), f"law '{self.kind}'", k))
        object.__setattr__(self, "range", _check_range(self.range, f"law '{self.kind}'"))

    def core_fields(self) -> dict:
        """The numbers the C core's tf_law takes (a, b, x, y)."""
        raise NotImplementedError

    # -- coefficients ------------------------------------------------------------------------
    def coefficient_names(self) -> list:
        """Names of the coefficients that can be fitted (``a``, ``values[2]``, ...), in the order
        of the C core's coefficient derivatives."""
        return list(self.keys)

    def coefficients(self) -> list:
        """Every coefficient's value, in the order of :meth:`coefficient_names`."""
        return [float(getattr(self, k)) for k in self.keys]

    def with_coefficients(self, coefficients) -> "Law":
        return dataclasses.replace(self, **dict(zip(self.keys, (float(c) for c in coefficients))))

    def coefficient_unit(self, name: str, unit: str) -> str:
        """The unit of coefficient ``name`` of a law whose value is in ``unit``."""
        return unit

    def scaled(self, factor: float) -> "Law":
        """The law times ``factor`` (every kind but exp is linear in its coefficients; a table's PCHIP too)."""
        return self.with_coefficients([c * factor for c in self.coefficients()])

    # -- values ------------------------------------------------------------------------------
    def __call__(self, T):
        return self.evaluate(T)[0]

    def evaluate(self, T):
        """(value, dvalue/dT) at T (scalars or arrays)."""
        v, d = _bridge.law_eval(self, np.ascontiguousarray(np.atleast_1d(T), dtype=float))
        if np.ndim(T) == 0:
            return float(v[0]), float(d[0])
        return v, d

    def slope(self, T):
        return self.evaluate(T)[1]

    def in_range(self, T) -> bool:
        """Whether ``T`` lies in the calibrated range, within RANGE_TOLERANCE of its ends (a run nominally at a fit's
        end temperature whose record averages a little off it is one of the fit's temperatures)."""
        rng = getattr(self, "range", None)
        if rng is None:
            return True
        T = np.atleast_1d(T)
        return bool(np.all((T >= rng[0] - RANGE_TOLERANCE) & (T <= rng[1] + RANGE_TOLERANCE)))

    # -- file form ---------------------------------------------------------------------------
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

    @classmethod
    def from_table(cls, d: dict, where: str, rng) -> "Law":
        return cls(*(num(d[k], where, k) for k in cls.keys), range=rng)

    def __eq__(self, other):
        return type(self) is type(other) and self.to_dict() == other.to_dict()

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items() if k != "law")
        return f"{type(self).__name__}({args})"


def _check_range(rng, where):
    if rng is None:
        return None
    r = num_array(rng, where, "range", 2)
    if len(r) != 2 or not r[0] < r[1]:
        raise InputError(f"{where}: 'range' must be [low, high] with low < high, got {list(rng)!r}")
    return (float(r[0]), float(r[1]))


@dataclass(frozen=True, eq=False, repr=False)
class Const(Law):
    """A constant: the value at every temperature.

    Parameters
    ----------
    value : float
        The value, in the unit of the parameter the law gives.
    range : tuple of float, optional
        The calibrated interval (low, high) [C], low < high; a simulation outside it warns
        (TemperatureRangeWarning). Default None: no range.

    Raises
    ------
    InputError
        A coefficient that is not a finite number, or a range that is not (low, high) with low < high, named.

    Examples
    --------
    >>> import thermofriction as tf
    >>> float(tf.Const(value=2e5)(30.0))
    200000.0
    """

    value: float
    range: tuple | None = None
    kind = "const"
    keys = ("value",)

    def core_fields(self):
        return {"a": self.value}


@dataclass(frozen=True, eq=False, repr=False)
class Linear(Law):
    """a T + b, linear in the temperature T [C].

    Parameters
    ----------
    a : float
        The slope, in the parameter's unit per C.
    b : float
        The value at 0 C, in the parameter's unit.
    range : tuple of float, optional
        The calibrated interval (low, high) [C], low < high; a simulation outside it warns
        (TemperatureRangeWarning). Default None: no range.

    Raises
    ------
    InputError
        A coefficient that is not a finite number, or a range that is not (low, high) with low < high, named.

    Examples
    --------
    >>> import thermofriction as tf
    >>> law = tf.Linear(a=-0.02, b=1.5, range=(20.0, 50.0))
    >>> float(law(25.0))
    1.0
    """

    a: float
    b: float
    range: tuple | None = None
    kind = "linear"
    keys = ("a", "b")

    def core_fields(self):
        return {"a": self.a, "b": self.b}

    def coefficient_unit(self, name, unit):
        return f"{unit}/C" if name == "a" else unit


@dataclass(frozen=True, eq=False, repr=False)
class Exp(Law):
    """a exp(b T), exponential in the temperature T [C].

    Parameters
    ----------
    a : float
        The value at 0 C, in the parameter's unit.
    b : float
        The rate [1/C].
    range : tuple of float, optional
        The calibrated interval (low, high) [C], low < high; a simulation outside it warns
        (TemperatureRangeWarning). Default None: no range.

    Raises
    ------
    InputError
        A coefficient that is not a finite number, or a range that is not (low, high) with low < high, named.
    """

    a: float
    b: float
    range: tuple | None = None
    kind = "exp"
    keys = ("a", "b")

    def core_fields(self):
        return {"a": self.a, "b": self.b}

    def coefficient_unit(self, name, unit):
        return "1/C" if name == "b" else unit

    def scaled(self, factor):
        return dataclasses.replace(self, a=self.a * factor)


@dataclass(frozen=True, eq=False, repr=False)
class Poly(Law):
    """sum c[i] T^i, a polynomial in the temperature T [C].

    Parameters
    ----------
    c : array_like
        The coefficients, lowest degree first; c[i] in the parameter's unit per C^i.
    range : tuple of float, optional
        The calibrated interval (low, high) [C], low < high; a simulation outside it warns
        (TemperatureRangeWarning). Default None: no range.

    Raises
    ------
    InputError
        A coefficient that is not a finite number, or a range that is not (low, high) with low < high, named.
    """

    c: np.ndarray
    range: tuple | None = None
    kind = "poly"
    keys = ("c",)

    #: a polynomial of temperature with more terms is ill-conditioned (35^20 ~ 1e31) and overflows
    #: easily; a table or pwl law follows any shape instead
    MAX_COEFFICIENTS = 16

    def __post_init__(self):
        where = "law 'poly'"
        c = num_array(self.c, where, "c")
        if c.ndim != 1 or len(c) > self.MAX_COEFFICIENTS:
            raise InputError(f"{where}: 'c' has {len(c)} coefficients, more than {self.MAX_COEFFICIENTS} (degree "
                             f"{self.MAX_COEFFICIENTS - 1}); use a 'table' or 'pwl' law for a detailed shape")
        object.__setattr__(self, "c", np.ascontiguousarray(c, dtype=float))
        object.__setattr__(self, "range", _check_range(self.range, where))

    def core_fields(self):
        return {"y": self.c}

    def coefficient_names(self):
        return [f"c[{i}]" for i in range(len(self.c))]

    def coefficients(self):
        return list(self.c)

    def with_coefficients(self, coefficients):
        return dataclasses.replace(self, c=np.array([float(c) for c in coefficients]))

    def coefficient_unit(self, name, unit):
        return unit if name == "c[0]" else f"{unit}/C^{name[2:-1]}"

    @classmethod
    def from_table(cls, d, where, rng):
        try:
            return cls(d["c"], range=rng)
        except InputError as e:
            raise InputError(f"{where}: {str(e).partition(': ')[2]}") from None


@dataclass(frozen=True, eq=False, repr=False)
class PWL(Law):
    """Linear through (T[i], values[i]); extrapolated linearly with the end segments.

    Parameters
    ----------
    T : array_like
        The breakpoints [C], strictly increasing.
    values : array_like
        The values at the breakpoints, in the parameter's unit; as many as ``T``.
    range : tuple of float, optional
        The calibrated interval (low, high) [C], low < high; a simulation outside it warns
        (TemperatureRangeWarning). Default None: no range.

    Raises
    ------
    InputError
        A coefficient that is not a finite number, or a range that is not (low, high) with low < high, named.
    """

    T: np.ndarray
    values: np.ndarray
    range: tuple | None = None
    kind = "pwl"
    keys = ("T", "values")

    def __post_init__(self):
        where = f"law '{self.kind}'"
        T = num_array(self.T, where, "T")
        values = num_array(self.values, where, "values")
        if len(T) != len(values):
            raise InputError(f"{where}: 'T' and 'values' must have the same length ({len(T)} != {len(values)})")
        if np.any(np.diff(T) <= 0):
            raise InputError(f"{where}: 'T' must increase strictly")
        object.__setattr__(self, "T", np.ascontiguousarray(T, dtype=float))
        object.__setattr__(self, "values", np.ascontiguousarray(values, dtype=float))
        object.__setattr__(self, "range", _check_range(self.range, where))

    def core_fields(self):
        return {"x": self.T, "y": self.values}

    def coefficient_names(self):
        return [f"values[{i}]" for i in range(len(self.values))]

    def coefficients(self):
        return list(self.values)

    def with_coefficients(self, coefficients):
        return dataclasses.replace(self, values=np.array([float(c) for c in coefficients]))

    def check_points(self, where):
        """A law in a model needs two points or more (the C core's model check: a one-point law is
        a constant, which 'const' says plainly)."""
        if len(self.T) < 2:
            raise InputError(f"{where}: law '{self.kind}' needs at least two points (T and values of length 2 "
                             f"or more), got {len(self.T)}; for one value use law = \"const\"")

    @classmethod
    def from_table(cls, d, where, rng):
        try:
            law = cls(d["T"], d["values"], range=rng)
        except InputError as e:
            raise InputError(f"{where}: {str(e).partition(': ')[2]}") from None
        law.check_points(where)
        return law


@dataclass(frozen=True, eq=False, repr=False)
class Table(PWL):
    """Monotone cubic (PCHIP) through (T[i], values[i]); extrapolated linearly with the end slopes.

    Parameters
    ----------
    T : array_like
        The breakpoints [C], strictly increasing.
    values : array_like
        The values at the breakpoints, in the parameter's unit; as many as ``T``.
    range : tuple of float, optional
        The calibrated interval (low, high) [C], low < high; a simulation outside it warns
        (TemperatureRangeWarning). Default None: no range.

    Raises
    ------
    InputError
        A coefficient that is not a finite number, or a range that is not (low, high) with low < high, named.
    """

    kind = "table"

    def coefficient_names(self):
        return []  # the PCHIP slopes depend on the values nonlinearly: no sensitivities


LAWS = {cls.kind: cls for cls in (Const, Linear, Exp, Poly, PWL, Table)}


def law_from_dict(d, where: str) -> Law:
    """A law from its inline table in a model file, e.g. ``{ law = "exp", a = 1.15e8, b = -0.136 }``.

    Parameters
    ----------
    d : dict
        The parsed table: ``law`` (the kind), its coefficients and an optional ``range``.
    where : str
        The table's place in the file (``"[thermal.laws] sigma0"``), for the messages.

    Returns
    -------
    Law

    Raises
    ------
    InputError
        Not a table, an unknown kind or key, a missing coefficient, a value that is not a number, named with
        ``where``.
    """
    if not isinstance(d, dict):
        raise InputError(f"{where}: a law must be a table such as {{ law = \"linear\", a = ..., b = ... }}")
    kind = d.get("law")
    if not isinstance(kind, str) or kind not in LAWS:
        raise InputError(f"{where}: 'law' must be one of {', '.join(LAWS)}, got {kind!r}")
    cls = LAWS[kind]
    unknown = set(d) - set(cls.keys) - {"law", "range"}
    if unknown:
        raise InputError(f"{where}: {unknown_keys(unknown, [*cls.keys, 'range'], f'law {kind!r}')}")
    missing = [k for k in cls.keys if k not in d]
    if missing:
        raise InputError(f"{where}: law '{kind}' needs {', '.join(missing)}")
    return cls.from_table(d, where, _check_range(d.get("range"), where))


__all__ = ["Law", "Const", "Linear", "Exp", "Poly", "PWL", "Table", "LAWS", "law_from_dict"]
