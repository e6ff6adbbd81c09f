"""Laws of temperature and load (docs/models.md#laws-of-temperature-and-load): a friction parameter as a Model I
temperature law f(T) combined with a law of the run's load L (a normal force [N] or a load torque [N m]).

With ``s = |L|`` (or ``S tanh(|L|/S)`` with a ``saturation`` S, the load-dependent part levelling off above S)::

    product, proportional:  p = f(T) s                + c T s     (a Coulomb level fc = mu(T) |N|)
    product, affine:        p = f(T) (1 + k s)        + c T s     (f(T): the level at zero load)
    sum,     affine:        p = f(T) + k s            + c T s     (a gear's load-dependent part beside f(T))

``c`` (``interaction``, optional) is a fitted interaction between temperature and load. This module is the one place
in Python that knows a load law: its value, its derivatives in every coefficient (for the chain rule of a joint fit),
its range of validity in load and the warning outside it, its file form, and the fields of the C core's load term
(law.h: tf_load_term, the same equations in C, evaluated by the simulator and the real-time API at the run's load).
A model holding one is refused where the load is not an input yet (the online temperature estimator), with one
clear message.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, TemperatureRangeWarning, unknown_keys
from ..results import Finding, emit
from ._parse import num
from .laws import Law, _check_range, law_from_dict as temperature_law_from_dict

LOAD_KINDS = ("proportional", "affine")
COMBINES = ("product", "sum")
#: the keys of a load table, besides ``law``
LOAD_KEYS = ("k", "saturation", "combine", "interaction", "range")
#: a load within this fraction of its range's span of the range's ends is inside it
LOAD_RANGE_TOLERANCE = 0.02


class LoadRangeWarning(TemperatureRangeWarning):
    """A load outside the range a load law was calibrated on: its value there is an extrapolation (a law's range
    warning, reported wherever a temperature range's is)."""


@dataclass(frozen=True)
class LoadTerm:
    """How a parameter depends on the load (module docstring).

    Parameters
    ----------
    kind : {"proportional", "affine"}
        Proportional: the temperature law times the load's magnitude. Affine: a part that grows by ``k`` per unit
        of load.
    k : float, optional
        The affine kind's gain: per unit of load relative to f(T) in a product [1/N or 1/(N m)], in the parameter's
        unit per unit of load in a sum. Required for "affine", refused for "proportional".
    saturation : float, optional
        S > 0: the load's magnitude enters as S tanh(|L|/S); None: as |L|. Held, not fitted.
    combine : {"product", "sum"}, default "product"
        How the load part combines with the temperature law; "sum" needs the affine kind.
    interaction : float, optional
        c: a term c T s added (fitted where given; 0 is a start).
    range : tuple of float, optional
        The calibrated load magnitudes |L| (low, high), 0 <= low < high; a value asked outside it warns
        (LoadRangeWarning).

    Raises
    ------
    InputError
        An unknown kind or combination, a missing or extra ``k``, a saturation not > 0, a number that is not one.
    """

    kind: str
    k: float | None = None
    saturation: float | None = None
    combine: str = "product"
    interaction: float | None = None
    range: tuple | None = None

    def __post_init__(self):
        where = "load law"
        if self.kind not in LOAD_KINDS:
            raise InputError(f"{where}: 'law' must be one of {', '.join(LOAD_KINDS)}, got {self.kind!r}")
        if self.combine not in COMBINES:
            raise InputError(f"{where}: 'combine' must be \"product\" or \"sum\", got {self.combine!r}")
        if self.kind == "proportional" and self.combine == "sum":
            raise InputError(f"{where}: a proportional load law multiplies the temperature law (fc = mu(T) |load|): "
                             f"combine = \"product\"; for a part added to it use law = \"affine\"")
        if (self.k is None) == (self.kind == "affine"):
            raise InputError(f"{where}: 'k' is " + ("required by law = \"affine\"" if self.kind == "affine" else
                                                     "not a coefficient of law = \"proportional\""))
        for name in ("k", "saturation", "interaction"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, num(getattr(self, name), where, name))
        if self.saturation is not None and not self.saturation > 0:
            raise InputError(f"{where}: 'saturation' must be positive, got {self.saturation!r}")
        object.__setattr__(self, "range", _check_range(self.range, where))
        if self.range is not None and self.range[0] < 0:
            raise InputError(f"{where}: 'range' is of the load's magnitude |load|: low >= 0, got {list(self.range)}")

    def names(self) -> list:
        """The fitted coefficients' names, ``load.k`` and ``load.interaction`` where they apply."""
        return [f"load.{n}" for n in ("k", "interaction") if getattr(self, n) is not None]

    def magnitude(self, load):
        """s: the load's magnitude, saturated where a saturation is given."""
        a = np.abs(np.asarray(load, float))
        return a if self.saturation is None else self.saturation * np.tanh(a / self.saturation)

    def to_dict(self) -> dict:
        d = {"law": self.kind}
        for name in ("k", "saturation", "interaction"):
            if getattr(self, name) is not None:
                d[name] = float(getattr(self, name))
        d["combine"] = self.combine
        if self.range is not None:
            d["range"] = [float(self.range[0]), float(self.range[1])]
        return d

    def in_range(self, load) -> bool:
        """Whether every ``load``'s magnitude lies in the calibrated range (within LOAD_RANGE_TOLERANCE of its
        span)."""
        if self.range is None:
            return True
        tol = LOAD_RANGE_TOLERANCE * (self.range[1] - self.range[0])
        L = np.abs(np.atleast_1d(np.asarray(load, float)))
        return bool(np.all((L >= self.range[0] - tol) & (L <= self.range[1] + tol)))


@dataclass(frozen=True, eq=False, repr=False)
class LoadLaw(Law):
    """A friction parameter as a law of temperature and load: ``base`` f(T) combined with ``load`` (LoadTerm).

    Parameters
    ----------
    base : Law
        The temperature law f(T) (any Model I kind but a table, whose values have no sensitivities).
    load : LoadTerm
        The load dependence.

    Raises
    ------
    InputError
        ``base`` not a temperature law or ``load`` not a LoadTerm; evaluated without a load.

    Examples
    --------
    >>> from thermofriction.models import LoadLaw, LoadTerm, Linear
    >>> law = LoadLaw(Linear(a=-1e-3, b=0.12), LoadTerm("proportional"))
    >>> round(float(law.value(20.0, 50.0)), 6)
    5.0
    """

    base: Law
    load: LoadTerm

    @property
    def kind(self):
        return self.base.kind

    @property
    def range(self):
        return self.base.range

    def __post_init__(self):
        if not isinstance(self.base, Law) or isinstance(self.base, LoadLaw):
            raise InputError(f"a load law's base must be a temperature law (e.g. tf.Linear(a, b)), got {self.base!r}")
        if not isinstance(self.load, LoadTerm):
            raise InputError(f"a load law's load must be a LoadTerm, got {type(self.load).__name__}")

    def core_fields(self):
        """The temperature law's fields and ``load``: the C core's load term (law.h, tf_load_term) as (kind,
        combine, k, saturation (0: none), interaction (0/1), c)."""
        t = self.load
        return {**self.base.core_fields(),
                "load": (t.kind, t.combine, 0.0 if t.k is None else float(t.k),
                         0.0 if t.saturation is None else float(t.saturation), int(t.interaction is not None),
                         0.0 if t.interaction is None else float(t.interaction))}

    # -- coefficients ------------------------------------------------------------------------
    def coefficient_names(self):
        return self.base.coefficient_names() + self.load.names()

    def coefficients(self):
        return self.base.coefficients() + [float(getattr(self.load, n[5:])) for n in self.load.names()]

    def with_coefficients(self, coefficients):
        c = [float(x) for x in coefficients]
        nb = len(self.base.coefficient_names())
        load = dataclasses.replace(self.load, **{n[5:]: v for n, v in zip(self.load.names(), c[nb:])})
        return dataclasses.replace(self, base=self.base.with_coefficients(c[:nb]), load=load)

    def scaled(self, factor):
        raise InputError("a law of the load cannot be scaled as a whole; scale its temperature law")

    # -- values ------------------------------------------------------------------------------
    def evaluate(self, T):
        raise InputError(f"a law of the load ({self.load.kind}) needs the load: use value(T, load)")

    def value(self, T, load, warn: bool = True):
        """The parameter at temperature ``T`` [C] and ``load`` (scalars or arrays of one shape); warns
        (LoadRangeWarning) at a load outside the calibrated range."""
        if warn and not self.load.in_range(load):
            lo, hi = self.load.range
            emit([Finding(LoadRangeWarning, f"load {np.ravel(load)[0]:.4g} outside the range of |load| {lo:.4g}..{hi:.4g} "
                                            "the load law was calibrated on: its value there is an extrapolation")])
        f = np.asarray(self.base(np.asarray(T, float)), float)
        s = self.load.magnitude(load)
        term = self.load
        if term.kind == "proportional":
            v = f * s
        elif term.combine == "product":
            v = f * (1.0 + term.k * s)
        else:
            v = f + term.k * s
        if term.interaction is not None:
            v = v + term.interaction * np.asarray(T, float) * s
        return float(v) if np.ndim(v) == 0 else v

    def coefficient_derivatives(self, T: float, load: float) -> np.ndarray:
        """d value(T, load) / d each coefficient (``coefficient_names``' order): the temperature law's by central
        differences (exact for the kinds linear in their coefficients, 1e-8 relative for exp's rate), the load
        term's analytically."""
        term, s, T = self.load, float(self.load.magnitude(load)), float(T)
        c = np.array(self.base.coefficients(), float)
        out = []
        mult = s if term.kind == "proportional" else (1.0 + term.k * s if term.combine == "product" else 1.0)
        for k in range(c.size):
            h = 1e-4 * (abs(c[k]) if c[k] != 0 else max(float(np.max(np.abs(c))), 1e-300))
            up, down = c.copy(), c.copy()
            up[k] += h
            down[k] -= h
            out.append(mult * (float(self.base.with_coefficients(up)(T)) - float(self.base.with_coefficients(down)(T)))
                       / (2 * h))
        if term.k is not None:
            out.append(float(self.base(T)) * s if term.combine == "product" else s)
        if term.interaction is not None:
            out.append(T * s)
        return np.array(out)

    # -- file form ---------------------------------------------------------------------------
    def to_dict(self) -> dict:
        d = self.base.to_dict()
        d["load"] = self.load.to_dict()
        return d


def load_term_from_dict(d, where: str) -> LoadTerm:
    """A load term from its inline table, e.g. ``{ law = "affine", k = 2e-3, combine = "sum" }``.

    Parameters
    ----------
    d : dict
        The parsed table.
    where : str
        Its place in the file, for the messages.

    Returns
    -------
    LoadTerm

    Raises
    ------
    InputError
        Not a table, an unknown key, or a LoadTerm's own refusal, named with ``where``.
    """
    if not isinstance(d, dict):
        raise InputError(f"{where} load: must be a table such as {{ law = \"proportional\" }}")
    unknown = set(d) - {"law", *LOAD_KEYS}
    if unknown:
        raise InputError(f"{where} load: {unknown_keys(unknown, ['law', *LOAD_KEYS], 'a load law')}")
    try:
        return LoadTerm(d.get("law"), **{k: d[k] for k in LOAD_KEYS if k in d})
    except InputError as e:
        raise InputError(f"{where} load: {str(e).partition(': ')[2]}") from None


def law_from_dict(d, where: str) -> Law:
    """A law of temperature (models/laws.py) or, with a ``load`` table, of temperature and load.

    Parameters
    ----------
    d : dict
        The parsed inline table of the law.
    where : str
        Its place in the file (``"[thermal] fc"``), for the messages.

    Returns
    -------
    Law
        A temperature law, or a LoadLaw.

    Raises
    ------
    InputError
        A refusal of either law's reader, named with ``where``.
    """
    if not (isinstance(d, dict) and "load" in d):
        return temperature_law_from_dict(d, where)
    base = temperature_law_from_dict({k: v for k, v in d.items() if k != "load"}, where)
    if not base.coefficient_names() and base.kind == "table":
        raise InputError(f"{where}: a load law's temperature law cannot be a 'table' (no sensitivities); use 'pwl'")
    return LoadLaw(base, load_term_from_dict(d["load"], where))


def load_laws(model) -> dict:
    """The model's laws of load: parameter name -> LoadLaw."""
    return {n: law for n, law in getattr(model, "laws", {}).items() if isinstance(law, LoadLaw)}


__all__ = ["LoadTerm", "LoadLaw", "LoadRangeWarning", "load_term_from_dict", "law_from_dict", "load_laws"]
