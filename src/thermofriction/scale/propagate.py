"""Uncertainty propagation: a fit's parameter uncertainty carried into predictions at new
temperatures, by Monte Carlo on Dask.

    fit = tf.identify(data, method="model-i")
    bands = tf.propagate(fit, temperatures=[33, 37, 40], draws=400, seed=1)
    bands.time, bands.nominal, bands.lower, bands.upper        # (temperatures, samples) [m]
    bands.step_lower, bands.step_upper                          # the mean step per cycle's band [m]

Parameter sets are drawn from the fit's covariance (its standard errors and correlations): a
positive parameter (fitted in log space, its interval multiplicative) is drawn log-normally, the
others normally; the draws are made here from ``seed`` before any task runs, so the bands do not
depend on where the simulations ran. ``lower``/``upper`` hold the parameters' band (the model's
prediction); ``prediction_lower``/``prediction_upper`` add the measurement noise the fit
estimated, for where a new measurement would fall.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import _io
from .. import _args
from ..waveforms import Waveform
from ..errors import InputError, ThermofrictionError, shorten
from ..results import Result, Summary, fields, heading, lines
from .cluster import Runner
from .sweep import check_run_options

MAX_DRAWS = 1_000_000


#: how far a correlation matrix may stray from one by rounding (a fit's is exact to ~1e-15): a negative eigenvalue
#: down to -ROUNDING is taken as zero (the draws' square root clips it), anything further is refused
ROUNDING = 1e-8
#: draws stay within this many standard deviations of the centre (P(|z| > 10) = 2e-23 a draw): a spread whose
#: 10-sd range overflows a float is refused rather than drawn into infinities
_REACH = 10.0


def check_correlation(corr, names):
    """InputError unless ``corr`` is a correlation matrix of ``names``: square, finite, symmetric, unit
    diagonal, entries in [-1, 1], positive semi-definite (to ROUNDING). The message names the key 'correlation'."""
    corr = np.asarray(corr, float)
    n = len(names)
    if corr.shape != (n, n) or not np.all(np.isfinite(corr)):
        raise InputError(f"the fit's 'correlation' matrix must be {n} x {n} and finite ({', '.join(names)}): its "
                         f"uncertainty cannot be propagated")
    i, j = np.unravel_index(np.argmax(np.abs(corr - corr.T)), corr.shape)
    if abs(corr[i, j] - corr[j, i]) > ROUNDING:
        raise InputError(f"the fit's 'correlation' is not symmetric: C({names[i]}, {names[j]}) = {corr[i, j]:.6g} but "
                         f"C({names[j]}, {names[i]}) = {corr[j, i]:.6g}")
    k = int(np.argmax(np.abs(np.diag(corr) - 1.0)))
    if abs(corr[k, k] - 1.0) > ROUNDING:
        raise InputError(f"the fit's 'correlation' must have 1 on its diagonal: C({names[k]}, {names[k]}) = "
                         f"{corr[k, k]:.6g}")
    i, j = np.unravel_index(np.argmax(np.abs(corr)), corr.shape)
    if abs(corr[i, j]) > 1.0 + ROUNDING:
        raise InputError(f"the fit's 'correlation' must lie in [-1, 1]: C({names[i]}, {names[j]}) = {corr[i, j]:.6g}")
    low = float(np.linalg.eigvalsh((corr + corr.T) / 2)[0])
    if low < -ROUNDING:
        raise InputError(f"the fit's 'correlation' is not positive semi-definite (smallest eigenvalue {low:.3g}): "
                         f"no parameter set has these correlations")


def _covariance(result):
    """(names, centre in the drawing space, covariance there, which are drawn in log space); InputError, before any
    work, where the fit's uncertainty cannot be drawn from."""
    varying = [p for p in result.parameters.values() if p.vary]
    if not varying:
        raise InputError("the fit has no fitted parameters: nothing to propagate")
    names = [p.name for p in varying]
    theta = np.array([p.value for p in varying], float)
    se = np.array([math.nan if p.stderr is None else p.stderr for p in varying], float)
    bad = [n for n, s in zip(names, se) if not math.isfinite(s)]
    if bad:
        raise InputError(f"'{bad[0]}' has no finite standard error (not identifiable from the fit's data): its "
                         f"uncertainty cannot be propagated; fix it or fit it on more informative data")
    bad = [(n, s) for n, s in zip(names, se) if s < 0]
    if bad:
        raise InputError(f"'{bad[0][0]}': its standard error must be 0 or more, got {bad[0][1]!r}")
    corr = np.array(result.correlation, float)[:len(names), :len(names)]
    check_correlation(corr, names)
    log = np.array([p.positive for p in varying])
    centre = np.where(log, np.log(np.where(log, theta, 1.0)), theta)
    sd = np.where(log, se / np.where(log, theta, 1.0), se)  # log space: the relative error, to first order
    with np.errstate(over="ignore"):
        reach = np.abs(centre) + _REACH * sd
        reach = np.where(log, np.exp(reach), reach)
    bad = [k for k, r in enumerate(reach) if not np.isfinite(r)]
    if bad:
        k = bad[0]
        raise InputError(f"'{names[k]}': its standard error ({se[k]:.3g}{' = %.3g x its value' % sd[k] if log[k] else ''}"
                         f") is too large to draw from (draws within 10 sd would overflow the floating-point range): "
                         f"hold it, or fit it on more informative data")
    return names, centre, corr * np.outer(sd, sd), log


def check_drawable(result):
    """InputError, before any work, where the fit's uncertainty cannot be drawn from (what :func:`propagate`
    refuses: no finite or a negative standard error, a correlation that is not one, a spread that overflows)."""
    _covariance(result)


def draw_parameters(result, draws: int, seed: int = 0):
    """Seeded draws from the fit's covariance (positive parameters drawn in log space, as they were fitted).

    Parameters
    ----------
    result : FitResult
        The fit (or one read back from its results JSON).
    draws : int
        The number of parameter sets drawn.
    seed : int, default 0
        The seed of the draws.

    Returns
    -------
    tuple
        (names, array (draws x parameters)), in the parameters' units.

    Raises
    ------
    InputError
        A fit without fitted parameters, a parameter without a finite standard error, or a correlation matrix
        that is not one, named.
    """
    names, centre, cov, log = _covariance(result)
    w, V = np.linalg.eigh((cov + cov.T) / 2)
    root = V * np.sqrt(np.clip(w, 0.0, None))  # a covariance that is singular to rounding stays usable
    z = np.random.default_rng([int(seed), 21]).standard_normal((draws, len(names)))
    phi = centre + z @ root.T
    return names, np.where(log, np.exp(phi), phi)


def _run_draws(model, names, thetas, temperatures, waveform, sim):
    """Runs on a worker: displacement (draws, temperatures, samples), mean steps (draws,
    temperatures), and {row: reason} for draws that could not be simulated (all NaN)."""
    from ..fitting.parameters import with_values
    from ..simulation import simulate

    disp = steps = None
    errors = {}
    for i, theta in enumerate(thetas):
        try:
            m = with_values(model, dict(zip(names, (float(v) for v in theta))))
            why = m.unphysical_over_range()
            if why:
                raise InputError(f"drawn model leaves its physical domain: {why}")
            for j, T in enumerate(temperatures):
                res = simulate(m, temperature=float(T), input=waveform, **sim)
                if disp is None:
                    disp = np.full((len(thetas), len(temperatures), res.time.size), np.nan)
                    steps = np.full((len(thetas), len(temperatures)), np.nan)
                disp[i, j] = res.displacement
                steps[i, j] = res.step_sizes.mean() if res.step_sizes.size else np.nan
        except ThermofrictionError as e:
            errors[i] = str(e)
            if disp is not None:
                disp[i] = np.nan
                steps[i] = np.nan
        except Exception as e:  # noqa: BLE001 - one draw's surprise must not stop the others
            errors[i] = f"{type(e).__name__}: {e}"
            if disp is not None:
                disp[i] = np.nan
                steps[i] = np.nan
    return disp, steps, errors


@dataclasses.dataclass(eq=False)
class PropagationResult(Result):
    """Bands over draws, per temperature (rows) and output time (columns), SI units.

    Parameters
    ----------
    temperatures : numpy.ndarray
        The temperatures [C], one row each.
    time : numpy.ndarray
        The output times [s], one column each.
    level : float
        The bands' central probability.
    nominal : numpy.ndarray
        The fitted model's displacement [m].
    median, lower, upper : numpy.ndarray
        The draws' median displacement and the parameters' band [m].
    prediction_lower, prediction_upper : numpy.ndarray
        The band with the measurement noise the fit estimated [m].
    noise : float
        The fit's noise estimate [m] (0 when it had none).
    nominal_step, step_lower, step_upper : numpy.ndarray
        The mean step per cycle [m] per temperature: the fitted model's and its band.
    names : list of str
        The drawn parameters' names.
    parameters : numpy.ndarray
        The draws (draws x parameters), in the parameters' units.
    steps : numpy.ndarray
        Each draw's mean step per temperature [m] (NaN where it failed).
    final_displacement : numpy.ndarray
        Each draw's final displacement per temperature [m].
    failures : dict
        A failed draw's index -> its reason.
    wall_time : float, default nan
        The run's duration [s].
    where : str, default ""
        Where the tasks ran (threads, a Dask cluster's address).
    """

    temperatures: np.ndarray
    time: np.ndarray
    level: float
    nominal: np.ndarray            # the fitted model's displacement
    median: np.ndarray
    lower: np.ndarray              # the parameters' band
    upper: np.ndarray
    prediction_lower: np.ndarray   # with the measurement noise the fit estimated
    prediction_upper: np.ndarray
    noise: float                   # [m], the fit's noise estimate (0 when it had none)
    nominal_step: np.ndarray       # mean step per cycle [m], per temperature
    step_lower: np.ndarray
    step_upper: np.ndarray
    names: list
    parameters: np.ndarray         # the draws (draws x parameters)
    steps: np.ndarray              # each draw's mean step per temperature (NaN where it failed)
    final_displacement: np.ndarray  # each draw's final displacement per temperature
    failures: dict                 # draw index -> reason
    wall_time: float = math.nan
    where: str = ""

    @property
    def draws(self) -> int:
        return self.parameters.shape[0]

    def to_csv(self, path):
        """One row per temperature and output time: the nominal prediction, the median and both bands."""
        level = f"{100 * self.level:g}"
        head = ["temperature[C]", "time[s]", "nominal[m]", "median[m]", f"lower_{level}[m]", f"upper_{level}[m]",
                f"prediction_lower_{level}[m]", f"prediction_upper_{level}[m]"]
        n_t = self.time.size
        cols = [np.repeat(self.temperatures, n_t), np.tile(self.time, self.temperatures.size)]
        cols += [a.ravel() for a in (self.nominal, self.median, self.lower, self.upper, self.prediction_lower,
                                     self.prediction_upper)]
        with _io.atomic_write(path, "w", newline="") as fh:
            fh.write(",".join(head) + "\n")
            np.savetxt(fh, np.column_stack(cols), delimiter=",", fmt="%.12g")

    def to_dict(self) -> dict:
        """Everything the result holds, as plain JSON types (arrays as nested lists, SI units; docs/cli.md#propagate);
        :func:`load_propagation` reads it back."""
        fields = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        fields["failures"] = {str(k): v for k, v in self.failures.items()}
        return _io.jsonable({"kind": "propagation", "draws": self.draws, **fields})

    def to_json(self, path=None) -> str:
        """The result as JSON (:meth:`to_dict`), written atomically to ``path`` when given."""
        return _io.dump_json(self.to_dict(), path)

    def to_mat(self, path):
        """The result as a MATLAB file: one variable per key of :meth:`to_dict` (bands as temperatures x samples)."""
        from ..data.matlab_results import save_results_mat
        save_results_mat(self.to_dict(), path)

    def save(self, path):
        """By the name's extension: ``.csv`` (:meth:`to_csv`), ``.mat`` (:meth:`to_mat`), else JSON."""
        name = str(getattr(path, "path", path)).lower()
        return (self.to_csv if name.endswith(".csv") else self.to_mat if name.endswith(".mat") else self.to_json)(path)

    title = "Propagation"

    def summary(self) -> Summary:
        return Summary([("draws", self.draws), ("failed", len(self.failures)), ("level", f"{100 * self.level:g} %"),
                        ("temperatures", ", ".join(f"{T:g}" for T in self.temperatures) + " C"),
                        ("noise", f"{self.noise * 1e9:.4g} nm")])

    def _frame(self) -> dict:
        """One row per temperature: the mean step per cycle and the final displacement, nominal and band [m]."""
        return {"temperature": self.temperatures, "nominal_step": self.nominal_step, "step_lower": self.step_lower,
                "step_upper": self.step_upper, "final_displacement": self.nominal[:, -1],
                "final_lower": self.lower[:, -1], "final_upper": self.upper[:, -1]}

    def _blocks(self) -> list:
        return [heading(self.title, f"{self.draws} draws ({len(self.failures)} failed), {100 * self.level:g} % bands"),
                lines(f"{T:g} C: step per cycle {self.nominal_step[j] * 1e6:.5g} um "
                      f"[{self.step_lower[j] * 1e6:.5g}, {self.step_upper[j] * 1e6:.5g}]; final displacement "
                      f"{self.nominal[j, -1] * 1e6:.5g} um [{self.lower[j, -1] * 1e6:.5g}, "
                      f"{self.upper[j, -1] * 1e6:.5g}]" for j, T in enumerate(self.temperatures))]

    def _html_blocks(self) -> list:
        blocks = self._blocks()
        return blocks[:1] + [fields(self.summary().rows())] + blocks[1:]

    def __repr__(self):
        return (f"PropagationResult({self.draws} draws at {', '.join(f'{T:g}' for T in self.temperatures)} C, "
                f"{100 * self.level:g} % bands)")


    def plot(self):
        """The bands as a matplotlib figure (the report's prediction-band figure)."""
        from .figures import bands_figure
        return bands_figure(self)

def load_propagation(path) -> PropagationResult:
    """A propagation result from the JSON that :meth:`PropagationResult.to_json` (``thermofriction propagate -o
    X.json``) wrote; InputError naming the file and the key for anything else."""
    from .._reading import read_input_json

    d = read_input_json(path, "propagation result (JSON)")
    if not isinstance(d, dict) or d.get("kind") != "propagation":
        raise InputError(f"{path}: not a propagation result (the JSON that 'thermofriction propagate -o X.json' "
                         f"writes)")
    values = {}
    for f in dataclasses.fields(PropagationResult):
        if f.name not in d and f.default is dataclasses.MISSING:
            raise InputError(f"{path}: missing key '{f.name}'")
        v = d.get(f.name, f.default)
        try:
            if f.name in ("names", "where"):
                ok = isinstance(v, list) and all(isinstance(n, str) for n in v) if f.name == "names" else \
                    isinstance(v, str)
                if not ok:
                    raise ValueError
            elif f.name == "failures":
                v = {int(k): str(r) for k, r in v.items()}
            elif f.name in ("level", "noise", "wall_time"):
                v = float(v)
            else:
                v = np.asarray(v, dtype=float)
        except (TypeError, ValueError, AttributeError):
            raise InputError(f"{path}: '{f.name}' is not what a propagation result holds there") from None
        values[f.name] = v
    res = PropagationResult(**values)
    n_T, n_t = res.temperatures.size, res.time.size
    # the axes first: an empty or unordered one would fail in the report's figures, after its work
    if res.temperatures.ndim != 1 or not n_T or not np.all(np.isfinite(res.temperatures)):
        raise InputError(f"{path}: 'temperatures' must be a non-empty list of finite numbers [C]")
    if res.time.ndim != 1 or not n_t or not np.all(np.isfinite(res.time)) or not np.all(np.diff(res.time) > 0):
        raise InputError(f"{path}: 'time' must be a non-empty, increasing list of finite times [s]")
    for name in ("nominal", "median", "lower", "upper", "prediction_lower", "prediction_upper"):
        if getattr(res, name).shape != (n_T, n_t):
            raise InputError(f"{path}: '{name}' must have one row of {n_t} samples per temperature ({n_T})")
    for name in ("nominal_step", "step_lower", "step_upper"):
        if getattr(res, name).shape != (n_T,):
            raise InputError(f"{path}: '{name}' must have one value per temperature ({n_T})")
    if res.parameters.ndim != 2 or res.parameters.shape[1] != len(res.names):
        raise InputError(f"{path}: 'parameters' must hold one row per draw, one column per name in 'names'")
    if not 0 < res.level < 1:
        raise InputError(f"{path}: 'level' must be between 0 and 1, got {res.level:g}")
    return res


def _checked(result, temperatures, draws, seed, input, duration, sample_rate, level, solver, controller, scheduler,
             workers, batch_size, progress):
    """propagate's arguments checked before any work; returns (the fitted model, the temperatures as an array)."""
    if input is not None and not isinstance(input, Waveform):
        _args.refuse("input", "a Waveform or None", input)
    check_run_options(duration, sample_rate, solver, controller, scheduler, workers, batch_size, progress)
    temps = _args.number_list(temperatures, "temperatures", "C")
    model = getattr(result, "model", None)
    if model is None or not hasattr(result, "parameters"):
        raise InputError(f"result must be a fit (tf.identify's FitResult), got {shorten(result)}")
    check_drawable(result)  # before the nominal runs
    _args.whole(draws, "draws", low=2, high=MAX_DRAWS)
    _args.whole(seed, "seed", low=0)
    if not 0 < _args.number(level, "level") < 1:
        raise InputError(f"level must be between 0 and 1, got {shorten(level)}")
    return model, temps


def propagate(result, temperatures, *, draws: int = 200, seed: int = 0, input=None, duration: float = 1.0,
              sample_rate: float = 1000.0, level: float = 0.95, solver=None, controller=None, scheduler=None,
              workers=None, batch_size=None, progress=None) -> PropagationResult:
    """Draws ``draws`` parameter sets from ``result``'s covariance, simulates each at every temperature, and
    returns the central ``level`` bands of the displacement and of the mean step per cycle.

    Parameters
    ----------
    result : FitResult
        The fit whose parameters, standard errors and correlations are drawn from (a fit read back from its
        results JSON too).
    temperatures : sequence of float
        The temperatures [C] simulated.
    draws : int, default 200
        The parameter sets drawn.
    seed : int, default 0
        The seed of the draws.
    input : Waveform, optional
        The drive; default the model's ``[input]``.
    duration : float, default 1.0
        Each simulation's length [s].
    sample_rate : float, default 1000.0
        The output grid's rate [Hz].
    level : float, default 0.95
        The bands' central probability, between 0 and 1.
    solver : AutoSwitch or Dopri5 or Rodas4 or str, optional
        As for ``simulate``.
    controller : StepSizeController, optional
        As for ``simulate``.
    scheduler : str or distributed.Client, optional
        Where the tasks run: None or "threads" (threads in this process, one per core, or ``workers`` of them:
        the C core releases the GIL), "sequential" (in this process, in order), "processes" (an embedded local
        Dask cluster of ``workers`` processes), an address (``tcp://HOST:8786``, a scheduler file) or a
        ``distributed.Client`` (docs/scale.md).
    workers : int, optional
        The threads or processes; default one per core.
    batch_size : int, optional
        Draws per task; default chunks of at least ~20 ms of work on threads, ~100 ms on Dask.
    progress : callable, optional
        Called with the number of draws done.

    Returns
    -------
    PropagationResult
        Per temperature and output time: the fitted model's displacement [m], the median and ``level`` bands
        of the draws (the parameters' band, and with the measurement noise the fit estimated), the mean step per
        cycle's band, and the draws that failed with their reasons.

    Raises
    ------
    InputError
        An argument of the wrong type or value, named; a fit without fitted parameters; a parameter without a
        finite standard error; a correlation matrix that is not one (not symmetric, not positive
        semi-definite), named.
    """
    import time

    from ..simulation import simulate

    model, temps = _checked(result, temperatures, draws, seed, input, duration, sample_rate, level, solver, controller,
                            scheduler, workers, batch_size, progress)
    waveform = input if input is not None else model.input
    if waveform is None:
        raise InputError("the fitted model has no [input]: give input= (e.g. tf.Sawtooth(amplitude=30, frequency=5))")
    sim = dict(duration=duration, sample_rate=sample_rate, solver=solver, controller=controller)
    t0 = time.perf_counter()
    nominal = [simulate(model, temperature=float(T), input=waveform, **sim) for T in temps]  # checks the arguments
    per_draw = time.perf_counter() - t0  # a draw's runs take about what the nominal ones took: the chunks' size
    names, thetas = draw_parameters(result, int(draws), int(seed))
    with Runner(scheduler, workers) as runner:
        # at most 100 draws per chunk: a chunk's displacements (draws x temperatures x samples) travel back whole
        spans, outs = runner.map_chunks(
            _run_draws, int(draws), lambda a, b: (model, names, thetas[a:b], temps, waveform, sim),
            batch_size=batch_size, item_seconds=per_draw, largest=100, progress=progress,
            on_error=lambda span, reason: (None, None, {k: reason for k in range(span[1] - span[0])}))
        where = runner.describe()
    n_t = nominal[0].time.size
    disp = np.full((int(draws), temps.size, n_t), np.nan)
    steps = np.full((int(draws), temps.size), np.nan)
    failures = {}
    for (a, b), (d, s, errs) in zip(spans, outs):
        if d is not None:
            disp[a:b], steps[a:b] = d, s
        failures.update({a + i: r for i, r in errs.items()})
    ok = np.array([i not in failures for i in range(int(draws))])
    if ok.sum() < 2:
        first = next(iter(failures.values()), "")
        raise ThermofrictionError(f"fewer than two of {draws} drawn models could be simulated: {first}")
    q = [50 * (1 - level), 50, 50 * (1 + level)]
    lo, med, hi = np.percentile(disp[ok], q, axis=0)
    noise = float((getattr(result, "fit_quality", None) or {}).get("noise") or 0.0)
    # a new measurement = a drawn model's prediction + independent Gaussian sensor noise: each side of
    # the band and the noise's quantile add in quadrature (exact for a Gaussian band; sampling the noise
    # per output sample would make a ragged band from a few hundred draws)
    from scipy.stats import norm
    zn = float(norm.ppf(0.5 * (1 + level))) * noise
    plo, phi = med - np.hypot(med - lo, zn), med + np.hypot(hi - med, zn)
    slo, shi = np.percentile(steps[ok], [q[0], q[2]], axis=0)
    return PropagationResult(
        temperatures=temps, time=nominal[0].time, level=float(level),
        nominal=np.array([r.displacement for r in nominal]), median=med, lower=lo, upper=hi,
        prediction_lower=plo, prediction_upper=phi, noise=noise,
        nominal_step=np.array([r.step_sizes.mean() if r.step_sizes.size else np.nan for r in nominal]),
        step_lower=slo, step_upper=shi, names=list(names), parameters=thetas, steps=steps,
        final_displacement=disp[:, :, -1], failures=dict(sorted(failures.items())),
        wall_time=time.perf_counter() - t0, where=where)


__all__ = ["propagate", "PropagationResult", "draw_parameters", "load_propagation", "check_drawable"]
