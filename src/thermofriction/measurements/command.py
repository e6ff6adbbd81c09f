"""A drive's command under a measured motion (docs/force-data.md#drives-without-a-torque-sensor): the force or
torque a drive was commanded (or its motor current times the torque constant) moves a single mass (a rotary
inertia) against friction. A digital drive computes its command u_k at t_k and holds it until the next sample
(zero-order hold), ``delay`` later, so that the momentum integrated over the held sample is

    u(t_k) = mean over [t_k + delay, t_k+1 + delay] of (F + J a) + offset

with F the friction of a prescribed-motion model driven by the measured motion, a the motion's acceleration, J
the mass (inertia), ``offset`` the command's bias and ``delay`` how late the drive realises its command (the
transport delay: a point sample of F + J a would act half a sample later, and the bristles' fast change after a
reversal, a few ms, is not its mean). The residuals are ``mean(F + J a) + offset - u(t - delay)``.

- **The friction's mean** over each held sample is taken by quadrature (Gauss-Legendre, three nodes on each half
  of the interval: measurements/command_terms.py HOLD_FRACTIONS) of the friction at those times, from the C core's
  exact stepping of the prescribed motion where it applies (with its exact sensitivities, averaged the same way:
  the Jacobian is that of the residuals computed), else integrated; a position ripple is added at the middle of
  each held sample. Its mean over the interval at ``t + delay``: the means on the sample grid, linearly
  interpolated at a delay between samples.
- **J and the offset** enter linearly: they are profiled out, as the force sensor's offset is -- the residuals
  and the Jacobian's columns projected onto the complement of the columns ``[a, 1]`` (per-experiment offsets:
  one column of ones per run; none: ``[a]`` and the model's own offset) -- and estimated with their standard
  errors at the optimum (measurements/command_start.py: command_finish). The fitted model keeps its prescribed
  motion and holds J, the offset and the delay in its ``[plant]`` (``inertia``, ``sensor_offset``, ``delay``), so
  that validation predicts a command from a model file alone.
- **The acceleration's mean** over a held sample is the velocity's change over it over its length
  (:func:`held_acceleration`), the velocity smoothed by Savitzky-Golay (SciPy's ``savgol_filter``: a quadratic
  fitted by least squares over a window of samples, its value at the centre; zero-phase: it delays nothing, so
  that J a lines up with the friction). The window is chosen from each record (:func:`accel_window`): the
  narrowest whose noise biases J by at most ACCEL_BIAS; the narrowest, 3 samples, leaves the velocity as it is.
  (Noise left in ``a`` is an error in a regressor and pulls J towards zero by its variance over the
  acceleration's: the position must resolve the acceleration. A wider window blurs what changes within it: a
  lightly damped presliding ringing after a reversal; a fixed 9-sample window shifted a 1 kHz servo's delay by
  0.1 ms and doubled its sigma1.)
- **The delay** (identify's ``delay=``, measurements/delay.py): ``auto`` reads it off the data before the fit
  (:func:`delay_scan` over a range from the data, on the means over the held samples) and uses it only where it
  exceeds a quarter of a sample (MIN_DELAY_SAMPLES), else it is 0, and the result says which; then it is profiled
  out at every evaluation of the fit (:class:`DelaySearch`); a range is searched within its bounds; a value is
  held; ``none`` is 0. The model's side is shifted (linear interpolation, the end values held beyond the record).

How the command is read is the model's ``[plant] command_hold`` (:func:`held`): ``"zero-order"`` (the default)
as above; ``"none"`` for point samples of a continuous torque (a current measured at each sample, say), compared
with ``F + J a`` at the samples (``u(t - delay) = F(t) + J a(t) + offset``, a: the Savitzky-Golay slope at the
centre of the window). The fitted model keeps it, so that validation reads the command as the fit did. Point
samples read as held take a delay half a sample short (the mean over a sample is the point value half a sample
later to second order) and lose the presliding's fast change after a reversal (tests/test_identify_command.py).
"""

from __future__ import annotations

import copy
import dataclasses

import numpy as np

from ..data.force import ForceExperiment
from ..errors import InputError
from .command_start import command_finish, command_initial
from . import ripple
from .command_terms import (ACCEL_BIAS, MIN_DELAY_SAMPLES, CommandTrace, DelaySearch, accel_window, acceleration,
                            applied_delay, coulomb_columns, delay_scan, delay_search, held, held_acceleration,
                            hold_means, hold_nodes, linear_fit, midpoints, node_experiment, nuisance_columns,
                            shifted, velocity_noise)
from .delay import AUTO
from .force import Force


def implied_friction(model, exp):
    """(velocity, friction) that a command record implies with ``model``'s inertia and delay: ``u(t) - J a(t +
    delay)`` against ``v(t + delay)`` (a: the mean over each held sample and v at its middle, or both at the
    sample: :func:`held`; the offset left in, as a force sensor's is); a friction record as it is."""
    if not Command.recognises(exp):
        return exp.drive_velocity, exp.force
    d, hold = model.plant.delay, held(model)
    a = held_acceleration(exp) if hold else acceleration(exp)
    v = midpoints(exp.drive_velocity) if hold else exp.drive_velocity
    return shifted(exp.time, v, -d), np.asarray(exp.force, float) - model.plant.inertia * shifted(exp.time, a, -d)



def _at_nodes(problem):
    """``problem`` with each trace's times at its hold nodes (the friction evaluated there)."""
    out = copy.copy(problem)
    out.traces = [dataclasses.replace(tr, time=tr.nodes) for tr in problem.traces]
    return out


def _held(F, J, traces):
    """The friction (and Jacobian) at every trace's hold nodes, concatenated, as its means over each held sample."""
    if F is None:
        return None, None
    n = [tr.nodes.size for tr in traces]
    edges = np.cumsum([0] + n)
    means = [hold_means(F[a:b], tr.time.size) for tr, a, b in zip(traces, edges[:-1], edges[1:])]
    jac = None if J is None else np.vstack([hold_means(J[a:b], tr.time.size)
                                            for tr, a, b in zip(traces, edges[:-1], edges[1:])])
    return np.concatenate(means), jac


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
    #: False: the residuals are the friction's means over the held samples minus the record, nothing profiled out
    #: (the fit's completion, measurements/command_start.py: :meth:`unprofiled`)
    profiles = True

    @classmethod
    def unprofiled(cls, offset: str = "none") -> "Command":
        """A command measurement whose residuals are ``mean(F) - u`` at the samples: no inertia, offset or delay
        profiled out (``offset`` must be "none": what command_finish estimates them from)."""
        m = cls(offset)
        m.profiles = False
        return m

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
        return super().offsets_in(traces) + 1 + int(self._search(traces).searched)  # the inertia, the delay

    def initial_model(self, init, method, data, experiments, *, parameters=(), **options):
        """The delay, the inertia and a first offset read off the data, then force data's initial model
        (measurements/command_start.py); ``parameters`` (the fitted names) are not needed here."""
        return command_initial(init, method, data, experiments, self.delay, force=Force, **options)

    def complete(self, res, experiments, init):
        """The inertia, the offsets and the delay estimated at the optimum (measurements/command_start.py)."""
        return command_finish(res, experiments, init, self, friction=Command.unprofiled)

    def make_trace(self, exp, model) -> CommandTrace:
        tr = super().make_trace(exp, model)
        fields = {f.name: getattr(tr, f.name) for f in dataclasses.fields(tr)}
        hold = held(model)
        if hold:
            fields["angle"] = midpoints(tr.angle)  # (a ripple's angle: the middle of each held sample)
        return CommandTrace(**fields, acceleration=held_acceleration(exp) if hold else acceleration(exp),
                            command=np.asarray(exp.force, float), delay=model.plant.delay,
                            velocity=np.asarray(exp.drive_velocity, float),
                            nodes=hold_nodes(exp.time) if hold else None)

    def _exact(self, problem, model, names, jac):
        """The friction's means over the held samples by the exact stepping (Force's, at the hold nodes); at the
        samples for point samples."""
        if problem.traces[0].nodes is None:
            return super()._exact(problem, model, names, jac)
        F, J = super()._exact(_at_nodes(problem), model, names, jac)
        return _held(F, J, problem.traces)

    def _integrated(self, problem, model, theta, jac, skip=(), outside=False):
        """The friction's means over the held samples, integrated (Force's, at the hold nodes); at the samples for
        point samples."""
        if problem.traces[0].nodes is None:
            return super()._integrated(problem, model, theta, jac, skip, outside)
        F, J = super()._integrated(_at_nodes(problem), model, theta, jac, skip, outside)
        return _held(F, J, problem.traces)

    def profiled(self, traces, r, J):
        """The residuals and Jacobian with J and the offsets profiled out: projected onto the complement of the
        acceleration's and the offsets' columns (variable projection; the columns do not depend on the
        parameters, so the projected Jacobian is exact). Where the model has a delay, the delay is profiled out
        too: the one that leaves the least residuals for this friction (:class:`DelaySearch`), the friction and
        the acceleration taken at t + delay; the Jacobian is then that at the best delay (its gradient of the
        cost is exact, by the envelope theorem) projected off the delay's column (:meth:`DelaySearch.jacobian`:
        the parameters' intervals with the delay free)."""
        if not self.profiles:
            return r, J
        search = self._search(traces)
        F = r + search.u  # (Force: r = F - measured, the command as recorded)
        delay = search.best(F)[0]
        return search.residuals(F, delay), None if J is None else search.jacobian(F, J, delay)

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

    def held_friction(self, model, exp, rtol=1e-8, fast=False) -> np.ndarray:
        """The friction's mean over each held sample of ``exp`` (:meth:`friction_of` at its hold nodes), a ripple
        added at the middle of each (as the fit adds it)."""
        outside = ripple.additive(model)
        F = hold_means(self.friction_of(ripple.without(model) if outside else model, node_experiment(exp), rtol,
                                        fast), len(exp.time))
        if outside:
            F = F + ripple.for_run(self, model, dataclasses.replace(exp, displacement=midpoints(exp.displacement)), F)
        return F

    def predicted(self, model, exp, rtol=1e-8, fast=False):
        """(predicted, measured): the mean of ``F + J a`` over each held sample (point samples: its value at the
        sample, :func:`held`) plus the offset, at ``t + delay``, and the command as recorded."""
        if held(model):
            side = self.held_friction(model, exp, rtol, fast) + model.plant.inertia * held_acceleration(exp)
        else:
            side = self.friction_of(model, exp, rtol, fast) + model.plant.inertia * acceleration(exp)
        pred = side + model.plant.sensor_offset
        return shifted(exp.time, pred, -model.plant.delay), np.asarray(exp.force, float)

    def validation_extras(self, model) -> dict:
        return {"sensor_offset": model.plant.sensor_offset, "inertia": model.plant.inertia,
                "delay": model.plant.delay}


__all__ = ["Command", "CommandTrace", "DelaySearch", "delay_search", "implied_friction", "held", "acceleration",
           "held_acceleration", "hold_nodes", "hold_means", "shifted",
           "delay_scan", "linear_fit", "coulomb_columns", "applied_delay", "nuisance_columns", "accel_window",
           "velocity_noise", "ACCEL_BIAS", "MIN_DELAY_SAMPLES"]
