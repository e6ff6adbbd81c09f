"""Force data at a run's load (docs/force-data.md#loads): a model whose laws depend on temperature and load
(models/load_laws.py) acts on one run through its parameters' values at the run's (temperature, load); the friction
force along the run's measured motion is the C core's exact stepping of the model holding those values as numbers,
with its sensitivities to them, and the chain rule to the laws' coefficients is each law's own derivatives
(``LoadLaw.coefficient_derivatives``; a temperature law's by central differences, as ``Problem.chain_matrix``).
A run whose motion the exact stepping does not apply to (or a temperature signal, or a load that varies over the run)
is refused here, naming the file: a fit of the laws takes each run at one (temperature, load).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .. import _bridge
from ..data.load import LOAD_VARIES, load_varies
from ..drive import drive
from ..errors import InputError
from ..models import Model
from ..models.load_laws import LoadLaw, LoadRangeWarning, LoadTerm, load_laws
from ..results import Finding, emit

#: a temperature law's derivatives through the same code as a load law's (a product with |load| = 1)
_NO_LOAD = LoadTerm("proportional")


def run_load(exp) -> float:
    """The load of force run ``exp``, or one InputError naming its file where it has none.

    Parameters
    ----------
    exp : ForceExperiment
        The run.

    Returns
    -------
    float
        Its load [N or N m].

    Raises
    ------
    InputError
        The run carries no load, or its load column varies over the run.
    """
    signal = getattr(exp, "load_signal", None)
    if load_varies(signal):
        raise InputError(f"{exp.file}: the load column varies over the run ({float(np.min(signal)):.4g} to "
                         f"{float(np.max(signal)):.4g}); a force fit of the laws of the load takes each run's constant "
                         f"load (within {100 * LOAD_VARIES:g} % of its mean); a simulation is driven by it per sample")
    if getattr(exp, "load", None) is None:
        raise InputError(f"{exp.file}: the model's laws depend on the load but the run has none: give 'load' in the "
                         f"manifest or a normal_force[N] / load_torque[N*m] column")
    return float(exp.load)


def law_derivatives(law, T: float, load: float) -> np.ndarray:
    """d law / d each coefficient at (T, load): a law of load's own; a temperature law's by central differences.

    Parameters
    ----------
    law : Law
        A temperature law or a LoadLaw.
    T : float
        The temperature [C].
    load : float
        The load [N or N m] (ignored by a temperature law).

    Returns
    -------
    numpy.ndarray
        One derivative per coefficient, in ``law.coefficient_names()``'s order.
    """
    if isinstance(law, LoadLaw):
        return law.coefficient_derivatives(T, load)
    return LoadLaw(law, _NO_LOAD).coefficient_derivatives(T, 1.0)


def model_at(model: Model, T: float, load: float | None, warn: bool = False) -> Model:
    """``model`` with every law replaced by its value at (T, load): a model of numbers, no thermal extension.

    Parameters
    ----------
    model : Model
        A Model I model (its laws may depend on the load).
    T : float
        The temperature [C].
    load : float or None
        The load [N or N m]; None only for a model without laws of load.
    warn : bool, default False
        Warn (LoadRangeWarning) at a load outside a law's range.

    Returns
    -------
    Model
    """
    outside = [f"'{n}' ({law.load.range[0]:.4g}..{law.load.range[1]:.4g})" for n, law in load_laws(model).items()
               if not law.load.in_range(load)]
    if warn and outside:  # one finding for the run, naming every law, as a temperature range's
        emit([Finding(LoadRangeWarning, f"load {load:.4g} is outside the calibrated range of |load| of the law(s) "
                                        f"for {', '.join(outside)}: their values there are extrapolations")])
    values = {n: (law.value(T, load, warn=False) if isinstance(law, LoadLaw) else float(law(T)))
              for n, law in model.laws.items()}
    return dataclasses.replace(model, thermal=None, friction=model.friction.with_values(**values))


def stepped_force(model: Model, exp, names=(), warn: bool = False) -> tuple:
    """(friction force on the run's samples, its derivatives in the friction parameters ``names`` at the run's
    conditions) of ``model`` at run ``exp``'s temperature and load, by the core's exact stepping.

    Parameters
    ----------
    model : Model
        A prescribed-motion Model I model.
    exp : ForceExperiment
        The run, carrying its load where the model has laws of load.
    names : sequence of str, default ()
        Friction parameters to differentiate in.
    warn : bool, default False
        Warn (LoadRangeWarning) at a load outside a law's range (a prediction's; a fit's steps do not).

    Returns
    -------
    tuple
        (F, dF of shape (samples, len(names))).

    Raises
    ------
    InputError
        No load where one is needed; a recorded temperature that varies; a model the exact stepping does not apply to.
    """
    load = run_load(exp) if load_laws(model) else getattr(exp, "load", None)
    d = drive(exp, model, start="record")
    if not isinstance(d.temperature, (int, float)):
        raise InputError(f"{exp.file}: the temperature varies over the run; a law of load is fitted on runs at a "
                         f"constant temperature (each run at one condition, stepped exactly)")
    at = model_at(model, float(d.temperature), load, warn)
    spec = _bridge.model_spec(at, float(d.temperature), d.waveform)
    if not _bridge.prescribed_applies(spec):
        raise InputError(f"{exp.file}: the core's exact stepping does not apply to this model ({model.friction.model});"
                         f" a force fit of a law of load needs it")
    try:
        return _bridge.prescribed_force(spec, np.asarray(exp.time, float), tuple(names))
    except _bridge.CoreFailure as e:
        raise InputError(f"{exp.file}: the model cannot be stepped at this run's conditions ({e})") from None


__all__ = ["run_load", "law_derivatives", "model_at", "stepped_force"]
