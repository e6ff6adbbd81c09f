"""The model: one actuator (plant, friction model, thermal extension, input, self-heating), and
its model file (TOML, docs/formats.md#model-files). ``load_model`` also takes the name of a
shipped preset."""

from __future__ import annotations

import difflib
import os
import tomllib
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path

import numpy as np
import tomli_w

from .._io import Target, atomic_write
from .._reading import read_text
from .. import _args
from ..errors import InputError, shorten, unknown_keys
from ..waveforms import Waveform, waveform_from_dict
from .domains import in_domain, own_domain
from .friction import (FRICTION_MODELS, GMS, PARAMETERS, Coulomb, Dahl, ElastoPlastic, LuGre, Stribeck,
                       check_friction_values)
from .fit_record import check_fit_record
from .laws import PWL, Law
from .load_laws import LoadLaw, law_from_dict
from .sides import STATIC_LEVELS
from .plants import MassPlant, PrescribedMotion, StickSlipPlant, plant_from_dict
from .thermal import Heat, ModelI, ModelII


@dataclass(frozen=True)
class Model:
    """One actuator: plant, friction model, thermal extension (or None), input (or None) and
    lumped thermal model of self-heating (or None).

    Parameters
    ----------
    plant : StickSlipPlant or MassPlant or PrescribedMotion
        What the friction acts in.
    friction : LuGre or Coulomb or Stribeck or Dahl or ElastoPlastic or GMS
        The friction model (None for each parameter a Model I law gives).
    thermal : ModelI or ModelII, optional
        The thermal extension; None: friction independent of temperature.
    input : Waveform, optional
        The drive (a model file's ``[input]``); ``simulate(input=...)`` overrides it.
    name : str, optional
        The model's name (a preset's, a fit's).
    description : str, optional
        A sentence on what the model is.
    heat : Heat, optional
        The lumped thermal model of self-heating; the temperature becomes a state.
    provenance : dict, optional
        Where a fitted model came from (docs/formats.md#provenance); not part of the physics (two models that
        differ only here compare equal).

    Raises
    ------
    InputError
        A part of the wrong type, named (``Model: 'plant' must be a StickSlipPlant, ...``); a law for a parameter
        the friction model also gives, or physically impossible values (fs < fc, ...), named.

    Examples
    --------
    >>> import thermofriction as tf
    >>> m = tf.Model(plant=tf.MassPlant(mass=1.0), friction=tf.LuGre(sigma0=1e5, sigma1=300.0, fc=1.0),
    ...              input=tf.Sine(amplitude=2.0, frequency=1.0))
    >>> res = tf.simulate(m, duration=0.5, sample_rate=100.0)
    >>> res.displacement.shape
    (51,)
    """

    plant: StickSlipPlant | MassPlant | PrescribedMotion
    friction: LuGre | Coulomb | Stribeck | Dahl | ElastoPlastic | GMS
    thermal: ModelI | ModelII | None = None
    input: Waveform | None = None
    name: str | None = None
    description: str | None = None
    heat: Heat | None = None
    #: where a fitted model came from (the [provenance] table, docs/formats.md#provenance): the data's
    #: hash, the method, the date, the version, the options; None for a model written by hand. Not
    #: part of the model's physics: two models that differ only here compare equal.
    provenance: dict | None = field(default=None, compare=False)

    def __post_init__(self):
        # the parts' types first, so that Model(None, None) names the argument
        for name, ok, what in (("plant", (StickSlipPlant, MassPlant, PrescribedMotion),
                                "StickSlipPlant, MassPlant or PrescribedMotion"),
                               ("friction", tuple(FRICTION_MODELS.values()), "friction model (LuGre, Coulomb, ...)"),
                               ("thermal", (ModelI, ModelII, type(None)), "ModelI, ModelII or None"),
                               ("input", (Waveform, type(None)), "Waveform or None")):
            if not isinstance(getattr(self, name), ok):
                raise InputError(f"Model: '{name}' must be a {what}, got {shorten(getattr(self, name))}")
        for name in ("name", "description"):
            if getattr(self, name) is not None and not isinstance(getattr(self, name), str):
                raise InputError(f"Model: '{name}' must be a string, got {shorten(getattr(self, name))}")
        laws = self.thermal.laws if isinstance(self.thermal, ModelI) else {}
        given = self.friction.values()
        for pname, law in laws.items():
            if pname not in self.friction.law_targets:
                raise InputError(f"[thermal]: '{pname}' is not a parameter of {self.friction.model}")
            if pname in given:
                raise InputError(f"'{pname}' is given both as a number in [friction] and as a law in "
                                 f"[thermal]; give it once")
            if not isinstance(law, Law):
                raise InputError(f"[thermal]: '{pname}' must be a law")
            if isinstance(law, PWL):
                law.check_points(f"[thermal] {pname}")
        for pname in self.friction.required:
            if pname not in given and pname not in laws:
                raise InputError(f"[friction]: missing '{pname}' (a number here, or a law in [thermal])")
        check_friction_values(self._number_values(), "[friction]")
        if isinstance(self.thermal, ModelII):
            if not isinstance(self.thermal.dF, Law):
                raise InputError("[thermal]: 'dF' must be a law")
            if isinstance(self.thermal.dF, PWL):
                self.thermal.dF.check_points("[thermal] dF")
        if self.heat is not None and not isinstance(self.heat, Heat):
            raise InputError("'heat' must be a Heat model (the [heat] section)")
        if self.provenance is not None:
            check_provenance(self.provenance, "[provenance]")

    def _number_values(self):
        v = self.friction.values()
        level, coulomb = STATIC_LEVELS[0]  # fs not given: fs = fc (no Stribeck effect)
        if level not in v and coulomb in v:
            v[level] = v[coulomb]
        return v

    # -- parameters at a temperature ------------------------------------------------------
    @property
    def laws(self) -> dict:
        return dict(self.thermal.laws) if isinstance(self.thermal, ModelI) else {}

    def parameters_at(self, T: float, load: float | None = None) -> dict:
        """Every friction parameter's value at temperature T (Model I laws applied), at ``load`` for a law of load
        (models/load_laws.py; required there)."""
        v = self.friction.values()
        for pname, law in self.laws.items():
            if isinstance(law, LoadLaw) and load is not None:
                v[pname] = law.value(float(T), float(load))
            else:
                v[pname] = law(float(T))
        level, coulomb = STATIC_LEVELS[0]
        if level not in v:
            v[level] = v[coulomb]
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

    def unphysical_over_range(self, points: int = 41) -> str | None:
        """Where, over each law's declared range, the model leaves its physical domain (a Model I
        parameter out of its domain, Model II's lambda <= 0), or None. A fitted model must pass this:
        then it simulates anywhere in its range."""
        for name, law in self.laws.items():
            if law.range is None or isinstance(law, LoadLaw):  # (a law of load: checked at its fitted conditions)
                continue
            T = np.linspace(law.range[0], law.range[1], points)
            ok = in_domain(name, law(T))
            if not ok.all():
                i = int(np.argmin(ok))
                return f"'{name}' is {float(law(T[i])):.4g} at {T[i]:.4g} C ({own_domain(name) or 'finite'} required)"
        if isinstance(self.thermal, ModelII) and self.thermal.form == "scale" and self.thermal.dF.range is not None:
            T = np.linspace(self.thermal.dF.range[0], self.thermal.dF.range[1], points)
            lam = np.atleast_1d(self.thermal_factor(T))
            if not np.all(np.isfinite(lam) & (lam > 0)):
                i = int(np.argmin(np.where(np.isfinite(lam), lam, -np.inf)))
                return f"Model II's lambda(T) = 1 + dF/fc is {lam[i]:.4g} at {T[i]:.4g} C (friction would reverse)"
        return self._level_below_coulomb(points)

    def _level_below_coulomb(self, points: int) -> str | None:
        """Where, over the laws' common range, a Model I static level falls below its Coulomb level (fs < fc, each a
        law or a constant): a relation no single law's domain holds, which a fitted constant fs beside a falling fc
        broke at the range's widened end (the model then could not be simulated at its own range's low end)."""
        rng = self.temperature_range() if isinstance(self.thermal, ModelI) else None
        if rng is None:
            return None
        T, values = np.linspace(rng[0], rng[1], points), self.friction.values()

        def at(name):
            if isinstance(self.laws.get(name), LoadLaw):
                return None
            if name in self.laws:
                return np.atleast_1d(self.laws[name](T))
            return None if values.get(name) is None else np.full(T.shape, float(values[name]))
        for level, coulomb in STATIC_LEVELS:
            a, b = at(level), at(coulomb)
            if a is not None and b is not None and np.any(a < b):
                i = int(np.argmax(a < b))
                return f"'{level}' ({a[i]:.4g}) is below '{coulomb}' ({b[i]:.4g}) at {T[i]:.4g} C"
        return None

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
        if self.provenance:
            d["provenance"] = _toml_plain(self.provenance)
        return d

    def to_toml(self) -> str:
        return tomli_w.dumps(self.to_dict())

    def save(self, path):
        """Writes the model file atomically (temporary file, then rename)."""
        text = self.to_toml()
        if isinstance(path, Target):  # the command line's checked output (a device, a link, a set member)
            with atomic_write(path, "w") as fh:
                fh.write(text)
            return
        try:
            target = Path(os.fspath(path))
        except TypeError:
            raise InputError(f"save: path must be a file name, got {shorten(path)}") from None
        if target.is_dir():
            raise InputError(f"{target}: is a folder; give a file name for the model (e.g. {target / 'model.toml'})")
        try:
            with atomic_write(target, "w") as fh:
                fh.write(text)
        except OSError as e:
            raise InputError(f"{target}: cannot write ({e.strerror or e})") from None

    def with_friction(self, **values) -> "Model":
        return replace(self, friction=self.friction.with_values(**values))


_TOP_KEYS = {"name", "description", "plant", "friction", "thermal", "heat", "input", "provenance"}

#: the [provenance] table's keys (docs/formats.md#provenance): strings, but for the lists and the options table
PROVENANCE_KEYS = ("method", "data", "data_sha256", "fit_files", "held_out_files", "date", "thermofriction",
                   "initial_model", "command", "options", "fit_record")


def _toml_plain(v):
    """Values TOML can hold: None dropped, tuples as lists, NumPy scalars as Python numbers."""
    if isinstance(v, dict):
        return {str(k): _toml_plain(x) for k, x in v.items() if x is not None}
    if isinstance(v, (list, tuple)):
        return [_toml_plain(x) for x in v if x is not None]
    if isinstance(v, np.generic):
        return v.item()
    return v


def check_provenance(p, where="[provenance]") -> dict:
    """The [provenance] table, checked: known keys; strings, lists of strings (the file lists) and a
    table of plain values (options)."""
    if not isinstance(p, dict):
        raise InputError(f"{where} must be a table")
    unknown = set(p) - set(PROVENANCE_KEYS)
    if unknown:
        raise InputError(f"{where}: {unknown_keys(unknown, PROVENANCE_KEYS)}")
    for key, value in p.items():
        if key in ("fit_files", "held_out_files"):
            if not isinstance(value, (list, tuple)) or not all(isinstance(x, str) for x in value):
                raise InputError(f"{where}: '{key}' must be a list of file names, got {shorten(value)}")
        elif key == "fit_record":
            check_fit_record(value, f"{where[:-1]}.fit_record]")
        elif key == "options":
            if not isinstance(value, dict):
                raise InputError(f"{where}: 'options' must be a table, got {shorten(value)}")
            for k, x in value.items():  # e.g. starts = 8, free = ["m_e"], laws = { fc = "linear" }
                items = list(x.values()) if isinstance(x, dict) else x if isinstance(x, (list, tuple)) else [x]
                if not all(isinstance(i, (str, bool, int, float)) for i in items):
                    raise InputError(f"{where}: options '{k}' must be a string, number, true/false, or a list or "
                                     f"table of them, got {shorten(x)}")
        elif not isinstance(value, str):
            raise InputError(f"{where}: '{key}' must be a string, got {shorten(value)}")
    return p


def model_from_dict(d: dict, source: str = "<model>", base_dir=None, friction_from=None) -> Model:
    """Builds a model from a parsed model file; errors name the file and the key.

    Parameters
    ----------
    d : dict
        The parsed TOML: ``[plant]``, ``[friction]``, and optionally ``[thermal]``, ``[input]``, ``[heat]``,
        ``name``, ``description``, ``[provenance]``.
    source : str, default "<model>"
        The file's name (or a preset's), for the messages.
    base_dir : str or os.PathLike, optional
        The folder that relative file names (a sampled input's ``file``) are read from.
    friction_from : callable, optional
        For a file without a ``[friction]`` section: a function of the parsed plant and input that returns one
        (identification's starting values from the data).

    Returns
    -------
    Model

    Raises
    ------
    InputError
        A missing section, an unknown key, a bad value or physically impossible values, named with
        ``source`` and the key.
    """
    try:
        fr = d.get("friction")
        bare = isinstance(fr, dict) and set(fr) == {"model"}  # a friction model named, no values: from the data
        if friction_from is not None and ("friction" not in d or bare) and isinstance(d.get("plant"), dict):
            inp = waveform_from_dict(d["input"], "[input]", base_dir) if isinstance(d.get("input"), dict) else None
            kind = {"model": fr["model"]} if bare else {}
            d = {**d, "friction": friction_from(plant_from_dict(d["plant"]), inp, **kind)}
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
            friction = replace(friction, **{k: None for k in thermal.laws if k in friction.law_targets})
        inp = waveform_from_dict(d["input"], "[input]", base_dir) if "input" in d else None
        heat = Heat.from_dict(d["heat"], "[heat]", base_dir) if "heat" in d else None
        for key in ("name", "description"):
            if key in d and not isinstance(d[key], str):
                raise InputError(f"'{key}' must be a string")
        provenance = check_provenance(d["provenance"]) if "provenance" in d else None
        return Model(plant, friction, thermal, inp, d.get("name"), d.get("description"), heat, provenance)
    except InputError as e:
        raise InputError(f"{source}: {e}") from None


def require_actuator(model: Model, task: str):
    """Datasets (docs/formats.md#datasets) record a stick-slip actuator: voltage in, end-effector displacement out.

    Parameters
    ----------
    model : Model
        The model a task is asked to run on a dataset.
    task : str
        The task (``"synthesize"``), for the message.

    Returns
    -------
    None

    Raises
    ------
    InputError
        The model's plant is not a ``StickSlipPlant``.
    """
    if not isinstance(model.plant, StickSlipPlant):
        raise InputError(f"{task} works on the stick-slip actuator (datasets record its voltage and displacement); "
                         f"this model's plant is '{model.plant.type}'")


PRESETS = ("li2009-model-i", "li2009-model-ii", "li2009-base", "li2009-self-heating", "canudas1995", "stage-model-i")


def preset_hint(name: str) -> str:
    """For a name that is not a preset: `` (did you mean the preset 'X'?)`` for a near miss, else the list."""
    close = difflib.get_close_matches(name, PRESETS, n=1, cutoff=0.6)
    return f" (did you mean the preset '{close[0]}'?)" if close else f" (presets: {', '.join(PRESETS)})"


def preset_path(name: str):
    """The shipped file of a preset.

    Parameters
    ----------
    name : str
        A preset's name (``PRESETS``).

    Returns
    -------
    pathlib.Path
        The preset's TOML file inside the installed package.

    Raises
    ------
    None
        Nothing is checked: an unknown name gives a path that does not exist (check ``name in PRESETS``).
    """
    return resources.files("thermofriction").joinpath("presets", f"{name}.toml")


def load_model(source, friction_from=None) -> Model:
    """Loads a model file (TOML, docs/formats.md#model-files), or a shipped preset by name (``PRESETS``).

    Parameters
    ----------
    source : str or os.PathLike
        A model file's path, or a preset's name (``"li2009-model-i"``); a file of that name comes first.
    friction_from : callable, optional
        For a file without a ``[friction]`` section: a function of the parsed plant and input that returns
        one (identification's starting values from the data; ``model_from_dict``).

    Returns
    -------
    Model
        The model, checked: plant, friction model, thermal extension, heat model and input.

    Raises
    ------
    InputError
        A source that is not a path or a preset; a file that cannot be read; a bad key or value, named with
        its file and section (``li2009.toml: [friction] sigma0 must be positive, got -1``).

    Examples
    --------
    >>> import thermofriction as tf
    >>> model = tf.load_model("li2009-model-i")
    >>> model.name
    'li2009-model-i'
    >>> type(model.friction).__name__
    'LuGre'
    """
    _args.path(source, "source")
    _args.function(friction_from, "friction_from")
    source = os.fspath(source)
    if isinstance(source, bytes):
        source = os.fsdecode(source)
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
            hint = preset_hint(source) if os.sep not in source and not source.endswith(".toml") else ""
            raise InputError(f"{source}: no such file{hint}")
        try:
            text = read_text(p, "model file (TOML)")
        except OSError as e:
            raise InputError(f"{source}: cannot read ({e.strerror or e})") from None
        except UnicodeDecodeError as e:
            raise InputError(f"{source}: not UTF-8 text ({e.reason} at byte {e.start})") from None
        base_dir = p.parent
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{source}: TOML syntax error: {e}") from None
    except RecursionError:  # tomllib recurses once per level of nested arrays or inline tables
        raise InputError(f"{source}: TOML nested too deeply") from None
    return model_from_dict(data, source, base_dir, friction_from)



__all__ = ["Model", "model_from_dict", "require_actuator", "PRESETS", "preset_path", "preset_hint", "load_model"]
