"""Solvers and the step-size controller: objects you pass to ``simulate``.

A solver names an integration method of the C core; the controller holds the tolerances and step
limits. They are separate so that either can change without the other.
"""

from __future__ import annotations

from dataclasses import dataclass

from .. import _args
from ..errors import InputError, shorten


@dataclass(frozen=True)
class Dopri5:
    """Dormand-Prince 5(4), explicit, 4th-order dense output. Best for non-stiff models."""

    name = "dopri5"


@dataclass(frozen=True)
class Rodas4:
    """Rodas4 (Hairer-Wanner), a 4(3) L-stable Rosenbrock method with analytic Jacobian and
    3rd-order dense output. For stiff models (stiff bristles, light end effectors)."""

    name = "rodas4"


@dataclass(frozen=True)
class AutoSwitch:
    """Per phase of the input, Dopri5 until its stiffness test fires, then Rodas4 where it is cheaper
    (default).

    Every corner of the input (a sawtooth's flyback and period start; and every GMS mode switch)
    starts a new phase with Dopri5: the ringing after a flyback is cheaper to follow with the
    explicit method, the slow ramp that follows with the stiff one. The Dopri5 phases run at 1/20 of
    the tolerances (GMS: 1/50): at equal tolerances Dopri5's global error on stick-slip is 10-50x
    Rodas4's, and the error only follows the tolerance when both kinds of phase deliver about the same
    accuracy. Their steps end at the relative velocity's reversals (not for GMS), where the friction's
    |v| kinks (Dopri5's error estimate does not see a kink inside a step), and Rodas4 waits until the
    velocity no longer rings (docs/performance.md)."""

    name = "auto"


SOLVERS = {"auto": AutoSwitch, "dopri5": Dopri5, "rodas4": Rodas4}


@dataclass(frozen=True)
class StepSizeController:
    """Error control: a step is accepted when the RMS over states of
    ``err_i / (atol_i + rtol * |y_i|)`` is at most 1 -- except for positions (the stage's and the
    driven body's), whose error is held to ``atol_i`` alone: a position counts from an arbitrary
    origin, and a stepping actuator or a pulled mass travels without bound, so ``rtol * |x|`` would
    loosen the control as it goes (a mass pulled 6 m had its slip onsets off by 0.5 % of the
    friction force's range).

    ``atol=None`` scales the absolute tolerance to each state: ``rtol`` times its characteristic
    magnitude (stage stroke for positions, stroke x natural frequency for velocities, fc/sigma0
    for the bristle deflection), so that micrometre motions are controlled as tightly as metres.

    Parameters
    ----------
    rtol : float, default 1e-6
        The relative tolerance, between 0 and 1.
    atol : float or sequence of float, optional
        The absolute tolerance: one value for every state, or one per state (in each state's SI unit), each
        > 0; default None, scaled to each state as said above.
    first_step : float, optional
        The first step [s], > 0; default chosen by the integrator.
    max_step : float, optional
        The largest step [s], > 0; default none.
    max_steps : int, default 10_000_000
        The most steps of a run (>= 1); more is a SolverError ("max_steps").

    Raises
    ------
    InputError
        A value of the wrong type or out of its range, named (``rtol must be between 0 and 1, got 2``).

    Examples
    --------
    >>> import thermofriction as tf
    >>> tf.StepSizeController(rtol=1e-8, max_step=1e-4).rtol
    1e-08
    """

    rtol: float = 1e-6
    atol: float | tuple | None = None
    first_step: float | None = None
    max_step: float | None = None
    max_steps: int = 10_000_000

    def __post_init__(self):  # one checker per kind of argument (_args.py)
        if not 0 < _args.number(self.rtol, "rtol") < 1:
            raise InputError(f"rtol must be between 0 and 1, got {shorten(self.rtol)}")
        _args.whole(self.max_steps, "max_steps", low=1)
        _args.number_list(self.atol, "atol", none=True, positive=True)  # one, or one per state
        for name in ("first_step", "max_step"):
            _args.number(getattr(self, name), name, "s", none=True, positive=True)


# ---------------------------------------------------------------------------------------------


__all__ = ["Dopri5", "Rodas4", "AutoSwitch", "StepSizeController", "SOLVERS"]
