"""Outputs never destroy anything and never leave debris (issue 17,
docs/limits.md#outputs-never-destroy-never-leave-debris).

Each reproduction of the issue is a test: special files written through, not replaced; symbolic
links followed; modes kept; an output that is an input refused; every write failure one line with
nothing written; the outputs of a run published as a set; temporaries removed on SIGTERM/SIGHUP and,
when stale, by a later run. Root-only cases (/dev/null, /dev/full, tmpfs mounts) skip elsewhere."""

import hashlib
import os
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

import thermofriction as tf
from child_signals import default_signals
from conftest import run_cli
from thermofriction import _io, _signals

SIM = ("simulate", "li2009-model-i", "--temperature", "35", "--duration", "0.1", "--sample-rate", "1000")
ROOT = os.geteuid() == 0
needs_root = pytest.mark.skipif(not ROOT, reason="needs root (special files, mounts)")


def snapshot(folder):
    """Every entry under ``folder`` (hidden ones too) -> (type, mode, content hash or link target)."""
    out = {}
    for p in sorted(Path(folder).rglob("*")):
        st = p.lstat()
        if stat.S_ISLNK(st.st_mode):
            out[str(p)] = ("link", os.readlink(p))
        elif stat.S_ISREG(st.st_mode):
            out[str(p)] = ("file", stat.S_IMODE(st.st_mode), hashlib.sha256(p.read_bytes()).hexdigest())
        else:
            out[str(p)] = ("other", stat.S_IFMT(st.st_mode))
    return out


def one_line_error(out, status):
    assert out.returncode == status, (out.returncode, out.stderr)
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("thermofriction: error: "), out.stderr
    assert "Traceback" not in out.stderr and "Exception ignored" not in out.stderr
    return lines[0]


def temporaries(folder):
    return [p.name for p in Path(folder).rglob("*") if _io.TMP_TAG in p.name]


@pytest.fixture(scope="module")
def dataset_dir(tmp_path_factory):
    """A small dataset (two fit and one validate experiment, 401 samples each) and a model file."""
    root = tmp_path_factory.mktemp("outputs")
    data = tf.synthesize(tf.load_model("li2009-model-i"), [30.0, 40.0], validate=[35.0], duration=0.2,
                         sample_rate=2000.0)
    tf.save_dataset(data, root / "ds")
    tf.load_model("li2009-model-i").save(root / "m.toml")
    return root


@pytest.fixture
def work(dataset_dir, tmp_path):
    """A private copy of the dataset and model for a test that may damage them."""
    import shutil
    shutil.copytree(dataset_dir / "ds", tmp_path / "ds")
    shutil.copy(dataset_dir / "m.toml", tmp_path / "m.toml")
    return tmp_path


@pytest.fixture
def mount(tmp_path):
    """mount("ro") or mount("size=64k"): a tmpfs at a fresh folder, unmounted afterwards."""
    points = []

    def make(options):
        point = tmp_path / f"mnt{len(points)}"
        point.mkdir()
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(point)], capture_output=True)
        if r.returncode != 0:
            pytest.skip(f"cannot mount a tmpfs here ({r.stderr.decode().strip()})")
        points.append(point)
        return point
    yield make
    for p in points:
        subprocess.run(["umount", str(p)], capture_output=True)


# -- special files: written through, never replaced ---------------------------------------------

@needs_root
@pytest.mark.parametrize("device", ["/dev/null", "/dev/full"])
def test_a_character_device_is_written_through_not_replaced(device, tmp_path):
    """Issue 17: `simulate ... -o /dev/null` turned /dev/null into a 570 KB regular file."""
    before = os.stat(device)
    assert stat.S_ISCHR(before.st_mode)
    out = run_cli(*SIM, "-o", device, cwd=tmp_path)
    after = os.stat(device)
    assert stat.S_ISCHR(after.st_mode) and after.st_rdev == before.st_rdev and after.st_ino == before.st_ino
    if device == "/dev/null":
        assert out.returncode == 0, out.stderr
    else:  # writing through /dev/full fails like a full disk: one line, exit 1
        assert "/dev/full: cannot write (No space left on device)" in one_line_error(out, 1)
    assert os.listdir(tmp_path) == [] and not temporaries("/dev")


def test_a_fifo_output_is_written_through(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    reader = subprocess.Popen(["cat", str(fifo)], stdout=subprocess.PIPE)
    out = run_cli(*SIM, "-o", fifo, cwd=tmp_path)
    received = reader.communicate(timeout=60)[0].decode()
    assert out.returncode == 0, out.stderr
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert received.startswith("time[s],") and len(received.splitlines()) == 102  # header + 101 samples
    assert sorted(os.listdir(tmp_path)) == ["pipe"]


def test_a_symlinked_output_updates_its_target_and_keeps_the_link(tmp_path):
    (tmp_path / "real").mkdir()
    target = tmp_path / "real" / "run.csv"
    target.write_text("old\n")
    link = tmp_path / "run.csv"
    link.symlink_to(target)
    out = run_cli(*SIM, "-o", link, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text().startswith("time[s],")
    dangling = tmp_path / "new.csv"
    dangling.symlink_to(tmp_path / "real" / "created.csv")  # a link to a file not yet there: created
    assert run_cli(*SIM, "-o", dangling, cwd=tmp_path).returncode == 0
    assert dangling.is_symlink() and (tmp_path / "real" / "created.csv").read_text().startswith("time[s],")
    assert not temporaries(tmp_path)


def test_an_existing_files_mode_is_kept_and_a_new_one_follows_the_umask(tmp_path):
    private = tmp_path / "private.csv"
    private.write_text("secret\n")
    private.chmod(0o600)
    assert run_cli(*SIM, "-o", private, cwd=tmp_path).returncode == 0
    assert stat.S_IMODE(private.stat().st_mode) == 0o600 and private.read_text().startswith("time[s],")
    model = tf.load_model("li2009-model-i")
    shared = tmp_path / "shared.toml"
    shared.write_text("")
    shared.chmod(0o664)
    model.save(shared)
    assert stat.S_IMODE(shared.stat().st_mode) == 0o664
    umask = os.umask(0o027)
    try:
        model.save(tmp_path / "fresh.toml")
    finally:
        os.umask(umask)
    assert stat.S_IMODE((tmp_path / "fresh.toml").stat().st_mode) == 0o640


def test_a_hard_linked_output_is_replaced_by_name_only(tmp_path):
    """A rename gives the output a new inode: another name of the old file keeps the old content
    (documented in docs/limits.md); nothing is lost."""
    a = tmp_path / "a.csv"
    a.write_text("old\n")
    os.link(a, tmp_path / "b.csv")
    assert run_cli(*SIM, "-o", a, cwd=tmp_path).returncode == 0
    assert a.read_text().startswith("time[s],") and (tmp_path / "b.csv").read_text() == "old\n"


# -- standard output -----------------------------------------------------------------------------

def test_stdout_dash_writes_the_csv(tmp_path):
    out = run_cli(*SIM, "-o", "-", cwd=tmp_path)
    assert out.returncode == 0 and out.stdout.startswith("time[s],") and len(out.stdout.splitlines()) == 102
    assert os.listdir(tmp_path) == []


@needs_root
@pytest.mark.parametrize("output", [("-o", "-"), ()], ids=["csv", "summary"])
def test_stdout_on_dev_full_is_one_line(output, tmp_path):
    """Issue 17: stdout on /dev/full gave a traceback."""
    with open("/dev/full", "w") as full:
        out = subprocess.run([sys.executable, "-m", "thermofriction", *SIM, *output], stdout=full,
                             stderr=subprocess.PIPE, text=True, cwd=tmp_path, timeout=300)
    assert "standard output: cannot write (No space left on device)" in one_line_error(out, 1)
    assert os.listdir(tmp_path) == []


def test_a_closed_pipe_on_stdout_is_quiet(tmp_path):
    proc = subprocess.Popen(f"{sys.executable} -m thermofriction {' '.join(SIM)} -o - | head -1", shell=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    stdout, stderr = proc.communicate(timeout=300)
    assert stdout.startswith("time[s],") and "Traceback" not in stderr and "Exception ignored" not in stderr


# -- an output that is an input: refused, exit 2, inputs unchanged ---------------------------------

REFUSALS = {
    "validate --json manifest": ("validate", "m.toml", "ds", "--json", "ds/dataset.toml"),
    "validate --json experiment": ("validate", "m.toml", "ds", "--json", "ds/T30C.csv"),
    "simulate -o model": ("simulate", "m.toml", "--temperature", "35", "--duration", "0.1", "-o", "m.toml"),
    "simulate -o model via symlink": ("simulate", "m.toml", "--temperature", "35", "--duration", "0.1",
                                      "-o", "link.toml"),
    "simulate -o model via hard link": ("simulate", "m.toml", "--temperature", "35", "--duration", "0.1",
                                        "-o", "hard.toml"),
    "simulate -o temperature file via symlink": ("simulate", "m.toml", "--temperature-file", "T.csv", "--duration",
                                                 "0.1", "-o", "link.csv"),
    "simulate -o temperature file via hard link": ("simulate", "m.toml", "--temperature-file", "T.csv",
                                                   "--duration", "0.1", "-o", "hard.csv"),
    "simulate -o temperature file": ("simulate", "m.toml", "--temperature-file", "T.csv", "--duration", "0.1",
                                     "-o", "T.csv"),
    "simulate -o sampled input": ("simulate", "m.toml", "--temperature", "35", "--input", "sampled:file=u.csv",
                                  "--duration", "0.1", "-o", "u.csv"),
    "report -o model": ("report", "m.toml", "ds", "-o", "m.toml"),
    "report -o manifest": ("report", "m.toml", "ds", "-o", "ds/dataset.toml"),
    "report -o results json": ("report", "m.toml", "ds", "-o", "m.json"),
    "identify -o X --json X": ("identify", "ds", "-o", "X", "--json", "X"),
    "identify -o init": ("identify", "ds", "--method", "base", "--init", "m.toml", "-o", "m.toml"),
    "identify --json experiment": ("identify", "ds", "--json", "ds/T40C.csv"),
    "synth over a dataset": ("synth", "li2009-model-i", "--temperatures", "31", "--duration", "0.2",
                             "--sample-rate", "2000", "-o", "ds"),
    "synth --force over its input": ("synth", "li2009-model-i", "--input", "sampled:file=ds/T31C.csv",
                                     "--temperatures", "31", "--duration", "0.2", "--sample-rate", "2000",
                                     "-o", "ds", "--force"),
}


#: the cases whose output name has an extension the command does not write (a model or manifest .toml, an
#: experiment .csv for --json, X for both outputs): refused for that before any input is read (issue 33)
NOT_WRITTEN_THERE = {"validate --json manifest", "validate --json experiment", "simulate -o model",
                     "simulate -o model via symlink", "simulate -o model via hard link", "report -o model",
                     "report -o manifest", "report -o results json", "identify -o X --json X",
                     "identify --json experiment"}


@pytest.mark.parametrize("case", sorted(REFUSALS))
def test_an_output_that_is_an_input_is_refused(case, work):
    """Issue 17: `validate m.toml ds --json ds/dataset.toml` overwrote the manifest with exit 0,
    `identify ds -o X --json X` lost the model, `synth -o existing` orphaned the old CSVs."""
    (work / "link.toml").symlink_to("m.toml")
    os.link(work / "m.toml", work / "hard.toml")
    (work / "T.csv").write_text("time[s],temperature[C]\n0,30\n1,40\n")
    (work / "link.csv").symlink_to("T.csv")
    os.link(work / "T.csv", work / "hard.csv")
    (work / "u.csv").write_text("time[s],voltage[V]\n0,0\n1,30\n")
    (work / "m.json").write_text("{}\n")
    (work / "ds" / "T31C.csv").write_text("time[s],voltage[V]\n0,0\n1,30\n")  # an input synth would write
    before = snapshot(work)
    t0 = time.monotonic()
    out = run_cli(*REFUSALS[case], cwd=work)
    line = one_line_error(out, 2)
    if case in NOT_WRITTEN_THERE:  # the name is no output of the command: refused for that, first
        assert "unknown extension" in line or "no extension" in line, line
    else:
        assert ("input of this run" in line or "the same file as" in line or "already holds a dataset" in line
                or "not a dataset folder" in line), line
    assert snapshot(work) == before
    assert time.monotonic() - t0 < 60  # refused before the work (identify would take longer)


# -- write failures: one line, nothing written ------------------------------------------------------

def test_output_is_a_folder_or_a_name_too_long_or_in_a_missing_folder(tmp_path):
    (tmp_path / "d").mkdir()
    before = snapshot(tmp_path)
    assert "is a folder" in one_line_error(run_cli(*SIM, "-o", "d", cwd=tmp_path), 2)
    assert "name too long" in one_line_error(run_cli(*SIM, "-o", "x" * 300 + ".csv", cwd=tmp_path), 2).lower()
    assert "does not exist" in one_line_error(run_cli(*SIM, "-o", "nowhere/x.csv", cwd=tmp_path), 2)
    (tmp_path / "loop").symlink_to("loop")
    assert "symbolic links" in one_line_error(run_cli(*SIM, "-o", "loop", cwd=tmp_path), 2)
    (tmp_path / "loop").unlink()
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("args, message", [
    (("simulate", "li2009-model-i", "--temperature", "35", "-o", ""), "-o: an empty output path"),
    (("synth", "li2009-model-i", "--temperatures", "31", "-o", "afile"), "afile: cannot create the dataset folder"),
    (("synth", "li2009-model-i", "--temperatures", "31", "-o", "afile/ds"), "afile is not a folder"),
    (("report", "li2009-model-i", "ds", "-o", "r.html", "--figures", "afile"), "--figures afile: not a folder"),
    (("demo", "-o", "afile"), "-o afile: not a folder"),
], ids=["empty path", "synth -o file", "synth -o under a file", "report --figures file", "demo -o file"])
def test_unusable_output_folders_are_refused_before_the_work(args, message, work):
    (work / "afile").write_text("keep\n")
    before = snapshot(work)
    assert message in one_line_error(run_cli(*args, cwd=work), 2)
    assert snapshot(work) == before


def test_identify_checks_every_output_before_the_work(work):
    """Issue 17: `identify ds -o fit.toml --json somedir` wrote fit.toml and then crashed."""
    (work / "somedir").mkdir()
    before = snapshot(work)
    t0 = time.monotonic()
    line = one_line_error(run_cli("identify", "ds", "-o", "fit.toml", "--json", "somedir", cwd=work), 2)
    assert "--json somedir: is a folder" in line and time.monotonic() - t0 < 30
    assert snapshot(work) == before


@needs_root
def test_a_read_only_file_system_is_refused_before_the_work(mount, work):
    ro = mount("ro")
    line = one_line_error(run_cli(*SIM, "-o", ro / "x.csv", cwd=work), 2)
    assert "Read-only file system" in line
    line = one_line_error(run_cli("identify", "ds", "-o", "fit.toml", "--json", ro / "r.json", cwd=work), 2)
    assert "Read-only file system" in line and not (work / "fit.toml").exists()
    line = one_line_error(run_cli("synth", "li2009-model-i", "--temperatures", "31", "-o", ro / "data",
                                  cwd=work), 2)
    assert "Read-only file system" in line
    assert os.listdir(ro) == []


@needs_root
def test_a_full_disk_leaves_the_old_output_and_no_debris(mount, tmp_path):
    disk = mount("size=64k")
    old = disk / "run.csv"
    old.write_text("old\n")
    old.chmod(0o640)
    line = one_line_error(run_cli(*SIM, "--duration", "2", "-o", old, cwd=tmp_path), 1)
    assert "No space left on device" in line
    assert old.read_text() == "old\n" and sorted(os.listdir(disk)) == ["run.csv"]


@needs_root
def test_synth_on_a_full_disk_keeps_the_old_dataset_whole(mount, tmp_path):
    """Issue 17: synth over an existing dataset on a full disk left a mix of new and old CSVs under
    the old manifest (which still loaded)."""
    disk = mount("size=256k")
    small = tf.synthesize(tf.load_model("li2009-model-i"), [30.0, 40.0], duration=0.2, sample_rate=2000.0)
    tf.save_dataset(small, disk / "ds")
    before = snapshot(disk)
    out = run_cli("synth", "li2009-model-i", "--temperatures", "30,40", "--duration", "0.2",
                  "--sample-rate", "200000", "-o", disk / "ds", "--force", cwd=tmp_path)
    assert "No space left on device" in one_line_error(out, 1)
    assert snapshot(disk) == before
    assert len(tf.load_dataset(disk / "ds").experiments) == 2
    out = run_cli("synth", "li2009-model-i", "--temperatures", "30,40", "--duration", "0.2",
                  "--sample-rate", "200000", "-o", disk / "new" / "ds", cwd=tmp_path)
    one_line_error(out, 1)
    assert snapshot(disk) == before  # the folders it created are gone again


def test_the_library_raises_its_own_error_for_a_folder(tmp_path):
    """model.save('/tmp') raised IsADirectoryError."""
    with pytest.raises(tf.ThermofrictionError, match="is a folder"):
        tf.load_model("li2009-model-i").save(tmp_path)
    assert os.listdir(tmp_path) == []


# -- datasets: --force, orphans, a half-published set -------------------------------------------------

def test_synth_force_replaces_the_dataset_and_removes_its_orphans(work):
    (work / "ds" / "notes.txt").write_text("mine\n")  # not part of the dataset: kept
    out = run_cli("synth", "li2009-model-i", "--temperatures", "31", "--duration", "0.2", "--sample-rate", "2000",
                  "-o", "ds", "--force", cwd=work)
    assert out.returncode == 0, out.stderr
    assert sorted(os.listdir(work / "ds")) == ["T31C.csv", "dataset.toml", "notes.txt"]
    assert [e.file for e in tf.load_dataset(work / "ds").experiments] == ["T31C.csv"]


def test_save_dataset_refuses_an_existing_dataset_unless_overwrite(work):
    data = tf.load_dataset(work / "ds")
    before = snapshot(work)
    with pytest.raises(tf.ThermofrictionError, match=r"already holds a dataset.*overwrite=True"):
        tf.save_dataset(data, work / "ds")
    assert snapshot(work) == before
    tf.save_dataset(data, work / "ds", overwrite=True)
    assert snapshot(work) == before  # the same data, written again: the same files


_KILL_AT_RENAME = """
import os, sys
import thermofriction as tf
from thermofriction import _io
n = int(sys.argv[2])
real = os.replace
def replace(src, dst):
    global n
    n -= 1
    if n < 0:
        os._exit(137)   # SIGKILL's effect: no cleanup at all
    real(src, dst)
_io.os.replace = replace
data = tf.synthesize(tf.load_model("li2009-model-i"), [31.0, 32.0, 33.0], duration=0.2, sample_rate=2000.0)
tf.save_dataset(data, sys.argv[1], overwrite=True)
"""


@pytest.mark.parametrize("renames_done", [0, 1, 3])
def test_a_half_published_dataset_is_detected_by_the_loader(renames_done, work):
    """A kill between the renames (0: before any, 1: inside the CSVs, 3: before the manifest)
    leaves no manifest: load_dataset refuses it, naming the temporary files, instead of loading a
    mix of old and new files."""
    out = subprocess.run([sys.executable, "-c", _KILL_AT_RENAME, str(work / "ds"), str(renames_done)],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 137, out.stderr
    assert not (work / "ds" / "dataset.toml").exists()
    with pytest.raises(tf.InputError, match=r"interrupted write \(\..*thermofriction-.*\.tmp.*write it again"):
        tf.load_dataset(work / "ds")
    line = one_line_error(run_cli("validate", "m.toml", "ds", cwd=work), 2)
    assert "not completely written" in line


def test_identify_publishes_the_model_and_json_together(work):
    """Issue 17: the model and its JSON were two separate renames. A failing second output (here
    --json on a device that refuses every write) leaves no model either."""
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full")
    out = run_cli("identify", "ds", "--method", "base", "--starts", "1", "-q", "-o", "fit.toml",
                  "--json", "/dev/full", cwd=work)
    assert "No space left on device" in one_line_error(out, 1)
    assert not (work / "fit.toml").exists() and not temporaries(work)


def test_publish_together_is_all_or_nothing(tmp_path):
    (tmp_path / "b.txt").write_text("old b\n")
    with pytest.raises(RuntimeError):
        with _io.publish_together():
            with _io.atomic_write(tmp_path / "a.txt") as fh:
                fh.write("new a\n")
            with _io.atomic_write(tmp_path / "b.txt") as fh:
                fh.write("new b\n")
            assert not (tmp_path / "a.txt").exists()  # staged, not published
            raise RuntimeError("the run failed after writing")
    assert sorted(os.listdir(tmp_path)) == ["b.txt"] and (tmp_path / "b.txt").read_text() == "old b\n"
    with _io.publish_together():
        for name in ("a.txt", "b.txt"):
            with _io.atomic_write(tmp_path / name) as fh:
                fh.write(f"new {name}\n")
    assert (tmp_path / "a.txt").read_text() == "new a.txt\n" and (tmp_path / "b.txt").read_text() == "new b.txt\n"
    assert sorted(os.listdir(tmp_path)) == ["a.txt", "b.txt"]


def test_report_ignores_results_of_another_model(work):
    """A model and a JSON beside it that do not match (an identify killed between its renames, or
    an edit) are detected: a warning, and the JSON's numbers are not used for that model."""
    import json
    other = tf.load_model("li2009-model-ii")
    (work / "m.json").write_text(json.dumps({"method": "model-i", "model": _io.jsonable(other.to_dict())}))
    out = run_cli("report", "m.toml", "ds", "-o", "r.html", cwd=work)
    assert out.returncode == 0, out.stderr
    assert "m.json describes another model than m.toml" in out.stderr


# -- signals and stale temporaries -------------------------------------------------------------------

@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP], ids=["SIGTERM", "SIGHUP"])
def test_sigterm_and_sighup_while_writing_remove_the_temporary_file(sig, tmp_path):
    """Issue 17: SIGTERM (what timeout and job schedulers send) and SIGHUP left .NAME.XXXX.tmp files."""
    out_csv = tmp_path / "out.csv"
    proc = subprocess.Popen([sys.executable, "-m", "thermofriction", "simulate", "li2009-model-i", "--temperature",
                             "35", "--duration", "60", "-o", str(out_csv)], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=default_signals)
    try:
        deadline = time.monotonic() + 120
        while not list(tmp_path.glob(f".out.csv{_io.TMP_TAG}*.tmp")):  # writing 600,001 rows
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline
            time.sleep(0.02)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 128 + sig, err
    assert f"terminated by {signal.Signals(sig).name}; no output was written" in err and "Traceback" not in err
    assert os.listdir(tmp_path) == []


def test_signals_wait_while_a_set_is_renamed():
    """Between the renames of a set a signal only is recorded; it takes effect right after."""
    with _signals.critical(raise_after=False):
        _signals._handler(signal.SIGTERM, None)  # no exception: deferred
    with pytest.raises(_io.Terminated) as info:
        _signals.raise_deferred()
    assert info.value.signum == signal.SIGTERM and not _signals._deferred


def _dead_pid():
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_stale_temporaries_of_a_killed_run_are_recognised_and_removed(tmp_path):
    """SIGKILL cannot be caught: its temporary file stays, named so that a later write to the
    folder removes it once its process is gone and it is a minute old."""
    dead = _dead_pid()
    old = time.time() - 3600
    stale = tmp_path / f".run.csv{_io.TMP_TAG}{dead}-abcd1234.tmp"
    recent = tmp_path / f".other.csv{_io.TMP_TAG}{dead}-efgh5678.tmp"
    live = tmp_path / f".live.csv{_io.TMP_TAG}{os.getppid()}-ijkl9012.tmp"
    foreign = tmp_path / ".run.csv.abcd.tmp"  # not ours: never touched
    for p in (stale, recent, live, foreign):
        p.write_text("partial")
    for p in (stale, live, foreign):
        os.utime(p, (old, old))
    tf.load_model("li2009-model-i").save(tmp_path / "m.toml")
    assert sorted(os.listdir(tmp_path)) == sorted([recent.name, live.name, foreign.name, "m.toml"])


def test_sigkill_during_a_write_leaves_only_a_recognisable_temporary(tmp_path):
    out_csv = tmp_path / "out.csv"
    proc = subprocess.Popen([sys.executable, "-m", "thermofriction", "simulate", "li2009-model-i", "--temperature",
                             "35", "--duration", "60", "-o", str(out_csv)], cwd=tmp_path,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while not list(tmp_path.glob(f".out.csv{_io.TMP_TAG}*.tmp")):
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.02)
        proc.kill()
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    left = os.listdir(tmp_path)
    assert len(left) == 1 and _io._tmp_pid(left[0]) == proc.pid  # no out.csv: the old state
    old = time.time() - 3600
    os.utime(tmp_path / left[0], (old, old))
    assert run_cli(*SIM, "-o", out_csv, cwd=tmp_path).returncode == 0
    assert os.listdir(tmp_path) == ["out.csv"]
