"""The ``thermofriction`` command line: a thin layer over the library (docs/cli.md).

Every error is one line on stderr naming the file, key or value, with exit status 2 for
usage and data errors and 1 for failed computations; outputs are written atomically.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings

import numpy as np

from ._version import __version__
from .errors import InputError, ThermofrictionError
from .models import PRESETS, MassPlant, load_model
from .simulate import MAX_SAMPLES, SOLVERS, StepSizeController, simulate
from .waveforms import Sampled, parse_waveform


def _number(positive):
    """An argparse type: a finite float, positive when asked."""
    def parse(text):
        try:
            v = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
        if not math.isfinite(v) or (positive and v <= 0):
            raise argparse.ArgumentTypeError(f"must be a {'positive' if positive else 'finite'} number, got {text!r}")
        return v
    return parse


_positive_float = _number(positive=True)
_finite_float = _number(positive=False)


def _positive_int(text):
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {text!r}")
    return v


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="thermofriction",
        description="Temperature-aware friction models for precision motion systems "
                    "(Li et al., Rev. Sci. Instrum. 80, 045104, 2009, and beyond).",
        epilog="Exit status: 0 success, 1 a computation failed, 2 bad usage or data.")
    p.add_argument("--version", action="version", version=f"thermofriction {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    s = sub.add_parser(
        "simulate", help="simulate a model file (or a preset) and write the simulation CSV (docs/formats.md#simulation-output)",
        description="Simulate a model from rest -- a stick-slip actuator, a single mass (force-driven or "
                    "spring-pulled) or prescribed motion, with any friction model (lugre, coulomb, stribeck, "
                    "dahl, elastoplastic, gms) -- and write time, input, displacements, velocity, friction "
                    "force, temperature and internal states (SI units, temperature in C) on a uniform grid. "
                    "Without -o, prints a summary.",
        epilog=f"MODEL is a model file (TOML) or a preset name: {', '.join(PRESETS)}. "
               "Input specs: sawtooth:amplitude=A,frequency=F[,rise=0.99,offset=0,direction=1] | "
               "sine:amplitude=A,frequency=F[,offset=0] | square:amplitude=A,frequency=F,slew=S[,offset=0,duty=0.5] | "
               "step:amplitude=A[,time=0,slew=0,offset=0] | sampled:file=PATH (CSV with time[s] and one value column). "
               "The input is a voltage [V] for the stick-slip plant, a force [N] for the mass, the displacement [m] "
               "for prescribed motion.")
    s.add_argument("model", metavar="MODEL", help="model file (.toml) or preset name")
    temp = s.add_mutually_exclusive_group()
    temp.add_argument("--temperature", type=_finite_float, metavar="C",
                      help="constant interface temperature [C] (required for thermal models)")
    temp.add_argument("--temperature-file", metavar="F.csv",
                      help="temperature signal: CSV with time[s] and temperature[C], linearly interpolated")
    s.add_argument("--input", metavar="WAVEFORM", help="input waveform, overriding the model's [input]")
    s.add_argument("--duration", type=_positive_float, default=2.0, metavar="S",
                   help="simulated time [s] (default: 2)")
    s.add_argument("--sample-rate", type=_positive_float, default=10_000.0, metavar="HZ",
                   help="output sample rate [Hz] (default: 10000)")
    s.add_argument("-o", "--output", metavar="OUT.csv", help="CSV output file ('-' for standard output)")
    s.add_argument("--method", choices=sorted(SOLVERS), default="auto",
                   help="integrator: dopri5 (explicit), rodas4 (stiff), auto (default: dopri5, trying rodas4 "
                        "when it detects stiffness and keeping it only where it is cheaper)")
    s.add_argument("--rtol", type=_positive_float, default=1e-6, help="relative tolerance (default: 1e-6)")
    s.add_argument("--atol", type=_positive_float, default=None,
                   help="absolute tolerance for every state (default: rtol times each state's scale)")
    s.add_argument("--max-steps", type=_positive_int, default=10_000_000, metavar="N",
                   help="step limit (default: 10000000)")
    s.add_argument("--max-samples", type=_positive_int, default=MAX_SAMPLES, metavar="N",
                   help=f"limit on output samples, duration x sample rate + 1, each ~184 bytes in memory "
                        f"(default: {MAX_SAMPLES})")
    s.set_defaults(run=cmd_simulate)

    i = sub.add_parser(
        "identify", help="identify a model from a dataset (docs/formats.md#datasets) and write the fitted model and results",
        description="Fit a friction model (base), Model I or Model II to the 'fit' experiments of a dataset: "
                    "trust-region least squares with exact sensitivities from the C core, a multi-start "
                    "global phase, and standard errors, 95 % intervals and correlations at the optimum.",
        epilog="Writes FITTED.toml (loadable by simulate) and, with --json, the results JSON (docs/formats.md#results-json). "
               "The initial model provides the plant (masses, xi, wn, K) and the input waveform.")
    i.add_argument("dataset", metavar="DATASET", help="dataset folder (with dataset.toml)")
    i.add_argument("--method", choices=("plant", "base", "model-i", "model-ii", "heat"), default="model-i",
                   help="what to identify: plant (xi, wn, K from a recorded stage response), base (one friction "
                        "model for all temperatures), model-i or model-ii (default: model-i), or heat (the "
                        "[heat] section's C_th, R_th, eta from recorded temperature[C] columns)")
    i.add_argument("--friction", choices=("lugre", "dahl", "elastoplastic", "gms", "stribeck", "coulomb"),
                   help="friction model to identify (default: the initial model's); built from the initial model's "
                        "values where they share a parameter (docs/identification.md#friction-models)")
    i.add_argument("--init", metavar="MODEL.toml",
                   help="initial model: file or preset (default: the paper's preset for the method)")
    i.add_argument("--parameters", metavar="NAMES",
                   help="comma-separated parameters to fit with --method base (default: the friction model's, "
                        "LuGre's sigma0,sigma1,fc)")
    i.add_argument("--procedure", choices=("direct", "paper", "both"), default="direct",
                   help="Model II procedure (default: direct; both: report the paper's too)")
    i.add_argument("--law", action="append", default=[], metavar="PARAM=KIND",
                   help="Model I law kind for a parameter, e.g. sigma0=exp (default: chosen by AICc)")
    i.add_argument("--no-refine", action="store_true",
                   help="skip the joint refinement of the laws on all experiments")
    i.add_argument("--reference-temperature", type=_finite_float, metavar="C",
                   help="Model II base temperature (default: the lowest fit temperature)")
    i.add_argument("--starts", type=_positive_int, default=8, help="multi-start size (default: 8)")
    i.add_argument("--rtol", type=_positive_float, default=1e-8,
                   help="simulation tolerance during the fit (default: 1e-8)")
    i.add_argument("--seed", type=int, default=0, help="seed of the multi-start sample (default: 0)")
    i.add_argument("-o", "--output", metavar="FITTED.toml", help="fitted model file")
    i.add_argument("--json", metavar="RESULTS.json", help="results as JSON")
    i.add_argument("-q", "--quiet", action="store_true", help="no progress and no report")
    i.set_defaults(run=cmd_identify)

    v = sub.add_parser("validate", help="predict every experiment of a dataset with a model: the metrics of docs/formats.md#validation-metrics",
                       description="Simulate each experiment of DATASET with MODEL and report the paper's maximum "
                                   "prediction error, RMSE, NRMSE, final-displacement error and per-cycle step-size "
                                   "error, as a table and (with --json) as JSON.")
    v.add_argument("model", metavar="MODEL.toml", help="model file or preset")
    v.add_argument("dataset", metavar="DATASET", help="dataset folder (with dataset.toml)")
    v.add_argument("--json", metavar="METRICS.json", help="metrics as JSON (docs/formats.md#validation-metrics)")
    v.set_defaults(run=cmd_validate)

    r = sub.add_parser("report", help="an HTML report comparing models on a dataset",
                       description="Compare one or more models on a dataset in one self-contained HTML file "
                                   "(figures inlined as SVG; it opens offline). Identification results are read "
                                   "from a JSON file beside each model file (same name, .json), when there is one.")
    r.add_argument("paths", nargs="+", metavar="MODEL.toml... DATASET",
                   help="one or more model files (or presets), then the dataset folder")
    r.add_argument("-o", "--output", required=True, metavar="REPORT.html", help="the report")
    r.add_argument("--figures", metavar="DIR", help="also write every figure as SVG and PNG into DIR")
    r.add_argument("--title", help="the report's title")
    r.set_defaults(run=cmd_report)

    d = sub.add_parser("demo", help="the main job: synthesise the example dataset, identify, validate, report",
                       description="Synthesise the bundled example dataset from the paper's preset (seeded, with "
                                   "sensor noise, quantisation and temperature-sensor noise; two temperatures held "
                                   "out), identify Model I, Model II and a model without thermal effects, validate "
                                   "them and write report.html with the models and JSON results.")
    d.add_argument("-o", "--output", default="thermofriction-demo", metavar="DIR",
                   help="output folder (default: thermofriction-demo)")
    d.set_defaults(run=cmd_demo)

    try:  # dataset tools (synth) live with the data module
        from .data import add_synth_command
        add_synth_command(sub)
    except ImportError:  # pragma: no cover - during development only
        pass
    return p


def cmd_simulate(args) -> int:
    model = load_model(args.model)
    temperature = args.temperature
    if args.temperature_file:
        temperature = Sampled.from_csv(args.temperature_file)
    waveform = parse_waveform(args.input) if args.input else None
    spring_pulled = isinstance(model.plant, MassPlant) and model.plant.spring_stiffness > 0
    if waveform is None and model.input is None and not spring_pulled:
        raise InputError(f"{args.model}: the model has no [input]: give --input")
    if args.rtol >= 1:
        raise InputError(f"--rtol must be below 1, got {args.rtol!r}")
    controller = StepSizeController(rtol=args.rtol, atol=args.atol, max_steps=args.max_steps)
    t0 = time.perf_counter()
    res = simulate(model, args.duration, temperature=temperature, input=waveform, sample_rate=args.sample_rate,
                   solver=SOLVERS[args.method](), controller=controller, max_samples=args.max_samples)
    elapsed = time.perf_counter() - t0
    if args.output == "-":
        import io
        buf = io.StringIO()
        cols = res.columns()
        buf.write(",".join(cols) + "\n")
        np.savetxt(buf, np.column_stack(list(cols.values())), delimiter=",", fmt="%.12g")
        sys.stdout.write(buf.getvalue())
        return 0
    if args.output:
        res.to_csv(args.output)
    out = sys.stdout
    name = model.name or args.model
    if model.heat is not None:  # the temperature is a state: say where it went
        T = (f"self-heating from {res.temperature[0]:.4g} C to {res.temperature[-1]:.4g} C (peak "
             f"{res.temperature.max():.4g} C), ambient {model.heat.resolved(temperature).ambient_temperature:g} C")
    else:
        T = "at temperature " + (f"{temperature:g} C" if isinstance(temperature, float) else
                                 f"from {args.temperature_file}" if temperature is not None else "not used")
    print(f"{name}: {args.duration:g} s {T}, {len(res.time)} samples", file=out)
    print(f"  final displacement  {res.displacement[-1] * 1e6:.6g} um", file=out)
    print(f"  peak friction force {np.max(np.abs(res.friction_force)):.6g} N", file=out)
    if res.step_sizes.size:
        print(f"  step per cycle      {res.step_sizes.mean() * 1e6:.6g} um (mean of {res.step_sizes.size}), "
              f"last {res.step_sizes[-1] * 1e6:.6g} um", file=out)
        print(f"  mean velocity       {res.mean_velocity * 1e6:.6g} um/s", file=out)
    st = res.stats
    events = f", {st['events']} stick/slip switches" if st.get("events") else ""
    print(f"  solver              {st['solver']}: {st['steps']} steps, {st['rejected']} rejected{events}, "
          f"{elapsed * 1e3:.1f} ms", file=out)
    if args.output:
        print(f"  wrote               {args.output}", file=out)
    return 0


def _progress(quiet):
    """A status line on a terminal; nothing otherwise (or with --quiet)."""
    if quiet or not sys.stderr.isatty():
        return None, None
    from rich.console import Console
    console = Console(stderr=True)
    status = console.status("identifying")
    status.start()

    def update(message):
        status.update(message)
    return update, status


def cmd_identify(args) -> int:
    from .data import load_dataset
    from .identify import identify

    data = load_dataset(args.dataset)
    laws = {}
    for item in args.law:
        name, eq, kind = item.partition("=")
        if not eq or kind not in ("linear", "exp", "const"):
            raise InputError(f"--law '{item}': expected PARAM=linear|exp|const")
        laws[name.strip()] = kind
    params = [p.strip() for p in args.parameters.split(",")] if args.parameters else None
    if params and args.method != "base":
        raise InputError("--parameters applies to --method base only")
    update, status = _progress(args.quiet)
    try:
        fit = identify(data, args.method, init=args.init, friction=args.friction, parameters=params, procedure=args.procedure,
                       laws=laws or None, refine=not args.no_refine,
                       reference_temperature=args.reference_temperature, rtol=args.rtol, starts=args.starts,
                       seed=args.seed, progress=update)
    finally:
        if status is not None:
            status.stop()
    if args.output:
        fit.model.save(args.output)
    if args.json:
        fit.to_json(args.json)
    if not args.quiet:
        print(fit.report())
        for name, alt in fit.alternatives.items():
            print()
            print(alt.report())
        for path in (args.output, args.json):
            if path:
                print(f"wrote {path}")
    return 0


def cmd_validate(args) -> int:
    from .data import load_dataset
    from .validate import validate

    model = load_model(args.model)
    data = load_dataset(args.dataset)
    res = validate(model, data)
    if args.json:
        res.to_json(args.json)
    res.print_table(title=f"{model.name or args.model} on {args.dataset}")
    for w in res.warnings:
        print(f"thermofriction: warning: {w}", file=sys.stderr)
    for f in res.failures:  # the others were still predicted; the exit status says some were not
        print(f"thermofriction: {f.file}: not predicted: {f.reason}", file=sys.stderr)
    if args.json:
        print(f"wrote {args.json}")
    return 1 if res.failures else 0


def cmd_report(args) -> int:
    import json
    from pathlib import Path

    from .data import load_dataset
    from .report import Entry, entry_label, report

    if len(args.paths) < 2:
        raise InputError("report needs at least one model and a dataset: MODEL.toml... DATASET")
    *model_paths, dataset = args.paths
    data = load_dataset(dataset)
    entries = []
    for mp in model_paths:
        model = load_model(mp)
        fit = None
        side = Path(mp).with_suffix(".json")
        if Path(mp).exists() and side.exists():
            try:
                fit = json.loads(side.read_text())
            except (OSError, ValueError) as e:
                raise InputError(f"{side}: not readable JSON ({e})") from None
        label = entry_label(model, fit)
        if any(e.label == label for e in entries):
            label = f"{label} ({Path(mp).stem})"
        entries.append(Entry(label, model, fit))
    report(entries, data, args.output, figures_dir=args.figures, title=args.title,
           command="thermofriction " + " ".join(sys.argv[1:]))
    print(f"wrote {args.output}" + (f" and the figures in {args.figures}" if args.figures else ""))
    return 0


def cmd_demo(args) -> int:
    from .demo import run_demo

    update, status = _progress(False)
    try:
        out = run_demo(args.output, progress=update or (lambda m: print(f"  {m}", file=sys.stderr)))
    finally:
        if status is not None:
            status.stop()
    t = out["timings"]
    fits = out["fits"]
    print(f"thermofriction demo: {t['total']:.1f} s in all")
    for key, label in (("model-i", "Model I"), ("model-ii", "Model II"), ("base", "no thermal model")):
        s = out["validation"][key]["summary"].get("validate", {})
        print(f"  {label:17s} identified in {fits[key].wall_time:5.1f} s; held-out max error "
              f"{s.get('max_error_pct', float('nan')):.3g} %, RMSE {s.get('rmse_offset_removed', float('nan')) * 1e9:.4g} nm")
    print(f"  report: {out['report']}")
    return 0


#: each command's output files (argparse dests); their folders must exist before any work starts,
#: so that a long run does not fail at the end, or write one output and not the next
_OUTPUT_FILES = {"simulate": ("output",), "identify": ("output", "json"), "validate": ("json",), "report": ("output",)}


def _check_output_folders(args):
    from pathlib import Path
    for dest in _OUTPUT_FILES.get(args.command, ()):
        path = getattr(args, dest, None)
        if path and path != "-":
            folder = Path(path).parent
            if not folder.is_dir():
                raise InputError(f"{path}: folder {folder} does not exist")


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    caught = []

    def show(message, category, filename, lineno, file=None, line=None):
        caught.append(f"warning: {message}")
        print(f"thermofriction: warning: {message}", file=sys.stderr)

    warnings.showwarning = show
    try:
        _check_output_folders(args)
        return args.run(args)
    except ThermofrictionError as e:
        print(f"thermofriction: error: {e}", file=sys.stderr)
        return e.exit_status
    except KeyboardInterrupt:
        print("thermofriction: interrupted; no output was written", file=sys.stderr)
        return 130
    except MemoryError:
        print("thermofriction: error: out of memory (lower --duration or --sample-rate)", file=sys.stderr)
        return 1
    except BrokenPipeError:
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
