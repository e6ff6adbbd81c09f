"""Experiments and datasets in memory (SI units, temperature in degC), and the limits that every
reader applies."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..plausible import TEMPERATURE_RANGE  # noqa: F401  [degC] one range for files, manifests and simulate
from ..waveforms import Sampled, Waveform
from .load import load_varies

_LENGTH = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6, "nm": 1e-9}  # micro sign and Greek mu
_UNITS = {"time": {"s": 1.0, "ms": 1e-3}, "voltage": {"V": 1.0, "mV": 1e-3}, "displacement": _LENGTH,
          "stage_displacement": _LENGTH, "temperature": {"C": 1.0}}
_SI = {"time": "s", "voltage": "V", "displacement": "m", "stage_displacement": "m", "temperature": "C"}
REQUIRED = ("time", "voltage", "displacement")
MIN_SAMPLES = 10
SAMPLING_TOLERANCE = 0.01           # relative deviation of an interval from the median interval
TEMPERATURE_VARIES = 0.5            # [degC] peak-to-peak above which a recorded temperature is a signal
ROLES = ("fit", "validate")
MAX_ROWS = 10_000_000               # data rows per experiment file; ~1.5 GB peak at the limit (docs/limits.md)
MAX_ROWS_ENV = "THERMOFRICTION_MAX_ROWS"


def max_rows() -> int:
    """The row limit of experiment files: ``THERMOFRICTION_MAX_ROWS`` when set, else ``MAX_ROWS``.

    Returns
    -------
    int

    Raises
    ------
    InputError
        ``THERMOFRICTION_MAX_ROWS`` set to something that is not a positive whole number.
    """
    text = os.environ.get(MAX_ROWS_ENV, "").strip()
    if not text:
        return MAX_ROWS
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise InputError(f"{MAX_ROWS_ENV}={text!r}: must be a positive whole number of rows")
    return n


@dataclasses.dataclass(eq=False)
class Experiment:
    """One measured run, in SI units (temperature in degC).

    ``temperature`` is the manifest's value or else the mean of the recorded ``temperature_signal``;
    ``input`` is the exact waveform when the manifest gives one (``input = "sawtooth:..."``), else
    None (the recorded ``voltage`` is the input).

    Parameters
    ----------
    file : str
        The file the run was read from (its name in the dataset's folder).
    time : numpy.ndarray
        The sample times [s].
    voltage : numpy.ndarray
        The drive's voltage [V], one per sample.
    displacement : numpy.ndarray
        The measured displacement [m] (of the end effector), one per sample.
    temperature : float
        The run's temperature [C].
    temperature_signal : numpy.ndarray, optional
        The recorded temperature [C], one per sample.
    stage_displacement : numpy.ndarray, optional
        The recorded stage displacement [m], one per sample.
    role : {"fit", "validate"}, default "fit"
        Whether ``identify`` fits the run or holds it out.
    description : str, default ""
        The manifest's note on the run.
    input : Waveform, optional
        The exact drive when the manifest gives one.
    struct : str, optional
        In a MATLAB file holding several runs, the struct holding this one (docs/formats.md#matlab-files).
    headers : dict, optional
        Per column read ("displacement", "force", ...): (where the file holds it, the unit its header
        declared), what a unit warning names; None for an experiment made in memory.
    load : float, optional
        The run's constant load, a normal force [N] or a load torque [N m] (docs/formats.md#loads), carried like
        its temperature (a load column's mean); None: not given.
    load_signal : numpy.ndarray, optional
        The recorded load column [N or N m], one per sample (what drives a simulation of the run where it
        varies: ``load_input``).
    """

    file: str
    time: np.ndarray
    voltage: np.ndarray
    displacement: np.ndarray
    temperature: float
    temperature_signal: np.ndarray | None = None
    stage_displacement: np.ndarray | None = None
    role: str = "fit"
    description: str = ""
    input: Waveform | None = None
    #: in a MATLAB file holding several runs, the struct holding this one (docs/formats.md#matlab-files)
    struct: str | None = None
    #: per column read ("displacement", "force", ...): (where the file holds it, the unit its header declared),
    #: what a unit warning names (unit_scale.py); None for an experiment made in memory
    headers: dict | None = dataclasses.field(default=None, repr=False)
    #: the run's constant load [N or N m] (a normal force, a load torque), None where not given
    load: float | None = None
    #: the recorded load column [N or N m], one per sample, None without one
    load_signal: np.ndarray | None = dataclasses.field(default=None, repr=False)

    def load_input(self):
        """What ``simulate(..., load=...)`` takes: the recorded load column where it varies (data/load.py:
        load_varies) as a ``Sampled`` signal through its samples, else the constant ``load`` (None: none)."""
        if load_varies(self.load_signal):
            return Sampled(np.asarray(self.time, float), np.asarray(self.load_signal, float))
        return self.load

    @property
    def label(self) -> str:
        """How tables, JSON and reports name the run: its file, and in a MATLAB file holding several runs the
        struct too (``runs.mat:run1``)."""
        return f"{self.file}:{self.struct}" if self.struct else self.file

    @property
    def sample_rate(self) -> float:
        """[Hz] from the median sampling interval."""
        return float(1.0 / np.median(np.diff(self.time)))

    @property
    def duration(self) -> float:
        """[s] from the first to the last sample."""
        return float(self.time[-1] - self.time[0])

    def temperature_input(self):
        """What ``simulate(..., temperature=...)`` takes: the recorded temperature where it varies
        beyond its sensor noise, else the constant ``temperature``. "Varies" means a peak-to-peak
        above 0.5 C after a moving average over 2 % of the record (which removes white sensor noise
        but keeps thermal changes, slow on that scale); the smoothed signal is what is returned,
        as a ``Sampled`` waveform, so that sensor noise does not enter the simulation."""
        sig = self.temperature_signal
        if sig is None:
            return self.temperature
        smooth = _moving_average(np.asarray(sig, float), max(1, len(sig) // 50))
        if float(np.ptp(smooth)) > TEMPERATURE_VARIES:
            return Sampled(np.asarray(self.time, float), smooth)
        return self.temperature


def run_label(exp) -> str:
    """How tables name an experiment (:attr:`Experiment.label`; the file of a run made in memory without one)."""
    return getattr(exp, "label", None) or exp.file


def _moving_average(x, w):
    """Centred moving average over ``w`` samples (made odd), the window truncated at the ends;
    O(n) by cumulative sums."""
    n = x.size
    if w <= 1 or n < 3:
        return x
    half = w // 2
    m = float(np.mean(x))
    c = np.concatenate([[0.0], np.cumsum(x - m)])
    i = np.arange(n)
    lo, hi = np.clip(i - half, 0, n), np.clip(i + half + 1, 0, n)
    return m + (c[hi] - c[lo]) / (hi - lo)


@dataclasses.dataclass(eq=False)
class Dataset:
    """Experiments and where they came from (``path``: the folder, or None if not saved).

    Parameters
    ----------
    path : pathlib.Path, optional
        The dataset's folder; None for a dataset made in memory.
    name : str, optional
        The dataset's name.
    description : str, default ""
        The manifest's description.
    experiments : list of Experiment, default []
        The runs (``fit`` and ``validate`` list them by role).
    sha256 : tuple, optional
        (what was hashed, SHA-256) of the files as they were loaded; it travels with the dataset, to a worker
        on another machine too.
    """

    path: Path | None = None
    name: str | None = None
    description: str = ""
    experiments: list = dataclasses.field(default_factory=list)
    #: (what was hashed, SHA-256) of the files as they were loaded (data.files.dataset_sha256); it
    #: travels with the dataset, to a worker on another machine too
    sha256: tuple | None = dataclasses.field(default=None, repr=False, compare=False)

    @property
    def fit(self) -> list:
        return [e for e in self.experiments if e.role == "fit"]

    @property
    def validate(self) -> list:
        return [e for e in self.experiments if e.role == "validate"]

    @property
    def temperatures(self) -> list:
        return [e.temperature for e in self.experiments]


def first_periods(experiments, periods, at_least, input=None) -> list | None:
    """The experiments cut to their first ``periods`` periods of their input.

    Parameters
    ----------
    experiments : list of Experiment
        The runs (each's own ``input``, else ``input``).
    periods : float
        How many periods each cut keeps.
    at_least : float
        The periods every record must hold for the cut to be made.
    input : Waveform, optional
        The input of the runs that do not carry their own.

    Returns
    -------
    list of Experiment or None
        Copies with every sampled column cut; None where a run is shorter than ``at_least`` periods, its input
        has no period, or it is not an Experiment.
    """
    cut = []
    for e in experiments:
        period = getattr(getattr(e, "input", None) or input, "period", None)
        if not isinstance(e, Experiment) or not period or e.duration < at_least * period:
            return None
        n = int(np.searchsorted(e.time, e.time[0] + periods * period, side="right"))
        cut.append(dataclasses.replace(e, **{f.name: getattr(e, f.name)[:n] for f in dataclasses.fields(e)
                                             if isinstance(getattr(e, f.name), np.ndarray)
                                             and len(getattr(e, f.name)) == len(e.time)}))
    return cut


# -- experiment files -------------------------------------------------------------------------
