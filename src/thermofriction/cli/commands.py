"""What each subcommand does: a thin layer over the library."""

from __future__ import annotations

import sys
import time

import numpy as np

from .. import _io
from ..errors import InputError
from ..models import PRESETS, MassPlant, load_model
from ..simulate import SOLVERS, StepSizeController, simulate
from ..waveforms import Sampled, parse_waveform
from .outputs import _dataset_inputs, _model_inputs, _refuse_inputs, _target, _waveform_inputs


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
    _refuse_inputs(args, _model_inputs(args.model, model), args.temperature_file, _waveform_inputs(waveform))
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
        sys.stdout.flush()  # a write error (a full disk) is reported here, as one line (main)
        return 0
    if args.output:
        from ..data.matlab import is_matlab, simulation_to_mat
        if is_matlab(args.output):  # docs/formats.md#matlab-files
            simulation_to_mat(res, _target(args, "output"))
        else:
            res.to_csv(_target(args, "output"))
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
    from ..data import load_dataset
    from ..identify import identify

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
    init = args.init if args.init and args.init not in PRESETS else None
    _refuse_inputs(args, _dataset_inputs(data), init, *_model_inputs(init, None))
    if args.reference_temperature is not None and args.method != "model-ii":
        raise InputError("--reference-temperature applies to --method model-ii only")
    if args.rtol >= 1:
        raise InputError(f"--rtol must be below 1, got {args.rtol!r}")
    update, status = _progress(args.quiet)
    try:
        fit = identify(data, args.method, init=args.init, friction=args.friction, parameters=params,
                       free=args.free or (),
                       procedure=args.procedure,
                       laws=laws or None, refine=not args.no_refine,
                       reference_temperature=args.reference_temperature, rtol=args.rtol, starts=args.starts,
                       seed=args.seed, progress=update)
    finally:
        if status is not None:
            status.stop()
    import shlex
    fit = fit.with_command("thermofriction " + shlex.join(sys.argv[1:]))  # in the model's [provenance]
    with _io.publish_together():  # the model and its JSON appear together, or neither
        if args.output:
            fit.model.save(_target(args, "output"))
        if args.json:
            fit.to_json(_target(args, "json"))
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
    from ..data import load_dataset
    from ..validate import validate

    model = load_model(args.model)
    data = load_dataset(args.dataset)
    _refuse_inputs(args, _model_inputs(args.model, model), _dataset_inputs(data))
    res = validate(model, data)
    if args.json:
        res.to_json(_target(args, "json"))
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

    from ..data import load_dataset
    from ..report import Entry, entry_label, report

    if len(args.paths) < 2:
        raise InputError("report needs at least one model and a dataset: MODEL.toml... DATASET")
    *model_paths, dataset = args.paths
    data = load_dataset(dataset)
    entries = []
    inputs = list(_dataset_inputs(data))
    for mp in model_paths:
        model = load_model(mp)
        inputs += _model_inputs(mp, model)
        fit = None
        side = Path(mp).with_suffix(".json")
        if Path(mp).exists() and side.exists():
            inputs.append(str(side))
            try:
                fit = json.loads(side.read_text())
            except (OSError, ValueError) as e:
                raise InputError(f"{side}: not readable JSON ({e})") from None
            if isinstance(fit, dict) and "model" in fit and fit["model"] != _io.jsonable(model.to_dict()):
                # a model and its results are written together; a mismatch is an interrupted or
                # partly repeated identify, or an edit: its numbers would be wrong for this model
                print(f"thermofriction: warning: {side} describes another model than {mp} (an interrupted "
                      f"identify, or one of them was edited); its results are not used", file=sys.stderr)
                fit = None
        label = entry_label(model, fit)
        if any(e.label == label for e in entries):
            label = f"{label} ({Path(mp).stem})"
        entries.append(Entry(label, model, fit))
    _refuse_inputs(args, *inputs)
    with _io.publish_together(inputs=inputs):  # the page and its figures appear together, or none
        report(entries, data, args.output, figures_dir=args.figures, title=args.title,
               command="thermofriction " + " ".join(sys.argv[1:]))
    print(f"wrote {args.output}" + (f" and the figures in {args.figures}" if args.figures else ""))
    return 0


def cmd_demo(args) -> int:
    from ..demo import run_demo

    update, status = _progress(False)
    try:
        with _io.publish_together():  # every file of the demo appears at the end, or none
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
    print(f"  Model I against the truth the data were made from: {out['recovery']['model-i']['summary']}")
    print(f"  report: {out['report']}")
    return 0


#: each command's output files (argparse dest: option); they are checked before any work starts
#: (folder, name, writability, not a folder), so that a long run does not fail at the end, or write


def cmd_fmu(args) -> int:
    """Export a model as an FMI 2.0 co-simulation FMU (docs/fmu.md)."""
    from ..fmu import export_fmu  # zipfile and the binary only when asked for

    model = load_model(args.model)
    _refuse_inputs(args, _model_inputs(args.model, model))
    export_fmu(model, _target(args, "output"), temperature=args.temperature, model_identifier=args.model_identifier,
               source=args.model, integrator=args.integrator, step=args.step)
    how = f"fixed step {args.step:g} s" if args.integrator == "realtime" else "adaptive integrator"
    print(f"{model.name or args.model}: wrote {args.output} (FMI 2.0 co-simulation, linux64, {how})")
    return 0
