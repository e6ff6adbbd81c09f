"""A drive's command instead of a friction sensor (docs/force-data.md#drives-without-a-torque-sensor): a force
experiment may record, instead of ``friction_force[N]`` / ``friction_torque[N*m]``, the force or torque the drive
was commanded (``command_force[N]`` / ``command_torque[N*m]``) or its motor current (``current[A]``) with the
dataset's ``torque_constant`` [N m/A, or N/A for a linear motor]. The experiment then holds the command in N or
N m in ``force`` and says so in ``measured_quantity = "command"``; the measurement that fits it is
:class:`thermofriction.measurements.command.Command`."""

from __future__ import annotations

import math
import numbers

import numpy as np

from ..errors import InputError, shorten

#: column -> {unit: (scale to SI, "linear" | "rotary" | None)}: the columns of a drive's command
COMMAND_UNITS = {
    "command_force": {"N": (1.0, "linear"), "mN": (1e-3, "linear")},
    "command_torque": {"N*m": (1.0, "rotary"), "Nm": (1.0, "rotary"), "N m": (1.0, "rotary"),
                       "mN*m": (1e-3, "rotary"), "mNm": (1e-3, "rotary"), "mN m": (1e-3, "rotary")},
    "current": {"A": (1.0, None), "mA": (1e-3, None)},
}
COMMAND_SI = {"command_force": "N", "command_torque": "N*m", "current": "A"}
#: the keys of the columns read (data/force.py: column_key): a friction sensor's, a command's, a current's
MEASURED_KEYS = ("force", "command", "current")


def column_key_of(name: str) -> str | None:
    """The key of a command column in the columns read, None for any other column."""
    return {"command_force": "command", "command_torque": "command", "current": "current"}.get(name)


def check_torque_constant(value, where: str) -> float:
    """``value`` as a torque (force) constant: a positive finite number, or one InputError naming ``where``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not (math.isfinite(value) and value > 0):
        raise InputError(f"{where}: 'torque_constant' must be a positive number [N m/A, or N/A for a linear motor], "
                         f"got {shorten(value)}")
    return float(value)


def measured_force(path, cols: dict, torque_constant: float | None):
    """What a force experiment's file measured, in N or N m: (the values, "friction" | "command", the column's
    header). A current is multiplied by ``torque_constant``; without one it is refused, and so is a torque
    constant is not used for a file that records no current (the manifest's top-level one is for those that do;
    data/files.py refuses one in the entry of such a file)."""
    head = cols.get("headers", {})
    if "current" in cols:
        if torque_constant is None:
            raise InputError(f"{path}: the {head.get('current', 'current')} column is a motor current; give the "
                             f"drive's torque_constant [N m/A, or N/A for a linear motor] in dataset.toml (at the top, "
                             f"or in the experiment's [[experiment]] entry) to read it as a torque (force)")
        return np.asarray(cols["current"], float) * torque_constant, "command", head.get("current", "current")
    if "command" in cols:
        return cols["command"], "command", head.get("command", "command")
    return cols["force"], "friction", head.get("force")


__all__ = ["COMMAND_UNITS", "COMMAND_SI", "MEASURED_KEYS", "column_key_of", "check_torque_constant", "measured_force"]
