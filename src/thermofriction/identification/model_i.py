"""Model I (docs/models.md#model-i): per-temperature fits continued from temperature to temperature, a law per
parameter through the estimates, and a joint refinement of the law coefficients on all experiments."""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from .._lazy import lazy
from ..data.experiments import first_periods
from ..errors import ComputationError, InputError
from ..models import Const, Model, ModelI
from ..models.transforms import base_model
from .law_kinds import Refined, checked_kinds
from .laws import at_shared, fit_law, law_kinds_for, laws_on_information
from ..fitting.optimiser import AT_NOISE, fit
from ..fitting.parameters import EXCESS, Parameters, friction_parameters, get_value, unit_of, with_values
from ..measurements import make_traces
from .profile import (PROFILE_FIT_EVALUATIONS, PROFILE_POINTS, PROFILE_RANGE, PROFILE_XTOL, Profiled, fs_kept_above_fc,
                      profile_range, profiled, settled_constants, widened)
from .procedures import (along_temperatures, counted, fit_friction, fit_result, held_at, levels_held_as_ratios, fitted_names,
                         stribeck_start, temperature_groups, unrefined_result)
from .result import FitResult

optimize = lazy("scipy.optimize")


class _PerTemperature:
    """Model I's per-temperature fits: the lowest temperature first (it decides what the data cannot
    determine, which is then held at the initial model's law), then two continuation chains, one per core:
    upward from it, and downward from the highest temperature, which starts from the lowest temperature's fit
    carried there along the initial model's laws (not a neighbour: with the multi-start)."""

    def __init__(self, init, names, free, opts, measurement, progress):
        self.init, self.names, self.free, self.opts = init, names, free, opts
        self.measurement, self.progress = measurement, progress
        self.held, self.warnings = [], []
        self.joint = []  # held constants fitted on all experiments together in the joint refinement
        self.nfev = 0  # the evaluations of the constant's profile (profiled_constant)
        self.region = None  # (lowest, highest) value of that constant the profile's points do not exclude
        self.free_in_region = []  # the laws held for lack of information that were free in finding that range

    def run(self, groups):
        """[(temperature, result)] in temperature order."""
        T0, res0, following = self.fit_at(groups[0], None, first_of_all=True)
        fits = {}

        def step(i, carried, first):
            previous, neighbour = carried
            T, res, next_ = self.fit_at(groups[i], previous, neighbour=neighbour)
            fits[i] = (T, res)
            return next_, True

        rest = list(range(1, len(groups)))
        up, down = rest[:(len(rest) + 1) // 2], rest[(len(rest) + 1) // 2:][::-1]
        along_temperatures([(up, (following, True)), (down, (following, False))], step,
                           alone=(rest, (following, True)))
        return sorted([(T0, res0)] + [fits[i] for i in rest], key=lambda tr: tr[0])

    def start_at(self, T, previous):
        """The model a temperature's fit starts from: the neighbour's values carried along the initial model's
        laws (by their ratio, which a wrong level of a law does not change: the paper's sigma0 and fc change by
        a third over 3 C, many standard errors that a plain continuation would leave for the fit to walk), or
        the initial model's there; the held parameters always at the initial model's law."""
        init, names, held = self.init, self.names, self.held
        if previous is None:
            base = base_model(init, T)
        else:
            T_prev, base = previous
            shifts = {n: float(init.laws[n](T) / init.laws[n](T_prev)) for n in names
                      if n in init.laws and n not in held}
            shifts = {n: f for n, f in shifts.items() if math.isfinite(f) and f > 0}
            values = base.friction.values()
            new = {n: values[n] * f for n, f in shifts.items()}
            # a parameter held with a law follows it (not carried from the neighbour); fs carries its excess over fc
            new.update({n: float(init.laws[n](T)) for n in init.laws if n not in names})
            if "fs" in names and "fs" not in new and (values.get("fs") or 0.0) > (values.get("fc") or math.inf):
                new["fs"] = new.get("fc", values["fc"]) + values["fs"] - values["fc"]
            base = base.with_friction(**new) if new else base
        base = stribeck_start(dataclasses.replace(base, thermal=None), names)
        if held:  # parameters the data cannot determine follow the initial model's law
            base = held_at(init, T, base, held)
        return base

    def fit_at(self, group, previous, first_of_all=False, neighbour=True):
        """:meth:`_fit_at`; a relation between the values it starts or continues from broken there (fs below fc)
        fails as a computation naming the temperature, never as an error of the user's file (issue 40)."""
        try:
            return self._fit_at(group, previous, first_of_all, neighbour)
        except InputError as e:
            T, why = float(np.mean([x.temperature for x in group])), str(e).removeprefix("[friction]: ")
            raise ComputationError(f"Model I: the fit at {T:.4g} C cannot start: {why}, in the values carried "
                                   f"from the neighbouring temperature's fit, not in the initial model") from e

    def _fit_at(self, group, previous, first_of_all=False, neighbour=True):
        """The fit at one temperature, from the neighbouring temperature's model (continuation) or,
        without one, from the initial model's values there with the multi-start; returns (T, result,
        what the next temperature continues from)."""
        init, names = self.init, self.names
        T = float(np.mean([e.temperature for e in group]))
        base = self.start_at(T, previous)
        if self.progress:
            self.progress(f"Model I: fitting {', '.join(n for n in names if n not in self.held)} at {T:.4g} C")
        first = dict(self.opts)
        if previous is not None and neighbour:  # continuation from the neighbouring temperature
            first["starts"] = 1
        head = first_periods(group, HEAD_PERIODS, HEAD_MIN_PERIODS, init.input) if first_of_all else None
        res = self.from_heads(group, head, T, base, first) if head else self.fit_one(group, T, base, self.held, first)
        if first_of_all:
            undetermined = self.undetermined(res)
            # a shape constant (no law in the initial model: vs, sigma2, ...) that one temperature cannot separate
            # from the levels is held here and fitted once on all experiments together, where the temperatures'
            # different velocities and levels separate it; the levels then get their own chance at this
            # temperature. LuGre's default three keep the rule below (held at the initial model's, considered)
            constants = [n for n in undetermined if n not in init.laws and n not in ("fc", "sigma0", "sigma1")]
            if constants and len(constants) < len(names):
                self.held, self.joint = list(constants), list(constants)
                self.warnings.append(f"{', '.join(constants)} cannot be determined at one temperature (standard error "
                                     f"above 100 % at {T:.4g} C): held in the per-temperature fits and fitted as "
                                     f"{'a constant' if len(constants) == 1 else 'constants'} on all experiments "
                                     f"together")
                res = self.fit_one(group, T, base, self.held, self.opts)
                undetermined = [n for n in self.undetermined(res) if n not in self.held]
            if undetermined and len(undetermined) + len(self.held) < len(names):
                undetermined = self.held + undetermined
                self.held = undetermined
                lacking = [n for n in undetermined if n not in self.joint]
                self.warnings.append(f"{', '.join(lacking)} cannot be determined from these data (standard "
                                     f"error above 100 % at {T:.4g} C): held at the initial model's law")
                res = self.fit_one(group, T, held_at(init, T, base, undetermined), undetermined, self.opts)
        return T, res, (T, self.carried(res, T))

    def from_heads(self, group, head, T, base, opts):
        """The first fit from the initial model on the records' first periods (``head``), then on the whole
        records from its optimum; where that does not reach the noise (AT_NOISE), the whole records from the
        initial model too, as without the heads (the heads' optimum can be another basin: a freed m_e traded
        against the levels on two periods) but with the heads' optimum as the multi-start's first run, and the
        better of the two. Every evaluation is counted. The first fit
        from a rough start was most of a Model I fit's evaluations (benchmarks/study_cost.py: a poorly determined
        sigma1 walking to its bound, the multi-start after it); on a periodic input the first periods carry the
        friction levels."""
        spent, tried, found = [0, 0], [], []
        try:
            rough = self.fit_one(head, T, base, self.held, opts)
            spent = [rough.nfev, rough.njev]
            tried.append(self.fit_one(group, T, rough.model, self.held, {**opts, "starts": 1, "found": found}))
        except ComputationError:  # the whole records decide, from the initial model, as without the heads
            pass
        if not tried or not tried[0].fit_quality.get("ratio", math.inf) <= AT_NOISE:
            # the heads' optimum stands for the multi-start's first run from the initial model (the heads' fit
            # started there: a first run on the whole records walked 41 evaluations to it, seed 6 of the study)
            tried.append(self.fit_one(group, T, base, self.held, {**opts, "first": found[0]} if found else opts))
        res = min(tried, key=lambda r: r.cost)
        res.nfev = sum(r.nfev for r in tried) + spent[0]
        res.njev = sum(r.njev for r in tried) + spent[1]
        return res

    def carried(self, res, T):
        """What a fit continues from: ``res``'s model with only what this temperature determined. A parameter the
        data leave open (standard error above its value, e.g. sigma1 run to its bound) restarts from the initial
        model, or the next fit spends most of its evaluations walking back from a bound (or, from sigma1 near
        zero in log space, jumps to 1e9)."""
        open_ = [n for n in self.names if n not in self.held and not (
            _fitted(res, n).stderr is not None and math.isfinite(_fitted(res, n).stderr)
            and _fitted(res, n).stderr < abs(_fitted(res, n).value))]
        at_T = base_model(self.init, T).friction.values()
        reset = {n: at_T[n] for n in open_ if n in at_T and n != "fs"}
        now = res.model.friction.values()
        if "fs" in open_ and "fs" in at_T:  # fs by its excess over fc (fs >= fc)
            fc = reset.get("fc", now["fc"])
            reset["fs"] = fc + max(at_T["fs"] - at_T["fc"], 0.0)
        free = [n for n in self.names if n not in self.held]
        return res.model.with_friction(**fs_kept_above_fc(now, reset, free)) if reset else res.model

    def refit_all(self, groups, temps, starts, values: dict, opts, held=None) -> list:
        """Every temperature's fit with ``values`` held (and ``held``, default the fits' own), each from
        ``starts[i]`` (what it determined), on the two continuation threads; raises ComputationError where one
        fails."""
        fits, index = {}, list(range(len(groups)))
        half = (len(index) + 1) // 2
        held = self.held if held is None else held

        def step(i, carried, first):
            carried_model = self.carried(starts[i], temps[i])
            free = [n for n in self.names if n not in held and n not in values]
            base = carried_model.with_friction(**fs_kept_above_fc(carried_model.friction.values(), values, free))
            fits[i] = self.fit_one(groups[i], temps[i], base, held, {**self.opts, "starts": 1, **opts})
            self.nfev += fits[i].nfev
            return carried

        along_temperatures([(index[:half], None), (index[half:], None)], step, alone=(index, None))
        return [fits[i] for i in index]

    def profiled_constant(self, groups, per_T):
        """The per-temperature fits at the value of the one constant fitted on all experiments (``self.joint``)
        that minimizes their summed misfit, a bounded 1-D search in its log within a factor PROFILE_RANGE of the
        start, each temperature refitted with it held (from the fits at the nearest value tried). Given the
        constant, each temperature determines the levels; the joint refinement, left to find the constant along
        the valley the levels make with it, crept: a Stribeck velocity 2.5x off moved to 2.3x in 30 evaluations
        and to 1.07x in 100 (2 s records). Sets ``self.region``; returns per_T at the best value."""
        (name,) = self.joint
        v0 = float(self.init.friction.values()[name])
        temps = [T for T, _ in per_T]

        def profile(tried, held):
            """The summed misfit at a log factor, the fits refitted with ``held`` held (from the nearest tried)."""
            def cost(log_factor):
                nearest = tried[min(tried, key=lambda x: abs(x - log_factor))][1]
                try:
                    fits = self.refit_all(groups, temps, nearest, {name: v0 * math.exp(log_factor)},
                                          {"max_nfev": PROFILE_FIT_EVALUATIONS}, held=held)
                except ComputationError:
                    return math.inf
                tried[float(log_factor)] = (sum(f.cost for f in fits), fits)
                return tried[float(log_factor)][0]
            return cost

        tried = {0.0: (sum(r.cost for _, r in per_T), [r for _, r in per_T])}
        cost = profile(tried, self.held)
        optimize.minimize_scalar(cost, bounds=(-math.log(PROFILE_RANGE), math.log(PROFILE_RANGE)), method="bounded",
                                 options={"xatol": PROFILE_XTOL, "maxiter": PROFILE_POINTS})
        best = min(tried, key=lambda x: tried[x][0])
        # its range with the laws held for lack of information (sigma1 at the initial model's) free at each
        # temperature: held at a wrong value, such a law narrows the constant's profile (vs with sigma1 held 2x
        # off: 0.0033-0.0050 m/s, the truth's 0.006 6.4 in chi-square out; with sigma1 at the truth's law,
        # 0.0035-0.0069), and its stated range reaches the other intervals only linearly. The search keeps them
        # held: free, they flatten the profile so that its least can be anywhere (2 of 12 seeds stayed at the
        # start's vs, 2.5x off)
        around, around_cost = tried, cost
        self.free_in_region = [n for n in self.held if n not in self.joint]
        if self.free_in_region:
            around = {best: tried[best]}
            around_cost = profile(around, self.joint)
            around_cost(best)
        self.region = tuple(v0 * math.exp(x) for x in profile_range(around, best, around_cost))
        if best == 0.0:
            return per_T
        # the fits the laws are drawn through: at the best value with the full budget, from the first fits (the
        # search's short fits, chained from point to point, can leave a poorly determined sigma1 far out)
        try:
            final = self.refit_all(groups, temps, [r for _, r in per_T], {name: v0 * math.exp(best)}, {})
        except ComputationError:
            final = tried[best][1]
        return list(zip(temps, final))

    def undetermined(self, res) -> list:
        """The fitted names whose standard error at this temperature is above their value (or not finite)."""
        return [n for n in self.names if n not in self.held and (
            not math.isfinite(_fitted(res, n).stderr) or _fitted(res, n).stderr > abs(_fitted(res, n).value))]

    def fit_one(self, group, T, base, fixed, opts):
        """One temperature's fit (fs as its excess over fc); a fit that fails names the temperature, the
        parameters and where it started, as a failed computation (never as an error of the user's file)."""
        names = self.names + self.free
        try:
            return fit_friction(group, base, friction_parameters(base, names, fixed=fixed, excess=True),
                                method=f"base at {T:.4g} C", measurement=self.measurement, **opts)
        except (InputError, ComputationError) as e:
            start = ", ".join(f"{n} = {get_value(base, n):.4g}" for n in names)
            raise ComputationError(f"Model I: the fit at {T:.4g} C of {', '.join(n for n in names if n not in fixed)} "
                                   f"failed, from {start} (continued from the neighbouring temperature's fit along the "
                                   f"initial model's laws, with {opts.get('starts', 8)} start(s)): {e}") from e


#: the first fit from the initial model runs on each record's first HEAD_PERIODS periods of its input, where every
#: record of the temperature holds HEAD_MIN_PERIODS (_PerTemperature.from_heads; data.experiments.first_periods)
HEAD_PERIODS, HEAD_MIN_PERIODS = 2, 8


def _fitted(res, name):
    """The fitted Parameter of ``name`` (fs: its excess over fc, where it was fitted as one)."""
    return res.parameters[EXCESS] if name == "fs" and EXCESS in res.parameters else res.parameters[name]


def _estimate(res, name):
    """(value, standard error) of ``name`` at one temperature; fs from fc and the excess (delta method)."""
    if not (name == "fs" and EXCESS in res.parameters):
        return res.parameters[name].value, res.parameters[name].stderr
    x, fc = res.parameters[EXCESS], res.parameters["fc"]
    se_x, se_fc = x.stderr or 0.0, (fc.stderr or 0.0) if fc.vary else 0.0
    varying = [p.name for p in res.parameters.varying]
    rho = 0.0
    if fc.vary and res.correlation.shape == (len(varying),) * 2:
        rho = float(np.nan_to_num(res.correlation[varying.index(EXCESS), varying.index("fc")]))
    return x.value + fc.value, math.sqrt(max(se_x ** 2 + se_fc ** 2 + 2 * rho * se_x * se_fc, 0.0))




def _laws_through(per_T, names, held, init, laws):
    """A law per parameter through the per-temperature estimates (by AICc among KINDS, the initial model's kind
    preferred; a shape constant the initial model gives no law a constant too: laws.law_kinds_for; unless ``laws``
    names the kinds), refitted on the estimates' covariances; a held parameter keeps the
    initial model's. (Without the constant the Stribeck velocity got a slope from its estimates' scatter: on a 10
    ms-lag joint from a plant-only file it traded with fs's along their valley, fs up to 32 % off at 60 C. A constant
    for every parameter without a law cost displacement truths their slopes: Model I on 20 random truths covered 256
    of 300 points, tests/test_identify_coverage.py; with linear preferred over the exponential too, 250. On the
    joint over 8 seeds the 95 % intervals at each temperature now cover 229 of 240: tests/test_joint_coverage.py.)"""
    Ts = np.array([T for T, _ in per_T])
    new_laws, law_tables = {}, {}
    for n in names:
        if n in held:
            new_laws[n] = init.laws[n] if n in init.laws else Const(init.friction.values()[n])
            law_tables[n] = {"chosen": "held at the initial model", "law": new_laws[n].to_dict()}
            continue
        vals = np.array([_estimate(r, n)[0] for _, r in per_T])
        ses = np.array([_estimate(r, n)[1] for _, r in per_T])
        prior = init.laws[n].kind if n in init.laws else None
        kinds, over_const = law_kinds_for(n, prior, (laws or {}).get(n))
        law, table = fit_law(Ts, vals, ses, kinds, prefer=prior, parameter=n, over_const=over_const)
        new_laws[n] = law
        law_tables[n] = {"chosen": law.kind, "candidates": table, "temperatures": Ts, "values": vals,
                         "stderr": ses}
    fitted = [n for n in names if n not in held]
    refined = laws_on_information(Ts, per_T, {n: new_laws[n] for n in fitted})
    for n in fitted:
        if refined[n] is not new_laws[n]:  # the candidates' coefficients are by standard errors alone
            new_laws[n] = refined[n]
            law_tables[n]["weighted_by_covariance"] = new_laws[n].to_dict()
    return new_laws, law_tables


def _law_parameters(new_laws, held, free, model) -> Parameters:
    """The law coefficients (and the freed plant parameters) as the joint refinement's parameters."""
    params = Parameters()
    for n, law in new_laws.items():
        for cname, v in zip(law.coefficient_names(), law.coefficients()):
            name = f"{n}.{cname}"
            positive = law.kind == "exp" and cname == "a" and v > 0
            params.add(name, v, min=0.0 if positive else -math.inf, unit=unit_of(model, name), vary=n not in held)
    for n in free:
        params.add(n, get_value(model, n), min=0.0, unit=unit_of(model, n))
    return params


def _parameters_of(held, free):
    """The joint refinement's parameters of a model (its laws' coefficients, ``held`` held, ``free`` freed)."""
    return lambda m: _law_parameters(dict(m.thermal.laws), held, free, m)


def _above_fc(new_laws, per_T, Ts):
    """fs's law kept at or above fc's over the fit temperatures: where the laws through the estimates cross, fs's
    becomes fc's scaled by the estimates' median ratio fs/fc (at least 1). Returns a warning, or None."""
    if "fs" not in new_laws or "fc" not in new_laws:
        return None
    grid = np.linspace(float(Ts.min()), float(Ts.max()), 41)
    fs, fc = new_laws["fs"], new_laws["fc"]
    if np.all(np.asarray(fs(grid)) >= np.asarray(fc(grid))) or not fc.coefficient_names():
        return None
    ratio = max(float(np.median([_estimate(r, "fs")[0] / r.parameters["fc"].value for _, r in per_T])), 1.0)
    c = np.array(fc.coefficients(), float)
    c = np.r_[c[0] * ratio, c[1:]] if fc.kind == "exp" else c * ratio
    new_laws["fs"] = fc.with_coefficients(c)
    return (f"fs's law through the per-temperature estimates fell below fc's: fs follows fc's law times their median "
            f"ratio {ratio:.4g} instead, as the joint refinement's start")


@dataclasses.dataclass
class ModelIDetails:
    """What Model I's pipeline records besides the fit, written as the result's ``details`` (:meth:`as_dict`, the
    results JSON's keys in this order): the parameters held for lack of information, those fitted as one constant on
    all experiments, the held ones whose profile reached its range's end, each temperature's fit, each law's choice;
    where constants were settled by a profile (a joint refinement with a shape constant), their held ranges and the
    profile's secants (``_secants``, internal to the held values' tests, which remove it)."""

    held_for_lack_of_information: list
    fitted_as_constant: list
    per_temperature: list
    held_where_reached: list = dataclasses.field(default_factory=list)
    laws: dict = dataclasses.field(default_factory=dict)
    held_ranges: dict | None = None
    secants: dict | None = None

    def as_dict(self) -> dict:
        out = {"held_for_lack_of_information": self.held_for_lack_of_information,
               "fitted_as_constant": self.fitted_as_constant, "held_where_reached": self.held_where_reached,
               "per_temperature": self.per_temperature, "laws": self.laws}
        if self.held_ranges is not None:
            out.update(held_ranges=self.held_ranges, _secants=self.secants)
        return out


@counted
def identify_model_i(experiments, init: Model, *, laws=None, refine=True, progress=None, free=(), measurement=None,
                     parameters=None, **opts) -> FitResult:
    """Model I: per-temperature fits, a law per parameter (linear or exponential by AICc unless
    ``laws`` names one), then a joint refinement of the law coefficients on all experiments.

    Parameters
    ----------
    experiments : list of Experiment
        The experiments fitted (a dataset's ``fit``).
    init : Model
        The initial model.
    laws : dict, optional
        Law kinds per parameter, a kind or a list to choose from by AICc; default each chosen by AICc.
    refine : bool, default True
        End with the joint refinement.
    progress : callable, optional
        Called with one line of text at each stage.
    free : sequence of str, default ()
        Plant parameters (e.g. m_e) fitted too, one value shared by all experiments (per temperature first;
        their median starts the joint refinement).
    measurement : Measurement, optional
        How the residuals are formed; default the experiments' own, with its default offset policy.
    parameters : list of str, optional
        The friction parameters fitted, each with its own law; default the friction model's. Any other with a
        law in ``init`` keeps it, held.
    **opts
        Passed on to ``fit``: ``rtol``, ``starts``, ``seed``, ``max_nfev``, ...

    Returns
    -------
    FitResult

    Raises
    ------
    InputError
        Bad arguments (an unknown parameter name, no parameter to fit, an initial value outside its bounds),
        named.
    ComputationError
        The fit failed (SolverError where a simulation stopped).
    """
    free = list(free)
    t0 = time.perf_counter()
    groups = temperature_groups(experiments)
    if len(groups) < 2:
        raise InputError("Model I needs fit experiments at two or more temperatures")
    names = fitted_names(init, parameters)
    per_temperature = _PerTemperature(init, names, free, opts, measurement, progress)
    per_T = per_temperature.run(groups)
    if len(per_temperature.joint) == 1 and refine:
        per_T = per_temperature.profiled_constant(groups, per_T)
    held, warns, joint = per_temperature.held, per_temperature.warnings, per_temperature.joint
    if not refine:  # without a joint refinement nothing fits the constants: they stay held
        joint = []
    details = ModelIDetails([n for n in held if n not in joint], joint, per_temperature=[
        {"temperature": T, "files": [x["file"] for x in r.experiments], "rmse_offset_removed": r.rmse,
         "parameters": r.parameters.to_dict(), "warnings": r.warnings, "wall_time": r.wall_time} for T, r in per_T])
    # one plant for all temperatures: the median of the per-temperature estimates, each temperature's estimates
    # moved to it before the laws are drawn through them
    shared = {n: float(np.median([r.parameters[n].value for _, r in per_T])) for n in free}
    estimates = at_shared(per_T, free, shared) if free else per_T
    new_laws, details.laws = _laws_through(estimates, names, held, init, laws)
    for n in joint:  # from the value the per-temperature fits were made at (profiled_constant's)
        new_laws[n] = Const(float(per_T[0][1].model.friction.values()[n]))
        details.laws[n] = {"chosen": "a constant fitted on all experiments together", "law": new_laws[n].to_dict()}
    Ts = np.array([T for T, _ in per_T])
    warns += [w for w in [_above_fc(new_laws, estimates, Ts)] if w]
    kept = {**{n: law for n, law in init.laws.items() if n not in names},  # held with their laws
            **levels_held_as_ratios(init, names, new_laws, Ts)}
    held = [n for n in held if n not in joint] + list(kept)
    new_laws = {**new_laws, **kept}
    friction = dataclasses.replace(base_model(init, float(Ts.mean())).friction, **{n: None for n in new_laws})
    model = dataclasses.replace(init, friction=friction, thermal=ModelI(new_laws))
    if free:
        model = with_values(model, shared)
    if not refine:
        params = _law_parameters(new_laws, held, free, model)
        return unrefined_result("model-i", model, params, experiments, measurement, t0, [r for _, r in per_T],
                                "per-temperature fits and laws (no joint refinement)", warns, details.as_dict(),
                                rtol=opts.get("rtol", 1e-8))
    if progress:
        progress("Model I: joint refinement of the law coefficients on all experiments")
    params = _law_parameters(new_laws, held, free, model)
    traces = make_traces(experiments, model, measurement)
    ropts = dict(opts)
    ropts["starts"] = 1
    ropts.setdefault("max_nfev", 30)
    # from laws through the per-temperature optima weighted by their covariances: near the optimum
    outcome = fit(model, params, traces, near=True, **ropts)
    checkable = [] if joint else [n for n in names if n not in held and n not in (laws or {})]  # (law_kinds.py)
    checked = checked_kinds(Refined(model, params, outcome, traces), per_T, checkable, experiments, measurement,
                            _parameters_of(held, free), ropts, details.laws, warns)
    model, params, outcome, traces = checked.model, checked.params, checked.outcome, checked.traces
    prof = Profiled(model, params, outcome, traces)
    if free:  # a plant parameter's step can be blocked where a law meets its domain's edge (profile.py)
        prof = profiled(model, params, outcome, traces, experiments, measurement, free,
                        lambda m, fr: _law_parameters(dict(m.thermal.laws), held, fr, m), ropts)
    if joint:
        kept_open, undetermined, secants, ranges = settled_constants(
            prof, joint, per_temperature.region, lambda m, hold: _law_parameters(
                dict(m.thermal.laws), held + hold, free, m), experiments, measurement, ropts)
        details.held_for_lack_of_information += undetermined
        details.held_where_reached = kept_open
        details.held_ranges = {n: {**span, "free_in_profile": list(per_temperature.free_in_region)}
                               if span["from"] == "profile" else span for n, span in ranges.items()}
        details.secants = secants
        details.fitted_as_constant = [n for n in joint if n not in undetermined]
    res = fit_result("model-i", prof.model, prof.params, prof.outcome, prof.traces, t0, warns, details.as_dict())
    widened(res, prof.widen)
    return res


__all__ = ["identify_model_i"]
