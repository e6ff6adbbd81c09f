"""The result of a simulation: plain arrays with named fields."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._bridge import OUTPUTS
from .._io import atomic_write
from ..figures.friction_plots import simulation_figure
from ..results import Result, Summary


@dataclass(eq=False)
class SimulationResult(Result):
    """Plain arrays with named fields (SI units; temperature in degC).

    ``displacement``/``velocity`` are the driven body's (the end effector's, the mass's, or the
    prescribed motion); ``relative_displacement`` is x_e - x_p (the stage fields are None for
    plants without a stage); ``states`` holds the friction model's internal
    states (columns named by ``state_names``). For periodic inputs ``cycle_times`` are the
    period starts, ``step_sizes[k]`` the displacement over cycle k, ``mean_velocity`` the mean
    of the step sizes times the frequency. ``friction_work`` [J] is the friction force's work
    integral of |F v_r| dt from the start (with a heat model, or ``friction_work=True``; else
    None); with a heat model ``temperature`` is the interface temperature state.

    ``simulate`` makes it; each field is also an attribute.

    Parameters
    ----------
    time : numpy.ndarray
        The output times [s].
    input : numpy.ndarray
        The drive at those times, in ``input_unit``.
    stage_displacement, stage_velocity : numpy.ndarray or None
        The stage's displacement [m] and velocity [m/s]; None without a stage.
    displacement, velocity : numpy.ndarray
        The driven body's displacement [m] and velocity [m/s] (rad, rad/s for a rotary joint).
    relative_displacement, relative_velocity : numpy.ndarray
        The sliding displacement x_r [m] and velocity v_r [m/s] the friction sees.
    friction_force : numpy.ndarray
        The friction force [N] (N m for a rotary joint).
    temperature : numpy.ndarray
        The temperature [C] at each output time.
    states : numpy.ndarray
        The friction model's internal states, one column per state.
    state_names, state_units : tuple of str
        The states' names and units.
    cycle_times : numpy.ndarray
        A periodic input's period starts [s].
    step_sizes : numpy.ndarray
        The displacement over each cycle [m].
    mean_velocity : float
        The mean of the step sizes times the input's frequency [m/s].
    input_unit : str, default "V"
        The input's unit.
    stats : dict, default {}
        The integrator's counts (steps, rejected, rhs_evals, jac_evals, decompositions, events) and the solver used.
    friction_work : numpy.ndarray, optional
        The friction work [J] from the start, where asked or with a heat model.
    model_name : str, optional
        The simulated model's name (the figures' titles).
    rotary : bool, default False
        Whether the motion is a rotary joint's (rad, N m).
    findings : list of Finding, default []
        What the checks found (a temperature outside a law's calibrated range, a model that may create energy),
        as values; ``simulate`` warned each as it returned.
    """

    time: np.ndarray
    input: np.ndarray
    stage_displacement: np.ndarray | None
    stage_velocity: np.ndarray | None
    displacement: np.ndarray
    velocity: np.ndarray
    relative_displacement: np.ndarray
    relative_velocity: np.ndarray
    friction_force: np.ndarray
    temperature: np.ndarray
    states: np.ndarray
    state_names: tuple
    state_units: tuple
    cycle_times: np.ndarray
    step_sizes: np.ndarray
    mean_velocity: float
    input_unit: str = "V"
    stats: dict = field(default_factory=dict)
    friction_work: np.ndarray | None = None
    #: the simulated model's name (the figures' titles) and whether its motion is rotary (rad, N m)
    model_name: str | None = None
    rotary: bool = False
    #: what the checks found (results.Finding: a temperature outside a law's range, ...), warned as simulate returned
    findings: list = field(default_factory=list)

    def columns(self) -> dict:
        """The CSV columns (docs/formats.md#simulation-output), header -> array."""
        cols = {
            "time[s]": self.time,
            f"input[{self.input_unit}]": self.input,
            "stage_displacement[m]": self.stage_displacement,  # stick-slip only
            "displacement[m]": self.displacement,
            "velocity[m/s]": self.velocity,
            "friction_force[N]": self.friction_force,
            "temperature[C]": self.temperature,
        }
        for j, (name, unit) in enumerate(zip(self.state_names, self.state_units)):
            cols[f"{name}[{unit}]"] = self.states[:, j]
        cols["friction_work[J]"] = self.friction_work
        return {k: v for k, v in cols.items() if v is not None}

    title = "simulation"

    def _frame(self) -> dict:
        """Every output by name (the DataFrame's columns)."""
        data = {name: getattr(self, name) for name in OUTPUTS if getattr(self, name) is not None}
        for j, name in enumerate(self.state_names):
            data[name] = self.states[:, j]
        if self.friction_work is not None:
            data["friction_work"] = self.friction_work
        return data

    def to_dict(self) -> dict:
        """The summary, the solver's statistics and every output column (docs/formats.md#simulation-output)."""
        return {"summary": dict(self.summary()), "stats": self.stats,
                "columns": {k: v for k, v in self.columns().items()}}

    def to_csv(self, path):
        """Writes the simulation CSV (docs/formats.md#simulation-output) atomically."""
        cols = self.columns()
        table = np.column_stack(list(cols.values()))
        with atomic_write(path, "w", newline="") as fh:
            fh.write(",".join(cols) + "\n")
            np.savetxt(fh, table, delimiter=",", fmt="%.12g")

    def plot(self, what=None, title=None):
        """A matplotlib figure against time: the input, displacement, friction force and (when it
        changes) the temperature; ``what`` names other fields, e.g. ``("velocity", "temperature")``,
        or is ``"hysteresis"``: the friction force against the displacement (against x_e - x_p for
        stick-slip plants). Titled with the model's name and the temperature (or ``title``); units
        chosen from the data; a friction axis whose scale short flyback spikes would set is cut to
        its 1-99 % percentiles, as the panel says. The figure is not pyplot's: a notebook shows it
        once, ``fig.savefig(path)`` writes it."""
        return simulation_figure(self, what, title)

    def summary(self) -> Summary:
        rows = [("samples", f"{len(self.time)}"), ("duration", f"{self.time[-1] - self.time[0]:.6g} s"),
                ("final displacement", f"{self.displacement[-1] * 1e6:.6g} µm"),
                ("peak friction force", f"{np.max(np.abs(self.friction_force)):.4g} N")]
        if self.step_sizes.size:
            rows += [("cycles", f"{self.step_sizes.size}"),
                     ("mean step per cycle", f"{self.step_sizes.mean() * 1e6:.6g} µm"),
                     ("mean velocity", f"{self.mean_velocity * 1e6:.6g} µm/s")]
        rows.append(("solver", f"{self.stats.get('solver', '?')}: {self.stats.get('steps', '?')} steps"))
        return Summary(rows)

    def __repr__(self):
        return (f"SimulationResult({len(self.time)} samples over {self.time[-1] - self.time[0]:.6g} s, "
                f"final displacement {self.displacement[-1]:.6g} m, {len(self.step_sizes)} cycles)")



__all__ = ["SimulationResult"]
