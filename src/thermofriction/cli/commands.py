"""What each subcommand does: a thin layer over the library."""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from .. import _io
from .._progress import Progress
from ..data.force import LOAD_FILE_UNITS
from ..errors import InputError
from ..measurements.delay import parse_delay
from ..models import PRESETS, MassPlant, load_model
from ..results import collecting
from ..simulation import SOLVERS, StepSizeController, simulate
from ..waveforms import Sampled, parse_waveform
from .outputs import _dataset_inputs, _model_inputs, _refuse_inputs, _target, _waveform_inputs


def cmd_simulate(args) -> int:
    model = load_model(args.model)
    temperature = args.temperature
    if args.temperature_file:
        temperature = Sampled.from_csv(args.temperature_file)
    load = args.load
    if args.load_file:  # docs/cli.md#simulate: time[s] and normal_force[N] or load_torque[N*m]
        load = Sampled.from_csv(args.load_file, columns=LOAD_FILE_UNITS)
    waveform = parse_waveform(args.input) if args.input else None
    spring_pulled = isinstance(model.plant, MassPlant) and model.plant.spring_stiffness > 0
    if waveform is None and model.input is None and not spring_pulled:
        raise InputError(f"{args.model}: the model has no [input]: give --input")
    if args.rtol >= 1:
        raise InputError(f"--rtol must be below 1, got {args.rtol!r}")
    controller = StepSizeController(rtol=args.rtol, atol=args.atol, max_steps=args.max_steps)
    _refuse_inputs(args, _model_inputs(args.model, model), args.temperature_file, args.load_file,
                   _waveform_inputs(waveform))
    t0 = time.perf_counter()
    res = simulate(model, args.duration, temperature=temperature, load=load, input=waveform,
                   sample_rate=args.sample_rate, solver=SOLVERS[solver_of(args)](), controller=controller,
                   max_samples=args.max_samples)
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
        from ..data.matlab import is_matlab
        from ..data.matlab_results import simulation_to_mat
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
    if load is not None:
        T += ", at load " + (f"{load:g}" if isinstance(load, float) else f"from {args.load_file}")
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


def _identify_options(args):
    """(laws, parameters) from identify's options, checked: one dataset or a fleet alike."""
    laws = {}
    for item in args.law:
        name, eq, kind = item.partition("=")
        if not eq or kind not in ("linear", "exp", "const"):
            raise InputError(f"--law '{item}': expected PARAM=linear|exp|const")
        laws[name.strip()] = kind
    params = [p.strip() for p in args.parameters.split(",")] if args.parameters else None
    if params and args.method == "plant":
        raise InputError("--parameters applies to the friction methods; --method plant fits xi, wn and K")
    if args.reference_temperature is not None and args.method != "model-ii":
        raise InputError("--reference-temperature applies to --method model-ii only")
    if args.rtol >= 1:
        raise InputError(f"--rtol must be below 1, got {args.rtol!r}")
    return laws, params


def solver_of(args, default="auto", old="--method") -> str:
    """--solver; its earlier names (--method for simulate and sweep, --integrator for fmu) are still read, with
    a note (one meaning per option name: --method is identification's, the solver is --solver)."""
    if getattr(args, "solver_old", None):
        if args.solver not in (None, args.solver_old):
            raise InputError(f"{old} {args.solver_old} and --solver {args.solver} contradict each other")
        print(f"thermofriction: note: {old} is now --solver", file=sys.stderr)
        return args.solver_old
    return args.solver or default


def _offset(args):
    """--offset, or --no-offset (its earlier spelling of "none"); True: the measurement's default."""
    if getattr(args, "no_offset", False):
        if args.offset not in (None, "none"):
            raise InputError(f"--no-offset and --offset {args.offset} contradict each other")
        return "none"
    return True if args.offset is None else args.offset


def cmd_identify(args) -> int:
    from ..data import load_dataset
    from ..identification import identify

    if _fleet_paths(args) is not None:  # many datasets: the fleet path (scale/fleet.py)
        return cmd_identify_fleet(args)
    if isinstance(args.dataset, list):
        args.dataset = args.dataset[0]
    if getattr(args, "scheduler", None) or getattr(args, "workers", None):
        raise InputError("--scheduler and --workers apply to fleet identification (several datasets, or a folder "
                         "of datasets); one dataset is identified in this process")
    t0 = time.perf_counter()  # the command's own time, said after the fit's (which is only its least squares)
    with Progress("identify", enabled=not args.quiet) as progress:
        progress.stage(f"reading {args.dataset}")  # a file of millions of rows takes a while
        data = load_dataset(args.dataset, motion=args.motion)
        laws, params = _identify_options(args)
        init = args.init if args.init and args.init not in PRESETS else None
        _refuse_inputs(args, _dataset_inputs(data), init, *_model_inputs(init, None))
        progress.stage("identifying")
        fit = identify(data, args.method, init=args.init, friction=args.friction, parameters=params,
                       free=args.free or (),
                       procedure=args.procedure,
                       laws=laws or None, refine=not args.no_refine,
                       reference_temperature=args.reference_temperature,
                       controller=StepSizeController(rtol=args.rtol), starts=args.starts,
                       seed=args.seed, progress=progress.stage, offset=_offset(args),
                       max_evaluations=args.max_evaluations,
                       delay="auto" if args.delay is None else parse_delay(args.delay, "--delay"),
                       ripple_phase=args.ripple_phase)
    import shlex
    fit = fit.with_command("thermofriction " + shlex.join(sys.argv[1:]))  # in the model's [provenance]
    with _io.publish_together():  # the model and its JSON appear together, or neither
        if args.output:
            fit.model.save(_target(args, "output"))
        if args.json:  # a .mat name writes the same results for MATLAB
            (fit.to_mat if str(args.json).lower().endswith(".mat") else fit.to_json)(_target(args, "json"))
    if not args.quiet:
        print(fit.report())
        for name, alt in fit.alternatives.items():
            print()
            print(alt.report())
        for path in (args.output, args.json):
            if path:
                print(f"wrote {path}")
        print(f"identify took {time.perf_counter() - t0:.3g} s (reading, the fits, their checks and the held-out "
              f"predictions, writing)")
    return 0


def _fleet_paths(args):
    from ..scale.fleet import fleet_datasets
    return fleet_datasets(args.dataset)


def cmd_identify_fleet(args) -> int:
    """``thermofriction identify DATASET DATASET ...``: every dataset identified on the cluster; the
    fitted models, their results and the fleet summary are written together at the end."""
    from ..scale.fleet import identify_fleet

    paths = _fleet_paths(args)
    if not args.output:
        raise InputError("identifying several datasets writes a folder: give -o DIR (NAME.toml and NAME.json per "
                         "dataset, fleet.json and fleet.csv)")
    if args.json:
        raise InputError("--json applies to one dataset; with several, each dataset's results JSON goes into -o DIR")
    laws, params = _identify_options(args)
    from ..scale.fleet import refuse_overwriting_inputs
    refuse_overwriting_inputs(args.output, paths)  # before any identification, not after all of them
    with Progress("identify", len(paths), "datasets", enabled=not args.quiet) as progress:
        fleet = identify_fleet(paths, args.method, init=args.init, friction=args.friction, parameters=params,
                               free=args.free or (), procedure=args.procedure, laws=laws or None,
                               refine=not args.no_refine, reference_temperature=args.reference_temperature,
                               controller=StepSizeController(rtol=args.rtol), starts=args.starts, seed=args.seed,
                               scheduler=args.scheduler,
                               workers=args.workers, progress=progress.count)
    fleet.write(args.output)
    if not args.quiet:
        print(fleet.report())
        print(f"{len(fleet.names)} datasets in {fleet.wall_time:.3g} s on {fleet.where}")
        print(f"wrote {len(fleet.fits)} fitted models and results, fleet.json and fleet.csv in {args.output}")
    for name, reason in fleet.failures.items():
        print(f"thermofriction: {name}: not identified: {reason}", file=sys.stderr)
    return 1 if fleet.failures else 0


def cmd_validate(args) -> int:
    from ..data import load_dataset
    from ..validation import validate

    model = load_model(args.model)
    with Progress("validate") as progress:
        progress.stage(f"reading {args.dataset}")
        data = load_dataset(args.dataset, motion=args.motion)
        _refuse_inputs(args, _model_inputs(args.model, model), _dataset_inputs(data))
        progress.stage(f"predicting {len(data.experiments)} experiments")
        with collecting():  # the findings are in res.warnings, printed below
            res = validate(model, data, offset=args.offset, motion=args.motion, ripple_phase=args.ripple_phase)
    if args.json and not res.failures:  # a .mat name writes the same metrics for MATLAB
        (res.to_mat if str(args.json).lower().endswith(".mat") else res.to_json)(_target(args, "json"))
    res.print_table(title=f"{model.name or args.model} on {args.dataset}")
    for w in res.warnings:
        print(f"thermofriction: warning: {w}", file=sys.stderr)
    for f in res.failures:  # the others were still predicted; the exit status says some were not
        print(f"thermofriction: {f.file}: not predicted: {f.reason}", file=sys.stderr)
    if args.json and res.failures:  # a failed run (exit 1) publishes nothing: its metrics are incomplete
        print(f"thermofriction: {args.json} not written: {len(res.failures)} of {len(res.failures) + len(res.predictions)} "
              f"experiments were not predicted", file=sys.stderr)
    elif args.json:
        print(f"wrote {args.json}")
    return 1 if res.failures else 0


def cmd_demo(args) -> int:
    from ..demo import run_demo

    new_folders = _missing_folders(args.output, "data")  # run_demo creates them; a failed run removes them
    try:
        with _io.publish_together(), Progress("demo") as progress:  # every file of the demo at the end, or none
            out = run_demo(args.output, progress=progress.stage)
    except BaseException:  # an error, Ctrl-C, SIGTERM: the temporaries are gone, so are the folders
        _remove_empty(new_folders)
        raise
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


def _missing_folders(folder, *subfolders) -> list:
    """The folders on the way to ``folder`` (and its ``subfolders``) that do not exist yet, deepest first."""
    import os
    from pathlib import Path

    folder = Path(os.path.abspath(folder))
    missing = [folder / s for s in subfolders if not (folder / s).exists()]
    for p in (folder, *folder.parents):
        if p.exists():
            break
        missing.append(p)
    return missing


def _remove_empty(folders):
    """Removes each folder that is still empty (deepest first); one that holds anything stays."""
    import contextlib
    import os
    for f in folders:
        with contextlib.suppress(OSError):
            os.rmdir(f)


def cmd_sweep(args) -> int:
    """``thermofriction sweep``: the table is written once every point has run (nothing on Ctrl-C)."""
    from ..scale.sweep import sweep

    model = load_model(args.model)
    waveform = parse_waveform(args.input) if args.input else None
    if waveform is None and model.input is None:
        raise InputError(f"{args.model}: the model has no [input]: give --input")
    if args.rtol >= 1:
        raise InputError(f"--rtol must be below 1, got {args.rtol!r}")
    if args.output != "-" and str(args.output).lower().endswith(".parquet"):
        import importlib.util
        if importlib.util.find_spec("pyarrow") is None:
            raise InputError(f"-o {args.output}: writing Parquet needs pyarrow (pip install pyarrow); "
                             f"or give a .csv name")
    _refuse_inputs(args, _model_inputs(args.model, model), _waveform_inputs(waveform))
    from ..scale.sweep import _grid  # the grid's size for the progress bar, checked before any work
    _, n_points = _grid(args.grid)
    with Progress("sweep", n_points, "points", enabled=not args.quiet) as progress:
        res = sweep(model, args.grid, input=waveform, duration=args.duration, temperature=args.temperature,
                    metrics=args.metrics, sample_rate=args.sample_rate, solver=SOLVERS[solver_of(args)](),
                    controller=StepSizeController(rtol=args.rtol), scheduler=args.scheduler, workers=args.workers,
                    batch_size=args.batch_size, progress=progress.count)
    if args.output == "-":  # the table on standard output, the summary on standard error
        res.write_csv(sys.stdout)
        sys.stdout.flush()
    else:
        res.save(_target(args, "output"))
    summary = sys.stderr if args.output == "-" else sys.stdout
    for w in res.warnings:
        print(f"thermofriction: warning: {w}", file=sys.stderr)
    for i, reason in list(res.errors.items())[:5]:
        point = ", ".join(f"{n} = {res[n][i]:g}" for n in res.coordinates)
        print(f"thermofriction: point {i} ({point}) failed: {reason}", file=sys.stderr)
    if res.failed > 5:
        print(f"thermofriction: ... {res.failed - 5} more failed points (the error column of {args.output})",
              file=sys.stderr)
    if not args.quiet:
        rate = len(res) / res.wall_time if res.wall_time > 0 else math.nan
        print(f"{len(res)} points ({res.failed} failed) in {res.wall_time:.3g} s, {rate:.3g} simulations/s, "
              f"on {res.where}", file=summary)
        if args.output != "-":
            print(f"wrote {args.output}")
    return 1 if res.failed else 0


#: each command's output files (argparse dest: option); they are checked before any work starts
#: (folder, name, writability, not a folder), so that a long run does not fail at the end, or write


def cmd_fmu(args) -> int:
    """Export a model as an FMI 2.0 or 3.0 co-simulation FMU (docs/fmu.md)."""
    from ..fmu import export_fmu, prebuilt_platforms  # zipfile and the binary only when asked for

    solver = solver_of(args, "adaptive", "--integrator")
    model = load_model(args.model)
    _refuse_inputs(args, _model_inputs(args.model, model))
    export_fmu(model, _target(args, "output"), temperature=args.temperature, model_identifier=args.model_identifier,
               source=args.model, solver=solver, step=args.step, fmi=args.fmi, platforms=args.platforms,
               load=args.load)
    how = f"fixed step {args.step:g} s" if solver == "realtime" else "adaptive integrator"
    where = dict.fromkeys(prebuilt_platforms() if args.platforms is None else args.platforms)
    where = ", ".join([*where, "C sources"])
    print(f"{model.name or args.model}: wrote {args.output} (FMI {args.fmi}.0 co-simulation, {where}, {how})")
    return 0
