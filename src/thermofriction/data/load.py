"""A run's load (docs/formats.md#loads): a normal force [N] or a load torque [N m], from the manifest's ``load`` or a
``normal_force[N]`` / ``load_torque[N*m]`` column (read with the other columns' unit rules by data/force.py). A run
carries its constant load (the column's mean: what a force fit of the laws of the load takes, per run) and the
column's samples (what drives a simulation of the run, per sample: drive.py)."""

from __future__ import annotations

import numpy as np

from ..errors import InputError

#: the columns that hold a run's load
LOAD_COLUMNS = ("normal_force", "load_torque")
#: a load column whose peak-to-peak exceeds this fraction of its mean magnitude varies over the run: a force fit of
#: the laws of the load (a constant per run) refuses it; the simulator is driven by its samples
LOAD_VARIES = 0.05


def load_varies(signal) -> bool:
    """Whether a load column varies over its run: a peak-to-peak above LOAD_VARIES of its mean magnitude.

    Parameters
    ----------
    signal : array_like or None
        The column's samples [N or N m]; None: no column.

    Returns
    -------
    bool
    """
    if signal is None:
        return False
    L = np.asarray(signal, float)
    return bool(np.ptp(L) > LOAD_VARIES * abs(float(np.mean(L))))


def load_column(cols: dict):
    """The samples of a run's load column (``normal_force`` or ``load_torque``), None without one.

    Parameters
    ----------
    cols : dict
        The file's columns read, in SI units.

    Returns
    -------
    numpy.ndarray or None
    """
    given = [k for k in LOAD_COLUMNS if cols.get(k) is not None]
    return np.asarray(cols[given[0]], float) if given else None


def run_load(path, cols: dict, load=None) -> float | None:
    """A run's constant load [N or N m]: the manifest's ``load`` or the mean of a ``normal_force[N]`` /
    ``load_torque[N*m]`` column (varying or not: a force fit refuses a varying one, measurements/force_load.py);
    None with neither. Refused, naming the file: both, or two load columns.

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
    return float(np.mean(np.asarray(cols[given[0]], float)))
