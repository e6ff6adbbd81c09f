"""A drive's delay as identification takes it (docs/force-data.md#drives-without-a-torque-sensor): ``auto`` (searched
over a range read off the data), ``none`` (0, not fitted), a value held, or a range ``MIN:MAX`` searched; and the
range the search covers (:func:`search_range`), with the reason it ends where it does.

The automatic range spans, either way, the least of: half the motion's time scale ``rms(v) / rms(a)`` (a sine's
period over 2 pi: a delay of that size shifts the motion by half a radian, 29 degrees, far beyond a drive that
follows it; wider, a misaligned record finds minima within, and a periodic motion aliases delays a period apart),
a quarter of the shortest record, and MAX_DELAY_SAMPLES sampling intervals."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np

from .. import _args
from ..errors import ComputationError, InputError, shorten

#: the automatic search spans at most this many sampling intervals either way (each one a least squares)
MAX_DELAY_SAMPLES = 200
#: ... and at most this fraction of the motion's time scale rms(v)/rms(a)
MOTION_FRACTION = 0.5
KINDS = ("auto", "none", "value", "range")
_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}
_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(s|ms|us|µs)?\s*$")
HOW_TO_WIDEN = "give the range to search: --delay MIN:MAX (e.g. 0:200ms; Python: delay=(0.0, 0.2))"


@dataclasses.dataclass(frozen=True)
class DelaySpec:
    """How the fit takes the delay: ``kind`` one of KINDS; ``lo``/``hi`` [s] the value (both) or the range."""

    kind: str = "auto"
    lo: float = 0.0
    hi: float = 0.0

    def __str__(self) -> str:
        if self.kind in ("auto", "none"):
            return self.kind
        if self.kind == "value":
            return f"{self.lo * 1e3:.6g}ms"
        return f"{self.lo * 1e3:.6g}ms:{self.hi * 1e3:.6g}ms"


AUTO = DelaySpec()


def _seconds(value, name: str, whole) -> float:
    if _args.is_number(value):
        x = float(value)
    else:
        m = _QUANTITY.match(value) if isinstance(value, str) else None
        if not m:
            raise InputError(f"{name} must be auto, none, a delay in seconds (or with a unit: 5ms, 500us) or a range "
                             f"MIN:MAX, got {shorten(whole)}")
        x = float(m.group(1)) * _UNITS[m.group(2) or "s"]
    if not math.isfinite(x) or abs(x) > 1e3:
        raise InputError(f"{name}: a delay must be finite and at most 1000 s, got {shorten(whole)}")
    return x


def parse_delay(value, name: str = "delay") -> DelaySpec:
    """``value`` as a DelaySpec: "auto"; None or "none"; a number [s] or a string with a unit ("5ms"); a range
    "MIN:MAX" or a (min, max) pair. One InputError naming ``name`` otherwise."""
    if isinstance(value, DelaySpec):
        return value
    if value is None or (isinstance(value, str) and value.strip().lower() == "none"):
        return DelaySpec("none")
    if isinstance(value, str) and value.strip().lower() == "auto":
        return AUTO
    if isinstance(value, str) and ":" in value:
        value_pair = value.split(":")
        if len(value_pair) != 2:
            raise InputError(f"{name}: a range is MIN:MAX, got {shorten(value)}")
    elif isinstance(value, (tuple, list)):
        value_pair = list(value)
        if len(value_pair) != 2:
            raise InputError(f"{name}: a range is a (min, max) pair, got {shorten(value)}")
    else:
        return DelaySpec("value", _seconds(value, name, value), _seconds(value, name, value))
    lo, hi = (_seconds(v, name, value) for v in value_pair)
    if not lo < hi:
        raise InputError(f"{name}: a range's minimum must be below its maximum, got {shorten(value)}")
    return DelaySpec("range", lo, hi)


def median_interval(times) -> float:
    return float(np.median(np.concatenate([np.diff(np.asarray(t, float)) for t in times])))


def search_range(spec: DelaySpec, times, velocities, accelerations):
    """The candidate delays of a search, whole sampling intervals: (dt, the integers k of the delays k dt, the
    reason the range ends where it does). ``auto``: the module's rule; ``range``: within MIN:MAX (at least three
    intervals, within half the shortest record, else InputError naming ``delay``)."""
    dt = median_interval(times)
    shortest = min(len(t) for t in times)
    if spec.kind == "range":
        ks = np.arange(math.ceil(spec.lo / dt - 1e-9), math.floor(spec.hi / dt + 1e-9) + 1)
        if ks.size < 3:
            raise InputError(f"delay: the range {spec} spans fewer than 3 sampling intervals ({dt * 1e3:.4g} ms): "
                             f"widen it, or hold the delay at a value")
        if max(abs(ks[0]), abs(ks[-1])) > shortest // 2:
            raise InputError(f"delay: the range {spec} reaches beyond half the shortest record "
                             f"({shortest // 2 * dt * 1e3:.4g} ms)")
        return dt, ks, f"the range given ({spec})"
    v = np.concatenate([np.asarray(x, float) for x in velocities])
    a = np.concatenate([np.asarray(x, float) for x in accelerations])
    rms_a = float(np.sqrt(np.mean(a ** 2)))
    scale = float(np.sqrt(np.mean(v ** 2))) / rms_a if rms_a > 0 else math.inf
    bounds = {f"half the motion's time scale rms(v)/rms(a) = {scale * 1e3:.4g} ms":
              int(round(MOTION_FRACTION * scale / dt))
              if math.isfinite(scale) else MAX_DELAY_SAMPLES,
              f"a quarter of the shortest record ({shortest // 4 * dt * 1e3:.4g} ms)": shortest // 4,
              f"{MAX_DELAY_SAMPLES} sampling intervals": MAX_DELAY_SAMPLES}
    why = min(bounds, key=bounds.get)
    K = max(1, bounds[why])
    return dt, np.arange(-K, K + 1), f"±{K * dt * 1e3:.4g} ms: {why}"


def check_not_at_end(spec: DelaySpec, i: int, ks, dt: float, reason: str) -> None:
    """A search whose least residuals lie at its end (index ``i`` of ``ks``) gave no estimate: ComputationError
    saying the range searched and how to widen it."""
    if ks.size < 3 or 0 < i < ks.size - 1:
        return
    at, span = ks[i] * dt * 1e3, f"{ks[0] * dt * 1e3:.4g} to {ks[-1] * dt * 1e3:.4g} ms"
    if spec.kind == "range":
        raise ComputationError(
            f"the delay's least residuals lie at the end of the range given ({spec}: {at:.4g} ms): no estimate "
            f"within it. Widen the range (--delay MIN:MAX), or check that the command and the motion are recorded "
            f"on the same clock (docs/force-data.md#drives-without-a-torque-sensor)")
    raise ComputationError(
        f"the command and the motion look misaligned in time by {abs(at):.4g} ms or more: the delay search's least "
        f"residuals lie at its end ({at:.4g} ms; it searched {span}, {reason}), or the motion does not determine a "
        f"delay. Check that the command and the motion are recorded on the same clock; to search further, "
        f"{HOW_TO_WIDEN}; or hold it (--delay VALUE) or drop it (--delay none) "
        f"(docs/force-data.md#drives-without-a-torque-sensor)")


__all__ = ["DelaySpec", "AUTO", "KINDS", "parse_delay", "search_range", "check_not_at_end", "median_interval",
           "MAX_DELAY_SAMPLES", "HOW_TO_WIDEN"]
