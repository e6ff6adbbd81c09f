"""What every report page shares: the models compared (Entry), their AICc comparison and parameter tables."""

from __future__ import annotations

import dataclasses
import html
import math
import re

import numpy as np

from ..models import PARAMETER_UNITS, Model, ModelI, ModelII
from ..validation import ValidationResult
from .page import fmt_number, html_table
from ..fitting.shown import cells
from ..figures.fit_plots import as_float, law_outside_intervals, per_temperature_estimates

@dataclasses.dataclass
class Entry:
    """One model in the report, with its identification results when known (FitResult.to_dict()).

    Parameters
    ----------
    label : str
        The model's name in the report ("Model I", "no thermal model", ...).
    model : Model
        The model.
    fit : dict, optional
        Its identification results (``FitResult.to_dict()``).
    validation : ValidationResult, optional
        Its validation on the report's data; computed by the report where None.
    """

    label: str
    model: Model
    fit: dict | None = None
    validation: ValidationResult | None = None


def entry_label(model: Model, fit: dict | None = None) -> str:
    if fit and fit.get("method"):
        m = fit["method"]
        return {"model-i": "Model I", "base": "no thermal model"}.get(m, m.replace("model-ii", "Model II"))
    if isinstance(model.thermal, ModelI):
        return "Model I"
    if isinstance(model.thermal, ModelII):
        return "Model II"
    return "no thermal model"



def akaike(entries):
    """(difference, weight) of each entry's fit or None, and the number of groups: :func:`akaike_scaled` without
    the divisor c."""
    scaled, groups = akaike_scaled(entries)
    return [None if a is None else a[:2] for a in scaled], groups


def akaike_scaled(entries):
    """AICc difference to the best and Akaike weight of each entry's fit, or None: only between fits
    of the same data (the same experiments and points), where AICc is comparable; the weights sum to
    one over such a group. Correlated residuals carry less information than their count: the differences
    are divided by c, the integrated autocorrelation time of the most general fit's residuals (its variance
    inflation; as QAIC divides by overdispersion), so that a comparison on smooth, correlated residuals is not
    absurdly sure. Returns ([(difference, weight, c) or None per entry], the number of groups)."""
    groups = {}
    for i, e in enumerate(entries):
        f = e.fit or {}
        a = f.get("aicc")
        if a is None or not math.isfinite(float(a)):
            continue
        key = (f.get("n_points"), tuple(sorted(str(x.get("file")) for x in f.get("experiments") or [])))
        groups.setdefault(key, []).append((i, float(a)))
    out = [None] * len(entries)
    for members in groups.values():
        c = inflation_of_most_general([entries[i].fit for i, _ in members])
        best = min(a for _, a in members)
        w = {i: math.exp(-0.5 * (a - best) / c) for i, a in members}
        total = sum(w.values())
        for i, a in members:
            out[i] = ((a - best) / c, w[i] / total, c)
    return out, len(groups)


def inflation_of_most_general(fits) -> float:
    """The variance inflation (residuals' integrated autocorrelation time, at least 1) of the fit with the most
    fitted parameters among ``fits`` (dicts), the lowest AICc among those."""
    def size(f):
        return sum(1 for p in (f.get("parameters") or {}).values() if p.get("vary"))
    general = max(fits, key=lambda f: (size(f), -float(f.get("aicc", math.inf))))
    return max(float((general.get("statistics") or {}).get("variance_inflation", 1.0) or 1.0), 1.0)


def _aicc_cells(a):
    """(ΔAICc, Akaike weight) as text: a difference with its sign and thousands, a weight too small to
    print as "< 0.001" rather than a misleading 0.000."""
    if not a:
        return "—", "—"
    d, w, c = a
    scaled = f" (÷ c = {c:.3g})" if c > 1.5 else ""
    return (f"{d:+,.1f}{scaled}" if d else f"0 (best){scaled}"), ("< 0.001" if w < 1e-3 else f"{w:.3f}")


COMPARISON_COLUMNS = ["model", "friction", "max error, held out [%]", "mean max error, held out [%]",
                      "RMSE, held out [nm]", "max error, fit [%]", "ΔAICc", "Akaike weight", "identification time"]
EXPERIMENT_COLUMNS = ["model", "file", "T [°C]", "role", "max error [%]", "RMSE [nm]", "NRMSE", "final error [%]",
                      "step error [%]"]


def comparison_rows(entries):
    rows = []
    aic, _ = akaike_scaled(entries)
    for e, a in zip(entries, aic):
        s = e.validation.summary()
        v = s.get("validate", s.get("fit", {}))
        f = e.fit or {}
        rows.append([e.label, e.model.friction.model, fmt_number(v.get("max_error_pct")), fmt_number(v.get("mean_max_error_pct")),
                     fmt_number(v.get("rmse_offset_removed", math.nan) * 1e9, "{:.4g}"), fmt_number(s.get("fit", {}).get("max_error_pct")),
                     *_aicc_cells(a), fmt_number(f.get("wall_time"), "{:.2f} s")])
    return rows


def _unit(u: str) -> str:
    """Temperatures in °C in units shown to a reader: "1/C" -> "1/°C", "N/C^2" -> "N/°C^2"."""
    return re.sub(r"/C(?![A-Za-z_])", "/°C", u or "")


def _covariance(fit: dict, names):
    """The covariance of fitted parameters ``names`` from a fit's standard errors and correlation
    (zero for a parameter held fixed); None when they are not known."""
    params = fit.get("parameters") or {}
    corr = fit.get("correlation") or {}
    idx = {n: i for i, n in enumerate(corr.get("names") or [])}
    matrix = np.asarray(corr.get("matrix") if corr.get("matrix") is not None else np.zeros((0, 0)), dtype=object)
    se = []
    for n in names:
        p = params.get(n)
        if p is None:
            return None
        x = as_float(p.get("stderr"))  # None, "inf" (JSON), a number
        se.append(x if n in idx else 0.0)
    if not all(math.isfinite(x) for x in se):
        return None
    C = np.zeros((len(names), len(names)))
    for i, a in enumerate(names):
        for j, b in enumerate(names):
            if i == j:
                C[i, j] = se[i] ** 2
            elif a in idx and b in idx:
                r = float(matrix[idx[a]][idx[b]]) if matrix.size else math.nan
                C[i, j] = (r if math.isfinite(r) else 0.0) * se[i] * se[j]
    return C


def law_at(law, T, fit, name):
    """(value, standard error) of a parameter's law at T; the error by the delta method from the
    fit's covariance of the law's coefficients (None when unknown)."""
    value = float(law(T))
    names = [f"{name}.{c}" for c in law.coefficient_names()]
    C = _covariance(fit or {}, names) if names else None
    if C is None:
        return value, None
    c = np.array(law.coefficients(), float)
    grad = np.zeros(len(c))
    for i in range(len(c)):  # central differences: any law kind, evaluated by the core
        h = 1e-6 * max(abs(c[i]), 1e-12)
        up, dn = c.copy(), c.copy()
        up[i] += h
        dn[i] -= h
        grad[i] = (float(law.with_coefficients(up)(T)) - float(law.with_coefficients(dn)(T))) / (2 * h)
    return value, float(math.sqrt(max(grad @ C @ grad, 0.0)))


def reference_temperature(law, fallback):
    rng = getattr(law, "range", None)
    return float(round(0.5 * (rng[0] + rng[1]))) if rng else float(round(fallback))


def _equation(name, law, Tr, unit):
    T = f"{Tr:g} °C"
    if law.kind == "exp":
        return f"{name}(T) = {name}({T}) · exp(b · (T − {T})), b = {law.b:.4g} 1/°C"
    if law.kind == "linear":
        return f"{name}(T) = {name}({T}) + a · (T − {T}), a = {law.a:.4g} {_unit(unit + '/C')}"
    if law.kind == "const":
        return f"{name}(T) = {name} (no temperature dependence)"
    if law.kind == "poly":
        return f"{name}(T) = Σ c_i T^i (degree {len(law.c) - 1})"
    return f"{name}(T): {'linear' if law.kind == 'pwl' else 'monotone cubic'} between {len(law.T)} points"


def law_rows(entry, fallback_T):
    """Model I: each law's equation, its value at a reference temperature in the calibrated range
    (not the extrapolation to 0 °C that an exponential law's coefficient a is), its change per °C,
    its values at the range's ends, and whether it stays inside the per-temperature intervals."""
    rows, outside = [], law_outside_intervals(entry.fit or {}, entry.model)
    for name, law in entry.model.laws.items():
        unit = PARAMETER_UNITS.get(name, "")
        Tr = reference_temperature(law, fallback_T)
        value, se = law_at(law, Tr, entry.fit, name)
        per_deg = 100 * float(law.slope(Tr)) / value if value else math.nan
        rng = getattr(law, "range", None)
        ends = (f"{fmt_number(law(rng[0]), '{:.4g}')} at {rng[0]:g} °C, {fmt_number(law(rng[1]), '{:.4g}')} at {rng[1]:g} °C"
                if rng else "—")
        T = per_temperature_estimates(entry.fit or {}, name)[0]
        inside = ("—" if not T.size else f"yes, all {T.size}" if name not in outside else
                  f"no: outside at {', '.join(f'{t:g}' for t in outside[name])} °C")
        rows.append([name, _equation(name, law, Tr, unit), f"{Tr:g}", fmt_number(value, "{:.5g}"), fmt_number(se, "{:.3g}"), unit,
                     fmt_number(per_deg, "{:+.3g} %/°C"), ends, inside])
    return rows, outside


def breakpoint_rows(entry):
    """Model II: dF's breakpoints, each with its temperature, value, standard error and the friction
    factor there."""
    dF = entry.model.thermal.dF
    params = (entry.fit or {}).get("parameters") or {}
    varying = set(((entry.fit or {}).get("correlation") or {}).get("names") or [])
    rows = []
    if dF.kind not in ("pwl", "table"):
        return rows
    for i, (T, v) in enumerate(zip(dF.T, dF.values)):
        pname = f"dF.values[{i}]"
        p = params.get(pname) or {}
        fixed = bool(params) and pname not in varying
        lam = entry.model.thermal_factor(float(T)) if entry.model.thermal.form == "scale" else math.nan
        rows.append([f"{T:.2f}", fmt_number(v, "{:.5g}"), "fixed" if fixed else fmt_number(p.get("stderr"), "{:.3g}"),
                     fmt_number(lam, "{:.4f}"), "reference temperature (dF = 0 by definition)" if fixed and v == 0 else ""])
    return rows


def _parameter_table(entry, keep):
    rows = []
    for name, p in ((entry.fit or {}).get("parameters") or {}).items():
        if not keep(name):
            continue
        rows.append([name, *cells(p), _unit(p.get("unit", ""))])  # (the one display: fitting/shown.py)
    return rows


def parameter_section(entries, fit_T) -> str:
    """Per model: its fitted parameters; Model I's laws with their equations and values at a
    reference temperature; Model II's breakpoints; the raw coefficients as in the model file."""
    out = []
    for e in entries:
        parts = []
        plain = _parameter_table(e, lambda n: "." not in n and not n.startswith("dF"))
        if plain:
            parts.append(html_table(["parameter", "value", "std. error", "95 % interval", "unit"], plain, text=(4,)))
        if e.model.laws:
            rows, outside = law_rows(e, fit_T)
            parts.append("<p class='note'>Temperature laws (Model I). Each is given at a reference temperature "
                         "in the middle of the range it was calibrated on; the standard error there follows from "
                         "the coefficients' covariance. An exponential law's coefficient <code>a</code> in the "
                         "model file is its value extrapolated to 0 °C, far outside the data.</p>" + html_table(
                ["parameter", "law", "T_ref [°C]", "value at T_ref", "std. error", "unit", "change per °C",
                 "at the range's ends", "inside the per-temperature 95 % intervals"], rows, text=(5,), wrap=(1, 7, 8)))
            if outside:
                parts.append("<p class='note'>" + "; ".join(
                    f"The refined law of <b>{html.escape(n)}</b> lies outside the per-temperature 95 % interval at "
                    f"{', '.join(f'{t:g}' for t in T)} °C" for n, T in outside.items()) +
                    ". The refined law is fitted to all trajectories at once, while each per-temperature "
                    "estimate comes from one temperature's data and trades this parameter against the others "
                    "(their correlation): a law that misses intervals is the best compromise over all "
                    "temperatures, or a sign that its shape does not follow the data there. The held-out errors "
                    "say which.</p>")
        if isinstance(e.model.thermal, ModelII):
            rows = breakpoint_rows(e)
            if rows:
                parts.append("<p class='note'>Thermal-induced friction dF(T) (Model II), linear between its "
                             "breakpoints; the friction force is scaled by λ = 1 + dF/fc"
                             f" (fc = {fmt_number(e.model.friction.values().get('fc'), '{:.4g}')} N).</p>" +
                             html_table(["breakpoint T [°C]", "dF [N]", "std. error [N]", "λ", "note"], rows, wrap=(4,)))
        coef = _parameter_table(e, lambda n: "." in n or n.startswith("dF"))
        if coef:
            parts.append("<details><summary>the fitted coefficients as stored in the model file</summary>" +
                         html_table(["coefficient", "value", "std. error", "95 % interval", "unit"], coef, text=(4,)) +
                         "</details>")
        if parts:
            out.append(f"<h3>{html.escape(e.label)}</h3>" + "".join(parts))
    return ("<section><h2>Identified parameters</h2>" + "".join(out) + "</section>") if out else ""


__all__ = ["Entry", "entry_label", "akaike", "akaike_scaled", "inflation_of_most_general", "comparison_rows", "law_at", "reference_temperature", "law_rows",
           "breakpoint_rows", "parameter_section"]
