"""The ``thermofriction`` command line: a thin layer over the library (docs/cli.md).

Every error is one line on stderr naming the file, key or value, with exit status 2 for
usage and data errors and 1 for failed computations; outputs are written atomically.
"""

from __future__ import annotations

import os
import sys
import warnings

from .. import _io
from ..errors import ThermofrictionError
from .commands import cmd_demo, cmd_identify, cmd_simulate, cmd_validate
from .report_command import cmd_report
from .outputs import _check_outputs
from .parser import MAX_STARTS, build_parser


def _run(args):
    """The command's function, looked up here when it is called (so that it can be replaced, e.g. in tests);
    the others' (synth, presets, ...) are the ``run`` their parsers set."""
    return globals().get(f"cmd_{args.command}", args.run)


def main(argv=None) -> int:
    # NumPy's "overflow encountered in ..." says nothing a user can act on: results are checked
    # (non-finite outputs and values are refused with a message of their own)
    warnings.filterwarnings("ignore", message=".* encountered in ", category=RuntimeWarning)
    _tolerant_streams()
    parser = build_parser()
    args = parser.parse_args(argv)
    caught = []

    def show(message, category, filename, lineno, file=None, line=None):
        text = f"warning: {message}"
        if text in caught:  # said once per command: a report simulates a model hundreds of times
            return
        caught.append(text)
        print(f"thermofriction: {text}", file=sys.stderr)

    warnings.showwarning = show
    handlers = _io.install_signal_handlers()  # SIGTERM/SIGHUP remove temporary files too
    _io.published.clear()
    try:
        _check_outputs(args)
        status = _run(args)(args)
        sys.stdout.flush()
        return status
    except ThermofrictionError as e:
        print(f"thermofriction: error: {e}", file=sys.stderr)
        return e.exit_status
    except KeyboardInterrupt:
        print(f"thermofriction: interrupted; {_after_signal()}", file=sys.stderr)
        return 130
    except _io.Terminated as e:
        import signal
        print(f"thermofriction: terminated by {signal.Signals(e.signum).name}; {_after_signal()}", file=sys.stderr)
        return 128 + e.signum
    except MemoryError:
        # advice only where the options exist (identify has neither)
        hint = {"simulate": " (lower --duration or --sample-rate)", "synth": " (lower --duration or --sample-rate)",
                "identify": " (use fewer or shorter experiments, or fewer --starts)"}.get(args.command, "")
        print(f"thermofriction: error: out of memory{hint}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # a reader that stopped early (| head): not an error worth a message
        _silence_stdout()
        return 1
    except OSError as e:  # writing standard output or the terminal: a full disk, a closed terminal
        print(f"thermofriction: error: {e.filename or 'standard output'}: cannot write ({e.strerror or e})",
              file=sys.stderr)
        _silence_stdout()
        return 1
    finally:
        _io.restore_signal_handlers(handlers)


def _tolerant_streams():
    """Standard output and error that cannot encode a character (PYTHONIOENCODING=ascii, a latin-1
    terminal, the C locale) write it as an escape (``\\xb0`` for a degree sign in a model's name) instead of stopping the
    command with a UnicodeEncodeError after its work is done."""
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)  # a TextIOWrapper; tests may swap in others
        if reconfigure is not None and getattr(stream, "errors", "strict") in ("strict", "surrogateescape"):
            try:
                reconfigure(errors="backslashreplace")
            except (ValueError, OSError):  # a closed or detached stream: nothing to write to anyway
                pass


def _after_signal():
    if not _io.published:
        return "no output was written"
    return "outputs completed before it: " + ", ".join(map(str, _io.published))


def _silence_stdout():
    """Points standard output at /dev/null so that Python's final flush of what could not be
    written raises nothing more (the error was reported once)."""
    import contextlib
    with contextlib.suppress(OSError, ValueError, AttributeError):
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
        os.close(fd)


__all__ = ["main", "build_parser", "MAX_STARTS", "cmd_simulate", "cmd_identify", "cmd_validate", "cmd_report",
           "cmd_demo"]
