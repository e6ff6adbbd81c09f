"""Measurements: what an experiment recorded, and how a model is held against it (docs/architecture.md#measurements).

A registry of the measured quantities -- :class:`Displacement` (driven by a voltage), :class:`Force` (friction
force or torque under a measured motion) and :class:`Command` (a drive's command under a measured motion: friction
plus the inertia's force). ``identify``, ``validate`` and ``report`` ask a dataset's measurement
once, with :func:`measurement_of`, and then ask it what they need. A new measured quantity is a module here that
implements :class:`Measurement` and an entry in :data:`REGISTRY`.
"""

from __future__ import annotations

from ..errors import InputError, shorten
from ..models import Model
from .base import OFFSETS, Measurement, MetricWarning, Trace, amount, center  # (MetricWarning: validate's)
from .displacement import Displacement, Prediction, step_sizes  # (Prediction, step_sizes: validate's)
from .force import Force, ForcePrediction, steady_state_curve
from .command import Command
from .ripple import RIPPLE_PHASES, check_phase_option, decide

#: The measured quantities, the most specific first: an experiment is the first one's that recognises it.
REGISTRY = {"command": Command, "force": Force, "displacement": Displacement}


def kind_of(exp) -> str:
    """The measurement an experiment records: the first of ``REGISTRY`` that recognises it.

    Parameters
    ----------
    exp : Experiment or ForceExperiment
        The experiment.

    Returns
    -------
    str
        "command", "force" or "displacement".

    Raises
    ------
    StopIteration
        None recognises it (cannot happen: displacement takes every experiment).
    """
    return next(name for name, cls in REGISTRY.items() if cls.recognises(exp))


def measurement_of(data, *, offset=None, ripple_phase="auto") -> Measurement:
    """The measurement of ``data``, with its offset policy. A dataset that mixes measurements is refused.

    Parameters
    ----------
    data : Dataset or list of Experiment
        The dataset or its experiments.
    offset : str or bool, optional
        None or True for the measurement's default, a policy's name (OFFSETS: "shared", "per-experiment",
        "none"), or False for "none" (the model's own offset, fitted by none).
    ripple_phase : {"auto", "recorded", "per-run"}, default "auto"
        Force data: the position ripple's angle (measurements/ripple.py), "auto" decided from ``data`` and said in
        the measurement's ``ripple_note``.

    Returns
    -------
    Measurement
        ``Displacement``, ``Force`` or ``Command``.

    Raises
    ------
    InputError
        A dataset that mixes measurements; an offset policy that does not apply to them; an unknown ripple phase.
    """
    m = _measurement_of(data, offset)
    if isinstance(m, Force):
        m.ripple_phase, m.ripple_note = ripple_phase, None
        if check_phase_option(ripple_phase) == "auto":
            m.ripple_phase, m.ripple_note = decide(data)
    return m


def _measurement_of(data, offset) -> Measurement:
    exps = list(getattr(data, "experiments", data))
    kinds = {kind_of(e) for e in exps} or {"displacement"}
    if len(kinds) > 1:
        if kinds == {"command", "force"}:
            raise InputError("the dataset mixes experiments that record the friction with ones that record a drive's "
                             "command (or current); keep them in separate datasets")
        raise InputError("the dataset mixes force (torque) experiments with actuator (voltage, displacement) ones; "
                         "keep them in separate datasets")
    cls = REGISTRY[kinds.pop()]
    if offset is None or offset is True:
        return cls()
    if offset is False:
        offset = "none"
    if offset not in OFFSETS:
        raise InputError(f"offset must be one of {', '.join(OFFSETS)}, got {shorten(offset)}")
    return cls(offset)


def make_traces(experiments, model: Model, measurement=None):
    """One trace per experiment, made by their measurement (default: the experiments' own, with its default
    offset policy).

    Parameters
    ----------
    experiments : list of Experiment
        The experiments.
    model : Model
        The model the traces are driven as (its input and temperature handling).
    measurement : Measurement, optional
        How the residuals are formed; default the experiments' own, with its default offset policy.

    Returns
    -------
    list of Trace

    Raises
    ------
    InputError
        An experiment the measurement cannot drive the model with.
    """
    measurement = measurement or measurement_of(experiments)
    return [measurement.make_trace(exp, model) for exp in experiments]


__all__ = ["Measurement", "Trace", "OFFSETS", "Displacement", "Force", "Command", "ForcePrediction", "REGISTRY",
           "measurement_of", "kind_of", "RIPPLE_PHASES", "amount", "center", "steady_state_curve"]
