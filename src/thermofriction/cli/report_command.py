"""`thermofriction report`: an HTML page comparing models on a dataset, with the prediction bands of a propagation
(docs/cli.md#report)."""

from __future__ import annotations

import sys

from .. import _io
from .._progress import Progress
from ..errors import InputError
from ..models import load_model
from .outputs import _dataset_inputs, _model_inputs, _refuse_inputs


def cmd_report(args) -> int:
    from ..data import load_dataset

    if len(args.paths) < 2:
        raise InputError("report needs at least one model and a dataset: MODEL.toml... DATASET")
    *model_paths, dataset = args.paths
    with Progress("report") as progress:
        progress.stage(f"reading {dataset}")  # a file of millions of rows takes a while
        data = load_dataset(dataset, motion=args.motion)
        progress.stage(f"simulating the models on {len(data.experiments)} experiments, writing {args.output}")
        _report(args, model_paths, data)
    print(f"wrote {args.output}" + (f" and the figures in {args.figures}" if args.figures else ""))
    return 0


def _report(args, model_paths, data):
    """The models (each with its results JSON where one sits beside it) compared on ``data``, written."""
    import json
    from pathlib import Path

    from ..reporting import Entry, entry_label, report

    entries = []
    inputs = list(_dataset_inputs(data)) + ([args.bands] if args.bands else [])
    bands = _bands(args.bands, data)
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
        report(entries, data, args.output, figures_dir=args.figures, title=args.title, bands=bands,
               command="thermofriction " + " ".join(sys.argv[1:]), offset=args.offset, motion=args.motion,
               ripple_phase=args.ripple_phase)


def _bands(path, data):
    """report --bands: the propagation result that propagate -o X.json wrote; the displacement page shows it."""
    if not path:
        return None
    from ..measurements import measurement_of
    from ..scale.propagate import load_propagation
    if measurement_of(data).name != "displacement":
        raise InputError(f"--bands {path}: prediction bands are shown for displacement data; {data.path} holds "
                         f"{measurement_of(data).name} data")
    return load_propagation(path)


__all__ = ["cmd_report"]
