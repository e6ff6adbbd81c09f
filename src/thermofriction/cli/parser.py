"""The command line's arguments: every subcommand, option and its checks (docs/cli.md)."""

from __future__ import annotations

import argparse
import math

from .._reading import strict_float
from .._version import __version__
from ..errors import shorten
from ..models import FRICTION_MODELS, PRESETS
from ..simulation import MAX_SAMPLES, SOLVERS
from .commands import cmd_demo, cmd_identify, cmd_simulate, cmd_validate
from .report_command import cmd_report
from .outputs import formats_text
from .init import add_init_command
from .presets import add_presets_command
from .propagate import add_propagate_command
from .synth import add_synth_command


def _number(positive):
    """An argparse type: a finite float, positive when asked."""
    def parse(text):
        try:
            v = strict_float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not a number: {shorten(text)}") from None
        if not math.isfinite(v) or (positive and v <= 0):
            raise argparse.ArgumentTypeError(f"must be a {'positive' if positive else 'finite'} number, got {text!r}")
        return v
    return parse


_positive_float = _number(positive=True)
_finite_float = _number(positive=False)


def _int_in(low, high=None):
    """An argparse type: a whole number in [low, high] (high None: no upper bound)."""
    def parse(text):
        try:
            if "_" in text:  # int() takes 1_000; no option value means that
                raise ValueError
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not a whole number: {shorten(text)}") from None
        if v < low:
            raise argparse.ArgumentTypeError(f"must be at least {low}, got {shorten(text)}")
        if high is not None and v > high:
            raise argparse.ArgumentTypeError(f"must be at most {high}, got {shorten(text)}")
        return v
    return parse


_positive_int = _int_in(1)
#: identify.MAX_STARTS, not imported from there (identify loads SciPy); a test keeps them equal
MAX_STARTS = 10_000


def _temperature(text):
    """An argparse type: a plausible temperature [C] (the range of dataset temperatures)."""
    from ..data.experiments import TEMPERATURE_RANGE
    v = _finite_float(text)
    lo, hi = TEMPERATURE_RANGE
    if not lo <= v <= hi:
        raise argparse.ArgumentTypeError(f"{v:g} C is not a plausible temperature (expected {lo:g} to {hi:g} C)")
    return v


def _solver_option(p, help_text):
    """--solver (the integrator); --method, its earlier name, still read (commands.solver_of says it is old)."""
    p.add_argument("--solver", choices=sorted(SOLVERS), default=None, help=help_text)
    p.add_argument("--method", dest="solver_old", choices=sorted(SOLVERS), help=argparse.SUPPRESS)


def _force_options(p, scoring=False):
    """The options of force (torque) data (docs/force-data.md) for commands that read a dataset; ``scoring``: a
    command that scores a fitted model, whose defaults are its fit record's (how identify scored it)."""
    record = " (default: as the model was fitted, from its fit record; else" if scoring else " (default:"
    p.add_argument("--offset", choices=("shared", "per-experiment", "none"),
                   help="force data: the sensor offset, one fitted for all experiments (shared), one "
                        "per experiment (a sensor re-zeroed between runs; in validate, estimated on every "
                        f"experiment, held-out ones included), or none (the model's own){record} shared)")
    p.add_argument("--motion", choices=("auto", "position", "velocity"),
                   help="force data: what drives the model, overriding the dataset's 'motion'" + record +
                        " the dataset's, else auto: the velocity column where it is the position's derivative, else "
                        "the position)")
    p.add_argument("--ripple-phase", choices=("auto", "recorded", "per-run"), default=None if scoring else "auto",
                   help="force data with a position ripple: its angle, the recorded position (recorded), or a phase "
                        "estimated per run where positions are relative to each run (per-run)"
                        + (", as the model was fitted (its fit record), else auto:" if scoring else "; default auto:")
                        + " per-run where every run starts at position 0, else recorded (said among the fit's warnings)")


def _writes(command, dest, what):
    """An output option's help: what it writes and the extensions it takes (outputs.FORMATS, the one list)."""
    how = "by the name's extension; other names are refused" if "or" in formats_text(command, dest) else \
        "other names are refused"
    return f"{what}; writes {formats_text(command, dest)} ({how})"


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
                    f"spring-pulled) or prescribed motion, with any friction model ({', '.join(FRICTION_MODELS)}) "
                    "-- and write time, input, displacements, velocity, friction "
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
    load = s.add_mutually_exclusive_group()
    load.add_argument("--load", type=_finite_float, metavar="L",
                      help="constant load (normal force [N] or load torque [N m]) the model's laws of load read "
                           "(required for a model with one; ignored by a model without)")
    load.add_argument("--load-file", metavar="F.csv",
                      help="load signal: CSV with time[s] and normal_force[N] or load_torque[N*m], linearly "
                           "interpolated")
    s.add_argument("--input", metavar="WAVEFORM", help="input waveform, overriding the model's [input]")
    s.add_argument("--duration", type=_positive_float, default=2.0, metavar="S",
                   help="simulated time [s] (default: 2)")
    s.add_argument("--sample-rate", type=_positive_float, default=10_000.0, metavar="HZ",
                   help="output sample rate [Hz] (default: 10000)")
    s.add_argument("-o", "--output", metavar="OUT.csv", help=_writes(
        "simulate", "output", "the simulation: columns as CSV (docs/formats.md#simulation-output) or MATLAB "
                              "vectors; '-' writes the CSV to standard output"))
    _solver_option(s, "integrator: dopri5 (explicit), rodas4 (stiff), auto (default: dopri5, trying rodas4 when it "
                      "detects stiffness and keeping it only where it is cheaper)")
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
    i.add_argument("dataset", metavar="DATASET", nargs="+",
                   help="dataset folder (with dataset.toml); several, or one folder of dataset folders, identify "
                        "a fleet: each dataset on the Dask cluster, -o DIR gets NAME.toml and NAME.json per "
                        "dataset and the fleet summary fleet.json and fleet.csv (docs/scale.md)")
    i.add_argument("--method", choices=("plant", "base", "model-i", "model-ii", "heat", "warm-up"),
                   default="model-i",
                   help="what to identify: plant (xi, wn, K from a recorded stage response), base (one friction "
                        "model for all temperatures), model-i or model-ii (default: model-i), heat (the "
                        "[heat] section's C_th, R_th, eta from recorded temperature[C] columns), or warm-up "
                        "(force data: Model I's laws and a one- or two-node heat path from warm-up records with "
                        "only the ambient temperature known)")
    i.add_argument("--friction", choices=tuple(FRICTION_MODELS),
                   help="friction model to identify (default: the initial model's); built from the initial model's "
                        "values where they share a parameter (docs/identification.md#friction-models)")
    i.add_argument("--init", metavar="MODEL.toml",
                   help="initial model: file or preset (default: the paper's preset for the method)")
    i.add_argument("--parameters", metavar="NAMES",
                   help="comma-separated friction parameters to fit (default: the friction model's, LuGre's "
                        "sigma0,sigma1,fc), any of the model's: e.g. sigma0,sigma1,fc,fs,vs; with --method model-i "
                        "each gets its own temperature law, with model-ii they are the base parameters")
    i.add_argument("--free", metavar="NAMES",
                   help="plant parameters to fit too, one value shared by all experiments, comma-separated: m_e, m "
                        "(the masses), xi, wn, K (c, k, T_em for a plant in physical form); e.g. --free m_e,m")
    i.add_argument("--procedure", choices=("direct", "paper", "both"), default="direct",
                   help="Model II procedure (default: direct; both: report the paper's too)")
    i.add_argument("--law", action="append", default=[], metavar="PARAM=KIND",
                   help="Model I law kind for a parameter, e.g. sigma0=exp (default: chosen by AICc)")
    i.add_argument("--no-refine", action="store_true",
                   help="skip the joint refinement of the laws on all experiments")
    i.add_argument("--reference-temperature", type=_temperature, metavar="C",
                   help="Model II base temperature, with --method model-ii (default: the lowest fit temperature)")
    i.add_argument("--starts", type=_int_in(1, MAX_STARTS), default=8,
                   help=f"multi-start size, 1 to {MAX_STARTS} (default: 8)")
    i.add_argument("--rtol", type=_positive_float, default=1e-8,
                   help="simulation tolerance during the fit (default: 1e-8)")
    i.add_argument("--seed", type=_int_in(0), default=0, help="seed of the multi-start sample, 0 or more (default: 0)")
    i.add_argument("--max-evaluations", type=_int_in(1, 100_000), metavar="N",
                   help="the most model evaluations of each least-squares stage (default: the stages' own limits)")
    # force (torque) data (docs/force-data.md)
    _force_options(i)
    i.add_argument("--delay", metavar="auto|none|VALUE|MIN:MAX",
                   help="a drive's command data: the delay searched over a range read off the data (auto, the "
                        "default), none (0), held at VALUE [s, or with a unit: 5ms], or searched within MIN:MAX")
    i.add_argument("--no-offset", action="store_true",
                   help="force data: the same as --offset none (hold the initial model's [plant] sensor_offset)")
    i.add_argument("-o", "--output", metavar="FITTED.toml", help=_writes(
        "identify", "output", "the fitted model file, loadable by every command that takes a MODEL")
        + "; with several datasets, the folder DIR that receives NAME.toml and NAME.json per dataset")
    i.add_argument("--json", metavar="RESULTS.json", help=_writes(
        "identify", "json", "the results (docs/formats.md#results-json), as JSON or as MATLAB structs"))
    i.add_argument("-q", "--quiet", action="store_true", help="no progress and no report")
    _scheduler_options(i, " (several datasets only)")
    i.set_defaults(run=cmd_identify)

    v = sub.add_parser("validate", help="predict every experiment of a dataset with a model: the metrics of docs/formats.md#validation-metrics",
                       description="Simulate each experiment of DATASET with MODEL and report the paper's maximum "
                                   "prediction error, RMSE, NRMSE, final-displacement error and per-cycle step-size "
                                   "error, as a table and (with --json) as JSON.")
    v.add_argument("model", metavar="MODEL.toml", help="model file or preset")
    v.add_argument("dataset", metavar="DATASET", help="dataset folder (with dataset.toml)")
    v.add_argument("--json", metavar="METRICS.json", help=_writes(
        "validate", "json", "the metrics (docs/formats.md#validation-metrics), as JSON or as MATLAB structs"))
    _force_options(v, scoring=True)
    v.set_defaults(run=cmd_validate)

    r = sub.add_parser("report", help="an HTML report comparing models on a dataset",
                       description="Compare one or more models on a dataset in one self-contained HTML file "
                                   "(figures inlined as SVG; it opens offline). Identification results are read "
                                   "from a JSON file beside each model file (same name, .json), when there is one.")
    r.add_argument("paths", nargs="+", metavar="MODEL.toml... DATASET",
                   help="one or more model files (or presets), then the dataset folder")
    r.add_argument("-o", "--output", required=True, metavar="REPORT.html", help=_writes(
        "report", "output", "the report, one self-contained HTML file"))
    r.add_argument("--figures", metavar="DIR", help="also write every figure as SVG and PNG into DIR")
    r.add_argument("--title", help="the report's title")
    r.add_argument("--bands", metavar="BANDS.json",
                   help="add the prediction bands that 'thermofriction propagate -o BANDS.json' wrote (displacement "
                        "data)")
    _force_options(r, scoring=True)
    r.set_defaults(run=cmd_report)

    d = sub.add_parser("demo", help="the main job: synthesise the example dataset, identify, validate, report",
                       description="Synthesise the bundled example dataset from the paper's preset (seeded, with "
                                   "sensor noise, quantisation and temperature-sensor noise; two temperatures held "
                                   "out), identify Model I, Model II and a model without thermal effects, validate "
                                   "them and write report.html with the models and JSON results.")
    d.add_argument("-o", "--output", default="thermofriction-demo", metavar="DIR",
                   help="output folder (default: thermofriction-demo)")
    d.set_defaults(run=cmd_demo)

    _add_fmu_command(sub)

    add_synth_command(sub)
    _add_sweep_command(sub)
    add_presets_command(sub)
    add_init_command(sub)
    add_propagate_command(sub, temperature=_temperature, positive_float=_positive_float, int_in=_int_in,
                          writes=_writes, scheduler_options=_scheduler_options)
    return p


def _add_fmu_command(sub):
    """`thermofriction fmu`: export a model as an FMI 2.0 co-simulation FMU (docs/fmu.md)."""
    f = sub.add_parser(
        "fmu", help="export a model as an FMI 2.0 co-simulation FMU for Simulink, OpenModelica, fmpy, ... (docs/fmu.md)",
        description="Write MODEL as an FMI 2.0 (or, with --fmi 3, FMI 3.0) co-simulation FMU for Linux x86-64 and, "
                    "when the package was built with the MinGW-w64 cross compiler (or --platforms asks for it), Windows "
                    "x86-64 (the C core inside, the C library its only dependency), with its C sources, from "
                    "which an importer compiles it for any other platform. Inputs: the plant's drive (voltage, force or motion) and, for Model I "
                    "and II, the temperature [C] (with a [heat] section, the ambient temperature), and for a law of the load "
                    "the load (normal_force [N], or load_torque [N m] for a rotary joint). Outputs: "
                    "displacement, velocity, friction force, the stage displacement (stick-slip) and the "
                    "temperature (heat). Every plant, friction, law and heat parameter is a tunable parameter. "
                    "The model's [input] is not part of the FMU: the importer drives it.",
        epilog="Examples: thermofriction fmu li2009-model-i -o li2009-model-i.fmu; "
               "thermofriction fmu li2009-model-i -o rt.fmu --solver realtime --step 1e-5")
    f.add_argument("model", metavar="MODEL", help="model file (.toml) or preset name")
    f.add_argument("-o", "--output", required=True, metavar="OUT.fmu", help=_writes("fmu", "output", "the FMU file"))
    f.add_argument("--temperature", type=_finite_float, metavar="C",
                   help="start value of the temperature input [C] (with [heat]: of the ambient temperature)")
    f.add_argument("--load", type=_finite_float, metavar="N",
                   help="a model with a law of the load: start value of its load input [N, or N m for a rotary "
                        "joint] (default: the middle of the load laws' range of |load|)")
    f.add_argument("--model-identifier", metavar="NAME",
                   help="the FMU's model identifier, letters, digits and _ (default: from the model's name)")
    f.add_argument("--solver", choices=("adaptive", "realtime"), default=None,
                   help="between communication points: the adaptive error-controlled integrator (default; for "
                        "accuracy) or fixed real-time steps of --step seconds (a deterministic cost per step)")
    f.add_argument("--integrator", dest="solver_old", choices=("adaptive", "realtime"), help=argparse.SUPPRESS)
    f.add_argument("--step", type=_finite_float, metavar="SECONDS",
                   help="the realtime solver's fixed step [s], e.g. 1e-5 (a tenth of the fastest time "
                        "constant or less)")
    f.add_argument("--fmi", type=int, choices=(2, 3), default=2, help="the FMI version: 2 (default) or 3")
    f.add_argument("--platforms", type=_platform_list, metavar="LIST",
                   help="build the binaries for these platforms now, comma-separated: linux64 (cc), win64 "
                        "(x86_64-w64-mingw32-gcc); none: the C sources only (every FMU carries them). Default: the "
                        "binaries built with the package")
    from .commands import cmd_fmu
    f.set_defaults(run=cmd_fmu)


def _platform_list(text: str) -> list[str]:
    """--platforms: comma-separated names (checked by export_fmu); none: no binary."""
    names = [name.strip() for name in text.split(",") if name.strip()]
    return [] if names == ["none"] else names


def _scheduler_options(parser, only=""):
    """Where the work runs (docs/scale.md): shared by sweep and fleet identification."""
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="an existing Dask cluster: tcp://HOST:8786 or a scheduler file; 'processes' starts a "
                             "local Dask cluster of worker processes; 'sequential' runs in this process, in order "
                             f"(default: threads in this process, one per core){only}")
    parser.add_argument("--workers", type=_positive_int, metavar="N",
                        help=f"threads, or worker processes of the local Dask cluster (default: one per core){only}")


def _add_sweep_command(sub):
    from ..scale.sweep import DEFAULT_METRICS, METRICS
    from .commands import cmd_sweep

    w = sub.add_parser(
        "sweep", help="a design map: simulate a model at every point of a grid, one row of metrics per point",
        description="Simulate MODEL at every point of the grid given by the --grid options (their Cartesian "
                    "product, the last varying fastest) and write one row per point: the point's coordinates, "
                    "then the metrics. Runs on threads on this machine's cores, a local Dask cluster or an "
                    "existing one (--scheduler). A point that fails is written with empty metrics and its reason "
                    "in the error column; the others go on (exit status 1 when any failed).",
        epilog="Grid names: temperature [C]; load [N, or N m for a rotary joint] for a model with a law of the load; "
               "a field of the input waveform (amplitude, frequency, rise, offset, "
               "duty, slew); a model parameter (sigma0, sigma1, fc, fs, vs, sigma2, a law coefficient such as "
               "sigma0.b, dF.values[1], a plant parameter such as m_e). Metrics: "
               + "; ".join(f"{k} [{u}] {what}" for k, (u, what, _) in METRICS.items()) + ".")
    w.add_argument("model", metavar="MODEL", help="model file (.toml) or preset name")
    w.add_argument("--grid", action="append", required=True, metavar="NAME=VALUES",
                   help="an axis: NAME=START:STOP:STEP (STOP included) or NAME=V1,V2,...; repeat for more axes")
    w.add_argument("--input", metavar="WAVEFORM", help="input waveform, overriding the model's [input]")
    w.add_argument("--temperature", type=_finite_float, metavar="C",
                   help="temperature [C] of every point, when the grid has no temperature axis")
    w.add_argument("--duration", type=_positive_float, default=1.0, metavar="S",
                   help="simulated time per point [s] (default: 1)")
    w.add_argument("--sample-rate", type=_positive_float, default=10_000.0, metavar="HZ",
                   help="output sample rate [Hz] the metrics are taken from (default: 10000)")
    w.add_argument("--metrics", default=",".join(DEFAULT_METRICS), metavar="NAMES",
                   help=f"comma-separated metrics (default: {','.join(DEFAULT_METRICS)})")
    _solver_option(w, "integrator (default: auto)")
    w.add_argument("--rtol", type=_positive_float, default=1e-6, help="relative tolerance (default: 1e-6)")
    _scheduler_options(w)
    w.add_argument("--batch-size", type=_positive_int, metavar="N",
                   help="points per task (default: sized from the first points' time, at least ~20 ms of work "
                        "each on threads and ~100 ms on Dask, 4 or more per worker)")
    w.add_argument("-o", "--output", required=True, metavar="SWEEP.csv", help=_writes(
        "sweep", "output", "the table: CSV ('-' for standard output), MATLAB vectors (one per column), or "
                           "Parquet (needs pyarrow)"))
    w.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no summary")
    w.set_defaults(run=cmd_sweep)

