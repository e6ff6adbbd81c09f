"""File output that never leaves a partly written file behind."""

from __future__ import annotations

import contextlib
import json
import math
import os
import tempfile
from pathlib import Path

from .errors import InputError


@contextlib.contextmanager
def atomic_write(path, mode="w", **kwargs):
    """Writes to a temporary file in the target's folder and renames it over the target only
    when the block finishes; on any error (or Ctrl-C) the temporary file is removed."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise InputError(f"{path}: folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, mode, **kwargs) as fh:
            yield fh
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 is for the temporary file, not the output
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def jsonable(obj):
    """Plain JSON types: arrays to lists, non-finite floats to "inf"/"-inf"/"nan" strings (JSON
    has none), numpy scalars to Python ones."""
    import numpy as np
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        return x if math.isfinite(x) else ("inf" if x > 0 else "-inf" if x < 0 else "nan")
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def dump_json(data: dict, path=None) -> str:
    """JSON text of ``data``; written atomically to ``path`` when given."""
    text = json.dumps(jsonable(data), indent=2, allow_nan=False)
    if path is not None:
        with atomic_write(path, "w") as fh:
            fh.write(text + "\n")
    return text
