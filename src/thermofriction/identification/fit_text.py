"""A fit's report and its notebook table (FitResult holds the data; this module says it): the structured blocks
of :mod:`thermofriction.results`, which its one formatter writes as text and HTML, and the fit-quality verdict
in words."""

from __future__ import annotations

import math

import numpy as np

from ..measurements import amount
from ..results import fields, heading, lines, table
from .load_kinds import equation, form_of
from ..fitting.shown import shown  # the one display of an interval (at a bound, undetermined, > 1000 %)

#: the parameter table's columns
HEAD = ("name", "value", "stderr", "rel", "95 % interval", "unit")
#: the label width of a fit report's fields ("data points      = ...")
WIDTH = 16


def parameter_rows(fit) -> list:
    """One row of text cells per parameter (HEAD's columns)."""
    return [(p.name, *shown(p.to_dict()), p.unit) for p in fit.parameters.values()]


def verdict(q) -> str:
    """The fit quality's verdict (``FitResult.fit_quality``) in words."""
    if q["adequate"] is False and q.get("verdict_basis") == "ripple":
        return (f"NOT adequate (a position ripple in the residuals: a refit with it removes "
                f"{100 * q['ripple']['gain']:.2g} % of the misfit)")
    if q["adequate"] is False and q.get("verdict_basis") == "held values":
        return f"NOT adequate (held values contradicted; the noise cannot be estimated: {q.get('why')})"
    if q.get("verdict_basis") == "baseline":  # the noise unknown: the model against a model-free map (baseline.py)
        b = q["baseline"]
        return (f"{'adequate' if q['adequate'] else 'NOT adequate'} relative to a model-free map of the same runs "
                f"(held-out RMSE {b['ratio']:.3g} x the map's, at most {b['factor']:g}; the noise cannot be estimated: "
                f"{q.get('why')})")
    if q["adequate"] is None:
        return f"adequacy unknown ({q.get('why') or 'the noise cannot be estimated from the data'})"
    return "adequate" if q["adequate"] else "NOT adequate"


def _not_adequate(fit) -> list:
    """The one verdict (fit_quality), first and in plain words, as the warnings say it."""
    if fit.adequate is not False:
        return []
    held = [h for h in (fit.fit_quality or {}).get("held") or [] if h["contradicted"]]
    basis, b = fit.fit_quality.get("verdict_basis"), fit.fit_quality.get("baseline") or {}
    return ["NOT ADEQUATE: " + (
        f"{len(held)} held value(s) contradicted by the data (the noise cannot be estimated from these data: "
        f"the residuals are not compared with it)" if basis == "held values" else
        f"held-out RMSE {b.get('ratio', math.nan):.3g} x a model-free map's on the same runs (the noise cannot "
        f"be estimated from these data)" if basis == "baseline" else
        f"the residuals hold a position ripple ({100 * fit.fit_quality['ripple']['gain']:.2g} % of the misfit)"
        if basis == "ripple" else
        f"residuals {fit.fit_quality['ratio']:.3g} x the measurement noise"
        + (f", {len(held)} held value(s) contradicted by the data" if held else "")) + " (see the first warnings)"]


def _offset_rows(fit) -> list:
    o, unit = fit.sensor_offset, fit.unit
    if o.get("per_experiment"):
        return [("sensor offset", f"{r['value']:.6g} +- {r['stderr']:.3g} {unit} ({r['file']}, its own)")
                for r in o["per_experiment"]]
    if not o:
        return []
    how = "fitted, shared by all experiments" if o.get("fitted") else "held (--offset none)"
    err = f" +- {o['stderr']:.3g}" if o.get("fitted") and o.get("stderr") is not None else ""
    if err and not math.isfinite(o["stderr"]):
        err, how = "", how + "; not determined: see the warnings"
    return [("sensor offset", f"{o['value']:.6g}{err} {unit} ({how})")]


def _plant_rows(plant) -> list:
    """A drive's inertia and delay (command data: the measurement's completion), as the report says them."""
    if not plant:
        return []
    J, d = plant["inertia"], plant["delay"]
    est = f"estimate {d['estimate'] * 1e3:.4g} +- {d['stderr'] * 1e3:.2g} ms"
    return [("inertia J", f"{J['value']:.6g} +- {J['stderr']:.3g} {J['unit']} (95 %: [{J['ci95'][0]:.5g}, "
                          f"{J['ci95'][1]:.5g}])"),
            ("delay", f"{d['value'] * 1e3:.4g} ms ({est}; {d['note']})")]


def _paper_lines(fit) -> list:
    """What the paper's procedure of Model II did, step by step, with its numbers."""
    p = fit.details["paper"]
    lin = p.get("linear_fit", {})
    Ts = ", ".join(f"{t:.4g}" for t in np.atleast_1d(p.get("temperatures", [])))
    law = p.get("dF_law", {})
    knots = ", ".join(f"{v:+.4g} N at {t:.4g} C" for t, v in zip(law.get("T", []), law.get("values", [])))
    return [f"1. base model fitted at the reference temperature "
            f"{fit.details.get('reference_temperature', math.nan):.4g} C",
            f"2. final displacement against temperature ({Ts} C): two straight segments, breakpoint "
            f"{p.get('breakpoint', math.nan):.4g} C, R^2 = {p.get('segmented_r2', math.nan):.3f}",
            f"3. final displacement against a constant dF, simulated: linear, slope "
            f"{lin.get('slope', math.nan) * 1e6:.4g} um/N, R^2 = {lin.get('r2', math.nan):.3f}",
            f"4. dF(T) read through that line: {knots}",
            "no trajectory fit: no RMSE and no intervals here; `validate` gives this model's errors"]


def _correlated(fit, above: float = 0.5) -> list:
    names = [p.name for p in fit.parameters.varying]
    if np.shape(fit.correlation) != (len(names), len(names)):  # no joint fit, no correlations
        return []
    c = fit.correlation
    pairs = [(names[i], names[j], c[i, j]) for i in range(len(names)) for j in range(i + 1, len(names))
             if np.isfinite(c[i, j]) and abs(c[i, j]) > above]
    return [f"C({a}, {b}) = {r:+.3f}" for a, b, r in sorted(pairs, key=lambda x: -abs(x[2]))]


def _node_choice(hp) -> str:
    """The heat path's node count and why (``details["heat_path"]["choice"]``)."""
    c, n = hp["choice"], hp["nodes"]
    if "delta" not in c:
        return f"{n} node ({c.get('two_nodes', 'two nodes not evaluated')})"
    delta, limit = c["delta"], c["threshold"]
    if c["asked"] != "auto":
        return (f"{n} node{'s' * (n > 1)} (held: nodes={c['asked']}; a second node lowers AICc by {delta:.4g}, the "
                f"rule keeps it above {limit:g}: {'two' if delta > limit else 'one'} by the data)")
    return (f"{n} node{'s' * (n > 1)} (a second node, the housing, lowers AICc by {delta:.4g}: "
            f"{'more' if n == 2 else 'not more'} than {limit:g}; on {c['effective_samples']:.4g} effective samples)")


def _band_text(tr) -> str:
    """A record's contact temperature: its start, end and range, and its 95 % band's width."""
    c = np.asarray(tr["contact"], float)
    width = np.asarray(tr["upper"], float) - np.asarray(tr["lower"], float)
    return (f"{c[0]:.4g} -> {c[-1]:.4g} C (range {c.min():.4g} to {c.max():.4g} C), 95 % band {np.median(width):.2g} K "
            f"wide (median; at most {width.max():.2g} K)")


def heat_path_lines(fit) -> list:
    """A warm-up fit's heat path in words: the node count and why, the time constants, the proxy, the scale and
    the contact temperature per record ("undetermined" where the scale is).

    Parameters
    ----------
    fit : FitResult
        A warm-up fit (method "warm-up": ``details["heat_path"]`` and ``details["temperature"]``).

    Returns
    -------
    list of str
        The report's "Heat path" lines.
    """
    hp = fit.details["heat_path"]
    taus = ", ".join(f"{t['value']:.4g} s +- {t['ci95_half_width']:.2g}" for t in hp["time_constants"])
    proxy = hp.get("proxy")
    out = [f"nodes: {_node_choice(hp)}", f"time constants (95 %): {taus}",
           "proxy: " + (f"follows the {proxy['node']} node, lag tau_p {proxy['tau_p']:.4g} s" if proxy else "none"),
           f"temperature scale: {hp['scale']}", f"eta: {hp['eta']}"]
    if hp["scale"] == "undetermined":
        return out + ["heat path's resistances and capacities: undetermined",
                      "contact temperature: undetermined (the time constants above are scale-free)"]
    traj = fit.details["temperature"]
    return out + [f"contact temperature, {label}: {_band_text(tr)}" for label, tr in traj.items()] + \
        _held_out_lines(fit)


def _held_out_lines(fit) -> list:
    """The held-out records (role "validate"), predicted, not fitted: each one's RMSE against the fit's."""
    out = []
    for r in (r for r in fit.experiments if r.get("role") == "validate"):
        q = r["fit_quality"]
        verdict_text = "adequate" if q["adequate"] else "NOT adequate"
        where = f"; predicted contact {r['contact_range'][0]:.4g} to {r['contact_range'][1]:.4g} C" if "contact_range" in r else ""
        out.append(f"held out, {r['file']}: RMSE {amount(q['rmse'], fit.unit)}, {q['ratio']:.3g}x the fit's "
                   f"(threshold {q['threshold']:.3g}): {verdict_text} ({r['start']}{where})")
    return out


def load_lines(fit) -> list:
    """A fit of laws of temperature and load, in lines: how it was made, each law's equation, form and ranges, and
    the per-condition estimates the laws went through."""
    d = fit.details["load"]
    out = [f"procedure: {d['procedure']}" + (f" ({d['why_joint']})" if d.get("why_joint") else ""),
           f"loads: {', '.join(f'{x:.4g}' for x in d['loads'])}; L in {fit.unit}, T in C"]
    for name, law in fit.model.laws.items():
        rng = getattr(getattr(law, "load", None), "range", None)
        out.append(f"{equation(name, law)}  [{form_of(law)}; T {_span(law.range)} C, |L| {_span(rng)}]")
    for c in d.get("conditions", []):
        est = ", ".join(f"{n} = {v:.5g} +- {c['stderr'][n]:.2g}" for n, v in c["values"].items())
        out.append(f"at {c['temperature']:.4g} C, load {c['load']:.4g}: {est} ({', '.join(c['files'])})")
    return out


def _span(rng) -> str:
    return "-" if rng is None else f"{rng[0]:.4g}..{rng[1]:.4g}"


def fit_blocks(fit) -> list:
    """A fit's report (like lmfit's fit report) as the structured blocks of thermofriction.results."""
    blocks = [heading(f"Fit: {fit.method}"), lines(_not_adequate(fit))]
    if fit.n_points == 0 and "paper" in fit.details:  # no trajectory fit: say what was done instead
        blocks.append(lines([f"{'done' if fit.success else 'REFUSED'}: {fit.message}"] + _paper_lines(fit)))
        rows = []
    else:
        blocks.append(lines([f"{'converged' if fit.success else 'NOT CONVERGED'}: {fit.message}"]))
        rows = [("data points", str(fit.n_points)),
                ("rmse", f"{amount(fit.rmse, fit.unit)} ({fit.removed} removed)")]
        rows += _offset_rows(fit) + _plant_rows(fit.details.get("plant"))
    q = fit.fit_quality
    if q is not None:
        rows.append(("noise (data)", f"{amount(q['noise'], fit.unit)}; rmse/noise = {q['ratio']:.3g}, "
                                     f"lag-1 autocorrelation {q['autocorrelation']:.2f}, {verdict(q)}"))
    rows += [("evaluations", f"{fit.nfev} (Jacobians {fit.njev}), starts = {fit.starts}"),
             ("fit time", f"{fit.wall_time:.3g} s (the least-squares fits; not the checks after them)")]
    blocks += [fields(rows, WIDTH), heading("Parameters"), table(HEAD, parameter_rows(fit))]
    if fit.method == "warm-up":  # docs/self-heating.md#warm-up-without-a-contact-temperature
        blocks += [heading("Heat path"), lines(heat_path_lines(fit))]
    if fit.details.get("load"):  # laws of temperature and load (identification/load_identify.py)
        blocks += [heading("Laws of temperature and load"), lines(load_lines(fit))]
    pairs = _correlated(fit)
    if pairs:
        blocks += [heading("Correlations", "(|C| > 0.5)"), lines(pairs)]
    if fit.warnings:
        blocks += [heading("Warnings"), lines(fit.warnings)]
    return blocks


def fit_html_blocks(fit) -> list:
    """A fit's notebook table as blocks: the headline (converged, RMSE, the noise and the verdict, the time), where
    the model came from, then the text report's blocks (its fields, parameters, correlations and warnings)."""
    q = fit.fit_quality
    quality = "" if q is None else (f", noise {amount(q['noise'], fit.unit)}: rmse/noise {q['ratio']:.3g}, "
                                    f"{verdict(q)}")
    rmse = "" if fit.n_points == 0 else f", rmse {amount(fit.rmse, fit.unit)}"
    prov = fit.model.provenance or {}
    origin = [f"{fit.model.name or ''}: data sha256 {prov['data_sha256'][:12]}…, {prov.get('date', '')}, "
              f"thermofriction {prov.get('thermofriction', '')}"] if prov.get("data_sha256") else []
    # the headline and the model's origin, then the report's own blocks: the notebook shows what the text does
    return [heading(f"Fit: {fit.method}", f"— {'converged' if fit.success else 'not converged'}{rmse}{quality}, "
                                          f"{fit.wall_time:.3g} s"),
            lines(origin)] + fit_blocks(fit)[1:]


__all__ = ["fit_blocks", "fit_html_blocks", "heat_path_lines", "verdict", "parameter_rows", "HEAD"]
