"""Connecting to an existing Dask scheduler (``scheduler="tcp://HOST:8786"`` or a scheduler file): the
file read here and the address probed, so that a damaged file or something else than a scheduler at the
address is one message naming it, not Dask's traceback or a wait without end."""

from __future__ import annotations

import os

from ..errors import InputError

#: a Dask scheduler file is a few hundred bytes of JSON (dask scheduler --scheduler-file)
_SCHEDULER_FILE_LIMIT = 1 << 20
#: a Dask message's 8-byte length prefix beyond this is not a greeting (text read as a length: ~1e18)
_GREETING_LIMIT = 1 << 26


def read_scheduler_file(path) -> str:
    """The address in a scheduler file (JSON with an ``address``, as ``dask scheduler --scheduler-file``
    writes it), or one InputError naming the file: Dask's own reader fails on a damaged file with an
    AssertionError or a KeyError."""
    from .._reading import read_text

    what = "a Dask scheduler file (JSON with an \"address\", as 'dask scheduler --scheduler-file' writes)"
    try:
        if os.path.getsize(path) > _SCHEDULER_FILE_LIMIT:
            raise InputError(f"scheduler {path}: not {what}: {os.path.getsize(path)} bytes")
        text = read_text(path, "scheduler file")
    except OSError as e:
        raise InputError(f"scheduler {path}: cannot read ({e.strerror or e})") from None
    except UnicodeDecodeError:
        raise InputError(f"scheduler {path}: not {what}: not UTF-8 text") from None
    import json
    try:
        info = json.loads(text)
    except ValueError as e:
        raise InputError(f"scheduler {path}: not {what}: {e}") from None
    address = info.get("address") if isinstance(info, dict) else None
    if not isinstance(address, str) or not address.strip():
        raise InputError(f"scheduler {path}: not {what}: no \"address\" in it")
    return address.strip()


def probe(address):
    """For a TCP address: when something answers there, that it greets as a Dask scheduler does (at once,
    with a message of a plausible length), so that an HTTP or SSH server is named as not a scheduler instead
    of Dask waiting forever or reading its text as a 3 EiB message ("out of memory"). Nothing listening, or
    another protocol (tls://, ucx://): left to Dask, which retries until its connect timeout."""
    import re
    import socket
    import struct

    m = re.fullmatch(r"(?:tcp://)?\[?([^\[\]/]+?)\]?:(\d+)/?", address)
    if m is None:
        return
    host, port = m.group(1), int(m.group(2))
    timeout = _connect_timeout()
    try:
        sock = socket.create_connection((host, port), timeout=timeout)
    except OSError:
        return  # Dask tries again until its timeout and then says so
    with sock:
        head = b""
        try:
            while len(head) < 8:
                chunk = sock.recv(8 - len(head))
                if not chunk:
                    break
                head += chunk
        except OSError:  # socket.timeout included
            pass
    if len(head) < 8:
        said = f"it sent {head!r} and closed the connection" if head else f"it said nothing within {timeout:g} s"
        raise InputError(f"scheduler {address}: not a Dask scheduler ({said}; a scheduler greets a client at once); "
                         f"start one with 'dask scheduler' (docs/scale.md)")
    (length,) = struct.unpack("<Q", head)
    if not 0 < length <= _GREETING_LIMIT:
        raise InputError(f"scheduler {address}: not a Dask scheduler (it answered {head!r}...); start one with "
                         f"'dask scheduler' (docs/scale.md)")


def _connect_timeout() -> float:
    """Dask's connect timeout [s] (distributed.comm.timeouts.connect), 30 s where it cannot be read."""
    try:
        import dask.config
        from dask.utils import parse_timedelta
        return float(parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"), default="s"))
    except Exception:  # noqa: BLE001 - a hint only
        return 30.0


__all__ = ["read_scheduler_file", "probe"]
