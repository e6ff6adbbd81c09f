"""A pytest plugin that records every identification the tests run, for checking that a behaviour-preserving
change is behaviour-preserving (issue 39: identification results identical before and after, 1e-10 relative).

Use: ``THERMOFRICTION_RECORD_FITS=before.jsonl pytest -p record_fits tests/`` on the old code, the same with
``after.jsonl`` on the new (with ``PYTHONPATH=tests/record_fits_site`` the command lines the tests start are
recorded too), then ``python tests/record_fits.py before.jsonl after.jsonl [--subset]`` (``--subset``: only the tests the
second run ran). Every call of
``thermofriction.identify`` (the API, the fleet and the command line's in-process calls) writes one line: the test,
the call's number in it, and the result's JSON (``to_dict()``) less what is not a result (wall times, paths)."""

from __future__ import annotations

import functools
import json
import math
import os
import re
import sys

#: keys whose values are not results of the fit (times, files on this machine)
IGNORED = {"wall_time", "created", "date", "data", "path", "file", "folder", "seconds", "elapsed", "time_s"}

_current = {"test": None, "count": 0}
_PORT = re.compile(r"tcp://[\w.]+:\d+")  # (a Dask worker's address differs per run)
_TMP = re.compile(r"\S*?/pytest-\d+/|/tmp/tmp\w+/")


def _plain(x):
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items() if str(k) not in IGNORED}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if hasattr(x, "tolist"):
        return _plain(x.tolist())
    if isinstance(x, float) and not math.isfinite(x):
        return repr(x)
    return x if isinstance(x, (int, float, str, bool)) or x is None else repr(x)


def _wrap(identify, out):
    @functools.wraps(identify)
    def recorded(*args, **kwargs):
        result = identify(*args, **kwargs)
        _current["count"] += 1
        try:
            body = _plain(result.to_dict())
        except Exception as exc:  # noqa: BLE001 - a result that cannot be written is recorded as such
            body = {"unrecordable": repr(exc)}
        with open(out, "a", encoding="utf-8") as fh:
            fh.write(json.dumps({"test": _current["test"], "call": _current["count"], "result": body}) + "\n")
        return result
    return recorded


def pytest_configure(config):
    out = os.environ.get("THERMOFRICTION_RECORD_FITS")
    if not out:
        return
    import thermofriction as tf
    import thermofriction.identification as identification
    wrapped = _wrap(identification.identify, out)
    tf.identify = wrapped
    identification.identify = wrapped


def install_in_child():
    """In a command line a test started: every identification keyed by the test and the command's arguments."""
    import thermofriction.identification as identification
    test = os.environ["PYTEST_CURRENT_TEST"].rsplit(" (", 1)[0]
    args = _TMP.sub("<tmp>/", " ".join(sys.argv[1:]))
    _current["test"] = f"{test} [cli {args}]"
    identification.identify = _wrap(identification.identify, os.environ["THERMOFRICTION_RECORD_FITS"])


def pytest_runtest_setup(item):
    _current["test"], _current["count"] = item.nodeid, 0


def _close(a, b, rtol, path, bad):
    if isinstance(a, float) or isinstance(b, float):
        if not (isinstance(a, (int, float)) and isinstance(b, (int, float))):
            bad.append(f"{path}: {a!r} vs {b!r}")
        elif abs(a - b) > rtol * max(abs(a), abs(b)) and not (a == b):
            bad.append(f"{path}: {a!r} vs {b!r} (rel {abs(a - b) / max(abs(a), abs(b)):.1e})")
    elif isinstance(a, dict) and isinstance(b, dict):
        for k in sorted((set(a) | set(b)) - IGNORED):
            if k not in a or k not in b:
                bad.append(f"{path}.{k}: only in {'before' if k in a else 'after'}")
            else:
                _close(a[k], b[k], rtol, f"{path}.{k}", bad)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            bad.append(f"{path}: {len(a)} items vs {len(b)}")
        for i, (x, y) in enumerate(zip(a, b)):
            _close(x, y, rtol, f"{path}[{i}]", bad)
    elif isinstance(a, str) and isinstance(b, str):
        if _TMP.sub("<tmp>/", a) != _TMP.sub("<tmp>/", b):  # (a test's temporary folder differs per run)
            bad.append(f"{path}: {a!r} vs {b!r}")
    elif a != b:
        bad.append(f"{path}: {a!r} vs {b!r}")


def compare(before: str, after: str, rtol: float = 1e-10, subset: bool = False) -> list[str]:
    """The differences between two recordings, one line each (empty: identical to ``rtol``); with ``subset``,
    only the tests the second recording ran (a part of the suite run after a change against all of it before)."""
    def load(p):
        with open(p, encoding="utf-8") as fh:
            return {(_PORT.sub("tcp://<host>", r["test"]), r["call"]): r["result"] for r in map(json.loads, fh)}
    a, b = load(before), load(after)
    if subset:
        ran = {t for t, _ in b}
        a = {k: v for k, v in a.items() if k[0] in ran}
    bad = [f"{k}: only in {'before' if k in a else 'after'}" for k in sorted(set(a) ^ set(b))]
    for k in sorted(set(a) & set(b)):
        _close(a[k], b[k], rtol, f"{k[0]}#{k[1]}", bad)
    return bad


if __name__ == "__main__":
    subset = "--subset" in sys.argv
    paths = [a for a in sys.argv[1:] if a != "--subset"]
    diffs = compare(paths[0], paths[1], float(paths[2]) if len(paths) > 2 else 1e-10, subset=subset)
    print("\n".join(diffs[:200]) or "identical")
    print(f"{len(diffs)} differences", file=sys.stderr)
    sys.exit(1 if diffs else 0)
