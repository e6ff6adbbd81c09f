"""`thermofriction propagate`: a fit's parameter uncertainty carried into predictions at new temperatures
(tf.propagate; docs/cli.md#propagate)."""

from __future__ import annotations

import argparse
import sys

from .._progress import Progress
from ..errors import InputError
from ..simulation import SOLVERS, StepSizeController
from ..waveforms import parse_waveform
from .outputs import _refuse_inputs, _target, _waveform_inputs


def add_propagate_command(sub, *, temperature, positive_float, int_in, writes, scheduler_options):
    """Registers ``propagate``; the argparse types and shared options come from parser.py."""
    from ..scale.propagate import MAX_DRAWS

    p = sub.add_parser(
        "propagate", help="carry a fit's parameter uncertainty into prediction bands at new temperatures",
        description="Draw parameter sets from a fit's covariance (the standard errors and correlations that "
                    "identify --json wrote; positive parameters log-normally), simulate each at every temperature "
                    "and write the central bands of the displacement and of the mean step per cycle, with and "
                    "without the measurement noise the fit estimated. Runs where sweep does (threads in this process by default, or Dask); the draws are "
                    "made from --seed before any task runs, so the bands do not depend on where they ran.",
        epilog="example: thermofriction identify data --json fit.json -o fit.toml; thermofriction propagate "
               "fit.json --temperatures 33,37,40 --draws 400 -o bands.json; thermofriction report fit.toml data "
               "--bands bands.json -o report.html")
    p.add_argument("fit", metavar="RESULTS.json", help="the results JSON of a fit (identify --json RESULTS.json)")
    p.add_argument("--temperatures", required=True, type=_temperatures(temperature), metavar="C,C,...",
                   help="temperatures [C] to predict at, comma-separated")
    p.add_argument("--draws", type=int_in(2, MAX_DRAWS), default=200, metavar="N",
                   help=f"parameter sets drawn, 2 to {MAX_DRAWS} (default: 200)")
    p.add_argument("--seed", type=int_in(0), default=0, metavar="N", help="seed of the draws, 0 or more (default: 0)")
    p.add_argument("--level", type=_fraction, default=0.95, metavar="P",
                   help="the bands' central probability, between 0 and 1 (default: 0.95)")
    p.add_argument("--input", metavar="WAVEFORM", help="input waveform (default: the fitted model's [input])")
    p.add_argument("--duration", type=positive_float, default=1.0, metavar="S",
                   help="simulated time per draw and temperature [s] (default: 1)")
    p.add_argument("--sample-rate", type=positive_float, default=1000.0, metavar="HZ",
                   help="output sample rate of the bands [Hz] (default: 1000)")
    p.add_argument("--solver", choices=sorted(SOLVERS), default=None, help="integrator (default: auto)")
    p.add_argument("--rtol", type=positive_float, default=1e-6, help="relative tolerance (default: 1e-6)")
    scheduler_options(p)
    p.add_argument("--batch-size", type=int_in(1), metavar="N", help="draws per task (default: sized from the "
                   "nominal runs' time, 4 or more per worker, at most 100 draws each)")
    p.add_argument("-o", "--output", metavar="BANDS.json", help=writes(
        "propagate", "output", "the bands: JSON (everything, for report --bands), CSV (one row per temperature "
                               "and time) or MATLAB structs"))
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no summary")
    p.set_defaults(run=cmd_propagate)
    return p


def _temperatures(temperature):
    def parse(text):
        items = [t.strip() for t in text.split(",")]
        if not all(items):
            raise argparse.ArgumentTypeError(f"expected temperatures [C] separated by commas, got {text!r}")
        return [temperature(t) for t in items]
    return parse


def _fraction(text):
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not 0 < v < 1:
        raise argparse.ArgumentTypeError(f"must be between 0 and 1 (exclusive), got {text!r}")
    return v


def cmd_propagate(args) -> int:
    """The bands are computed, then written (nothing is written on a failure or Ctrl-C)."""
    from ..scale.propagate import check_drawable, propagate
    from .fits import load_fit

    fit = load_fit(args.fit)
    try:  # the fit's uncertainty, before any work: the message names the file
        check_drawable(fit)
    except InputError as e:
        raise InputError(f"{args.fit}: {e}") from None
    waveform = parse_waveform(args.input) if args.input else None
    if waveform is None and fit.model.input is None:
        raise InputError(f"{args.fit}: the fitted model has no [input]: give --input")
    if args.rtol >= 1:
        raise InputError(f"--rtol must be below 1, got {args.rtol!r}")
    _refuse_inputs(args, args.fit, _waveform_inputs(waveform))
    with Progress("propagate", args.draws, "draws", enabled=not args.quiet) as progress:
        res = propagate(fit, args.temperatures, draws=args.draws, seed=args.seed, input=waveform,
                        duration=args.duration, sample_rate=args.sample_rate, level=args.level,
                        solver=SOLVERS[args.solver or "auto"](), controller=StepSizeController(rtol=args.rtol),
                        scheduler=args.scheduler, workers=args.workers, batch_size=args.batch_size, progress=progress.count)
    if args.output:
        res.save(_target(args, "output"))
    for i, reason in list(res.failures.items())[:3]:
        print(f"thermofriction: warning: draw {i} could not be simulated: {reason}", file=sys.stderr)
    if len(res.failures) > 3:
        print(f"thermofriction: warning: ... {len(res.failures) - 3} more draws could not be simulated (the bands "
              f"are from the {res.draws - len(res.failures)} others)", file=sys.stderr)
    if not args.quiet:
        print(res.report())
        print(f"{res.draws} draws x {len(res.temperatures)} temperatures in {res.wall_time:.3g} s on {res.where}")
        if args.output:
            print(f"wrote {args.output}")
    return 0


__all__ = ["add_propagate_command", "cmd_propagate"]
