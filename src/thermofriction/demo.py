"""The main job in one call: synthesise the example dataset from the paper's preset, identify
Model I, Model II and a model without thermal effects, validate them on held-out temperatures and
write the HTML report with the JSON results."""

from __future__ import annotations

import time
from pathlib import Path

from .models import load_model

FIT_TEMPERATURES = (30.8, 32.0, 33.9, 35.7, 37.0, 38.4, 40.0, 41.5)
HELD_OUT = (33.0, 39.2)


def run_demo(folder="thermofriction-demo", progress=None, command=None) -> dict:
    """Writes ``folder``/data (the dataset), the fitted models and their JSON results,
    validation.json and report.html. Returns a summary with the paths and timings."""
    from .data import save_dataset, synthesize
    from .identification import identify
    from .reporting import Entry, report
    from .validation import validate

    def say(msg):
        if progress:
            progress(msg)

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    timings = {}
    t0 = time.perf_counter()
    say("synthesising the example dataset from the paper's Model I preset")
    truth = load_model("li2009-model-i")
    data = synthesize(truth, FIT_TEMPERATURES, validate=HELD_OUT, duration=2.0, sample_rate=10_000.0,
                      noise=20e-9, quantization=5e-9, temperature_noise=0.05, seed=2009, name="li2009-synthetic")
    save_dataset(data, folder / "data", overwrite=True)  # the demo's own folder
    timings["synthesise"] = time.perf_counter() - t0
    start = load_model("li2009-base")  # a user's starting point: LuGre at 30 C, no thermal model
    fits = {}
    for key, method, kwargs in (("model-i", "model-i", {}), ("model-ii", "model-ii", {"procedure": "both"}),
                                ("base", "base", {})):
        say(f"identifying {key}")
        fit = identify(data, method, init=start, progress=progress, **kwargs)
        fit.model.save(folder / f"{key}.toml")
        fit.to_json(folder / f"{key}.json")
        fits[key] = fit
        timings[key] = fit.wall_time
    say("validating on the held-out temperatures and writing the report")
    t1 = time.perf_counter()
    entries = []
    validation = {}
    for key, label in (("model-i", "Model I"), ("model-ii", "Model II"), ("base", "no thermal model")):
        v = validate(fits[key].model, data)
        validation[key] = v.to_dict()
        entries.append(Entry(label, fits[key].model, fits[key].to_dict(), v))
    from ._io import dump_json
    dump_json(validation, folder / "validation.json")
    recovery = truth_recovery(fits, truth)
    dump_json(recovery, folder / "recovery.json")
    labels = {"model-i": "Model I", "model-ii": "Model II", "base": "no thermal model"}
    report(entries, data, folder / "report.html", command=command or "thermofriction demo",
           title="thermofriction demo — the paper's actuator at 30.8-41.5 °C",
           truth={labels[k]: v for k, v in recovery.items()})
    timings["validate and report"] = time.perf_counter() - t1
    timings["total"] = time.perf_counter() - t0
    return {"folder": folder, "report": folder / "report.html", "fits": fits, "validation": validation,
            "recovery": recovery, "timings": timings}


def truth_recovery(fits, truth) -> dict:
    """Whether each fit recovers the truth the demo's data were made from, or why it cannot say."""
    out = {}
    for key, fit in fits.items():
        rows = fit.recovery(truth, FIT_TEMPERATURES)
        if rows:
            missed = [f"{r['parameter']} at {r['temperature']:g} C" for r in rows if not r["covered"]]
            out[key] = {"covered": len(rows) - len(missed), "points": len(rows), "missed": missed, "rows": rows,
                        "summary": f"the 95 % intervals of the fitted laws cover the truth at {len(rows) - len(missed)} "
                                   f"of {len(rows)} (parameter, temperature) points"
                                   + (f"; not at {', '.join(missed)}" if missed else "")}
        else:
            out[key] = {"covered": None, "points": 0, "missed": [], "rows": [],
                        "summary": "not comparable with the truth: " + _why_not_comparable(fit, truth)}
    return out


def _why_not_comparable(fit, truth) -> str:
    from .models import ModelI, ModelII
    kind = {ModelI: "Model I", ModelII: "Model II"}
    made = f"the data are made from {kind.get(type(truth.thermal), 'a model without a thermal part')} ({truth.name})"
    if isinstance(truth.thermal, ModelI) and isinstance(fit.model.thermal, ModelII):
        return (f"{made}, whose sigma0, sigma1 and fc change with temperature at different rates; Model II scales "
                f"them all by one factor lambda(T), so it has no law to compare and is not expected to reach the noise")
    if fit.model.thermal is None:
        return f"{made}; a model without a thermal part has no temperature law to compare"
    return f"{made}; a {kind.get(type(fit.model.thermal), 'different')} fit has no law that corresponds to the truth's"
