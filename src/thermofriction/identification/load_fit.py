"""Laws of temperature and load fitted to force data at several loads (docs/force-data.md#loads).

``fit_load_laws`` is a straight joint fit: every law's coefficients (and any friction parameter named in ``free``)
against every fit run at once, each run at its own (temperature, load), the residuals the force errors with each
run's sensor offset profiled out (``offset = "per-experiment"``: the offset re-zeroed between runs) or one shared
offset. The forces and their sensitivities come from the core's exact stepping at each run's conditions and the chain
rule through each law's derivatives (measurements/force_load.py). The standard errors are the Gauss-Newton ones
times the residuals' integrated autocorrelation time (correlated noise carries fewer independent samples than it
has rows; stationary noise assumed, the same on every run).

``check_load_blind`` tells a model without a law of load that it is load-blind where the runs span loads: it tests
the runs' friction-level errors against their loads and tries the law before saying so (an affine load term added to
each level law, fitted, its gain measured on the held-out runs where there are some).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .._lazy import lazy
from ..errors import ComputationError, InputError
from ..fitting.uncertainty import inflation_of
from ..measurements.force_load import law_derivatives, run_load, stepped_force
from ..models import Model, ModelI
from ..models.load_laws import LoadLaw, LoadTerm, load_laws

optimize, stats = lazy("scipy.optimize"), lazy("scipy.stats")

#: the level parameters a load acts on first (a Coulomb and a static level, each side)
LEVELS = ("fc", "fs", "fc_neg", "fs_neg")
#: the load-blind test's significance level
BLIND_ALPHA = 0.01


@dataclass
class LoadFit:
    """A joint fit of laws of temperature and load.

    Parameters
    ----------
    model : Model
        The fitted model.
    names : list of str
        The fitted coefficients (``fc.a``, ``fc.load.k``, ``sigma2``, ...).
    values, stderr : numpy.ndarray
        Their values and standard errors (correlation of the noise accounted for).
    covariance : numpy.ndarray
        Their covariance.
    rmse : dict
        Fit run file -> RMSE of the force [N or N m], its offset removed.
    offsets : dict
        Fit run file -> its estimated offset.
    correlation_time : float
        The residuals' integrated autocorrelation time [samples] the errors are inflated by.
    nfev : int, default 0
        The evaluations of the residuals the fit made.
    message : str, default ""
        The solver's message.
    """

    model: Model
    names: list
    values: np.ndarray
    stderr: np.ndarray
    covariance: np.ndarray
    rmse: dict
    offsets: dict
    correlation_time: float
    nfev: int = 0
    message: str = ""

    def law_interval(self, name: str, T: float, load: float, z: float = 1.96) -> tuple:
        """(value, half-width of the ``z`` interval) of parameter ``name``'s law at (T, load), through the
        coefficients' covariance.

        Parameters
        ----------
        name : str
            A parameter with a law (``fc``).
        T : float
            The temperature [C].
        load : float
            The load [N or N m].
        z : float, default 1.96
            The normal quantile (95 %).

        Returns
        -------
        tuple of float
        """
        law = self.model.laws[name]
        g = np.zeros(len(self.names))
        d = law_derivatives(law, T, load)
        for k, c in enumerate(law.coefficient_names()):
            g[self.names.index(f"{name}.{c}")] = d[k]
        value = law.value(T, load, warn=False) if isinstance(law, LoadLaw) else float(law(T))
        return float(value), float(z * math.sqrt(max(g @ self.covariance @ g, 0.0)))


def _names(model: Model, free) -> list:
    names = [f"{p}.{c}" for p, law in model.laws.items() for c in law.coefficient_names()]
    for p in free:
        if p in model.laws or p not in model.friction.values():
            raise InputError(f"free: '{p}' is not a friction parameter given as a number in this model")
    return names + list(free)


def _with(model: Model, names, x) -> Model:
    laws, k = dict(model.laws), 0
    for p, law in model.laws.items():
        n = len(law.coefficient_names())
        laws[p] = law.with_coefficients(x[k:k + n])
        k += n
    values = {p: float(v) for p, v in zip(names[k:], x[k:])}
    return dataclasses.replace(model, thermal=ModelI(laws), friction=model.friction.with_values(**values))


def _run(model, exp, names):
    """(force, Jacobian in ``names``) of one run."""
    params = list(model.laws) + [n for n in names if "." not in n]
    F, dF = stepped_force(model, exp, params)
    T, load = float(exp.temperature), getattr(exp, "load", None)
    cols = []
    for j, law in enumerate(model.laws.values()):
        d = law_derivatives(law, T, 1.0 if load is None else load)
        cols.append(dF[:, j:j + 1] * d[None, :])
    cols.append(dF[:, len(model.laws):])
    return F, np.hstack(cols)


def centred(r, J, sizes, offset):
    """Residuals and Jacobian with the offset policy's means removed.

    Parameters
    ----------
    r : numpy.ndarray
        The residuals of the runs, one after the other.
    J : numpy.ndarray
        Their Jacobian (a row per residual).
    sizes : list of int
        The runs' sample counts.
    offset : {"per-experiment", "shared", "none"}
        Each run's mean removed, the whole group's, or none.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
    """
    if offset == "none":
        return r, J
    if offset == "shared":
        return r - r.mean(), J - J.mean(axis=0)
    edges = np.cumsum([0, *sizes])
    r, J = r.copy(), J.copy()
    for a, b in zip(edges[:-1], edges[1:]):
        r[a:b] -= r[a:b].mean()
        J[a:b] -= J[a:b].mean(axis=0)
    return r, J


def fit_load_laws(model: Model, experiments, free=(), offset: str = "per-experiment") -> LoadFit:
    """Fits the model's laws (of temperature and load, or of temperature alone) jointly to force runs at several
    loads and temperatures (module docstring).

    Parameters
    ----------
    model : Model
        A prescribed-motion Model I model, its laws the start.
    experiments : Dataset or list of ForceExperiment
        The runs; those whose role is "fit" are fitted, each carrying its load where a law depends on it.
    free : sequence of str, default ()
        Friction parameters given as numbers, fitted as well (``sigma2``, ``vs``).
    offset : {"per-experiment", "shared", "none"}, default "per-experiment"
        The sensor offsets profiled out: one per run, one for all, or none.

    Returns
    -------
    LoadFit

    Raises
    ------
    InputError
        No fit run, a run without the load a law needs, an unknown ``free`` name or ``offset``; a Model II or
        self-heating model.
    ComputationError
        The fit could not be computed.
    """
    if model.thermal is not None and not isinstance(model.thermal, ModelI) or model.heat is not None:
        raise InputError("fit_load_laws fits Model I laws (of temperature, or of temperature and load) at constant "
                         "temperatures; this model has Model II or a self-heating model")
    if offset not in ("per-experiment", "shared", "none"):
        raise InputError(f"offset must be \"per-experiment\", \"shared\" or \"none\", got {offset!r}")
    runs = [e for e in getattr(experiments, "experiments", experiments) if getattr(e, "role", "fit") == "fit"]
    if not runs:
        raise InputError("experiments: no run with role \"fit\"")
    if load_laws(model):
        for e in runs:
            run_load(e)
    names = _names(model, free)
    x0 = np.array([*(c for law in model.laws.values() for c in law.coefficients()),
                   *(float(model.friction.values()[p]) for p in free)])
    sizes = [len(e.time) for e in runs]
    measured = np.concatenate([np.asarray(e.force, float) for e in runs])
    bad = 1e3 * float(np.std(measured))
    cache = {}

    def evaluate(x):
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            try:
                m = _with(model, names, x)
                out = [_run(m, e, names) for e in runs]
                r = np.concatenate([o[0] for o in out]) - measured
                cache[key] = centred(r, np.vstack([o[1] for o in out]), sizes, offset)
            except InputError:  # a step where a rule between parameters breaks (fs below fc): rejected
                cache[key] = (np.full(measured.size, bad), np.zeros((measured.size, x.size)))
        return cache[key]
    res = optimize.least_squares(lambda x: evaluate(x)[0], x0, jac=lambda x: evaluate(x)[1], x_scale="jac",
                                 method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=200)
    if res.status <= 0 or np.all(evaluate(res.x)[0] == bad):
        raise ComputationError(f"the joint fit of the laws did not converge ({res.message}) in {res.nfev} "
                               f"evaluations; start the laws nearer the data")
    fitted = _result(model, names, res.x, runs, measured, sizes, offset, evaluate)
    fitted.nfev, fitted.message = int(res.nfev), str(res.message)
    return fitted


def _result(model, names, x, runs, measured, sizes, offset, evaluate) -> LoadFit:
    r, J = evaluate(x)
    edges = np.cumsum([0, *sizes])
    per_run = [r[a:b] for a, b in zip(edges[:-1], edges[1:])]
    n_offsets = {"per-experiment": len(runs), "shared": 1, "none": 0}[offset]
    dof = max(r.size - x.size - n_offsets, 1)
    tau, _ = inflation_of(r, sizes)  # the engine's integrated autocorrelation time, runs weighted by length
    cov = float(r @ r) / dof * tau * np.linalg.pinv(J.T @ J)
    fitted = with_ranges(_with(model, names, x), runs)
    raw = np.concatenate([_run(fitted, e, names)[0] for e in runs]) - measured
    offsets = {e.file: -float(np.mean(raw[a:b])) for e, a, b in zip(runs, edges[:-1], edges[1:])}
    return LoadFit(fitted, names, x, np.sqrt(np.diag(cov)), cov,
                   {e.file: float(np.sqrt(np.mean(q ** 2))) for e, q in zip(runs, per_run)}, offsets, tau)


def with_ranges(model: Model, runs) -> Model:
    """``model`` with each law's ranges those of the fit runs: the temperatures', and for a law of load the loads'
    magnitudes (as ``identify`` writes a Model I law's), where the runs span more than one value.

    Parameters
    ----------
    model : Model
        The fitted model.
    runs : list of ForceExperiment
        The fit runs.

    Returns
    -------
    Model
    """
    T = [float(e.temperature) for e in runs]
    L = [abs(float(e.load)) for e in runs if getattr(e, "load", None) is not None]
    laws = {}
    for p, law in model.laws.items():
        base = law.base if isinstance(law, LoadLaw) else law
        if max(T) > min(T):
            base = dataclasses.replace(base, range=(min(T), max(T)))
        if isinstance(law, LoadLaw):
            load = dataclasses.replace(law.load, range=(min(L), max(L))) if L and max(L) > min(L) else law.load
            laws[p] = LoadLaw(base, load)
        else:
            laws[p] = base
    return dataclasses.replace(model, thermal=ModelI(laws))


def held_out_rmse(model: Model, experiments) -> dict:
    """Each run's RMSE [N or N m] of ``model`` predicting it at its own temperature and load, its own offset
    removed (the offset policy "per-experiment": a sensor re-zeroed between runs).

    Parameters
    ----------
    model : Model
        A prescribed-motion Model I model.
    experiments : Dataset or list of ForceExperiment
        The runs (any role).

    Returns
    -------
    dict
        File -> RMSE.
    """
    out = {}
    for e in getattr(experiments, "experiments", experiments):
        err = stepped_force(model, e)[0] - np.asarray(e.force, float)
        out[e.file] = float(np.sqrt(np.mean((err - err.mean()) ** 2)))
    return out
