"""What an exported FMU declares (docs/fmu.md): its variables and their value references, the resource file the
binary reads, and modelDescription.xml for FMI 2.0 and 3.0 with a default experiment."""

from __future__ import annotations

import datetime
from xml.sax.saxutils import quoteattr

import numpy as np

from . import _bridge
from ._version import __version__
from .errors import InputError
from .models import MassPlant, Model, PrescribedMotion, StickSlipPlant

#: The resource file's format version (core/fmu/fmu_common.c, FMU_FORMAT).
FORMAT = 2
#: The binary's limits (fmu_common.c: MAX_VR value references, MAX_POINTS points of one law).
MAX_VALUE_REFERENCE = 2048
MAX_POINTS = 256
FIRST_PARAMETER = 16


#: Fixed value references of the inputs and outputs (fmu_common.c).
VR_DRIVE, VR_TEMPERATURE, VR_DISPLACEMENT, VR_VELOCITY, VR_FRICTION_FORCE, VR_TEMPERATURE_OUT, VR_STAGE = range(7)

#: The temperature estimator's outputs and inputs (fmu_common.c), with ``export_fmu(..., estimator=...)``.
VR_TEMPERATURE_ESTIMATE, VR_TEMPERATURE_VARIANCE, VR_MEASURED_FORCE, VR_PROXY_TEMPERATURE, VR_AMBIENT = range(7, 12)

#: The estimator's parameters in the binary's order (fmu_common.c: EST_*): name, unit, description.
ESTIMATOR_PARAMETERS = (
    ("C_th", "J/K", "heat capacity of the contact node"),
    ("R_th", "K/W", "thermal resistance from the contact to the housing node (or to ambient)"),
    ("eta", "", "fraction of the friction power that heats the contact"),
    ("C_2", "J/K", "heat capacity of the housing node (0: one node)"),
    ("R_2", "K/W", "thermal resistance from the housing node to ambient"),
    ("tau_p", "s", "lag of the proxy temperature"),
    ("q_contact", "K2/s", "process noise of the contact temperature"),
    ("q_housing", "K2/s", "process noise of the housing temperature"),
    ("q_proxy", "K2/s", "process noise of the proxy temperature"),
    ("r_F", "N2", "noise variance of the measured friction force"),
    ("r_p", "K2", "noise variance of the proxy temperature"),
    ("v_min", "m/s", "no friction update below this sliding speed"),
)

#: The load input [N or N m] of a model with a law of the load (fmu_common.c).
VR_LOAD = 12

#: Value reference of FMI 3's independent variable time (fmi3_cs.c, VR_TIME).
VR_TIME = 15


# SI base units of the units the FMU declares (FMI 2.0 UnitDefinitions); others are declared by name.
_BASE_UNITS = {
    "m": {"m": 1}, "m/s": {"m": 1, "s": -1}, "N": {"kg": 1, "m": 1, "s": -2}, "V": {"kg": 1, "m": 2, "s": -3, "A": -1},
    "kg": {"kg": 1}, "s": {"s": 1}, "N/m": {"kg": 1, "s": -2}, "N s/m": {"kg": 1, "s": -1}, "N/s": {"kg": 1, "m": 1, "s": -3},
    "rad/s": {"rad": 1, "s": -1}, "m/V": {"kg": -1, "m": -1, "s": 3, "A": 1}, "N/V": {"m": -1, "s": 1, "A": 1},
    "J/K": {"kg": 1, "m": 2, "s": -2, "K": -1}, "K/W": {"kg": -1, "m": -2, "s": 3, "K": 1},
    "K2": {"K": 2}, "K2/s": {"K": 2, "s": -1}, "N2": {"kg": 2, "m": 2, "s": -4}, "N m": {"kg": 1, "m": 2, "s": -2},
}



class _Variable:
    def __init__(self, name, vr, unit, description, start=None, causality="parameter", variability="tunable",
                 role=None, i=0, j=0):
        self.name, self.vr, self.unit, self.description, self.start = name, vr, unit, description, start
        self.causality, self.variability, self.role, self.i, self.j = causality, variability, role, i, j


def _estimator_io(model: Model, estimator, ambient: float) -> list:
    """The estimator's inputs and outputs (its ambient temperature: the heat model's input where there is one)."""
    out = [_Variable("measured_friction_force", VR_MEASURED_FORCE, "N", "measured friction force for the temperature "
                     "estimator (NaN: none this step)", float("nan"), "input", "continuous")]
    if estimator.proxy != "none":
        out.append(_Variable("proxy_temperature", VR_PROXY_TEMPERATURE, "degC", f"proxy temperature lagging the "
                             f"{estimator.proxy} (NaN: none this step)", float("nan"), "input", "continuous"))
    if model.heat is None:
        out.append(_Variable("ambient_temperature", VR_AMBIENT, "degC", "ambient temperature of the estimator's heat "
                             "path", ambient, "input", "continuous"))
    out += [_Variable("temperature_estimate", VR_TEMPERATURE_ESTIMATE, "degC", "estimated contact temperature",
                      causality="output", variability="continuous"),
            _Variable("temperature_variance", VR_TEMPERATURE_VARIANCE, "K2", "variance of the estimated contact "
                      "temperature", causality="output", variability="continuous")]
    return out


def variables_of(model: Model, spec: dict, temperature: float | None, step: float | None = None, estimator=None,
                 load=None):
    """The FMU's variables: inputs, outputs, then every parameter with its role in the binary; with ``estimator``
    (a TemperatureEstimator) its inputs, outputs and parameters too; ``load``: the load input's (name, unit, what,
    start) for a model with a law of the load (fmu.py: _load_input), else None."""
    plant = model.plant
    drive = {StickSlipPlant: ("voltage", "V", "drive voltage of the actuator"),
             MassPlant: ("force", "N", "force applied to the mass"),
             PrescribedMotion: ("motion", "m", "the prescribed displacement of the body (its slope is the sliding "
                                "velocity: give input derivatives, else the motion reaches each value one "
                                "communication step later)")}[type(plant)]
    variables = [_Variable(drive[0], VR_DRIVE, drive[1], drive[2], 0.0, "input", "continuous")]
    thermal = model.thermal is not None
    heat = model.heat
    if heat is not None:
        T_amb = heat.resolved(temperature).ambient_temperature if (heat.ambient_temperature is not None
                                                                    or temperature is not None) else 20.0
        variables.append(_Variable("ambient_temperature", VR_TEMPERATURE, "degC",
                                   "ambient temperature of the heat balance", T_amb, "input", "continuous"))
    elif thermal:
        rng = model.temperature_range()
        T0 = temperature if temperature is not None else (rng[0] if rng else 20.0)
        variables.append(_Variable("temperature", VR_TEMPERATURE, "degC",
                                   "temperature of the friction interface", float(T0), "input", "continuous"))
    load_var = _Variable(load[0], VR_LOAD, load[1], load[2], load[3], "input", "continuous") if load else None
    variables += [load_var] if load else []
    variables += [
        _Variable("displacement", VR_DISPLACEMENT, "m", "displacement of the driven body (end effector, mass, or "
                  "the prescribed motion)", causality="output", variability="continuous"),
        _Variable("velocity", VR_VELOCITY, "m/s", "velocity of the driven body", causality="output",
                  variability="continuous"),
        _Variable("friction_force", VR_FRICTION_FORCE, "N", "friction force resisting sliding (thermal extension "
                  "included)", causality="output", variability="continuous"),
    ]
    if heat is not None:
        variables.append(_Variable("temperature", VR_TEMPERATURE_OUT, "degC", "interface temperature (the heat "
                                   "balance's state)", causality="output", variability="continuous"))
    if isinstance(plant, StickSlipPlant):
        variables.append(_Variable("stage_displacement", VR_STAGE, "m", "displacement of the driving stage",
                                   causality="output", variability="continuous"))
    est_T0 = variables[1].start if len(variables) > 1 and variables[1].vr == VR_TEMPERATURE else 20.0
    if estimator is not None:
        variables += _estimator_io(model, estimator, est_T0)

    vr = FIRST_PARAMETER

    def add(name, unit, description, start, role, i=0, j=0, variability="tunable"):
        nonlocal vr
        variables.append(_Variable(name, vr, unit, description, float(start), role=role, i=i, j=j,
                                   variability=variability))
        vr += 1

    # the plant, in the model file's own form
    if isinstance(plant, StickSlipPlant):
        add("plant.m", "kg", "equivalent stage mass", plant.mass, "m")
        add("plant.m_e", "kg", "end-effector mass", plant.end_effector_mass, "m_e")
        if plant.modal:
            xi, wn, K = plant.modal_parameters()
            add("plant.xi", "", "damping ratio", xi, "xi")
            add("plant.wn", "rad/s", "natural frequency", wn, "wn")
            add("plant.K", "m/V", "static gain", K, "K")
        else:
            c, k, T_em = plant.physical()
            add("plant.c", "N s/m", "stage damping", c, "c")
            add("plant.k", "N/m", "stage stiffness", k, "k")
            add("plant.T_em", "N/V", "transducer ratio", T_em, "T_em")
    elif isinstance(plant, MassPlant):
        add("plant.m", "kg", "mass", plant.mass, "m")
        add("plant.k_s", "N/m", "stiffness of the pulling spring", plant.spring_stiffness, "k_s")
        add("plant.v_0", "m/s", "pull velocity of the spring's end", plant.pull_velocity, "v_0")

    # the friction parameters given as numbers (those following a law are the laws' coefficients)
    friction = model.friction
    numbers = {k: v for k, v in friction.values().items() if k not in friction.arrays}
    for name in _bridge.PARAMETERS:
        if name in numbers:
            add(f"friction.{name}", _bridge.PARAMETER_UNITS[name], f"{friction.model} parameter {name}",
                spec["params"][_bridge.PARAMETERS.index(name)], "p", _bridge.PARAMETERS.index(name))
    arrays = friction.description.arrays  # (GMS: each element's k and w, element by element)
    for e, row in enumerate(zip(*(getattr(friction, name) for name in arrays))):
        for (name, array), value in zip(arrays.items(), row):
            add(f"friction.{name}[{e + 1}]", array.unit, array.element.format(e=e + 1), value, array.role, e)

    # the laws' coefficients (breakpoints fixed: settable before initialisation only)
    laws = [(name, _bridge.PARAMETERS.index(name), law, _bridge.PARAMETER_UNITS[name])
            for name, law in model.laws.items()]
    if getattr(model.thermal, "model", None) == "II":
        laws.append(("dF", len(_bridge.PARAMETERS), model.thermal.dF, "N"))
    for name, index, law, unit in laws:
        where = f"thermal.{name}"
        what = f"{law.kind} law of {name}"
        term, law = getattr(law, "load", None), getattr(law, "base", law)  # a law of the load: its temperature law
        if law.kind == "const":
            add(f"{where}.value", unit, f"value of the {what}", law.value, "law_a", index)
        elif law.kind in ("linear", "exp"):
            add(f"{where}.a", law.coefficient_unit("a", unit), f"a of the {what}", law.a, "law_a", index)
            add(f"{where}.b", law.coefficient_unit("b", unit), f"b of the {what}", law.b, "law_b", index)
        elif law.kind == "poly":
            for j, c in enumerate(law.c):
                add(f"{where}.c[{j + 1}]", law.coefficient_unit(f"c[{j}]", unit), f"coefficient of T^{j} of the {what}",
                    c, "law_y", index, j)
        else:  # pwl, table
            for j, (T, v) in enumerate(zip(law.T, law.values)):
                add(f"{where}.T[{j + 1}]", "degC", f"breakpoint {j + 1} of the {what}", T, "law_x", index, j,
                    variability="fixed")
                add(f"{where}.values[{j + 1}]", unit, f"value at breakpoint {j + 1} of the {what}", v, "law_y",
                    index, j)
        Lu = load_var.unit if term is not None else ""
        for key, role, u in (("k", "load_k", f"1/{Lu}" if term and term.combine == "product" else f"{unit}/{Lu}"),
                             ("saturation", "load_sat", Lu), ("interaction", "load_c", f"{unit}/C/{Lu}")):
            if term is not None and getattr(term, key) is not None:
                add(f"{where}.load.{key}", u, f"{key} of the {term.kind} load term of {name}", getattr(term, key),
                    role, index)

    if heat is not None:
        h = heat.resolved(variables[1].start)
        add("heat.C_th", "J/K", "heat capacity of the interface", h.heat_capacity, "C_th")
        add("heat.R_th", "K/W", "thermal resistance to ambient", h.thermal_resistance, "R_th")
        add("heat.eta", "", "fraction of the friction power that heats the interface", h.heat_fraction, "eta")
        add("heat.T_0", "degC", "start temperature", h.initial_temperature, "T_0", variability="fixed")
    if estimator is not None:
        for i, (name, unit, what) in enumerate(ESTIMATOR_PARAMETERS):
            add(f"estimator.{name}", unit, what, getattr(estimator, name), "estimator", i)
        add("estimator.T_0", "degC", "the estimate's start (every node)", est_T0, "estimator", i + 1,
            variability="fixed")
        add("estimator.variance_0", "K2", "the start's variance", 25.0, "estimator", i + 2, variability="fixed")
    if step is not None:
        add("integrator.step", "s", "the fixed step of the real-time integrator (several per communication "
            "step; the last shortened to end on the communication point)", step, "step", variability="fixed")
    if vr > MAX_VALUE_REFERENCE:
        raise InputError(f"the model has {vr - FIRST_PARAMETER} parameters; an FMU takes at most "
                         f"{MAX_VALUE_REFERENCE - FIRST_PARAMETER}")
    return variables


def _elements(friction) -> int:
    """How many elements a friction model with arrays has (GMS's), else 0."""
    return len(getattr(friction, friction.arrays[0])) if friction.arrays else 0


def resource_text(model: Model, spec: dict, variables, solver: str = "adaptive", estimator=None,
                  load_range=None) -> str:
    """resources/model.tfm: the structure and the parameters' roles (read by fmu_common.c); with ``estimator``
    its line (the proxy kind, the ambient temperature's start); with a load input its start, the load terms'
    structure and ``load_range`` (their common range of |load|, None: none)."""
    lines = [f"thermofriction-fmu {FORMAT}",
             f"# {model.name or 'model'}: written by thermofriction {__version__}",
             f"plant {spec['plant']} {int(isinstance(model.plant, StickSlipPlant) and model.plant.modal)}",
             f"friction {spec['friction']} {_elements(model.friction)}",
             f"thermal {spec['thermal']} {spec['dF_form']} {spec['fs_follows_fc']}",
             f"heat {int(model.heat is not None)}",
             f"temperature_input {int(model.thermal is not None and model.heat is None)}",
             f"integrator {solver}"]
    rng = model.temperature_range()
    if rng is not None:
        lines.append(f"range {rng[0]!r} {rng[1]!r}")
    if model.heat is not None and model.heat.external_heat is not None:
        w = _bridge.waveform_tuple(model.heat.external_heat)
        lines.append("p_ext " + " ".join([str(w[0])] + [repr(float(x)) for x in w[1:8]]))
    laws = spec["laws"] or [None] * len(_bridge.PARAMETERS)
    for i, law in enumerate([*laws, spec["dF"]]):
        if law is not None:
            n = 0 if law[4] is None else len(law[4])
            lines.append(f"law {i} {law[0]} {n}")
        if law is not None and len(law) > 5:  # a load term: kind combine interaction (k, S, c: parameters)
            lines.append(f"load_law {i} {law[5][0]} {law[5][1]} {law[5][4]}")
    temperature_start = next((v.start for v in variables if v.vr == VR_TEMPERATURE), float("nan"))
    lines.append(f"input 0.0 {temperature_start!r}" if temperature_start == temperature_start else "input 0.0 0.0")
    load_start = next((v.start for v in variables if v.vr == VR_LOAD), None)
    if load_start is not None:
        lines.append(f"load_input {load_start!r}")
        if load_range is not None:
            lines.append(f"load_range {float(load_range[0])!r} {float(load_range[1])!r}")
    if estimator is not None:
        starts = {v.vr: v.start for v in variables if v.causality == "input"}
        ambient = starts.get(VR_AMBIENT, starts.get(VR_TEMPERATURE, 20.0))
        lines.append(f"estimator {_bridge.PROXY_CODES[estimator.proxy]} {ambient!r}")
    for v in variables:
        if v.role:
            lines.append(f"var {v.vr} {v.role} {v.i} {v.j} {int(v.variability == 'fixed')} {v.start!r}")
    return "\n".join(lines) + "\n"


def _xml_number(x: float) -> str:
    """A start value as xs:double writes it (NaN: a measurement input's "none")."""
    return "NaN" if x != x else repr(x)


def _default_experiment_xml(model: Model, step: float | None) -> str:
    stop, h, _ = default_experiment(model, step)
    return f'  <DefaultExperiment startTime="0" stopTime="{stop!r}" stepSize="{h!r}" tolerance="1e-06"/>'


def description_xml2(model: Model, variables, identifier: str, guid: str, source: str | None,
                     step: float | None = None, sources=()) -> str:
    """modelDescription.xml of an FMI 2.0 co-simulation FMU; ``sources``: the C files of its ``sources/`` folder
    (``<SourceFiles>``, from which an importer compiles the FMU)."""
    files = [f'      <File name={quoteattr(name)}/>' for name in sources]
    out = [*_head(model, identifier, f'fmiVersion="2.0" guid="{guid}"', source, step),
           '  variableNamingConvention="structured" numberOfEventIndicators="0">',
           f'  <CoSimulation modelIdentifier="{identifier}" canHandleVariableCommunicationStepSize="true"',
           '    canInterpolateInputs="true" maxOutputDerivativeOrder="0" canGetAndSetFMUstate="true"',
           '    canSerializeFMUstate="false" providesDirectionalDerivative="false"'
           + ('>' if files else '/>'),
           *(['    <SourceFiles>', *files, '    </SourceFiles>', '  </CoSimulation>'] if files else []),
           *_units_xml(variables)]
    out += [*_LOG_CATEGORIES,
            _default_experiment_xml(model, step),
            '  <ModelVariables>']
    outputs = []
    for index, v in enumerate(variables, start=1):
        attrs = [f"name={quoteattr(v.name)}", f'valueReference="{v.vr}"', f"description={quoteattr(v.description)}",
                 f'causality="{v.causality}"', f'variability="{v.variability}"']
        real = [f"unit={quoteattr(v.unit)}"] if v.unit else []
        if v.causality == "parameter":
            attrs.append('initial="exact"')
            real.append(f'start="{v.start!r}"')
        elif v.causality == "input":
            real.append(f'start="{_xml_number(v.start)}"')
        else:
            outputs.append(index)
        out.append(f'    <ScalarVariable {" ".join(attrs)}><Real {" ".join(real)}/></ScalarVariable>')
        out[-1] = out[-1].replace(" >", ">")
    out += ['  </ModelVariables>', '  <ModelStructure>', '    <Outputs>']
    out += [f'      <Unknown index="{i}"/>' for i in outputs]
    out += ['    </Outputs>', '    <InitialUnknowns>']
    out += [f'      <Unknown index="{i}"/>' for i in outputs]
    out += ['    </InitialUnknowns>', '  </ModelStructure>', '</fmiModelDescription>', '']
    return "\n".join(out)


def default_experiment(model: Model, step: float | None = None) -> tuple[float, float, str]:
    """The FMU's default experiment: a step that resolves the model's ``[input]``.

    1/200 of its period and 1/20 of its shortest ramp (a sawtooth's fall or rise, a square's or step's slew,
    the closest samples), over two periods (a step: until ten slews after it; no periodic input: 1 s). Without
    an ``[input]``: 0.1 ms over 1 s. With the realtime integrator the step is a whole number of its fixed
    steps (at least one). docs/fmu.md#the-default-experiment-and-held-inputs says why.

    Parameters
    ----------
    model : Model
        The model exported.
    step : float, optional
        The realtime integrator's fixed step [s]; None for the adaptive one.

    Returns
    -------
    tuple
        (stop time [s], communication step [s], why: the sentence the FMU's description carries).

    Raises
    ------
    None
        Nothing is checked here: ``export_fmu`` checks its arguments first.
    """
    w = model.input
    stop, why = 1.0, "no [input] in the model: 0.1 ms"
    candidates = []
    period = getattr(w, "period", None)
    if period:
        candidates.append((period / 200, f"1/200 of the input's period {period:g} s"))
        stop = 2 * period
    if w is not None and w.kind == "sawtooth":
        ramp = min(w.rise, 1 - w.rise) * period
        candidates.append((ramp / 20, f"1/20 of the sawtooth's {'fall' if w.rise > 0.5 else 'rise'} {ramp:g} s"))
    elif w is not None and w.kind in ("square", "step") and w.slew > 0:
        candidates.append((w.slew / 20, f"1/20 of the {w.kind}'s slew {w.slew:g} s"))
        if w.kind == "step":
            stop = max(w.time + 10 * w.slew, 10 * w.slew)
    elif w is not None and w.kind == "sampled":
        dt = float(np.min(np.diff(w.time)))
        candidates.append((dt, f"the input's closest samples, {dt:g} s apart"))
        stop = float(w.time[-1])
    h, why = min(candidates) if candidates else (1e-4, why)
    h = float(f"{h:.2g}")  # a round number
    if step is not None:
        n = max(1, round(h / step))
        h, why = step * n, why + f", as {n} fixed step{'s' if n > 1 else ''} of {step:g} s"
    return stop, h, why


_LOG_CATEGORIES = [
    '  <LogCategories>',
    '    <Category name="logStatusWarning" description="a temperature outside the laws\' calibrated range"/>',
    '    <Category name="logStatusError" description="refused inputs or parameters, failed integrations"/>',
    '  </LogCategories>']


def _head(model: Model, identifier: str, version: str, source: str | None, step: float | None) -> list[str]:
    """The model description's first lines: the version attributes, modelName, description (the model's
    own and where it came from), the tool and the date."""
    provenance = f"exported by thermofriction {__version__}" + (f" from {source}" if source else "")
    provenance += (f"; fixed-step real-time integrator, step {step:g} s" if step is not None
                   else "; adaptive integrator")
    description = ((model.description + " -- ") if model.description else "") + provenance
    return ['<?xml version="1.0" encoding="UTF-8"?>',
            f'<fmiModelDescription {version} modelName={quoteattr(model.name or identifier)}',
            f'  description={quoteattr(description)} generationTool="thermofriction {__version__}"',
            f'  generationDateAndTime="{datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")}"']


def _units_xml(variables, extra=()) -> list[str]:
    out = ['  <UnitDefinitions>']
    for u in sorted({v.unit for v in variables if v.unit} | set(extra)):
        if u == "degC":
            out.append('    <Unit name="degC"><BaseUnit K="1" offset="273.15"/></Unit>')
        elif u in _BASE_UNITS:
            attrs = " ".join(f'{k}="{e}"' for k, e in _BASE_UNITS[u].items())
            out.append(f'    <Unit name={quoteattr(u)}><BaseUnit {attrs}/></Unit>')
        else:
            out.append(f'    <Unit name={quoteattr(u)}/>')
    return out + ['  </UnitDefinitions>']


def description_xml3(model: Model, variables, identifier: str, guid: str, source: str | None,
                     step: float | None = None) -> str:
    """modelDescription.xml of an FMI 3.0 co-simulation FMU: the FMI 2 export's variables as Float64, and time."""
    out = [*_head(model, identifier, f'fmiVersion="3.0" instantiationToken="{guid}"', source, step),
           '  variableNamingConvention="structured">',
           f'  <CoSimulation modelIdentifier="{identifier}" canHandleVariableCommunicationStepSize="true"',
           '    canGetAndSetFMUState="true" canSerializeFMUState="false" providesDirectionalDerivatives="false"',
           '    providesAdjointDerivatives="false" hasEventMode="false" maxOutputDerivativeOrder="0"/>',
           *_units_xml(variables, extra=("s",)),  # time's
           *_LOG_CATEGORIES,
           _default_experiment_xml(model, step),
           '  <ModelVariables>',
           f'    <Float64 name="time" valueReference="{VR_TIME}" causality="independent" variability="continuous"'
           ' description="the simulation time" unit="s"/>']
    outputs = []
    for v in variables:
        attrs = [f"name={quoteattr(v.name)}", f'valueReference="{v.vr}"', f"description={quoteattr(v.description)}",
                 f'causality="{v.causality}"', f'variability="{v.variability}"']
        if v.unit:
            attrs.append(f"unit={quoteattr(v.unit)}")
        if v.causality in ("parameter", "input"):
            attrs.append(f'start="{_xml_number(v.start)}"')
        else:
            outputs.append(v.vr)
        out.append(f'    <Float64 {" ".join(attrs)}/>')
    out += ['  </ModelVariables>', '  <ModelStructure>']
    out += [f'    <Output valueReference="{vr}"/>' for vr in outputs]
    out += [f'    <InitialUnknown valueReference="{vr}"/>' for vr in outputs]
    out += ['  </ModelStructure>', '</fmiModelDescription>', '']
    return "\n".join(out)


__all__ = ["variables_of", "VR_LOAD", "resource_text", "description_xml2", "description_xml3", "default_experiment",
           "FORMAT", "VR_TIME", "ESTIMATOR_PARAMETERS"]
