"""Position references for the closed loop (``thermofriction.control.simulate_loop``), sampled at the
control period: a sine, a point-to-point move, and a duty cycle of moves and dwells repeated for minutes."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .compensation import _number
from .errors import InputError


@dataclass(frozen=True)
class Reference:
    """A position reference sampled at the control period: time, position x_ref, velocity v_ref.

    Parameters
    ----------
    name : str
        The reference's name in tables.
    time : numpy.ndarray
        The control instants [s].
    position : numpy.ndarray
        x_ref [m].
    velocity : numpy.ndarray
        v_ref [m/s].
    """

    name: str
    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray


#: the most samples of a reference (10 million: ~240 MB for its three arrays)
MAX_REFERENCE_SAMPLES = 10_000_000


def _check_length(where, duration, dt):
    if duration / dt > MAX_REFERENCE_SAMPLES:
        raise InputError(f"{where}: duration / dt = {duration / dt:.3g} samples, more than the limit of "
                         f"{MAX_REFERENCE_SAMPLES}: lengthen dt or shorten the reference")


def sine_reference(amplitude: float, frequency: float, duration: float, dt: float = 1e-4) -> Reference:
    """x_ref = amplitude (1 - cos(2 pi f t)): starts at rest at 0, reverses every half period.

    Parameters
    ----------
    amplitude : float
        [m]; the reference spans 0 to 2 amplitude.
    frequency : float
        [Hz], > 0.
    duration : float
        [s], > 0.
    dt : float, default 1e-4
        The control period [s], > 0.

    Returns
    -------
    Reference

    Raises
    ------
    InputError
        A value that is not a finite number or out of range, named; more samples than the limit.
    """
    where = "sine_reference"
    amplitude, frequency = _number(where, "amplitude", amplitude), _number(where, "frequency", frequency, positive=True)
    duration, dt = _number(where, "duration", duration, positive=True), _number(where, "dt", dt, positive=True)
    _check_length(where, duration, dt)
    t = np.arange(int(round(duration / dt)) + 1) * dt
    w = 2 * math.pi * frequency
    return Reference(f"sine {amplitude * 1e3:g} mm, {frequency:g} Hz", t, amplitude * (1 - np.cos(w * t)),
                     amplitude * w * np.sin(w * t))


def point_to_point(distance: float, move_time: float, dwell: float, dt: float = 1e-4) -> Reference:
    """A quintic (minimum-jerk) move of ``distance`` in ``move_time``, a dwell, and back the same way.

    Parameters
    ----------
    distance : float
        [m].
    move_time : float
        Each move's duration [s], > 0.
    dwell : float
        The rest between the moves [s], >= 0.
    dt : float, default 1e-4
        The control period [s], > 0.

    Returns
    -------
    Reference

    Raises
    ------
    InputError
        A value that is not a finite number or out of range, named; more samples than the limit.
    """
    where = "point_to_point"
    distance, move_time = _number(where, "distance", distance), _number(where, "move_time", move_time, positive=True)
    dwell, dt = _number(where, "dwell", dwell, minimum=0.0), _number(where, "dt", dt, positive=True)
    _check_length(where, 2 * (move_time + dwell), dt)
    n = int(round((2 * (move_time + dwell)) / dt)) + 1
    t = np.arange(n) * dt
    period = move_time + dwell
    x, v = np.zeros(n), np.zeros(n)
    for k, sign in ((0, 1.0), (1, -1.0)):
        s = np.clip((t - k * period) / move_time, 0.0, 1.0)
        inside = (t >= k * period) & (t <= k * period + move_time)
        x += sign * distance * (10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5)
        v += np.where(inside, sign * distance * (30 * s ** 2 - 60 * s ** 3 + 30 * s ** 4) / move_time, 0.0)
    return Reference(f"point-to-point {distance * 1e3:g} mm in {move_time:g} s", t, x, v)


def duty_cycle(distance: float, move_time: float, dwell: float, duration: float, dt: float = 1e-4) -> Reference:
    """``point_to_point`` repeated for ``duration``: out, dwell, back, dwell, ..., as a stage works for
    minutes (the warm-up study of docs/control.md).

    Parameters
    ----------
    distance : float
        [m].
    move_time : float
        Each move's duration [s], > 0.
    dwell : float
        The rest after each move [s], >= 0.
    duration : float
        [s], > 0 (the last cycle cut there).
    dt : float, default 1e-4
        The control period [s], > 0.

    Returns
    -------
    Reference

    Raises
    ------
    InputError
        A value that is not a finite number or out of range, named; more samples than the limit.
    """
    where = "duty_cycle"
    duration = _number(where, "duration", duration, positive=True)
    _check_length(where, duration, _number(where, "dt", dt, positive=True))
    cycle = point_to_point(distance, move_time, dwell, dt)
    m = cycle.time.size - 1  # one cycle's periods (its last sample is the next cycle's first)
    n = int(round(duration / dt)) + 1
    reps = -(-n // m) + 1
    x = np.tile(cycle.position[:-1], reps)[:n]
    v = np.tile(cycle.velocity[:-1], reps)[:n]
    return Reference(f"duty cycle {distance * 1e3:g} mm in {move_time:g} s, {dwell:g} s dwell, {duration:g} s",
                     np.arange(n) * dt, x, v)


__all__ = ["Reference", "MAX_REFERENCE_SAMPLES", "sine_reference", "point_to_point", "duty_cycle"]
