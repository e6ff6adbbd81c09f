"""Output files that never destroy anything and never leave debris
(docs/limits.md#outputs-never-destroy-never-leave-debris).

- A regular file is written to a temporary file beside its target (``.NAME.thermofriction-PID-XXXX.tmp``),
  flushed to disk and renamed over the target only when complete; an existing target keeps its mode
  (and, where permitted, its owner). A symbolic link is followed: its target is updated, the link kept.
- A character device or FIFO (``/dev/null``, a named pipe) is written through, never replaced.
- Inside ``publish_together()`` every output of a run is staged and they are renamed into place
  together at the end, or none is; the renames run with SIGINT/SIGTERM/SIGHUP deferred.
- Every ``OSError`` becomes an :class:`OutputError`: one line naming the path.
- Temporaries of a process that no longer runs are recognised by their name and removed by later writes.
"""

from __future__ import annotations

import contextlib
import json
import os
import stat
import tempfile
import threading
import time
from pathlib import Path

from ._json import jsonable
from ._signals import Terminated, critical, install_signal_handlers, raise_deferred, restore_signal_handlers
from .errors import InputError

#: marks the temporary files this package creates: ``.NAME`` + TMP_TAG + ``PID-XXXX.tmp``
TMP_TAG = ".thermofriction-"
#: a temporary file is stale when its process is gone and it has not changed for this long [s]
#: (the age guards against a live writer on another machine sharing the folder)
STALE_AGE = 60.0


class OutputError(InputError):
    """An output that cannot be written. Exit status 2 when refused before any work (fix the
    path), 1 when the writing itself failed (a full disk, an I/O error)."""

    def __init__(self, message, exit_status=2):
        super().__init__(message)
        self.exit_status = exit_status


def _why(err: OSError) -> str:
    return err.strerror or str(err)


class Target:
    """Where one output goes, resolved and checked: ``kind`` is "file" (written by a rename) or
    "stream" (a character device or FIFO, written through); ``real`` is the path with symbolic
    links followed; ``st`` the existing file's status (None for a new file)."""

    def __init__(self, path, option=None, label=None):
        self.path = path
        self.label = label or (f"{option} {path}" if option else f"{path}")
        p = os.fspath(path)
        if isinstance(p, bytes):
            p = os.fsdecode(p)
        if not p:
            raise OutputError(f"{option + ': ' if option else ''}an empty output path")
        if "\0" in p:
            raise OutputError(f"{self.label!r}: a file name cannot contain a NUL character")
        self.real = os.path.realpath(p)  # a link's target; a dangling link's would-be target
        self.folder = os.path.dirname(self.real) or "."
        self.name = os.path.basename(self.real)
        try:
            self.st = os.stat(self.real)
        except FileNotFoundError:
            self.st = None
        except OSError as e:  # a symlink loop, a name too long, a folder that is a file, no permission
            raise OutputError(f"{self.label}: cannot write ({_why(e)})") from None
        if self.st is None:
            self.kind = "file"
            if not os.path.isdir(self.folder):
                raise OutputError(f"{self.label}: folder {os.path.dirname(p) or '.'} does not exist")
        elif stat.S_ISDIR(self.st.st_mode):
            raise OutputError(f"{self.label}: is a folder, not a file")
        elif stat.S_ISCHR(self.st.st_mode) or stat.S_ISFIFO(self.st.st_mode):
            self.kind = "stream"
        elif stat.S_ISREG(self.st.st_mode):
            self.kind = "file"
        else:
            raise OutputError(f"{self.label}: not a regular file, character device or FIFO; refusing to write")

    def check(self):
        """Everything that can be known before writing: the name fits the file system, the folder
        takes a new file (a probe temporary file, removed at once), a stream is writable."""
        if self.kind == "stream":
            if not os.access(self.real, os.W_OK):
                raise OutputError(f"{self.label}: cannot write (permission denied)")
            return self
        try:
            limit = os.pathconf(self.folder, "PC_NAME_MAX")
        except (OSError, ValueError):
            limit = 255
        if len(os.fsencode(self.name)) > limit:
            raise OutputError(f"{self.label}: file name too long ({len(os.fsencode(self.name))} bytes, "
                              f"the file system allows {limit})")
        fd, tmp = self._mkstemp()
        os.close(fd)
        os.unlink(tmp)
        return self

    def identity(self):
        """(device, inode) of the existing file, or None."""
        return (self.st.st_dev, self.st.st_ino) if self.st is not None else None

    def _mkstemp(self):
        stem = os.fsdecode(os.fsencode(self.name)[:80])  # the temporary name must fit where NAME fits
        try:
            return tempfile.mkstemp(prefix=f".{stem}{TMP_TAG}{os.getpid()}-", suffix=".tmp", dir=self.folder)
        except OSError as e:  # read-only file system, no permission, no space for a directory entry
            raise OutputError(f"{self.label}: cannot write in {self.folder} ({_why(e)})") from None


def check_folder(path, label=None):
    """Before any work: ``path`` is a folder, or one can be created there (a probe temporary file in
    the nearest existing folder); OutputError (exit 2) otherwise."""
    label = label or str(path)
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise OutputError(f"{label}: not a folder (a file of that name exists)")
    existing, first_missing = path, None
    while not existing.exists():  # the nearest folder that exists must take the new ones
        first_missing = existing
        if existing.parent == existing:
            break
        existing = existing.parent
    if not existing.is_dir():
        raise OutputError(f"{label}: cannot create the folder ({existing} is not a folder)")
    Target(first_missing if first_missing is not None else path / ".probe", label=label).check()


def remove_stale_temporaries(folder) -> list[str]:
    """Removes this package's temporary files in ``folder`` left by a process that no longer runs
    (killed by SIGKILL or a power loss) and unchanged for STALE_AGE seconds; returns their names."""
    removed = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    now = time.time()
    for name in names:
        pid = _tmp_pid(name)
        if pid is None or pid == os.getpid() or _alive(pid):
            continue
        path = os.path.join(folder, name)
        with contextlib.suppress(OSError):
            st = os.lstat(path)
            if stat.S_ISREG(st.st_mode) and now - st.st_mtime > STALE_AGE:
                os.unlink(path)
                removed.append(name)
    return removed


def _tmp_pid(name):
    """The process id in a temporary file name of this package, or None for any other name."""
    if not (name.startswith(".") and name.endswith(".tmp")) or TMP_TAG not in name:
        return None
    pid, _, rest = name.rpartition(TMP_TAG)[2].partition("-")
    return int(pid) if pid.isdigit() and rest else None


def stale_temporaries(folder) -> list[str]:
    """Names of this package's temporary files in ``folder`` (of any process)."""
    try:
        return sorted(n for n in os.listdir(folder) if _tmp_pid(n) is not None)
    except OSError:
        return []


def _alive(pid) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's process
        return True
    return True


def _fsync_folder(folder):
    with contextlib.suppress(OSError):  # not every file system can sync a folder
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


_state = threading.local()
published = []       # targets renamed into place by this process (the CLI's message on a signal)


class _Staged:
    """The outputs of one run: temporaries waiting to be renamed, files to remove around the renames."""

    def __init__(self, inputs=()):
        self.files = []            # (target, tmp)
        self.remove_before = []    # paths removed before the renames (a manifest that must not outlive them)
        self.remove_after = []     # paths removed after them (files the new set no longer lists)
        self.inputs = [i for i in inputs if i is not None]

    def discard(self):
        for _, tmp in self.files:
            _discard(tmp)
        self.files.clear()

    def publish(self):
        label, done = "the outputs", []
        with critical():  # a signal meanwhile takes effect after the whole set, not in its middle
            try:
                for path in self.remove_before:
                    with contextlib.suppress(FileNotFoundError):
                        os.unlink(path)
                for target, tmp in self.files:
                    label = target.label
                    os.replace(tmp, target.real)
                    done.append(target)
                    published.append(target.path)
                for path in self.remove_after:
                    with contextlib.suppress(FileNotFoundError):
                        os.unlink(path)
                for folder in {t.folder for t in done}:
                    _fsync_folder(folder)
            except OSError as e:
                self.discard_remaining(done)
                raise OutputError(f"{label}: cannot write ({_why(e)})", exit_status=1) from None

    def discard_remaining(self, done):
        for target, tmp in self.files:
            if target not in done:
                _discard(tmp)


def current_set():
    """The set of outputs being staged on this thread (inside ``publish_together``), or None."""
    return getattr(_state, "staged", None)


@contextlib.contextmanager
def publish_together(inputs=()):
    """Inside the block, :func:`atomic_write` stages each file; when the block ends they are all
    renamed into place, in the order written, or, on any error, all removed and no target is
    touched. ``inputs`` are the run's input files: an output that is one of them is refused.
    Nested blocks join the outer one."""
    outer = current_set()
    if outer is not None:
        outer.inputs.extend(i for i in inputs if i is not None)
        yield outer
        return
    staged = _state.staged = _Staged(inputs)
    try:
        yield staged
    except BaseException:
        _state.staged = None
        staged.discard()
        raise
    _state.staged = None
    staged.publish()


def refuse_inputs(targets, inputs):
    """Refuses (OutputError, exit 2) an output that is one of the run's input files -- the same
    file by device and inode, so also through a symbolic or hard link -- or two outputs that are
    the same file. ``targets`` are :class:`Target`; ``inputs`` paths (missing ones are skipped)."""
    ids = {}
    for p in inputs:
        if p is None:
            continue
        with contextlib.suppress(OSError, ValueError):
            st = os.stat(p)
            ids.setdefault((st.st_dev, st.st_ino), p)
            ids.setdefault(os.path.realpath(p), p)
    seen = {}
    for t in targets:
        if t.kind == "stream":  # a device or FIFO is not destroyed by writing to it
            continue
        for key in (t.identity(), t.real):
            if key is not None and key in ids:
                raise OutputError(f"{t.label}: is also an input of this run ({ids[key]}); refusing to overwrite it")
        for key in (t.identity(), t.real):
            if key is not None and key in seen:
                raise OutputError(f"{t.label}: the same file as {seen[key].label}; give two different files")
        for key in (t.identity(), t.real):
            if key is not None:
                seen[key] = t


@contextlib.contextmanager
def atomic_write(path, mode="w", **kwargs):
    """A file handle whose content reaches ``path`` only if the block finishes (see the module's
    docstring): a temporary file renamed over the target, or, for a device or FIFO, the target
    itself. On any error, Ctrl-C or SIGTERM (with the command line's handlers) the temporary file
    is removed and the target is untouched. Inside ``publish_together()`` the rename waits for the
    end of the set. Raises :class:`OutputError` for every ``OSError``."""
    staged = current_set()
    target = path if isinstance(path, Target) else Target(path)
    if staged is not None and staged.inputs:
        refuse_inputs([target], staged.inputs)
    if target.kind == "stream":
        try:
            with open(target.real, mode, **kwargs) as fh:
                yield fh
        except OSError as e:
            raise OutputError(f"{target.label}: cannot write ({_why(e)})", exit_status=1) from None
        return
    remove_stale_temporaries(target.folder)
    with critical(raise_after=False):  # a signal between creating the temporary file and the try would leave it
        fd, tmp = target._mkstemp()
    try:
        raise_deferred()
        with os.fdopen(fd, mode, **kwargs) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())  # the data on disk before the name points at it (a crash leaves old or new)
        if target.st is not None:  # keep the existing file's mode and, where allowed, its owner
            os.chmod(tmp, stat.S_IMODE(target.st.st_mode))
            if (target.st.st_uid, target.st.st_gid) != (os.geteuid(), os.getegid()):
                with contextlib.suppress(OSError):
                    os.chown(tmp, target.st.st_uid, target.st.st_gid)
        else:
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 is for the temporary file, not the output
        if staged is not None:
            staged.files.append((target, tmp))
            return
        with critical(raise_after=False):
            os.replace(tmp, target.real)
            published.append(target.path)
        _fsync_folder(target.folder)
    except OSError as e:
        _discard(tmp)
        raise OutputError(f"{target.label}: cannot write ({_why(e)})", exit_status=1) from None
    except BaseException:
        _discard(tmp)
        raise
    raise_deferred()


def _discard(tmp):
    """Removes a temporary file; a second signal meanwhile waits (it would skip the removal)."""
    with critical(raise_after=False), contextlib.suppress(OSError):
        os.unlink(tmp)


def dump_json(data: dict, path=None) -> str:
    """JSON text of ``data``; written atomically to ``path`` when given."""
    text = json.dumps(jsonable(data), indent=2, allow_nan=False)
    if path is not None:
        with atomic_write(path, "w") as fh:
            fh.write(text + "\n")
    return text


__all__ = ["atomic_write", "publish_together", "refuse_inputs", "Target", "OutputError", "Terminated",
           "install_signal_handlers", "restore_signal_handlers", "remove_stale_temporaries", "stale_temporaries", "jsonable", "dump_json",
           "TMP_TAG"]
