"""Reading input files and numbers strictly.

Only regular files are read: a device such as /dev/zero never ends and a FIFO may block forever,
so either is refused with one line before anything is read. Numbers in CSV cells and option values
are read by ``strict_float``: Python's ``float()`` also takes ``1_0`` (as 10), which no data file
means.
"""

from __future__ import annotations

import os
import stat

from .errors import InputError

_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"))


def _kind(mode) -> str:
    for test, name in _KINDS:
        if test(mode):
            return name
    return "not a regular file"


def _a(what: str) -> str:
    return ("an " if what[:1] in "aeiou" else "a ") + what


def read_bytes(path, what: str = "file") -> bytes:
    """The bytes of the regular file ``path``; InputError for anything else (a folder, a device, a
    FIFO). OSError (a missing file, no permission) is left to the caller, which names it."""
    # O_NONBLOCK: opening a FIFO for reading must not wait for a writer; cleared before reading
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            kind = _kind(mode)
            if kind == "a folder":
                raise InputError(f"{path}: is a folder, not {_a(what)}")
            raise InputError(f"{path}: is {kind}, not a regular file: give {_a('regular ' + what)} (input from a device "
                             f"or a pipe may never end)")
        os.set_blocking(fd, True)
        with os.fdopen(fd, "rb") as fh:
            fd = None
            return fh.read()
    finally:
        if fd is not None:
            os.close(fd)


def read_input_file(path, what: str = "file") -> bytes:
    """``read_bytes`` with every failure as one InputError naming the file: missing, a folder, unreadable,
    or a name the system cannot use (a NUL byte)."""
    try:
        return read_bytes(path, what)
    except InputError:  # a folder or a device, named by read_bytes (InputError is a ValueError: not below)
        raise
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder, not {_a(what)}") from None
    except OSError as e:
        raise InputError(f"{path}: cannot read ({e.strerror or e})") from None
    except ValueError as e:  # a NUL byte in the path
        raise InputError(f"{str(path)!r}: not a usable file name ({e})") from None


def read_input_json(path, what: str = "JSON file"):
    """The JSON value in ``path``, every failure (the file, its encoding, its syntax) as one InputError naming it."""
    import json

    try:
        return json.loads(read_input_file(path, what).decode("utf-8"))
    except UnicodeDecodeError as e:
        raise InputError(f"{path}: not UTF-8 text ({e.reason} at byte {e.start})") from None
    except InputError:
        raise
    except (ValueError, RecursionError) as e:
        raise InputError(f"{path}: not JSON ({e})") from None


def read_text(path, what: str = "file", encoding: str = "utf-8") -> str:
    """``read_bytes`` decoded (UnicodeDecodeError is left to the caller)."""
    return read_bytes(path, what).decode(encoding)


def strict_float(text: str) -> float:
    """``float(text)`` without the underscores Python allows between digits (``1_0`` is 10 there);
    ValueError otherwise."""
    if "_" in text:
        raise ValueError(f"could not convert string to float: {text!r}")
    return float(text)


__all__ = ["read_bytes", "read_input_file", "read_text", "strict_float"]
