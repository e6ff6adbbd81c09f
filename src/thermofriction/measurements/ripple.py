"""The position ripple of a force fit in the joint's own angle (docs/force-data.md, "The ripple's angle").

Under a prescribed motion the ripple ``R(x) = sum_k a_k cos(2 pi k x / P) + b_k sin(2 pi k x / P)`` is added to the
friction force and enters no state (core/src/plant.c: ``friction_at``; docs/models.md#direction-and-position), so
the force of a model with a ripple is the force of the same model without it plus ``R`` at the position. A force
fit therefore runs the model without its ripple (the C core's exact stepping where it applies, at the cost of a fit
without a ripple) and adds ``R`` and its closed-form partials to the amplitudes here, evaluated at the **recorded
position** of each sample: the joint's own angle, not the driving velocity integrated from 0.

Where each run's positions are relative to its own start (no homing), the ripple's phase differs from run to
run: ``ripple_phase = "per-run"`` gives each run a nuisance angle offset ``phi`` (``R(x + phi)``), profiled out
like a per-run sensor offset (the best ``phi`` per run on a grid refined by Gauss-Newton; the Jacobian projected
off its column, variable projection). The first trace of a fit is the reference (``phi = 0``): the amplitudes are
in its angle. ``"recorded"`` uses the recorded angle as it is; ``"auto"`` (the default) takes ``"per-run"`` when
every run of two or more starts at position 0 (within ZERO_START of the positions' range: positions relative to each
run), else
``"recorded"``, and says which (:func:`decide`).

This applies to models whose ripple is a plain additive term: not Model II (which scales the ripple with the rest
of the force) and no Model I law on a ripple parameter; those keep the ripple inside the model's own run (the C
core's exact stepping where it applies, which adds it as the plant does, else the integrated runs) at the driving
waveform's position (which starts at the run's first recorded position), without per-run phases."""

from __future__ import annotations

import math
import threading

import numpy as np

from .. import _args
from ..errors import InputError
from ..models import ModelI
from ..models.sides import RIPPLE_AMPLITUDES, RIPPLE_ORDER

#: The choices of the ripple's phase (docs/force-data.md, "The ripple's angle").
RIPPLE_PHASES = ("auto", "recorded", "per-run")
#: "auto": runs start "at 0" when their first recorded position is within this fraction of the largest run's range.
ZERO_START = 1e-3
#: The phase search: grid points over one period, then Gauss-Newton steps.
PHASE_GRID = 72
PHASE_STEPS = 4
_PARAMS = ("ripple_period", *RIPPLE_AMPLITUDES)


def check_phase_option(value, where: str = "ripple_phase") -> str:
    if not isinstance(value, str) or value not in RIPPLE_PHASES:
        _args.refuse(where, "one of " + ", ".join(repr(p) for p in RIPPLE_PHASES), value)
    return value


def has_ripple(model, names=()) -> bool:
    """Whether ``model`` has a ripple (a period and an amplitude, a value or a Model I law) or ``names`` fit an
    amplitude."""
    f = model.friction
    return (bool(getattr(f, "ripple_period", None)) and any(getattr(f, n, None) or n in model.laws
                                                            for n in RIPPLE_AMPLITUDES)) or \
        any(n in RIPPLE_AMPLITUDES for n in names)


def additive(model) -> bool:
    """Whether the ripple of ``model`` is a plain additive term that can be taken outside the simulation: a
    period given, not Model II, no Model I law on a ripple parameter."""
    if not getattr(model.friction, "ripple_period", None):
        return False
    if model.thermal is not None and not isinstance(model.thermal, ModelI):
        return False
    return not any(n in _PARAMS for n in model.laws)


def without(model):
    """``model`` without its ripple (the base force)."""
    return model.with_friction(**{n: None for n in _PARAMS})


def amplitudes(model) -> np.ndarray:
    return np.array([getattr(model.friction, n, None) or 0.0 for n in RIPPLE_AMPLITUDES])


def evaluate(model, angle, names=()):
    """(R, dR/d names (n x len(names): the amplitudes among ``names``, zero columns for the others), dR/dx) at
    ``angle`` [m or rad]."""
    x = np.asarray(angle, float)
    w = 2.0 * math.pi / model.friction.ripple_period
    a = amplitudes(model)
    R, dx = np.zeros(x.size), np.zeros(x.size)
    cols = {}
    for k in range(1, RIPPLE_ORDER + 1):
        c, s = np.cos(k * w * x), np.sin(k * w * x)
        ak, bk = a[2 * k - 2], a[2 * k - 1]
        R += ak * c + bk * s
        dx += k * w * (bk * c - ak * s)
        cols[f"ripple_cos{k}"], cols[f"ripple_sin{k}"] = c, s
    J = np.zeros((x.size, len(names)))
    for j, n in enumerate(names):
        if n in cols:
            J[:, j] = cols[n]
    return R, J, dx


def harmonics(angle, period) -> np.ndarray:
    """The ripple's harmonics at ``angle``: every ripple at ``angle`` shifted by any phase is a product of these with
    the amplitudes rotated (:func:`shifted`).

    Parameters
    ----------
    angle : array_like
        The positions [m or rad].
    period : float
        The ripple's period, in the positions' unit.

    Returns
    -------
    numpy.ndarray
        n x 2 RIPPLE_ORDER: cos(k w x), sin(k w x) for k = 1..RIPPLE_ORDER (cos1, sin1, cos2, ...), w = 2 pi / period.
    """
    x = np.asarray(angle, float)
    w = 2.0 * math.pi / period
    H = np.empty((x.size, 2 * RIPPLE_ORDER))
    for k in range(1, RIPPLE_ORDER + 1):
        H[:, 2 * k - 2], H[:, 2 * k - 1] = np.cos(k * w * x), np.sin(k * w * x)
    return H


#: the harmonics of the angles a fit evaluates again and again ({id: (angle, period, harmonics)}: the angle kept,
#: so that its id is not reused while it is here); their sines and cosines were most of a force fit's ripple
_HARMONICS = {}
#: at most this many bytes of harmonics (and their angles) kept (a fit's run of 20,000 samples: 1.1 MB)
_HARMONICS_BYTES = 64 * 2 ** 20
_HARMONICS_LOCK = threading.Lock()


def _kept_bytes() -> int:
    """The bytes the kept harmonics and their angles hold."""
    return sum(np.asarray(a).nbytes + H.nbytes for a, _, H in _HARMONICS.values())


def _harmonics_of(angle, period) -> np.ndarray:
    """:func:`harmonics` of a trace's (unchanging) angle array, computed once per array and period."""
    with _HARMONICS_LOCK:
        hit = _HARMONICS.get(id(angle))
    if hit is not None and hit[0] is angle and hit[1] == period:
        return hit[2]
    H = harmonics(angle, period)
    if H.nbytes > _HARMONICS_BYTES // 4:  # (a record too long to keep: computed each time, as before)
        return H
    with _HARMONICS_LOCK:
        _HARMONICS.pop(id(angle), None)
        while _HARMONICS and _kept_bytes() + H.nbytes + np.asarray(angle).nbytes > _HARMONICS_BYTES:
            _HARMONICS.pop(next(iter(_HARMONICS)))
        _HARMONICS[id(angle)] = (angle, period, H)
    return H


def _rotated(model, phi):
    """(alpha, beta, cos, sin): R(x + phi) = H alpha and dR/dx(x + phi) = H beta for the harmonics H at x (the
    angle-addition formulas: harmonic k's amplitudes rotated by k w phi), and that rotation's cos and sin per k;
    for an array of phases, a row of each per phase."""
    w = 2.0 * math.pi / model.friction.ripple_period
    a = amplitudes(model)
    k = np.arange(1, RIPPLE_ORDER + 1)
    kwphi = np.multiply.outer(np.asarray(phi, float), k * w)
    c, s = np.cos(kwphi), np.sin(kwphi)
    ak, bk = a[0::2], a[1::2]
    alpha, beta = np.empty(c.shape[:-1] + a.shape), np.empty(c.shape[:-1] + a.shape)
    alpha[..., 0::2], alpha[..., 1::2] = ak * c + bk * s, bk * c - ak * s
    beta[..., 0::2], beta[..., 1::2] = k * w * alpha[..., 1::2], -k * w * alpha[..., 0::2]
    return alpha, beta, c, s


def shifted(model, H, phi, names=()):
    """:func:`evaluate` at ``angle + phi`` from the harmonics ``H`` at ``angle``: products instead of sines and
    cosines of the whole run (equal to rounding; closer, at large angles, than the shifted angle's own rounding).

    Parameters
    ----------
    model : Model
        The model whose ripple (period and amplitudes) is evaluated.
    H : numpy.ndarray
        The harmonics at the unshifted angle (:func:`harmonics`, at the model's period).
    phi : float
        The angle offset [m or rad].
    names : sequence of str, optional
        The parameters whose columns are returned (the amplitudes' nonzero, the others' zero).

    Returns
    -------
    tuple of numpy.ndarray
        (R, dR/d names, dR/dx) at ``angle + phi``, as :func:`evaluate` returns them.
    """
    alpha, beta, c, s = _rotated(model, phi)
    J = np.zeros((H.shape[0], len(names)))
    for j, n in enumerate(names):
        if n in RIPPLE_AMPLITUDES:
            i = RIPPLE_AMPLITUDES.index(n)
            hc, hs = H[:, i - i % 2], H[:, i - i % 2 + 1]
            k = i // 2
            J[:, j] = hc * c[k] - hs * s[k] if i % 2 == 0 else hs * c[k] + hc * s[k]
    return H @ alpha, J, H @ beta


def _phase_cost(model, x, r0, centred: bool, H=None):
    """cost(phi) = |r0 + R(x + phi)|^2 (about its mean where ``centred``) from the harmonics at ``x`` computed once
    (``H``, :func:`harmonics`, or computed here): shifted by phi, each harmonic's amplitudes rotate by k w phi (the
    angle-addition formulas), so the cost is a quadratic form in the rotated amplitudes (their Gram matrix and
    projections of r0). Each point of the phase's grid was the ripple evaluated on the whole run again: two thirds
    of a fit with a ripple and a phase per run."""
    C = harmonics(x, model.friction.ripple_period) if H is None else H
    e0 = np.asarray(r0, float)
    if centred:
        C, e0 = C - C.mean(axis=0), e0 - e0.mean()
    G, h, c0 = C.T @ C, C.T @ e0, float(e0 @ e0)

    def cost(phi):  # (one phase, or an array of them at once: the grid)
        alpha = _rotated(model, phi)[0]
        return c0 + 2.0 * (alpha @ h) + np.einsum("...i,ij,...j->...", alpha, G, alpha)
    return cost


def best_phase(model, angle, r0, centred: bool, H=None) -> float:
    """The angle offset ``phi`` in [0, P) that leaves the least ``r0 + R(angle + phi)`` (about its mean where
    ``centred``: an offset profiled out too); 0 where the model has no amplitude. ``H``: the harmonics at ``angle``
    (:func:`harmonics`) where the caller has them."""
    if not np.any(amplitudes(model)):
        return 0.0
    P = model.friction.ripple_period
    H = harmonics(angle, P) if H is None else H
    grid = P * np.arange(PHASE_GRID) / PHASE_GRID
    cost = _phase_cost(model, angle, r0, centred, H)
    phi = float(grid[int(np.argmin(cost(grid)))])
    for _ in range(PHASE_STEPS):  # Gauss-Newton on the angle offset
        R, _, g = shifted(model, H, phi)
        e = r0 + R
        if centred:
            e, g = e - e.mean(), g - g.mean()
        gg = float(g @ g)
        if not gg > 0:
            break
        step = -float(g @ e) / gg
        if cost(phi + step) > cost(phi):
            break
        phi += step
    return phi % P


def added(measurement, problem, model, r0, J):
    """(residuals, Jacobian, phase columns): ``r0`` (the model's force without its ripple minus the record, over all
    traces) with the ripple added at each trace's recorded angle, its amplitudes' columns added to ``J`` (in the
    fitted names); per run (``measurement.ripple_phase``), each trace after the first at its own best angle offset,
    whose column dR/dx is returned for :func:`projected` (None for a trace without one)."""
    per_run = measurement.ripple_phase == "per-run"
    centred = measurement.offset != "none"
    r = np.array(r0, float)
    J = None if J is None else np.array(J, float)
    names = problem.names if J is not None else ()
    g_list, start = [], 0
    for i, tr in enumerate(problem.traces):
        sl = slice(start, start + tr.n_residuals)
        phased = per_run and i > 0  # the first trace is the reference: the amplitudes are in its angle
        H = _harmonics_of(tr.angle, model.friction.ripple_period)  # (the same angles at every evaluation)
        phi = best_phase(model, tr.angle, r[sl], centred, H) if phased else 0.0
        R, Jr, dx = shifted(model, H, phi, names)
        r[sl] += R
        if J is not None:
            J[sl] += Jr
        g_list.append(dx if phased else None)
        start = sl.stop
    measurement.phases_fitted = sum(g is not None for g in g_list)
    return r, J, g_list


def projected(J, g_list, traces, offset: str):
    """``J`` with each run's rows projected off its phase column (variable projection, Kaufman's form: the phase
    profiled out as an offset is); the column taken about its mean where an offset is profiled out too."""
    if J is None:
        return None
    start = 0
    for tr, g in zip(traces, g_list):
        n = tr.n_residuals
        if g is not None:
            gc = g - g.mean() if offset != "none" else g
            gg = float(gc @ gc)
            if gg > 0:
                J[start:start + n] -= np.outer(gc, gc @ J[start:start + n]) / gg
        start += n
    return J


def started(measurement, model, experiments, names) -> object:
    """``model`` with the fitted ripple amplitudes (among ``names``) solved from the data where the start gives them
    all as zero: the ripple is linear in its amplitudes, so the least-squares amplitudes of the record minus the
    start's force without its ripple (with each run's offset, or one shared, alongside as the policy fits them) are
    one linear solve. A fit starting the amplitudes at zero moved the nonlinear parameters first and ended in
    another minimum on a measured joint (a 3 N m ripple found at 0.2 N m: held-out RMSE 2.1 against 0.7 once the
    amplitudes start where the data put them). Per-run phases: solved on the first run (the reference angle)."""
    fitted = [n for n in names if n in RIPPLE_AMPLITUDES]
    if not fitted or not additive(model) or any(getattr(model.friction, n, None) for n in fitted):
        return model
    runs = list(experiments)[:1] if measurement.ripple_phase == "per-run" else list(experiments)
    base = without(model)
    n_offsets = {"per-experiment": len(runs), "shared": 1}.get(measurement.offset, 0)
    blocks, rows = [], []
    for k, exp in enumerate(runs):
        x = np.asarray(exp.displacement, float)
        offsets = np.zeros((x.size, n_offsets))
        if n_offsets:
            offsets[:, k if measurement.offset == "per-experiment" else 0] = 1.0
        blocks.append(np.hstack([evaluate(model, x, fitted)[1], offsets]))
        rows.append(np.asarray(exp.force, float) - measurement.friction_of(base, exp, fast=True))
    A = np.vstack(blocks)
    solved = np.linalg.lstsq(A, np.concatenate(rows), rcond=None)[0][:len(fitted)]
    if not np.all(np.isfinite(solved)):
        return model
    return model.with_friction(**{n: float(a) for n, a in zip(fitted, solved)})


def for_run(measurement, model, exp, base, measured=None) -> np.ndarray:
    """The ripple of one run at its recorded angle; per run (``measurement.ripple_phase``) at the angle offset that
    fits ``measured`` best (``base``: the force without the ripple), at the reference angle without a record."""
    x = np.asarray(exp.displacement, float)
    phi = 0.0
    if measurement.ripple_phase == "per-run" and measured is not None:
        measurement.phases_estimated = True
        phi = best_phase(model, x, base + model.plant.sensor_offset - np.asarray(measured, float),
                         measurement.offset == "per-experiment")
    return evaluate(model, x + phi)[0]


def check_per_run(measurement, model, names=(), method=None):
    """A phase per run needs the ripple as a plain additive term (:func:`additive`) in every model the fit or the
    validation runs: InputError (naming ripple_phase) for Model II, a Model I law on a ripple parameter, or a
    ripple amplitude that ``method`` "model-i" would give a law (``names``: the parameters fitted)."""
    if getattr(measurement, "ripple_phase", None) != "per-run" or not has_ripple(model, names):
        return
    laws = method == "model-i" and any(n in RIPPLE_AMPLITUDES for n in names)
    if method == "model-ii" or laws or not additive(model) and getattr(model.friction, "ripple_period", None):
        why = ("Model II scales the ripple with the rest of the force" if method == "model-ii" or (
            model.thermal is not None and not isinstance(model.thermal, ModelI)) else
            "a Model I law on a ripple amplitude makes it part of the model's run")
        raise InputError(f"ripple_phase \"per-run\" (a phase per run) needs the ripple as a plain term added to the "
                         f"force, and {why}: fit the amplitudes with method \"base\" (or hold them), or give "
                         f"ripple_phase \"recorded\" (--ripple-phase recorded)")


def phases_said(measurement) -> str:
    """What a validation's RMSE has had removed besides the offsets, where it estimated each run's ripple phase."""
    return "; each experiment's ripple phase estimated on it (ripple_phase \"per-run\"), held-out ones included" \
        if getattr(measurement, "phases_estimated", False) else ""


def decide(experiments) -> tuple:
    """("recorded" | "per-run", why): per-run where every one of two or more runs starts at position 0 (within
    ZERO_START of the largest run's range of positions), recorded otherwise."""
    exps = list(getattr(experiments, "experiments", experiments))
    starts = [float(np.asarray(e.displacement, float)[0]) for e in exps]
    span = max((float(np.ptp(np.asarray(e.displacement, float))) for e in exps), default=0.0)
    if len(exps) >= 2 and all(abs(s) <= ZERO_START * span for s in starts):
        return "per-run", (f"every run's recorded position starts at 0 ({len(exps)} runs): positions relative to each "
                           f"run, so each run's ripple phase is estimated (ripple_phase = \"per-run\"; "
                           f"\"recorded\" forces the recorded angle)")
    return "recorded", ("the runs' recorded positions start at different angles: the ripple is taken at the recorded "
                        "angle (ripple_phase = \"recorded\"; \"per-run\" estimates a phase per run)")


__all__ = ["started", "RIPPLE_PHASES", "ZERO_START", "added", "additive", "amplitudes", "best_phase",
           "check_phase_option", "check_per_run", "decide", "phases_said", "evaluate", "for_run", "harmonics",
           "has_ripple", "projected", "shifted", "without"]
