"""``thermofriction synth``: its arguments and what it does -- a dataset synthesised from a model
(data/synth.py's ``synthesize``), written as a dataset folder, with the command line's progress."""

from __future__ import annotations

import math
from pathlib import Path

from .._io import publish_together
from .._progress import Progress
from ..data.save import check_dataset_folder, save_dataset
from ..data.synth import MAX_EXPERIMENTS, synthesize
from ..errors import InputError
from ..models import PRESETS, load_model
from ..plausible import parse_length
from ..waveforms import Sampled, parse_waveform


def _float_list(text, what):
    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"{what}: expected comma-separated numbers, got '{text}'") from None
    if not all(math.isfinite(v) for v in vals):
        raise InputError(f"{what}: temperatures must be finite numbers, got '{text}'")
    return vals


def add_synth_command(subparsers):
    """Registers ``thermofriction synth`` on an argparse subparsers object.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The command line's subcommands.

    Returns
    -------
    argparse.ArgumentParser
        The ``synth`` command's parser.

    Raises
    ------
    argparse.ArgumentError
        A command of that name already registered.
    """
    s = subparsers.add_parser(
        "synth", help="synthesise a measured dataset from a model, with realistic sensor effects",
        description="Simulate MODEL at each temperature and write a dataset folder (docs/formats.md#datasets: dataset.toml "
                    "and one experiment CSV per temperature) with white displacement noise, quantisation, "
                    "an optional slow sensor drift, a noisy temperature record and the stage displacement. "
                    "Seeded and reproducible: the same options give the same files, and each experiment "
                    "has its own random stream, so adding a temperature changes no other experiment.",
        epilog="example: thermofriction synth li2009-model-i --temperatures 30.8,33.9,35.7,38.4,41.5 "
               "--validate 33,40 --noise 20e-9 --quantization 5e-9 -o data")
    s.add_argument("model", metavar="MODEL", help="model file (.toml) or preset name, e.g. li2009-model-i")
    s.add_argument("--temperatures", required=True, metavar="C,C,...",
                   help="temperatures [C] of the experiments with role 'fit', comma-separated")
    s.add_argument("--validate", default="", metavar="C,C,...",
                   help="temperatures [C] of held-out experiments (role 'validate'), comma-separated")
    s.add_argument("--duration", type=float, default=2.0, metavar="S",
                   help="length of each experiment [s] (default: 2)")
    s.add_argument("--sample-rate", type=float, default=10_000.0, metavar="HZ",
                   help="sampling rate of the recorded signals [Hz] (default: 10000)")
    s.add_argument("--input", metavar="WAVEFORM",
                   help="input waveform, e.g. sawtooth:amplitude=30,frequency=5,rise=0.999 "
                        "(default: the model's [input])")
    s.add_argument("--noise", default="20nm", metavar="LENGTH",
                   help="standard deviation of the white displacement-sensor noise [m], or with a unit "
                        "(20nm, 0.02um) (default: 20nm)")
    s.add_argument("--quantization", default="0", metavar="LENGTH",
                   help="displacement-sensor resolution [m], or with a unit (5nm): values are rounded to "
                        "multiples of it (default: 0, none)")
    s.add_argument("--temperature-noise", type=float, default=0.0, metavar="C",
                   help="standard deviation of the temperature-sensor noise [C]; a non-zero value "
                        "records a temperature[C] column (default: 0)")
    s.add_argument("--drift", type=float, default=0.0, metavar="M_PER_S",
                   help="slow linear displacement-sensor drift [m/s], with a random sign per experiment "
                        "(default: 0)")
    s.add_argument("--record-temperature", action="store_true", default=None,
                   help="write a temperature[C] column (the true temperature plus --temperature-noise)")
    s.add_argument("--record-stage", action="store_true",
                   help="also write the stage displacement (stage_displacement[um], same noise), "
                        "for identifying the plant")
    s.add_argument("--seed", type=int, default=0, metavar="N", help="random seed (default: 0)")
    s.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="dataset folder to write (created if needed); a folder that already holds a dataset "
                        "is refused unless --force")
    s.add_argument("--force", action="store_true",
                   help="replace the dataset in the output folder (its files that the new one does not list "
                        "are removed)")
    s.set_defaults(run=cmd_synth)
    return s


def cmd_synth(args) -> int:
    """``thermofriction synth``: writes the dataset and prints one line per file.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (docs/cli.md#synth).

    Returns
    -------
    int
        The exit status, 0.

    Raises
    ------
    InputError
        A bad option (``--duration`` that is not positive, ...), named; an output folder that cannot be
        written.
    """
    for opt, v in (("--duration", args.duration), ("--sample-rate", args.sample_rate)):
        if not (v > 0 and math.isfinite(v)):
            raise InputError(f"{opt} must be a positive number, got {v!r}")
    args.noise = parse_length(args.noise, "--noise")
    args.quantization = parse_length(args.quantization, "--quantization")
    for opt, v in (("--noise", args.noise), ("--quantization", args.quantization),
                   ("--temperature-noise", args.temperature_noise)):
        if not (v >= 0 and math.isfinite(v)):
            raise InputError(f"{opt} must be a non-negative number, got {v!r}")
    if not math.isfinite(args.drift):
        raise InputError(f"--drift must be a finite number, got {args.drift!r}")
    fit_T = _float_list(args.temperatures, "--temperatures")
    if not fit_T:
        raise InputError("--temperatures: give at least one temperature, e.g. --temperatures 30.8,35.7,41.5")
    val_T = _float_list(args.validate or "", "--validate")
    if len(fit_T) + len(val_T) > MAX_EXPERIMENTS:  # before the model is read, the folder checked
        raise InputError(f"--temperatures, --validate: {len(fit_T) + len(val_T)} temperatures, more than the limit "
                         f"of {MAX_EXPERIMENTS} experiments per synthesised dataset (docs/limits.md): synthesise "
                         f"several datasets")
    check_dataset_folder(args.output, args.force, hint="--force")  # before the work, not after it
    model = load_model(args.model)
    waveform = parse_waveform(args.input) if args.input else None
    if waveform is None and model.input is None:
        raise InputError(f"{args.model}: the model has no [input] waveform: give --input, "
                         f"e.g. --input sawtooth:amplitude=30,frequency=5")
    with Progress("synth", len(fit_T) + len(val_T), "experiments") as progress:
        data = _synthesized(model, fit_T, val_T, waveform, args, progress)
        inputs = [] if args.model in PRESETS else [args.model]
        for w in (waveform, model.input):
            if isinstance(w, Sampled) and w.file:
                inputs += [w.file, str(Path(args.model).parent / w.file)]
        progress.stage(f"writing {args.output}")
        with publish_together(inputs=inputs):  # refuses to replace or remove an input file
            folder = save_dataset(data, args.output, overwrite=args.force)
    for e in data.experiments:
        print(f"wrote {folder / e.file} ({e.role}, {e.temperature:g} C, {e.time.size} samples)")
    print(f"wrote {folder / 'dataset.toml'} ({len(data.fit)} fit, {len(data.validate)} validate)")
    return 0


def _synthesized(model, fit_T, val_T, waveform, args, progress):
    """synth's dataset, counted on ``progress``; an InputError names the command."""
    try:
        return synthesize(model, fit_T, validate=val_T, duration=args.duration, sample_rate=args.sample_rate,
                          input=waveform, noise=args.noise, quantization=args.quantization,
                          temperature_noise=args.temperature_noise, drift=args.drift,
                          record_temperature=args.record_temperature, record_stage=args.record_stage,
                          seed=args.seed, progress=lambda done, _total: progress.count(done))
    except InputError as e:
        raise InputError(f"synth: {e}") from None


__all__ = ["add_synth_command", "cmd_synth"]
