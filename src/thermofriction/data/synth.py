"""Synthetic datasets with realistic sensor effects (noise, quantisation, temperature-sensor
noise); the ``thermofriction synth`` command is cli/synth.py."""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from .. import _args
from ..models import Model, require_actuator
from ..plausible import input_voltage_problem
from ..simulation import StepSizeController, simulate
from ..waveforms import Sampled, Waveform
from .experiments import MIN_SAMPLES, Dataset, Experiment
from .files import check_temperature

#: the most experiments (fit and validate temperatures together) of one synthesised dataset: each is a
#: simulation (~0.1-1 s for the default 2 s at 10 kHz) and a file; a longer list is most likely a mistake
#: (a range typed as a list), and a real one is better split into several datasets
MAX_EXPERIMENTS = 1000


def _nonneg(label, v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        raise InputError(f"{label} must be a number, got {v!r}") from None
    if not (v >= 0 and math.isfinite(v)):
        raise InputError(f"{label} must be a non-negative number, got {v!r}")
    return v


def _temperatures(values, label):
    if values is None:
        return []
    if isinstance(values, (int, float, np.number)):
        values = [values]
    return [check_temperature(float(T) if isinstance(T, np.number) else T, label) for T in values]


def _check_types(model, temperatures, validate, duration, sample_rate, noise, quantization, temperature_noise,
                 drift, input, record_temperature, record_stage, name):
    """synthesize's argument types (_args.py), before any work."""
    _args.model(model, Model)  # the argument types (_args.py): before any work
    _args.number_list(temperatures, "temperatures", "C", empty=True, none=True)
    _args.number_list(validate, "validate", "C", empty=True, none=True)
    for label, v in (("duration", duration), ("sample_rate", sample_rate), ("noise", noise),
                     ("quantization", quantization), ("temperature_noise", temperature_noise), ("drift", drift)):
        _args.number(v, label)
    _args.instance(input, Waveform, "input", "a Waveform", none=True)
    if record_temperature is not None:
        _args.flag(record_temperature, "record_temperature")
    _args.flag(record_stage, "record_stage")
    _args.text(name, "name", none=True)


def synthesize(model: Model, temperatures, *, validate=(), duration=2.0, sample_rate=10_000.0, input=None,
               noise=20e-9, quantization=0.0, temperature_noise=0.0, drift=0.0, record_temperature=None,
               record_stage=False, seed=0, name=None, progress=None) -> Dataset:
    """A dataset simulated from ``model`` at each temperature (role "fit") and at each ``validate``
    temperature (role "validate"), with realistic sensor effects.

    The manifest's temperature is the true one. Seeded and reproducible: each experiment draws from its own
    stream (``default_rng([seed, i])`` for the i-th fit temperature, ``[seed, j, 1]`` for the j-th validate
    one), so adding an experiment changes no other. At most ``MAX_EXPERIMENTS`` temperatures in all.

    Parameters
    ----------
    model : Model
        The model simulated (an actuator or a stage driven by a voltage).
    temperatures : sequence of float
        The fit experiments' temperatures [C], one experiment each.
    validate : sequence of float, default ()
        The held-out experiments' temperatures [C].
    duration : float, default 2.0
        Each experiment's length [s].
    sample_rate : float, default 10000.0
        The sampling rate [Hz].
    input : Waveform, optional
        The drive; default the model's ``[input]``.
    noise : float, default 20e-9
        The standard deviation of the white Gaussian displacement noise [m].
    quantization : float, default 0.0
        The displacement quantised to multiples of it [m]; 0: none.
    temperature_noise : float, default 0.0
        The standard deviation of the recorded temperature's sensor noise [C].
    drift : float, default 0.0
        A slow linear sensor drift [m/s], with a random sign per experiment.
    record_temperature : bool, optional
        Record a temperature column; default when ``temperature_noise`` > 0 (always with a heat model, whose
        temperature is an output).
    record_stage : bool, default False
        Record the stage displacement too, with the same noise and quantisation.
    seed : int, default 0
        The seed of the noise's random streams.
    name : str, optional
        The dataset's name; default ``"synthetic-"`` and the model's name.
    progress : callable, optional
        Called as ``progress(done, total)`` after each experiment.

    Returns
    -------
    Dataset
        The experiments in memory (``save_dataset`` writes them as a dataset folder).

    Raises
    ------
    InputError
        An argument of the wrong type or value, named; a model without an ``[input]`` and no ``input``; no
        temperature; more than ``MAX_EXPERIMENTS`` temperatures; fewer than ``MIN_SAMPLES`` samples per
        experiment.
    SolverError
        A simulation failed.

    Examples
    --------
    >>> import thermofriction as tf
    >>> model = tf.load_model("li2009-model-i")
    >>> data = tf.synthesize(model, [30.0, 40.0], validate=[35.0], duration=0.05, sample_rate=2000.0)
    >>> [(e.role, e.temperature) for e in data.experiments]
    [('fit', 30.0), ('fit', 40.0), ('validate', 35.0)]
    """
    _check_types(model, temperatures, validate, duration, sample_rate, noise, quantization, temperature_noise, drift,
                 input, record_temperature, record_stage, name)
    require_actuator(model, "synthesize")
    waveform = input if input is not None else model.input
    if waveform is None:
        raise InputError(f"{'model ' + repr(model.name) if model.name else 'the model'} has no [input] "
                         f"waveform: give input= (e.g. tf.Sawtooth(amplitude=30, frequency=5))")
    problem = input_voltage_problem(waveform)  # the dataset would be refused when it is loaded
    if problem:
        raise InputError(f"input: {problem}")
    fit_T = _temperatures(temperatures, "temperatures")
    val_T = _temperatures(validate, "validate")
    if not fit_T and not val_T:
        raise InputError("give at least one temperature (temperatures, or validate)")
    if len(fit_T) + len(val_T) > MAX_EXPERIMENTS:
        raise InputError(f"{len(fit_T) + len(val_T)} temperatures, more than the limit of {MAX_EXPERIMENTS} "
                         f"experiments per synthesised dataset: synthesise several datasets")
    if progress is not None and not callable(progress):
        raise InputError(f"progress must be a function (done, total) or None, got {type(progress).__name__}")
    noise = _nonneg("noise", noise)
    quantization = _nonneg("quantization", quantization)
    temperature_noise = _nonneg("temperature_noise", temperature_noise)
    try:
        drift = float(drift)
        duration = float(duration)
        sample_rate = float(sample_rate)
    except (TypeError, ValueError):
        raise InputError("drift, duration and sample_rate must be numbers") from None
    if not math.isfinite(drift):
        raise InputError(f"drift must be a finite number [m/s], got {drift!r}")
    if not (duration > 0 and math.isfinite(duration)):
        raise InputError(f"duration must be positive [s], got {duration!r}")
    if not (sample_rate > 0 and math.isfinite(sample_rate)):
        raise InputError(f"sample_rate must be positive [Hz], got {sample_rate!r}")
    if duration * sample_rate + 1 < MIN_SAMPLES:
        raise InputError(f"duration x sample_rate gives fewer than {MIN_SAMPLES} samples")
    _args.whole(seed, "seed", low=0)
    if record_temperature is None:  # a self-heating model's temperature is an output: always recorded
        record_temperature = temperature_noise > 0 or model.heat is not None
    runs = [(T, "fit", [int(seed), i]) for i, T in enumerate(fit_T)]
    runs += [(T, "validate", [int(seed), j, 1]) for j, T in enumerate(val_T)]
    label = model.name or "model"
    spec = "a sampled waveform" if isinstance(waveform, Sampled) else waveform.spec()
    exps = []
    used = set()
    for T, role, stream in runs:
        exps.append(_one_run(model, waveform, T, role, stream, used, duration=duration, sample_rate=sample_rate,
                             noise=noise, quantization=quantization, drift=drift, record_stage=record_stage,
                             record_temperature=record_temperature, temperature_noise=temperature_noise,
                             label=label, spec=spec, seed=seed))
        if progress is not None:
            progress(len(exps), len(runs))
    return Dataset(path=None, name=name or f"synthetic-{label}",
                   description=f"synthesised by thermofriction from {label}", experiments=exps)


def _one_run(model, waveform, T, role, stream, used, *, duration, sample_rate, noise, quantization, drift,
             record_stage, record_temperature, temperature_noise, label, spec, seed) -> Experiment:
    """One synthesised experiment at temperature ``T``: simulated, then the sensor's effects drawn from its own
    random stream; its file name is added to ``used``."""
    rng = np.random.default_rng(stream)
    res = simulate(model, duration, temperature=T, input=waveform, sample_rate=sample_rate,
                   controller=StepSizeController(rtol=1e-10))
    span = float(np.ptp(res.displacement))
    if record_stage and res.stage_displacement is not None:  # a plant test: the stage moves
        span = max(span, float(np.ptp(res.stage_displacement)))
    for what, v in (("noise", noise), ("quantization", quantization)):
        if v > span > 0:  # 20 meant as nanometres but given in metres
            raise InputError(f"{what} {v:g} m exceeds the simulated displacement range ({span:.3g} m) at "
                             f"{T:g} C: give it with a unit, e.g. 20nm")
    x = res.displacement + noise * rng.standard_normal(res.time.size)
    sign = 0
    if drift:
        sign = 1 if rng.random() < 0.5 else -1
        x = x + sign * drift * (res.time - res.time[0])
    if quantization > 0:
        x = np.round(x / quantization) * quantization
    stage = None
    if record_stage:
        stage = res.stage_displacement + noise * rng.standard_normal(res.time.size)
        if quantization > 0:
            stage = np.round(stage / quantization) * quantization
    T_true = res.temperature if model.heat is not None else T  # with [heat], T is the ambient one
    sig = T_true + temperature_noise * rng.standard_normal(res.time.size) if record_temperature else None
    effects = [f"noise {noise:g} m"]
    if quantization:
        effects.append(f"quantisation {quantization:g} m")
    if drift:
        effects.append(f"drift {sign * drift:+g} m/s")
    if record_temperature:
        effects.append(f"temperature noise {temperature_noise:g} C")
    desc = (f"synthesised from {label} at {T:g} C: input {spec}, {duration:g} s at {sample_rate:g} Hz, "
            f"{', '.join(effects)}, seed {seed}")
    stem = f"T{T:.10g}C{'-validate' if role == 'validate' else ''}"
    file, k = f"{stem}.csv", 1
    while file in used:
        k += 1
        file = f"{stem}-{k}.csv"
    used.add(file)
    return Experiment(file=file, time=res.time, voltage=res.input, displacement=x, temperature=T,
                      temperature_signal=sig, stage_displacement=stage, role=role, description=desc,
                      input=None if isinstance(waveform, Sampled) else waveform)


__all__ = ["synthesize", "MAX_EXPERIMENTS"]
