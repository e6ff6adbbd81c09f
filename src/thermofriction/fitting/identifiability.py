"""Identifiability (beside the uncertainty layer): the groups of parameters the data determine only together, from
the singular value decomposition of the column-scaled Jacobian at the optimum that the uncertainty layer makes (not
computed twice), with the combination the data do determine and, where the model's structure says it, what data
would separate them (docs/identification.md#identifiability).

The rule is Belsley, Kuh and Welsch's (Regression Diagnostics, 1980, ch. 3): a direction of the column-scaled
Jacobian whose condition index (the largest singular value over its own) is above 30 is a strong dependency, and the
parameters that owe more than half of their variance to it (their variance-decomposition proportions) form its
group. Of those groups only the ones the data leave undetermined are said: a member's standard error above half its
value (the "poorly determined" threshold of uncertainty.py), or infinite. A nuisance parameter (the sensor offset,
profiled out of the fit) is a member like the others but is not itself held to that test: its value may be zero."""

from __future__ import annotations

import math

import numpy as np

#: the condition index above which a direction is a strong dependency (Belsley, Kuh & Welsch 1980)
CONDITION_INDEX = 30.0
#: the share of a parameter's variance owed to a direction that makes it a member of that direction's group
PROPORTION = 0.5
#: a member's standard error, relative to its value, above which the group is undetermined (uncertainty.py's
#: "poorly determined")
UNDETERMINED_SHARE = 0.5
#: the name of the force sensor's offset where it is a member (its JSON key, docs/formats.md#results-json)
OFFSET = "sensor_offset"
_BRISTLES = {"sigma0", "sigma1", "C"}
_STRIBECK = {"fs", "vs", "fs_neg", "vs_neg", "fs_excess"}
_LEVELS = {"fc", "fs", "fs_excess"}
_MASSES = {"m", "m_e", "J"}
_STIFFNESSES = {"k", "k_s", "wn"}


def scaled_svd(J, undetermined):
    """The SVD of ``J`` with its columns scaled to unit length, and the covariance factor it gives:
    (S, Vt, col, bad, cov1) where ``col`` are the column norms (a zero column's taken as 1), ``bad`` the directions
    with a singular value at most ``undetermined`` times the largest (dropped: the data do not determine them),
    and ``cov1`` (J^T J)^-1 by the pseudo-inverse, with an infinite variance on every parameter that loads on a
    dropped direction (instead of a falsely tight one): the covariance is ``cov1`` times the residual variance."""
    col = np.linalg.norm(J, axis=0)
    col[col == 0] = 1.0
    _, S, Vt = np.linalg.svd(J / col, full_matrices=False)
    bad = S <= S[0] * undetermined if S.size and S[0] > 0 else np.ones_like(S, bool)
    inv = np.where(bad, 0.0, 1.0 / np.where(bad, 1.0, S) ** 2)
    cov1 = (Vt.T * inv) @ Vt / np.outer(col, col)
    loading = (Vt[bad] ** 2).sum(axis=0) if bad.any() else np.zeros(J.shape[1])
    idx = np.flatnonzero(loading > 1e-6)
    cov1[idx, idx] = math.inf
    return S, Vt, col, bad, cov1


def dependencies(S, Vt) -> list:
    """(direction index, condition index, member indices) of each strong dependency of a column-scaled Jacobian
    with singular values ``S`` (descending) and right singular vectors ``Vt``: condition index above
    CONDITION_INDEX and at least two columns owing more than PROPORTION of their variance to it."""
    S = np.asarray(S, float)
    if S.size < 2 or not S[0] > 0:
        return []
    floor = S[0] * 1e-150  # an exactly singular direction: its proportions are 1 (every variance is its)
    phi = Vt.T ** 2 / np.maximum(S, floor) ** 2          # phi[i, k]: parameter i's variance along direction k
    prop = phi / phi.sum(axis=1, keepdims=True)
    out = []
    for k in range(S.size):
        index = S[0] / max(S[k], floor)
        members = [i for i in range(prop.shape[0]) if prop[i, k] > PROPORTION]
        if index > CONDITION_INDEX and len(members) >= 2:
            out.append((k, float(index), members))
    return out


def groups(S, Vt, col, names, values, stderr, noise_scale, nuisance=(), bad=None) -> list:
    """The undetermined groups (docs/formats.md#results-json ``identifiability``): for each strong dependency
    (:func:`dependencies`) whose members the data leave undetermined, its members, the condition index, the
    direction that leaves the fit unchanged (in the members' own units), for two members the combination the data
    do determine with its standard error, and the advice its members' roles justify. ``col``: the Jacobian's
    column norms (its scaling), ``noise_scale``: the residual variance times its inflation (the covariance's
    factor), ``bad``: the directions the covariance drops as undetermined."""
    out = []
    bad = np.zeros(len(S), bool) if bad is None else np.asarray(bad, bool)
    for k, index, members in dependencies(S, Vt):
        loose = [i for i in members if names[i] not in nuisance and
                 (not math.isfinite(stderr[i]) or stderr[i] > UNDETERMINED_SHARE * abs(values[i]))]
        if not loose:
            continue
        who = [names[i] for i in members]
        step = np.array([Vt[k, i] / col[i] for i in members])
        step = step / step[np.argmax(np.abs(step))]
        step = step if step[0] >= 0 else -step
        group = {"parameters": who, "condition_index": index,
                 "undetermined": {n: float(s) for n, s in zip(who, step)}}
        if len(members) == 2:
            group["determined"] = _combination(S, Vt, col, members, who, values, noise_scale, k, bad)
        advice = advice_for(who)
        if advice:
            group["separate"] = advice
        group["warning"] = _sentence(group)
        out.append(group)
    return out


def _combination(S, Vt, col, members, who, values, noise_scale, k, bad) -> dict:
    """The combination of two members the data determine: orthogonal, in the scaled coordinates, to the direction
    they do not, written in their own units with the first member's coefficient 1, its value and standard error."""
    a, b = members
    d = np.zeros(Vt.shape[1])
    d[a], d[b] = Vt[k, b], -Vt[k, a]                   # orthogonal to the weak direction within the pair
    coef = d * col                                     # c = sum d_i z_i, z_i = col_i theta_i
    coef = coef / coef[a]
    a_scaled = coef / col                              # c = a_scaled . z
    keep = ~np.asarray(bad, bool)
    proj = Vt[keep] @ a_scaled
    var = noise_scale * float(np.sum(proj ** 2 / S[keep] ** 2))
    value = float(coef[a] * values[a] + coef[b] * values[b])
    w = float(coef[b])
    text = f"{who[0]} {'+' if w >= 0 else '-'} {'' if abs(abs(w) - 1) < 1e-3 else f'{abs(w):.3g} '}{who[1]}"
    return {"combination": text, "coefficients": {who[0]: 1.0, who[1]: w}, "value": value,
            "stderr": math.sqrt(var)}


def advice_for(members) -> str:
    """What data separate a group, where the model's structure says it; "" where it does not."""
    m = set(members)
    negative = {n for n in m if n.endswith("_neg")}
    said = []
    if OFFSET in m and negative:
        said.append("an asymmetry between the directions and a sensor offset shift both directions' levels "
                    "alike, and more runs in either direction do not separate them: --offset none if the sensor's "
                    "zero is known (a record of the sensor unloaded)")
    elif OFFSET in m and m & _LEVELS:
        said.append("runs in both directions (the Coulomb level changes sign with the velocity, the sensor offset "
                    "does not), or --offset none if the sensor's zero is known")
    if m & _BRISTLES:
        said.append("a longer stop or slower reversals (the bristles' stiffness and damping act only while the "
                    "velocity is near zero; in steady sliding the force does not depend on them)")
    if m & _STRIBECK and not m & _BRISTLES:
        said.append("steady sliding at speeds below and around vs (the Stribeck curve's shape shows only there)")
    if m & _MASSES and m & _STIFFNESSES:
        said.append("motion at more than one frequency (at one frequency w the data see only k - m w^2)")
    return "; ".join(said)


def _sentence(group) -> str:
    """The group as its warning says it."""
    who = group["parameters"]
    names = ", ".join(f"'{n}'" for n in who[:-1]) + f" and '{who[-1]}'"
    step = ", ".join(f"{n} {s:+.3g}" for n, s in group["undetermined"].items())
    text = (f"{names} are not determined separately by these data (condition index "
            f"{group['condition_index']:.3g}): moving them together as {step} (in their units) leaves the fit "
            f"unchanged")
    d = group.get("determined")
    if d:
        text += f"; {d['combination']} is determined ({d['value']:.4g} +- {d['stderr']:.2g}), not each"
    if group.get("separate"):
        text += f". What would separate them: {group['separate']}"
    return text


def no_information(names, col) -> dict:
    """Why a parameter whose Jacobian column is zero (the data carry nothing on it) is so, where the model says:
    a negative side's parameter acts only in negative sliding. {name: reason}."""
    return {n: "it acts only in negative sliding, and these data never slide in the negative direction: runs in "
               "both directions would determine it" for n, c in zip(names, col) if c == 0 and n.endswith("_neg")}


def with_groups(result, found):
    """``result`` (a FitResult) with ``found`` (the groups seen with the offsets' columns: a superset of those the
    fit saw with the offsets profiled out) in place of its own, in its warnings too; one group once (a
    per-experiment offset's, found on each run, is the same group)."""
    import dataclasses
    unique, seen = [], set()
    for g in found:
        if tuple(g["parameters"]) not in seen:
            seen.add(tuple(g["parameters"]))
            unique.append(g)
    old = {g["warning"] for g in result.identifiability}
    kept = [w for w in result.warnings if w not in old]
    at = next((i for i, w in enumerate(result.warnings) if w in old), len(kept))
    return dataclasses.replace(result, identifiability=unique,
                               warnings=kept[:at] + [g["warning"] for g in unique] + kept[at:])


__all__ = ["with_groups", "scaled_svd", "dependencies", "groups", "advice_for", "no_information", "CONDITION_INDEX", "PROPORTION", "OFFSET"]
