"""The parts of a position control loop with friction compensation (control.h): the PID, the two
compensations and what each is told about the temperature and the load, and the friction measurement an online
temperature estimator reads in the loop. ``thermofriction.control`` runs them (``simulate_loop``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _args
from .errors import InputError
from .estimation import TemperatureEstimator
from .models import FRICTION_MODELS, Model
from .simulation.checks import temperature_findings


# -- argument checks: the package's InputError naming the argument, before the C core sees it -----

def _number(where: str, name: str, value, *, minimum=None, positive=False) -> float:
    """A finite real number (not a string, not a bool), optionally > 0 or >= minimum (_args.number)."""
    return _args.number(value, f"{where}: {name}", minimum=minimum, positive=positive)


def _model(where: str, name: str, model) -> Model:
    if not isinstance(model, Model):
        raise InputError(f"{where}: {name} must be a thermofriction Model (e.g. tf.load_model(...)), "
                         f"got {type(model).__name__}")
    return model


def _samples(where: str, name: str, values, n=None) -> np.ndarray:
    """A 1-D array of finite floats (n of them when given)."""
    try:
        a = np.ascontiguousarray(values, float)
    except (TypeError, ValueError, OverflowError):  # (an int of 10**400 is no float)
        raise InputError(f"{where}: {name} must be an array of numbers") from None
    if a.ndim != 1 or (n is not None and a.size != n):
        raise InputError(f"{where}: {name} must be one-dimensional" + (f" with {n} values" if n is not None else "")
                         + f", got shape {a.shape}")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise InputError(f"{where}: {name}[{bad[0]}] is {float(a[bad[0]])!r}: every value must be finite")
    return a


def _check_at(where: str, model: Model, temperature: float):
    """The model's domain at one temperature (Model I parameters, Model II's lambda), with the
    simulator's messages; its findings (calibrated range, passivity) are the simulator's business."""
    try:
        temperature_findings(model, temperature)
    except InputError as e:
        raise InputError(f"{where}: {e}") from None


#: The friction models with a bristle state for the observer to estimate.
OBSERVED_MODELS = tuple(n for n, c in FRICTION_MODELS.items() if c.description.bristle)


@dataclass(frozen=True)
class PID:
    """u = kp e + ki int e + kd de/dt (derivative filtered with time constant ``tau_d``), e = x_ref - x.

    Parameters
    ----------
    kp : float
        The proportional gain [N/m].
    ki : float
        The integral gain [N/(m s)].
    kd : float
        The derivative gain [N s/m].
    tau_d : float, default 0.0
        The derivative filter's time constant [s], >= 0 (0: unfiltered).

    Raises
    ------
    InputError
        A gain that is not a finite number, or a negative ``tau_d``, named.
    """

    kp: float
    ki: float
    kd: float
    tau_d: float = 0.0

    def __post_init__(self):
        for name in ("kp", "ki", "kd"):
            _number("PID", name, getattr(self, name))
        _number("PID", "tau_d", self.tau_d, minimum=0.0)


def _told(where: str, temperature):
    """A compensation's temperature: None, a float, a 1-D float array (one per period) or an estimator."""
    if temperature is None or isinstance(temperature, TemperatureEstimator):
        return temperature
    if np.ndim(temperature) == 0:
        return _number(where, "temperature", temperature)
    return _samples(where, "temperature", temperature)


def _told_load(where: str, load):
    """A compensation's load: None (the stage's), a float (held: load-blind) or a 1-D float array (one per period)."""
    if load is None:
        return None
    if np.ndim(load) == 0:
        return _number(where, "load", load)
    return _samples(where, "load", load)


@dataclass(frozen=True, eq=False)
class FeedForward:
    """u_ff = F(v_ref, T) from ``model`` told ``temperature`` (None: the stage's, i.e. measured).

    Parameters
    ----------
    model : Model
        The friction model used for compensation.
    temperature : float, array_like or TemperatureEstimator, optional
        What the model is told: None, the stage's temperature (a perfect sensor, following it when it
        changes); a number [C], held (blind: a calibration temperature never updated); one value per
        control period [C] (a sensor's reading); or a ``TemperatureEstimator``, run in the loop on the
        friction it measures (``simulate_loop``'s ``friction_measurement``).
    load : float or array_like, optional
        The load [N or N m] the model's laws of the load are told (a model without one ignores it): None, the
        stage's (a perfect load sensor); a number, held (load-blind: a calibration load never updated); or one
        value per control period (a sensor's reading).

    Raises
    ------
    InputError
        Not a Model, or a temperature or load that is none of these, named.
    """

    model: Model
    temperature: float | np.ndarray | TemperatureEstimator | None = None
    load: float | np.ndarray | None = None
    kind = "feedforward"

    def __post_init__(self):
        _model("FeedForward", "model", self.model)
        object.__setattr__(self, "temperature", _told("FeedForward", self.temperature))
        object.__setattr__(self, "load", _told_load("FeedForward", self.load))


@dataclass(frozen=True, eq=False)
class Observer:
    """Canudas de Wit et al. (1995): z^' = v - sigma0 |v| z^/g(v) - gain (x - x_ref),
    u_c = sigma0 z^ + sigma1 z^' + sigma2 v, from ``model`` told ``temperature`` (None: measured).

    The observer estimates a bristle deflection, so ``model`` must have one: LuGre, Dahl or
    elasto-plastic. Coulomb and Stribeck have no state to observe (use ``FeedForward``); GMS has one
    per element and no published observer. ``gain`` [1/s] >= 0 (0: no correction).

    Parameters
    ----------
    model : Model
        The model, with a LuGre, Dahl or elasto-plastic friction model.
    gain : float, default 100.0
        The observer gain [1/s], >= 0.
    temperature : float, array_like or TemperatureEstimator, optional
        What the model is told, as ``FeedForward``'s ``temperature``.
    load : float or array_like, optional
        The load the model is told, as ``FeedForward``'s ``load``.

    Raises
    ------
    InputError
        Not a Model, a friction model without a bristle state, a negative gain, a temperature or load that is
        not one of ``FeedForward``'s kinds, named.
    """

    model: Model
    gain: float = 100.0
    temperature: float | np.ndarray | TemperatureEstimator | None = None
    load: float | np.ndarray | None = None
    kind = "observer"

    def __post_init__(self):
        _model("Observer", "model", self.model)
        kind = self.model.friction.model
        if kind not in OBSERVED_MODELS:
            raise InputError(f"Observer: the observer estimates a bristle state, which a {kind} model does not have "
                             f"(it needs a LuGre, Dahl or elasto-plastic model; use FeedForward for {kind})")
        _number("Observer", "gain", self.gain, minimum=0.0)
        object.__setattr__(self, "temperature", _told("Observer", self.temperature))
        object.__setattr__(self, "load", _told_load("Observer", self.load))


@dataclass(frozen=True)
class DisturbanceObserver:
    """The friction an online temperature estimator measures in the loop (control.h): a disturbance
    observer that knows the mass m and the control u and reads the encoder, x + noise, at each period:
    F = (u_{i-2} + u_{i-1}) / 2 - m (x_i - 2 x_{i-1} + x_{i-2}) / dt^2, the friction around t_{i-1}, at
    the velocity (x_i - x_{i-2}) / (2 dt), low-passed with time constant ``filter_time``.

    Parameters
    ----------
    position_noise : float, default 1e-9
        The encoder's position noise [m], white and normal (standard deviation), >= 0. At 10 kHz, 1 nm of
        position noise is 0.24 N of force noise on a 1 kg stage.
    filter_time : float, default 0.0
        The low-pass filter's time constant [s], >= 0 (0: none; the estimator averages).
    seed : int, default 0
        The noise's random seed.

    Raises
    ------
    InputError
        A value that is not a finite number, or negative, named.
    """

    position_noise: float = 1e-9
    filter_time: float = 0.0
    seed: int = 0

    def __post_init__(self):
        _number("DisturbanceObserver", "position_noise", self.position_noise, minimum=0.0)
        _number("DisturbanceObserver", "filter_time", self.filter_time, minimum=0.0)
        _args.whole(self.seed, "DisturbanceObserver: seed", low=0)

    def noise(self, n: int) -> np.ndarray | None:
        """The encoder's noise at ``n`` periods [m] (None without noise).

        Parameters
        ----------
        n : int
            The number of control periods.

        Returns
        -------
        numpy.ndarray or None
        """
        if self.position_noise == 0.0:
            return None
        return np.random.default_rng(self.seed).normal(0.0, self.position_noise, n)


#: Gains for the stage-model-i preset (1 kg): ~30 Hz bandwidth, well damped, at 10 kHz.
DEFAULT_PID = PID(kp=4e4, ki=4e5, kd=280.0, tau_d=2e-4)

__all__ = ["OBSERVED_MODELS", "PID", "DEFAULT_PID", "FeedForward", "Observer", "DisturbanceObserver"]
