"""Held-out records of a warm-up fit (docs/self-heating.md#warm-up-without-a-contact-temperature): the dataset's
``validate`` records predicted by the fitted laws and heat path, not fitted.

A held-out warm-up record starts where the record it ``continues`` ended (a fitted one or an earlier held-out
one), else soaked at its first proxy reading (its ambient's first where it has no proxy): the heat path's own start
is not fitted to a held-out record. A held-out soak run is predicted at its temperature. Each record's sensor offset
is removed (its mean error), as the fit removes it. A record is adequate where its RMSE is within the adequacy
threshold of the fitted records' pooled RMSE (the residual level the model reaches on data it saw). A contact
temperature that leaves the fit's temperature grid is said (the forces there are the laws' extrapolation).
"""

from __future__ import annotations

import numpy as np

from ..drive import drive
from ..fitting.quality import fit_quality
from .warm_up_path import first_bin_width, forces_at, track, warm_record


def _start(rec, path, ends):
    """A held-out record's start state: where the record it continues ended, else soaked at its proxy's first
    reading (its ambient's first without a proxy)."""
    if rec.continues is not None and rec.continues in ends:
        return ends[rec.continues], f"continues {rec.continues}"
    T0 = float(rec.proxy[0] if rec.proxy is not None else rec.ambient[0])
    how = "proxy's" if rec.proxy is not None else "ambient's"
    return np.full(path.states, T0), f"soaked at its {how} first reading, {T0:.4g} C"


def score_held_out(problem, theta, held, unit: str, level: float) -> tuple:
    """The held-out records' rows (role "validate") and the warnings they call for.

    Parameters
    ----------
    problem : WarmProblem
        The chosen fit's problem (identification/warm_up_fit.py).
    theta : numpy.ndarray
        Its fitted parameters.
    held : list of ForceExperiment
        The dataset's validate experiments: warm-up records and soak runs, in the dataset's order (a record that
        continues another comes after it).
    unit : str
        The force's unit ("N" or "N m").
    level : float
        The fitted records' pooled residual RMSE: a held-out record is adequate where its RMSE is within the
        adequacy threshold of it (its own noise estimate is unreliable on correlated noise; the fit's residuals
        are what the model reaches on data it saw).

    Returns
    -------
    (list of dict, list of str)
        One row per record (``file``, ``role`` "validate", ``warm_up``, ``rmse_offset_removed``, ``fit_quality``,
        ``start``, and for a warm-up record the contact temperature's range ``contact_range``), and the warnings:
        a held-out record not adequate, a contact temperature outside the fit's grid, a record whose ``continues``
        names no record before it.
    """
    model, path = problem.model_of(theta), problem.path_of(theta)
    tracks, _ = problem.run(theta)
    ends = {label: tr.end for label, tr in tracks.items()}
    lo, hi = float(problem.grid[0]), float(problem.grid[-1])
    rows, warnings = [], []
    for exp in held:
        if getattr(exp, "warm_up", False):
            rec = warm_record(exp, model, first_bin_width(exp.duration))
            if rec.continues is not None and rec.continues not in ends:
                warnings.append(f"held-out {rec.label}: continues {rec.continues!r}, which is neither a fitted nor "
                                "an earlier held-out record; predicted from a soaked start instead")
            x0, start = _start(rec, path, ends)
            tr = track(path, rec, forces_at(model, rec.waveform, rec.time, problem.grid), problem.grid,
                       problem.basis, x0)
            ends[rec.label] = tr.end
            prediction, extra = tr.force, {"contact_range": [float(tr.contact.min()), float(tr.contact.max())]}
            if tr.contact.min() < lo or tr.contact.max() > hi:
                warnings.append(f"held-out {rec.label}: its contact temperature ({tr.contact.min():.4g}.."
                                f"{tr.contact.max():.4g} C) leaves the fit's grid ({lo:.4g}..{hi:.4g} C): the "
                                "forces there are the laws' extrapolation")
            label, measured = rec.label, rec.force
        else:
            waveform = drive(exp, model, start="record").waveform
            prediction = forces_at(model, waveform, np.asarray(exp.time, float), [float(exp.temperature)])[0]
            label, measured, start, extra = exp.label, np.asarray(exp.force, float), "soak run", {}
        e = prediction - measured
        q = fit_quality(e - e.mean(), measured, noise=level)
        rows.append({"file": label, "temperature": None if extra else float(exp.temperature), "role": "validate",
                     "warm_up": bool(extra), "rmse_offset_removed": q["rmse"], "fit_quality": q, "unit": unit,
                     "start": start, **extra})
        if q["adequate"] is False:
            warnings.append(f"held-out {label}: predicted with {q['ratio']:.3g}x the fit's residual RMSE (RMSE "
                            f"{q['rmse']:.4g} {unit} against {level:.4g}; {start}), above the threshold "
                            f"{q['threshold']:.3g}: the fitted laws and heat path do not carry to it")
    return rows, warnings


__all__ = ["score_held_out"]
