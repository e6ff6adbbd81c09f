"""A drive's command under a measured motion (docs/force-data.md#drives-without-a-torque-sensor): the force or
torque a drive was commanded (or its motor current times the torque constant) moves a single mass (a rotary
inertia) against friction, so that

    u(t - delay) = F(t) + J a(t) + offset

with F the friction of a prescribed-motion model driven by the measured motion, a the motion's acceleration, J
the mass (inertia), ``offset`` the command's bias and ``delay`` how late the drive realises its command. The
residuals are ``F + J a + offset - u(t - delay)``.

- **J and the offset** enter linearly: they are profiled out, as the force sensor's offset is -- the residuals
  and the Jacobian's columns projected onto the complement of the columns ``[a, 1]`` (per-experiment offsets:
  one column of ones per run; none: ``[a]`` and the model's own offset) -- and estimated with their standard
  errors at the optimum (measurements/command_start.py: command_finish). The fitted model keeps its prescribed motion and
  holds J, the offset and the delay in its ``[plant]`` (``inertia``, ``sensor_offset``, ``delay``), so that
  validation predicts a command from a model file alone.
- **The acceleration** is a Savitzky-Golay derivative (SciPy's ``savgol_filter``: a quadratic fitted by least
  squares over a window of samples, its slope at the centre) of the velocity that drives the model, on a uniform
  grid at the median sampling interval. A centred window is a symmetric (zero-phase) filter: it delays nothing,
  so that J a lines up with the friction; it averages the differentiation's noise over the window, and it blurs
  what changes within it (a lightly damped presliding ringing after a reversal: a 9-sample window shifted a 1 kHz
  servo's delay by 0.1 ms and doubled its sigma1). The window is chosen from each record (:func:`accel_window`):
  the narrowest whose noise biases J by at most ACCEL_BIAS. (Noise left in ``a`` is an error in a regressor and
  pulls J towards zero by its variance over the acceleration's: the position must resolve the acceleration.)
- **The delay** (identify's ``delay=``, measurements/delay.py): ``auto`` reads it off the data before the fit
  (:func:`delay_scan` over a range from the data) and uses it only where it exceeds about a sample
  (MIN_DELAY_SAMPLES), else it is 0, and the result says which; a range is searched within its bounds; a value
  is held; ``none`` is 0. The model's side is shifted (linear interpolation, the end values held beyond the
  record).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..data.force import ForceExperiment
from ..errors import InputError
from .command_start import command_finish, command_initial
from .command_terms import (ACCEL_BIAS, MIN_DELAY_SAMPLES, CommandTrace, DelaySearch, accel_window, acceleration,
                            applied_delay, coulomb_columns, delay_scan, delay_search, linear_fit, nuisance_columns,
                            shifted, velocity_noise)
from .delay import AUTO
from .force import Force

def implied_friction(model, exp):
    """(velocity, friction) that a command record implies with ``model``'s inertia and delay: ``u(t) - J a(t +
    delay)`` against ``v(t + delay)`` (the offset left in, as a force sensor's is); a friction record as it is."""
    if not Command.recognises(exp):
        return exp.drive_velocity, exp.force
    d = model.plant.delay
    return (shifted(exp.time, exp.drive_velocity, -d),
            np.asarray(exp.force, float) - model.plant.inertia * shifted(exp.time, acceleration(exp), -d))


class Command(Force):
    """A drive's command (force, torque, or current times the torque constant) under a measured motion.

    Parameters
    ----------
    offset : {"shared", "per-experiment", "none"}, default "shared"
        The offset policy (OFFSETS): "shared", one fitted offset for all runs; "per-experiment", each run's own,
        estimated on it; "none", the model's own, held.
    ripple_phase : {"recorded", "per-run", "auto"}, default "recorded"
        The position ripple's angle, as for :class:`Force`.

    Raises
    ------
    InputError
        An offset policy that does not apply to these data; an unknown ripple phase.
    """

    name = "command"
    quantity = "drive command (force or torque)"
    #: how the fit takes the delay (delay.py; identify's delay=)
    delay = AUTO

    @staticmethod
    def recognises(exp) -> bool:
        return isinstance(exp, ForceExperiment) and exp.measured_quantity == "command"

    @property
    def removed(self) -> str:
        offset = {"shared": "the shared offset", "none": "the model's offset (held)",
                  "per-experiment": "each experiment's own offset"}[self.offset]
        return f"the inertia term J a and {offset} (fitted)"

    held_offset_said = "the command predicted with the model's inertia term and offset"
    held_offset_said_in_full = ("the command predicted with the model's inertia term and offset ([plant] inertia, "
                                "sensor_offset, at its delay)")

    @property
    def validation_removed(self) -> str:
        if self.offset == "per-experiment":
            return super().validation_removed
        return "the model's inertia term and offset ([plant] inertia, sensor_offset), as fitted"

    def offsets_in(self, traces) -> int:
        return super().offsets_in(traces) + 1  # the inertia

    def initial_model(self, init, method, data, experiments, *, parameters=(), **options):
        """The delay, the inertia and a first offset read off the data, then force data's initial model
        (measurements/command_start.py); ``parameters`` (the fitted names) are not needed here."""
        return command_initial(init, method, data, experiments, self.delay, force=Force, **options)

    def complete(self, res, experiments, init):
        """The inertia, the offsets and the delay estimated at the optimum (measurements/command_start.py)."""
        return command_finish(res, experiments, init, self, force=Force)

    def make_trace(self, exp, model) -> CommandTrace:
        tr = super().make_trace(exp, model)
        fields = {f.name: getattr(tr, f.name) for f in dataclasses.fields(tr)}
        return CommandTrace(**fields, acceleration=acceleration(exp), command=np.asarray(exp.force, float),
                            search_delay=model.plant.delay != 0, delay=model.plant.delay,
                            velocity=np.asarray(exp.drive_velocity, float))

    def profiled(self, traces, r, J):
        """The residuals and Jacobian with J and the offsets profiled out: projected onto the complement of the
        acceleration's and the offsets' columns (variable projection; the columns do not depend on the
        parameters, so the projected Jacobian is exact). Where the model has a delay, the delay is profiled out
        too: the one that leaves the least residuals for this friction (:class:`DelaySearch`), the friction and
        the acceleration taken at t + delay; the Jacobian is then that at the best delay (its gradient of the
        cost is exact, by the envelope theorem)."""
        search = self._search(traces)
        F = r + search.u  # (Force: r = F - measured, the command as recorded)
        delay = search.best(F)[0]
        return search.residuals(F, delay), None if J is None else search.project(search.shift(J, delay), delay)

    def _search(self, traces):
        key = (id(traces), len(traces), traces[0].delay, self.offset, self.delay)
        if getattr(self, "_cached", (None,))[0] != key:
            self._cached = (key, delay_search(traces, self.offset, self.delay, traces[0].delay))
        return self._cached[1]

    def checks(self, model, traces) -> list:
        return super().checks(model, traces) + [
            "for a drive's command: check the torque constant, and that the position resolves the acceleration "
            "(docs/force-data.md#drives-without-a-torque-sensor)"]

    def check_model(self, model, experiments):
        super().check_model(model, experiments)
        if not model.plant.inertia > 0:
            raise InputError("a drive's command is predicted with the moving part's inertia ([plant] inertia), and "
                             "this model has none: fit the model to command data (identify), or give it")

    def predicted(self, model, exp, rtol=1e-8, fast=False):
        """(predicted, measured): ``F + J a + offset`` at ``t + delay``, and the command as recorded."""
        pred = self.friction_of(model, exp, rtol, fast) + model.plant.inertia * acceleration(exp) + model.plant.sensor_offset
        return shifted(exp.time, pred, -model.plant.delay), np.asarray(exp.force, float)

    def validation_extras(self, model) -> dict:
        return {"sensor_offset": model.plant.sensor_offset, "inertia": model.plant.inertia,
                "delay": model.plant.delay}


__all__ = ["Command", "CommandTrace", "DelaySearch", "delay_search", "implied_friction", "acceleration", "shifted",
           "delay_scan", "linear_fit", "coulomb_columns", "applied_delay", "nuisance_columns", "accel_window",
           "velocity_noise", "ACCEL_BIAS", "MIN_DELAY_SAMPLES"]
