"""A force run's load (docs/formats.md#loads): a normal force [N] or a load torque [N m], constant over the run,
from the manifest's ``load`` or a ``normal_force[N]`` / ``load_torque[N*m]`` column (read with the other columns'
unit rules by data/force.py)."""

from __future__ import annotations

import numpy as np

from ..errors import InputError

#: the columns that hold a run's load
LOAD_COLUMNS = ("normal_force", "load_torque")
#: a load column whose peak-to-peak exceeds this fraction of its mean magnitude varies over the run (refused: a
#: per-sample load needs the simulator's load input, not there yet)
LOAD_VARIES = 0.05

def run_load(path, cols: dict, load=None) -> float | None:
    """A run's load [N or N m]: the manifest's ``load`` or the mean of a ``normal_force[N]`` / ``load_torque[N*m]``
    column; None with neither. Refused, naming the file: both, two load columns, or a column that varies (its
    peak-to-peak above LOAD_VARIES of its mean magnitude: a per-sample load needs the simulator's load input).

    Parameters
    ----------
    path : str or Path
        The file, for the messages.
    cols : dict
        Its columns read, in SI units.
    load : float, optional
        The manifest's load.

    Returns
    -------
    float or None

    Raises
    ------
    InputError
        As above.
    """
    given = [k for k in LOAD_COLUMNS if cols.get(k) is not None]
    if len(given) > 1 or (given and load is not None):
        what = "both a normal_force and a load_torque column" if len(given) > 1 else \
            f"both a {given[0]} column and the manifest's 'load'"
        raise InputError(f"{path}: {what}: give the run's load once")
    if not given:
        return None if load is None else float(load)
    L = np.asarray(cols[given[0]], float)
    mean = float(np.mean(L))
    if np.ptp(L) > LOAD_VARIES * abs(mean):
        raise InputError(f"{path}: column {given[0]}: the load varies over the run ({float(np.min(L)):.4g} to "
                         f"{float(np.max(L)):.4g}); a run's load must be constant (within {100 * LOAD_VARIES:g} % of "
                         f"its mean): a varying load needs the simulator's load input, not there yet")
    return mean

