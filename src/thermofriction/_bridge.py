"""The one door to the compiled C core.

Only this module imports ``_core``. It

- reads the contract from the core itself: the parameter order, the codes of plants, friction
  models, laws, thermal extensions, waveforms, solvers, statuses and sensitivity targets, and the
  output column layout (``_core.CONSTANTS``, set by the binding from the C headers; a test parses
  the headers and fails if either side has a name the other lacks);
- turns model objects into the core's description (``model_spec``), laws and waveforms into
  theirs;
- runs simulations, with or without forward sensitivities, and turns every failure status into a
  :class:`CoreFailure` (a :class:`~thermofriction.errors.SolverError`) that names the status.

Nothing else writes an integer code or a column index.
"""

from __future__ import annotations

import math

import numpy as np

from . import _core
from .errors import SolverError

_GROUPS = _core.CONSTANTS


def _ordered(group: str) -> tuple:
    """The names of a group in code order; the codes must be 0..n-1 (they index arrays)."""
    codes = _GROUPS[group]
    names = sorted(codes, key=codes.get)
    if [codes[n] for n in names] != list(range(len(names))):  # pragma: no cover - a broken build
        raise ImportError(f"the C core's {group} codes are not 0..{len(names) - 1}: {codes}")
    return tuple(names)


#: Friction parameters in the core's order, and their units (friction.h, TF_PARAMETERS).
PARAMETERS = _ordered("parameter")
PARAMETER_UNITS = {name: _core.PARAMETER_UNITS[name] for name in PARAMETERS}
#: A negative side without any viscous term (sigma2_neg = 0) in the core, where 0 means "sigma2"
_SMALLEST = 5e-324
PLANT_CODES = dict(_GROUPS["plant"])
FRICTION_CODES = dict(_GROUPS["friction"])
LAW_CODES = dict(_GROUPS["law"])
LOAD_KIND_CODES = dict(_GROUPS["load_kind"])
LOAD_COMBINE_CODES = dict(_GROUPS["load_combine"])
THERMAL_CODES = dict(_GROUPS["thermal"])
DF_FORM_CODES = dict(_GROUPS["df_form"])
WAVEFORM_CODES = dict(_GROUPS["waveform"])
METHOD_CODES = dict(_GROUPS["method"])
METHOD_NAMES = {code: name for name, code in METHOD_CODES.items()}
STATUS_NAMES = {code: name for name, code in _GROUPS["status"].items()}
TARGET_CODES = dict(_GROUPS["target"])
HEAT_PARAMETER_INDEX = dict(_GROUPS["heat_parameter"])
PLANT_PARAMETER_INDEX = dict(_GROUPS["plant_parameter"])
COMPENSATION_CODES = dict(_GROUPS["compensation"])
PROXY_CODES = dict(_GROUPS["proxy"])
#: Output channels, in column order; after them come the friction states, then the friction work.
OUTPUTS = _ordered("output")
OUTPUT_COLUMN = {name: i for i, name in enumerate(OUTPUTS)}
LIMITS = dict(_GROUPS["limit"])
#: The friction models' parameter domains, the C checks' own table (domains.h): model -> rows
#: (parameter, rule, other parameter or None, where it applies), in the order the core checks them. Rules:
#: "positive", "non-negative", "at-least" (other), "below-deflection" (below other / sigma0),
#: "positive-or-absent" (None in a model, 0 in the core); where: "always", "stribeck" (fs != fc),
#: "offset-form" (Model II's offset form).
FRICTION_DOMAINS = dict(_core.FRICTION_DOMAINS)
#: The static level a model leaves unset follows its Coulomb level (fs = fc; the core's ``fs_follows_fc``): the
#: positive side's "at-least" rule of the core's table (the negative side's, ``*_neg``, has the core's own default).
_STATIC, _COULOMB = next((p, other) for rows in FRICTION_DOMAINS.values() for p, rule, other, _ in rows
                         if rule == "at-least" and not p.endswith("_neg"))


def n_outputs(model, friction_work: bool) -> int:
    """Columns of a simulation's output array."""
    return len(OUTPUTS) + model.friction.nstate + bool(friction_work)


def state_index(model, name: str) -> int:
    """Index of a state in the core's state vector: the plant's mechanical states, the friction
    states, then the temperature (with a heat model) and the friction work."""
    mechanical = MECHANICAL_STATES[model.plant.type]
    if name in mechanical:
        return mechanical.index(name)
    if name == "T":
        if model.heat is None:
            raise ValueError("the model has no temperature state")
        return len(mechanical) + model.friction.nstate
    raise ValueError(f"no state '{name}'")


#: The plant's mechanical states, before the friction model's (plant.h, the core's state order).
MECHANICAL_STATES = {"stick-slip": ("x_p", "v_p", "x_e", "v_e"), "mass": ("x", "v"), "prescribed": ()}


# -- descriptions ------------------------------------------------------------------------------

def law_tuple(law):
    """(kind, a, b, x, y) of a temperature law (law.h, tf_law); a law of temperature and load adds its load term
    (kind, combine, k, saturation, interaction, c) (law.h, tf_load_term)."""
    fields = law.core_fields()
    out = (LAW_CODES[law.kind], float(fields.get("a", 0.0)), float(fields.get("b", 0.0)), fields.get("x"),
           fields.get("y"))
    if "load" in fields:
        kind, combine, k, saturation, interaction, c = fields["load"]
        out += ((LOAD_KIND_CODES[kind], LOAD_COMBINE_CODES[combine], float(k), float(saturation), int(interaction),
                 float(c)),)
    return out


def waveform_tuple(waveform):
    """(kind, amplitude, frequency, rise, offset, direction, slew, t0, t, v) (waveform.h)."""
    f = waveform.core_fields()
    return (WAVEFORM_CODES[waveform.kind], float(f.get("amplitude", 0.0)), float(f.get("frequency", 0.0)),
            float(f.get("rise", 0.0)), float(f.get("offset", 0.0)), float(f.get("direction", 1.0)),
            float(f.get("slew", 0.0)), float(f.get("t0", 0.0)), f.get("t"), f.get("v"))


def _thermal_kind(model) -> str:
    return {None: "none", "I": "model-i", "II": "model-ii"}[getattr(model.thermal, "model", None)]


def model_spec(model, temperature=None, input=None, friction_work: bool = False, load=None) -> dict:
    """The dict the binding unpacks into a tf_model (see _core.c). ``temperature``: a number, a
    ``Sampled`` signal, or None; with a heat model, the ambient temperature (a number). ``load``: a number, a
    waveform, or None (NaN: none), passed only to a model whose laws read it (a load term)."""
    plant = model.plant
    c = k = T_em = m_e = k_s = v_0 = 0.0
    m = 1.0
    if plant.type == "stick-slip":
        c, k, T_em = plant.physical()
        m, m_e = plant.mass, plant.end_effector_mass
    elif plant.type == "mass":
        m, k_s, v_0 = plant.mass, plant.spring_stiffness, plant.pull_velocity
    friction = model.friction
    values = {name: v for name, v in friction.values().items() if name not in friction.arrays}
    values.setdefault(_STATIC, values.get(_COULOMB, 0.0))
    values.setdefault("vs", 1e-3)
    if values.get("sigma2_neg") == 0.0:  # 0 is "not given" in the core (friction.h, tf_side_given)
        values["sigma2_neg"] = _SMALLEST
    params = np.array([0.0 if values.get(name) is None else values[name] for name in PARAMETERS], float)
    thermal = _thermal_kind(model)
    laws = None
    if thermal == "model-i":
        laws = [law_tuple(model.thermal.laws[n]) if n in model.thermal.laws else None for n in PARAMETERS]
    T_const, T_t, T_v = math.nan, None, None
    heat = None
    if model.heat is not None:
        h = model.heat.resolved(temperature)
        heat = (h.heat_capacity, h.thermal_resistance, h.heat_fraction, h.ambient_temperature,
                h.initial_temperature, waveform_tuple(h.external_heat) if h.external_heat is not None else None)
    elif temperature is not None and getattr(temperature, "kind", None) == "sampled":
        T_t, T_v = temperature.time, temperature.value
    elif temperature is not None:
        T_const = float(temperature)
    waveform = input if input is not None else model.input
    reads_load = laws is not None and any(law is not None and len(law) > 5 for law in laws)
    load_wave, load_const = None, math.nan
    if reads_load and hasattr(load, "core_fields"):  # a waveform (the core's zero kind is its constant's slot)
        load_wave, load_const = (None, 0.0) if load.kind == "zero" else (waveform_tuple(load), math.nan)
    elif reads_load and load is not None:
        load_const = float(load)
    # the arrays (GMS's k and w) by their roles, the binding's keys ("gms_k", "gms_w")
    arrays = {a.role: np.array(getattr(friction, n), float) for n, a in friction.description.arrays.items()}
    return {
        "plant": PLANT_CODES[plant.type], "m": m, "c": c, "k": k, "T_em": T_em, "m_e": m_e, "k_s": k_s, "v_0": v_0,
        "friction": FRICTION_CODES[friction.model], "params": params,
        **arrays,
        "fs_follows_fc": int(getattr(friction, _STATIC, None) is None and _STATIC not in model.laws),
        "thermal": THERMAL_CODES[thermal],
        "laws": laws,
        "dF": law_tuple(model.thermal.dF) if thermal == "model-ii" else None,
        "dF_form": DF_FORM_CODES[model.thermal.form] if thermal == "model-ii" else DF_FORM_CODES["scale"],
        "input": waveform_tuple(waveform) if waveform is not None else _ZERO_WAVEFORM,
        "T_const": T_const, "T_t": T_t, "T_v": T_v, "load": load_wave, "load_const": load_const,
        "heat": heat, "work": int(bool(friction_work)),
    }


_ZERO_WAVEFORM = (WAVEFORM_CODES["zero"], 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, None, None)


# -- evaluations -------------------------------------------------------------------------------

def law_eval(law, T: np.ndarray):
    """(values, slopes) of a law on a contiguous float64 array of temperatures."""
    v, d = np.empty_like(T), np.empty_like(T)
    _core.law_eval(law_tuple(law), T, v, d)
    return v, d


def law_eval_load(law, T: np.ndarray, L: np.ndarray) -> tuple:
    """(values, d/dT, d/dL, derivatives in every coefficient (n x ncoef)) of a law at (T[i], L[i]), by the C core
    (law.h: tf_law_eval_load, tf_law_coef_derivative); contiguous float64 arrays of one length."""
    v, dT, dL = np.empty_like(T), np.empty_like(T), np.empty_like(T)
    nc = len(law.coefficient_names())  # the core's count must agree (its output's size is checked)
    dc = np.empty(T.size * nc)
    _core.law_eval_load(law_tuple(law), T, L, v, dT, dL, dc)
    return v, dT, dL, dc.reshape(T.size, nc)


def waveform_eval(waveform, t: np.ndarray) -> np.ndarray:
    out = np.empty_like(t)
    _core.waveform_eval(waveform_tuple(waveform), t, out)
    return out


def waveform_corners(waveform, t0: float, t1: float) -> np.ndarray:
    out = np.empty(2)
    return np.array(_core.waveform_eval(waveform_tuple(waveform), np.array([t0, t1], float), out))


def state_scale(spec: dict) -> np.ndarray:
    """Each state's characteristic magnitude (what default absolute tolerances scale with)."""
    return np.asarray(_core.state_scale(spec))


def rhs_jac(spec: dict, t: float, y, dy, J=None) -> float:
    """Right-hand side into ``dy`` and Jacobian into ``J`` (if given) at one state; returns the
    friction force there (differential tests)."""
    return _core.rhs_jac(spec, float(t), y, dy, J)


def time_rhs(spec: dict, t: float, y, n_evals: int):
    """(seconds per right-hand-side evaluation, a checksum), timed in C (benchmarks)."""
    return _core.time_rhs(spec, float(t), y, int(n_evals))


# -- runs ----------------------------------------------------------------------------------------

class CoreFailure(SolverError):
    """The integrator stopped: ``status`` names why (``nonfinite``, ``step_underflow``, ``max_steps``,
    ``bad_argument``, ``no_memory``); ``time``, ``step``, ``state`` and ``stiff`` say where."""

    def __init__(self, message, status, time, step, state, stiff):
        super().__init__(message, time=time, state=state)
        self.core_message = message
        self.status = status
        self.step = step
        self.stiff = bool(stiff)


def _failure(e) -> CoreFailure:
    message, status, t_fail, h_fail, state, stiff = e.args
    return CoreFailure(message, STATUS_NAMES.get(status, f"status {status}"), t_fail, h_fail, tuple(state), stiff)


def run(spec: dict, t: np.ndarray, out: np.ndarray, *, method: str = "auto", rtol: float = 1e-6, atol=None,
        first_step: float = 0.0, max_step: float = 0.0, max_steps: int = 10_000_000) -> dict:
    """Integrates the model ``spec`` from rest, writing its outputs at times ``t`` into ``out``
    (shape (len(t), n_outputs), in C or Fortran order). Returns the solver's statistics, ``method`` the
    one that finished the run. Raises CoreFailure."""
    try:
        stats = _core.simulate(spec, t, out, METHOD_CODES[method], float(rtol), atol, float(first_step),
                               float(max_step), int(max_steps))
    except _core.SolverError as e:
        raise _failure(e) from None
    stats["method"] = METHOD_NAMES[stats["method"]]
    return stats


def run_sensitivities(spec: dict, targets: np.ndarray, t: np.ndarray, out: np.ndarray, sens: np.ndarray, *,
                      rtol: float, atol: np.ndarray, max_steps: int) -> dict:
    """As :func:`run` (Dormand-Prince), with the forward sensitivities of every state to the
    ``targets`` (int32 rows (kind, parameter, coefficient), see :func:`target`) into ``sens``
    (shape (len(t), n_states, n_targets))."""
    try:
        return _core.simulate_sensitivities(spec, targets, t, out, sens, float(rtol), atol, 0.0, 0.0,
                                            int(max_steps))
    except _core.SolverError as e:
        raise _failure(e) from None


def prescribed_applies(spec: dict) -> bool:
    """Whether :func:`prescribed_force` applies to the model ``spec`` (prescribed.h): a prescribed plant
    driven by a sampled position at a constant temperature, no Model II, no self-heating (any friction
    model)."""
    return bool(_core.prescribed_applies(spec))


def prescribed_force(spec: dict, t: np.ndarray, names=()) -> tuple:
    """The friction force at times ``t`` under the prescribed motion of ``spec``, stepped exactly segment by
    segment (prescribed.h: no integrator and no tolerance, but in the elasto-plastic transition band), and its
    derivatives with respect to the friction parameters ``names`` (at the run's temperature): (F, dF of shape
    (len(t), len(names))). Raises CoreFailure."""
    t = np.ascontiguousarray(t, float)
    F = np.empty(t.size)
    dF = np.empty((t.size, len(names)))
    try:
        _core.prescribed_force(spec, t, F, tuple(PARAMETERS.index(n) for n in names), dF)
    except _core.SolverError as e:
        raise _failure(e) from None
    return F, dF


def target(kind: str, index: int = 0, coefficient: int = 0) -> tuple:
    """A sensitivity target: ``kind`` one of ``param``, ``law``, ``dF``, ``heat``."""
    return (TARGET_CODES[kind], int(index), int(coefficient))


def loop(plant_spec, T_plant, comp_spec, T_comp, compensation: str, gain, mass, pid, dt, substeps, x_ref, v_ref,
         outputs, *, T_plant_series=None, T_comp_series=None, estimator=None, inertia_feedforward=False,
         load_plant=math.nan, load_comp=math.nan, load_plant_series=None, load_comp_series=None) -> str:
    """The fixed-step closed loop of control.h; returns its status name. ``outputs``: seven arrays of one
    value per period or None (x, u, F_comp, then the trace: F_plant, T_comp, T_variance, F_measured; the
    first three required). ``estimator``: None or (est_spec, config, T0, var0, T_amb, T_proxy, position_noise,
    dob_tau), config the tuple of ``temperature_estimate``. ``inertia_feedforward``: the control adds
    m (v_ref[i+1] - v_ref[i]) / dt. ``substeps`` beyond any C integer is passed as
    2**31, which the core refuses as it does any n x substeps above TF_LOOP_MAX_SUBSTEPS. The loads: a number
    each (NaN: none) or, where the series is given, one per period."""
    status = _core.loop(plant_spec, float(T_plant), T_plant_series, comp_spec, float(T_comp), T_comp_series,
                        COMPENSATION_CODES[compensation], float(gain), float(mass), tuple(float(g) for g in pid),
                        float(dt), min(int(substeps), 2**31), x_ref, v_ref, estimator, tuple(outputs),
                        bool(inertia_feedforward), float(load_plant), float(load_comp), load_plant_series,
                        load_comp_series)
    return STATUS_NAMES.get(status, f"status {status}")


def rt_steps(spec, T, v, dt, F_out, load=math.nan) -> float:
    """tf_rt_step over the velocities ``v`` (T and the load each a number or one per step); seconds, timed in C."""
    return _core.rt_steps(spec, T, v, float(dt), F_out, load)


def temperature_estimate(spec, config, T0, var0, v, F_measured, T_proxy, T_amb, dt, T_out, var_out, F_out,
                         load=None) -> float:
    """The temperature estimator of estimator.h over whole arrays (config: tf_temperature_config's fields in
    order; T_proxy and the load None or one per sample); the outputs written in place; seconds, timed in C."""
    return _core.temperature_estimate(spec, config, float(T0), float(var0), v, load, F_measured, T_proxy, T_amb,
                                      float(dt), T_out, var_out, F_out)


__all__ = ["PARAMETERS", "PLANT_CODES", "FRICTION_CODES", "LAW_CODES", "OUTPUTS", "OUTPUT_COLUMN", "MECHANICAL_STATES",
           "model_spec", "law_tuple", "law_eval_load", "LOAD_KIND_CODES", "LOAD_COMBINE_CODES", "waveform_tuple", "run", "run_sensitivities", "prescribed_force", "prescribed_applies", "CoreFailure", "target", "loop",
           "rt_steps", "temperature_estimate", "PROXY_CODES", "law_eval", "waveform_eval", "waveform_corners", "state_scale", "rhs_jac", "time_rhs",
           "n_outputs", "state_index"]
