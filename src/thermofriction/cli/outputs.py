"""The command line's outputs: checked before any work, never one of the run's inputs."""

from __future__ import annotations

import os

from .. import _io
from ..errors import shorten
from ..models import PRESETS
from ..waveforms import Sampled


_OUTPUT_FILES = {"simulate": {"output": "-o"}, "identify": {"output": "-o", "json": "--json"},
                 "validate": {"json": "--json"}, "report": {"output": "-o"},
                 "fmu": {"output": "-o"},
                 "sweep": {"output": "-o"}, "propagate": {"output": "-o"}}

#: (command, argparse dest) -> the extensions that output writes (the first is the usual one); any other name is
#: refused before any work (standard output '-', a character device or a FIFO take the first format)
FORMATS = {("simulate", "output"): (".csv", ".mat"), ("identify", "output"): (".toml",),
           ("identify", "json"): (".json", ".mat"), ("validate", "json"): (".json", ".mat"),
           ("report", "output"): (".html", ".htm"), ("fmu", "output"): (".fmu",),
           ("sweep", "output"): (".csv", ".mat", ".parquet"), ("propagate", "output"): (".json", ".csv", ".mat")}


def _check_outputs(args):
    """Resolves and checks every output file of the command (args.targets: dest -> Target)."""
    args.targets = {}
    if _fleet_output(args):
        return
    for dest, option in _OUTPUT_FILES.get(args.command, {}).items():
        path = getattr(args, dest, None)
        if path is not None and path != "-":  # (an empty path is refused, not taken for none)
            target = _io.Target(path, option)
            check_extension(args.command, dest, option, path, stream=target.kind == "stream")
            args.targets[dest] = target.check()
    _io.refuse_inputs(args.targets.values(), ())  # two outputs that are one file
    for option, folder in (("--figures", getattr(args, "figures", None)),
                           ("-o", args.output if args.command == "demo" else None)):
        if folder:
            _io.check_folder(folder, f"{option} {folder}")


def formats_text(command: str, dest: str) -> str:
    """The extensions an output writes, for messages and help texts: ".csv or .mat"."""
    exts = FORMATS[command, dest]
    return ", ".join(exts[:-1]) + " or " + exts[-1] if len(exts) > 1 else exts[0]


def check_extension(command, dest, option, path, stream=False):
    """Exit 2 when an output's name ends in an extension the command does not write (``-o out.xlsx``): one
    message naming the option, the value and the extensions it writes. A stream (a device, a FIFO) has no
    name to judge."""
    exts = FORMATS.get((command, dest))
    if exts is None or stream:
        return
    name = os.path.basename(os.fsdecode(os.fspath(path)))
    ext = os.path.splitext(name)[1].lower()
    if ext not in exts:
        what = f"unknown extension '{os.path.splitext(name)[1]}'" if ext else "no extension"
        hint = " (the results JSON is --json)" if (command, dest) == ("identify", "output") and ext == ".json" else ""
        shown = os.fspath(path) if len(os.fspath(path)) <= 100 else shorten(os.fspath(path))
        raise _io.OutputError(f"{option} {shown}: {what}; {command} {option} writes "
                              f"{formats_text(command, dest)}{hint}")


def _fleet_output(args) -> bool:
    """identify with several datasets writes into the folder -o DIR (scale/fleet.py): checked as one."""
    if args.command != "identify":
        return False
    from ..scale.fleet import fleet_datasets
    if fleet_datasets(args.dataset) is None:
        return False
    if args.output:
        _io.check_folder(args.output, f"-o {args.output}")
    return True


def _target(args, dest):
    """The checked Target of an output (main() made it), or the path when a command runs on its own."""
    return getattr(args, "targets", {}).get(dest) or getattr(args, dest)


def _refuse_inputs(args, *inputs):
    """Exit 2 before any work when an output is one of the run's input files."""
    flat = []
    for i in inputs:
        flat.extend(i if isinstance(i, (list, tuple)) else [i])
    _io.refuse_inputs(getattr(args, "targets", {}).values(), [os.fspath(i) for i in flat if i])


def _waveform_inputs(waveform):
    f = getattr(waveform, "file", None) if isinstance(waveform, Sampled) else None
    return [f] if f else []


def _model_inputs(path, model):
    """The files a model argument reads: the model file (not a preset) and a sampled input's file."""
    if not path or path in PRESETS:
        return []
    files = [path]
    inp = getattr(model, "input", None)
    for f in _waveform_inputs(inp):
        files += [f, os.path.join(os.path.dirname(os.fspath(path)), f)]
    return files


def _dataset_inputs(data):
    """A dataset's manifest and experiment files."""
    return [os.path.join(data.path, "dataset.toml")] + [os.path.join(data.path, e.file) for e in data.experiments]

