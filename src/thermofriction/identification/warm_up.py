"""Warm-up identification without a contact temperature (docs/self-heating.md#warm-up-without-a-contact-temperature):
the friction's temperature laws (Model I) fitted jointly with a lumped heat path driven by the friction power,
from force records under a duty cycle with only the ambient temperature known (warm-up records), beside soak runs
at known temperatures (which calibrate the laws) and/or a proxy temperature that lags the contact.

The scale: scaling every law's temperature slope by 1/s and the heat path's gains by s (and the rise over
ambient by s) leaves the forces unchanged. Soak runs at two temperatures or more, or a proxy, fix it; with neither,
the fit holds one law's slope at its initial value to stay defined and says the heat path's gains, the laws' slopes
and the temperature are undetermined (none of them is given as a number); the time constants are scale-free and
are given.

One node or two: the one-node path is fitted first, the two-node path from it (the proxy following either node);
the second node is kept when it lowers the corrected Akaike criterion by more than SECOND_NODE_AICC, computed on
the residuals' effective number of samples (their autocorrelation counted, fitting.uncertainty: inflation_of).
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from ..data.experiments import TEMPERATURE_RANGE
from ..drive import drive
from ..errors import ComputationError, InputError
from ..fitting.uncertainty import inflation_of
from ..fitting.quality import noise_level
from ..models import ModelI
from ..models.friction import FRICTION_MODELS
from ..fitting.parameters import get_value
from .warm_up_fit import Layout, SoakRun, WarmProblem, failed, held_values, law_slope_name, solve
from .warm_up_path import GRID_NODES, first_bin_width, grid_for, spline_basis, warm_record, forces_at
from .warm_up_result import warm_up_result

#: the drop in AICc [-] above which a second node is kept (Burnham & Anderson's "essentially no support" for the
#: model above it)
SECOND_NODE_AICC = 10.0
#: the evaluations of the short fits that decide which node a proxy follows
SCREEN_EVALUATIONS = 8
#: the lowest noise a block is weighted by, relative to its record's range (a noise-free record)
NOISE_FLOOR = 1e-4


@dataclasses.dataclass
class Setup:
    """What every candidate fit shares: the initial model, the fitted friction names, the records, the noise of
    each block, the value held to fix an undetermined scale, and how the scale is known."""

    init: object
    friction: list
    warm: list
    soak: list
    sigma: dict
    held: dict
    scale: str
    unit: str


def _noise(x) -> float:
    """A record's noise for weighting: the data's estimate, at least NOISE_FLOOR of its range or its quantum."""
    x = np.asarray(x, float)
    steps = np.abs(np.diff(x))
    quantum = float(steps[steps > 0].min()) / np.sqrt(12.0) if np.any(steps > 0) else 0.0
    return max(noise_level(x), quantum, NOISE_FLOOR * max(float(np.ptp(x)), 1e-12))


def _friction_names(init, parameters) -> list:
    """The fitted friction names: every coefficient of every law, and the constants (``parameters``, default the
    force measurement's own for the friction model, less those with laws and those at zero)."""
    names = [f"{p}.{c}" for p, law in init.laws.items() for c in law.coefficient_names()]
    described = FRICTION_MODELS[init.friction.model].description.fitted["force"]
    values = init.friction.values()
    constants = list(parameters) if parameters else [n for n in described if n not in init.laws
                                                      and (values.get(n) or 0.0) > 0.0]
    return names + [n for n in constants if n not in init.laws]


def setup(experiments, init, parameters=None) -> Setup:
    """The shared part of a warm-up fit from the ``experiments`` (warm-up records and soak runs) and the initial
    Model I model ``init``; InputError where the data or the model do not allow it."""
    warm_exps = [e for e in experiments if getattr(e, "warm_up", False)]
    soak_exps = [e for e in experiments if not getattr(e, "warm_up", False)]
    if not warm_exps:
        raise InputError("the warm-up fit needs a warm-up record (a force file with an ambient_temperature[C] "
                         "column, or the manifest's ambient_temperature, and no contact temperature)")
    if any(getattr(e, "measured_quantity", "friction") != "friction" for e in experiments):
        raise InputError("the warm-up fit takes friction (force or torque) records, not a drive's command")
    if not isinstance(init.thermal, ModelI) or not init.laws or init.plant.type != "prescribed":
        raise InputError("the warm-up fit starts from a Model I model of prescribed motion with the friction's "
                         "temperature laws (init: a model file with [thermal] model = \"I\", or soak runs at two "
                         "temperatures or more in the dataset, from which the laws are fitted first)")
    labels = [e.label for e in warm_exps]
    for e in warm_exps:
        if e.continues is not None and e.continues not in labels[:labels.index(e.label)]:
            raise InputError(f"{e.label}: continues {e.continues!r}, which is not an earlier warm-up record")
    duration = max(e.duration for e in warm_exps)
    width = first_bin_width(duration)
    warm = [warm_record(e, init, width) for e in warm_exps]
    soak = [SoakRun(e.label, np.asarray(e.time, float), np.asarray(e.force, float),
                    warm_record_waveform(e, init), float(e.temperature)) for e in soak_exps]
    sigma = {r.label: _noise(r.force) for r in warm} | {s.label: _noise(s.force) for s in soak}
    sigma |= {r.label + " proxy": _noise(r.proxy) for r in warm if r.proxy is not None}
    temperatures = sorted({round(s.temperature, 1) for s in soak})
    if any(r.proxy is not None for r in warm):
        scale = "proxy" + (f" and soak runs at {len(temperatures)} temperatures" if len(temperatures) > 1 else "")
        held = {}
    elif len(temperatures) > 1:
        scale, held = f"soak runs at {len(temperatures)} temperatures", {}
    else:
        slope = law_slope_name(init)
        if slope is None:
            raise InputError("without soak runs or a proxy the scale is undetermined, and holding it needs a linear "
                             "or exponential law")
        scale, held = "undetermined", held_values(init, slope)
    names = [n for n in _friction_names(init, parameters) if n not in held]
    unit = "N m" if experiments[0].rotary else "N"
    return Setup(init, names, warm, soak, sigma, held, scale, unit)


def warm_record_waveform(exp, model):
    """The waveform that drives ``model`` along a soak run's measured motion."""
    return drive(exp, model, start="record").waveform


def _layout(s: Setup, nodes: int, proxy: bool) -> Layout:
    heat = ["C_th", "R_th"] + (["C_2", "R_2"] if nodes == 2 else []) + (["tau_p"] if proxy else [])
    heads = [r.label for r in s.warm if r.continues is None]
    t0 = ["T_0"] if len(heads) == 1 else [f"T_0[{h}]" for h in heads]
    values = s.init.friction.values()
    log = [("." not in n and (values.get(n) or 0.0) > 0.0) for n in s.friction] + [True] * len(heat) + \
          [False] * len(t0)
    return Layout(s.friction + heat + t0, log, list(s.friction))


def _grid(s: Setup, low=None, high=None, nodes=GRID_NODES):
    amb = np.concatenate([r.ambient for r in s.warm])
    low = float(amb.min()) - 5.0 if low is None else low
    high = float(amb.max()) + 40.0 if high is None else high
    g = grid_for(low, high, nodes)
    return g, spline_basis(g)


def _problem(s: Setup, nodes, proxy_node, grid_basis) -> WarmProblem:
    proxy = any(r.proxy is not None for r in s.warm)
    return WarmProblem(s.init, _layout(s, nodes, proxy), s.warm, s.soak, nodes, proxy_node, *grid_basis, s.sigma,
                       s.held)


def _theta(problem: WarmProblem, s: Setup, heat: dict) -> np.ndarray:
    """The parameters with the friction's from the initial model, the heat path's from ``heat``, and each
    record's T_0 at its proxy's first reading (else its ambient's)."""
    out = []
    for n in problem.layout.names:
        if n in problem.layout.friction:
            out.append(get_value(s.init, n))
        elif n in heat:
            out.append(heat[n])
        else:
            label = n[4:-1] if n.startswith("T_0[") else s.warm[0].label
            rec = next(r for r in s.warm if r.label == label)
            out.append(float(rec.proxy[0] if rec.proxy is not None else rec.ambient[0]))
    return np.array(out, float)


def _mean_power(s: Setup) -> float:
    """The warm-up records' mean friction power [W] at the initial model's laws at their ambient temperatures."""
    p = [np.mean(np.abs(forces_at(s.init, r.waveform, r.time, [float(r.ambient[0])])[0]) * r.speed) for r in s.warm]
    return max(float(np.mean(p)), 1e-12)


def _best_start(problem: WarmProblem, s: Setup, candidates) -> np.ndarray | None:
    """Of the candidate heat paths, the start whose residuals are least (None where none can be evaluated)."""
    best, best_cost = None, np.inf
    for heat in candidates:
        theta = _theta(problem, s, heat)
        r = problem.residuals(problem.layout.to_phi(theta))
        cost = float(r @ r)
        if cost < best_cost and not failed(r):
            best, best_cost = theta, cost
    return best


def _one_node(s: Setup, grid_basis, progress):
    """The one-node fit, from the best of a few time constants, rises and proxy lags."""
    problem = _problem(s, 1, 0, grid_basis)
    duration = max(r.time[-1] - r.time[0] for r in s.warm)
    power = _mean_power(s)
    candidates = [{"R_th": rise / power, "C_th": tau * power / rise, "tau_p": lag}
                  for tau in (duration / 30, duration / 10, duration / 3) for rise in (3.0, 10.0, 30.0)
                  for lag in (duration / 100, duration / 20)]
    progress("warm-up: one node")
    theta, res = solve(problem, _best_start(problem, s, candidates))
    return problem, theta, res


def _two_nodes(s: Setup, grid_basis, one, progress):
    """The two-node fit from the one-node one (splits of its resistance and time constant), the proxy following
    the contact or the housing node, whichever fits better."""
    problem1, theta1, _ = one
    v = dict(zip(problem1.layout.names, theta1))
    R, tau = v["R_th"], v["R_th"] * v["C_th"]
    proxy = "tau_p" in v
    tried = []
    for node in ((0, 1) if proxy else (0,)):
        problem = _problem(s, 2, node, grid_basis)
        candidates = [{"R_th": f * R, "C_th": q * tau / (f * R), "R_2": (1 - f) * R, "C_2": 3 * tau / ((1 - f) * R),
                       **({"tau_p": v["tau_p"]} if proxy else {})}
                      for f in (0.2, 0.5) for q in (0.05, 0.2)]
        theta = _best_start(problem, s, candidates)
        if theta is None:
            continue
        if proxy:  # which node the proxy follows: a short fit of each, the better one fitted on
            theta, res = solve(problem, theta, max_nfev=SCREEN_EVALUATIONS)
            tried.append((res.cost, node, problem, theta))
        else:
            tried.append((0.0, node, problem, theta))
    if not tried:
        return None  # (said in the choice: no two-node start could be evaluated)
    _, node, problem, theta = min(tried, key=lambda x: x[0])
    progress(f"warm-up: two nodes{', the proxy on the ' + ('housing' if node else 'contact') if proxy else ''}")
    theta, res = solve(problem, theta)
    return problem, theta, res


def _aicc(res, k, n_eff) -> float:
    n = res.fun.size
    return n_eff * float(np.log(max(2 * res.cost, 1e-300) / n)) + 2 * k + 2 * k * (k + 1) / max(n_eff - k - 1, 1)


def _regridded(s: Setup, fit):
    """The fit again on a grid spanning the temperatures it reached (1 C beyond), where it differs from its own."""
    problem, theta, res = fit
    tracks, _ = problem.run(theta)
    T = np.concatenate([tr.states[:, :problem.nodes].ravel() for tr in tracks.values()])
    low = max(float(T.min()) - 1.0, TEMPERATURE_RANGE[0])
    high = min(float(T.max()) + 1.0, TEMPERATURE_RANGE[1])
    g = problem.grid
    if g[0] <= low and g[-1] >= high and (g[-1] - g[0]) < 2.0 * (high - low) + 4.0:
        return fit
    new = WarmProblem(s.init, problem.layout, s.warm, s.soak, problem.nodes, problem.proxy_node,
                      *_grid(s, low, high), problem.sigma, s.held)
    theta, res = solve(new, theta)
    return new, theta, res


def _reweighted(fit):
    """The fit again with each block weighted by its residuals' scatter at the optimum (so that every block
    carries unit variance, which the intervals assume)."""
    problem, theta, _ = fit
    problem.sigma = {name: max(float(np.sqrt(np.mean(e ** 2))), 1e-300) for name, e, _ in problem.blocks(theta)}
    theta, res = solve(problem, theta)
    return problem, theta, res


def identify_warm_up(experiments, init, *, parameters=None, nodes="auto", progress=None, held_out=()):
    """Fits the friction's temperature laws and the heat path from warm-up records (docs/self-heating.md).

    Parameters
    ----------
    experiments : list of ForceExperiment
        The fit experiments: warm-up records (an ambient temperature, no contact temperature; optionally a proxy
        temperature) and soak runs at known temperatures.
    init : Model
        The initial Model I model of prescribed motion (its laws, the starting values).
    parameters : list of str, optional
        The friction constants fitted beside the laws' coefficients; default the force measurement's.
    nodes : {"auto", 1, 2}, default "auto"
        The heat path's nodes: chosen by the data ("auto", AICc), or held.
    progress : callable, optional
        Called with a line of text at each stage.
    held_out : list of ForceExperiment, optional
        Held-out records (the dataset's validate experiments): predicted by the fitted laws and heat path, not
        fitted; their rows (role "validate") are in the result's ``experiments``, a misfit among its warnings.

    Returns
    -------
    FitResult
        Method "warm-up": the fitted Model I model, the heat path's values and intervals (or "undetermined"),
        the contact temperature's trajectory with its 95 % band in ``details["temperature"]``.

    Raises
    ------
    InputError
        No warm-up record; an initial model without laws; a record that continues one that is not before it.
    ComputationError
        The fit cannot be evaluated near its start.
    """
    t0 = time.perf_counter()
    progress = progress or (lambda line: None)
    if nodes not in ("auto", 1, 2):
        raise InputError(f"nodes must be \"auto\", 1 or 2, got {nodes!r}")
    s = setup(experiments, init, parameters)
    grid_basis = _grid(s)
    one = _regridded(s, _one_node(s, grid_basis, progress))
    two = _two_nodes(s, (one[0].grid, one[0].basis), one, progress)
    choice = {"rule": f"two nodes where they lower AICc by more than {SECOND_NODE_AICC:g}", "asked": nodes,
              "threshold": SECOND_NODE_AICC}
    if two is None:
        if nodes == 2:
            raise ComputationError("the two-node heat path cannot be evaluated from the one-node fit's optimum")
        choice["two_nodes"] = "not evaluated: no two-node start from the one-node optimum could be simulated"
        chosen, other = one, None
    else:
        two = _regridded(s, two)
        inflation, _ = inflation_of(two[2].fun, [e.size for _, e, _ in two[0].blocks(two[1])])
        n_eff = two[2].fun.size / inflation
        a1, a2 = _aicc(one[2], len(one[1]), n_eff), _aicc(two[2], len(two[1]), n_eff)
        choice.update(aicc_one=a1, aicc_two=a2, effective_samples=n_eff, delta=a1 - a2)
        pick_two = nodes == 2 or (nodes == "auto" and a1 - a2 > SECOND_NODE_AICC)
        chosen, other = (two, one) if pick_two else (one, two)
    choice["nodes"] = chosen[0].nodes
    progress("warm-up: reweighted by each record's residuals")
    final = _reweighted(chosen)
    return warm_up_result(s, final, other, choice, time.perf_counter() - t0, held=held_out)


__all__ = ["identify_warm_up", "setup", "Setup", "SECOND_NODE_AICC"]
