"""How an experiment drives a model: the input waveform, the temperature, the load (a normal force or a load
torque, per sample where the run's load column varies), and, for a model that heats itself, the ambient and start
temperatures. Identification, validation, reports and the
heating methods all ask here, so that a model is driven the same way wherever it is run.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .errors import InputError
from .waveforms import Sampled, Waveform, Zero


def input_of(model, input: Waveform | None = None) -> Waveform:
    """The waveform that drives ``model``: ``input`` if given, else the model's ``[input]``, else none
    (zero)."""
    if input is not None:
        return input
    return model.input if model.input is not None else Zero()


def experiment_waveform(exp, model) -> Waveform:
    """The input that drove an experiment: the manifest's, the model's when it reproduces the
    recorded voltage (to 1 % of its range), else the recorded voltage itself."""
    w = getattr(exp, "input", None)
    if w is not None:
        return w
    if model.input is not None:
        u = model.input(exp.time)
        if np.max(np.abs(u - exp.voltage)) <= 0.01 * max(float(np.ptp(exp.voltage)), 1e-12):
            return model.input
    return Sampled(exp.time, exp.voltage)


def ambient_temperature(exp, model) -> float:
    """The ambient temperature of a run of a model with a [heat] section: the model's T_amb, else
    the experiment's (manifest) temperature."""
    ambient = model.heat.ambient_temperature
    return float(exp.temperature) if ambient is None else float(ambient)


def recorded_start_temperature(exp) -> float | None:
    """Where the recorded temperature starts (None without a record): a parabola through the first
    2 % of the record, at the first sample (a plain mean there is biased by the heating already
    under way: 0.1 K, micrometres of misfit, in tests)."""
    sig = getattr(exp, "temperature_signal", None)
    if sig is None:
        return None
    sig = np.asarray(sig, float)
    if len(sig) < 3:
        return float(sig[0])
    k = max(3, len(sig) // 50)
    t = np.asarray(exp.time[:k], float) - float(exp.time[0])
    return float(np.polyval(np.polyfit(t, sig[:k], 2), 0.0))


@dataclasses.dataclass(frozen=True)
class Drive:
    """What one experiment gives a model to run with.

    ``temperature`` is what ``simulate(..., temperature=...)`` takes: the experiment's temperature
    (a number, or its recorded signal where that varies), or, with a heat model, the ambient
    temperature. With a heat model ``initial_temperature`` is where the run starts (None: the
    model's own rule, T_0 or else ambient) and ``measured_temperature`` the record. ``load`` is what
    ``simulate(..., load=...)`` takes: the run's constant load, its recorded ``normal_force[N]`` /
    ``load_torque[N*m]`` column as a ``Sampled`` signal where that varies (``Experiment.load_input``), or None."""

    waveform: Waveform
    temperature: float | Sampled
    initial_temperature: float | None = None
    measured_temperature: np.ndarray | None = None
    load: float | Sampled | None = None

    def model(self, model):
        """``model`` with its heat section set to this drive's ambient and start temperatures."""
        if model.heat is None:
            return model
        heat = dataclasses.replace(model.heat, ambient_temperature=float(self.temperature))
        if self.initial_temperature is not None:
            heat = dataclasses.replace(heat, initial_temperature=float(self.initial_temperature))
        return dataclasses.replace(model, heat=heat)


#: How a self-heating run's start temperature is chosen.
#: "record": where the experiment's temperature record starts (identification: each run from its own
#: start; a fit that estimates one start for all sets it itself).
#: "model": the model's T_0 when its file gives one (a fitted common start), else the record's start
#: (prediction).
START_RULES = ("record", "model")


def drive(exp, model, start: str = "model") -> Drive:
    """How experiment ``exp`` drives ``model``; ``start`` is one of :data:`START_RULES`."""
    if start not in START_RULES:
        raise ValueError(f"start must be one of {START_RULES}, got {start!r}")
    waveform = experiment_waveform(exp, model)
    load = exp.load_input() if hasattr(exp, "load_input") else getattr(exp, "load", None)
    if model.heat is None:
        T = exp.temperature_input() if hasattr(exp, "temperature_input") else exp.temperature
        return Drive(waveform, T, load=load)
    T0 = recorded_start_temperature(exp)
    if start == "record":
        if T0 is None:
            raise InputError(f"{exp.file}: the model heats itself ([heat] section) but the experiment records no "
                             f"temperature[C] column to fit it to")
    elif model.heat.initial_temperature is not None:
        T0 = None  # the model's own T_0
    measured = getattr(exp, "temperature_signal", None)
    return Drive(waveform, ambient_temperature(exp, model), T0,
                 None if measured is None else np.ascontiguousarray(measured, float), load)


__all__ = ["Drive", "drive", "input_of", "experiment_waveform", "ambient_temperature", "recorded_start_temperature",
           "START_RULES"]
