"""Errors that the command line turns into one clear message and an exit status."""


class ThermofrictionError(Exception):
    """Base class; ``exit_status`` is what the command line exits with."""

    exit_status = 1


class InputError(ThermofrictionError, ValueError):
    """Bad file, key, value or option (exit status 2)."""

    exit_status = 2


class ComputationError(ThermofrictionError, RuntimeError):
    """A computation failed (exit status 1)."""

    exit_status = 1


class SolverError(ComputationError):
    """The integrator stopped: ``time`` and ``state`` say where."""

    def __init__(self, message, time=None, state=None):
        super().__init__(message)
        self.time = time
        self.state = state


class TemperatureRangeWarning(UserWarning):
    """A temperature law was evaluated outside the range it was calibrated on."""


class PassivityWarning(UserWarning):
    """A friction model's parameters violate a passivity/dissipativity condition (it can create energy)."""


class ConditioningWarning(UserWarning):
    """The model is ill-conditioned where it will be simulated (default tolerances may not be enough)."""


class UnitWarning(UserWarning):
    """A record's values look like another unit than their header declares (docs/your-data.md#units): a scale
    implausible for the plant, or a power of 1000 off what the model produces for the same experiment."""


def shorten(value, limit: int = 60) -> str:
    """``repr(value)``, cut to about ``limit`` characters: a message quotes what it refuses, but a
    1 MB key or value is not echoed back whole."""
    text = repr(value)
    if len(text) <= limit:
        return text
    return f"{text[:limit - 20]}...{text[-10:]} ({len(text)} characters)"


def unknown_keys(keys, allowed, what="") -> str:
    """``unknown key 'x' for lugre (allowed: a, b)`` -- one wording for every unknown-key error."""
    keys = sorted(keys)
    if len(keys) > 5:
        keys = keys[:5] + [f"and {len(keys) - 5} more"]
        names = ", ".join(shorten(k) for k in keys[:5]) + f", {keys[5]}"
    else:
        names = ", ".join(shorten(k) for k in keys)  # repr: a key with a line break stays on one line
    head = f"unknown key {names}" if len(keys) == 1 else f"unknown keys {names}"
    return f"{head}{f' for {what}' if what else ''} (allowed: {', '.join(allowed)})"
