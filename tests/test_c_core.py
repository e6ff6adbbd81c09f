"""The C core builds on its own (no Python) and passes its own tests (core/tests/test_core.c)."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

CORE = Path(__file__).resolve().parents[1] / "core"


@pytest.mark.skipif(shutil.which("cmake") is None, reason="cmake is not installed")
def test_c_library_builds_standalone_and_its_tests_pass(tmp_path):
    build = tmp_path / "build"
    env = dict(os.environ)
    subprocess.run(["cmake", "-S", str(CORE), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release"], check=True,
                   capture_output=True, env=env)
    subprocess.run(["cmake", "--build", str(build), "-j", "2"], check=True, capture_output=True, env=env)
    out = subprocess.run(["ctest", "--test-dir", str(build), "--output-on-failure"], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
    direct = subprocess.run([str(build / "test_core")], capture_output=True, text=True)
    last = direct.stdout.strip().splitlines()[-1]
    passed, failed = (int(w) for w in last.replace(",", "").split()[::2])
    assert failed == 0 and passed > 30, direct.stdout


# ---------------------------------------------------------------------------------------------
# Hardening (issue 6): sanitisers, valgrind, and the coverage-guided fuzz target core/fuzz.
# On CI (CI=true) the tools are installed by .ci/run and a missing one fails the test instead of
# skipping it, so that a green CI run means these checks ran.
# ---------------------------------------------------------------------------------------------

CORPUS = CORE / "fuzz" / "corpus"
CORPUS_REALTIME = CORE / "fuzz" / "corpus_realtime"  # fuzz_realtime.c: the real-time and control APIs
CORPUS_FMU = CORE / "fuzz" / "corpus_fmu"  # fuzz_fmu.c: the FMU's resource file and entry points
# GCC's and clang's "undefined" leave out float-cast-overflow (a double converted to an integer type that
# cannot hold it: the FMU's step count once overflowed so); every sanitised build adds it
SANITIZE = "-DTF_SANITIZE=address,undefined,float-cast-overflow"


def need(tool):
    if shutil.which(tool) is None:
        if os.environ.get("CI"):
            pytest.fail(f"{tool} is not installed (.ci/run installs it)")
        pytest.skip(f"{tool} is not installed")


def build_core(build, *cmake_args):
    need("cmake")
    subprocess.run(["cmake", "-S", str(CORE), "-B", str(build), *cmake_args], check=True, capture_output=True)
    subprocess.run(["cmake", "--build", str(build), "-j", "2"], check=True, capture_output=True)


def corpus(folder=CORPUS, least=100):
    files = sorted(folder.iterdir())
    assert len(files) > least  # the seed corpus is there (a replay of nothing proves nothing)
    return [str(f) for f in files]


def test_c_tests_and_fuzz_corpus_are_clean_under_address_and_undefined_behaviour_sanitizers(tmp_path):
    """Sanitisers: the C tests and a replay of the fuzz corpora (every model, plant, law, input and
    method, with NaN, infinite and extreme parameters; the real-time programs; the FMU's resource files
    and call programs) built with -fsanitize=address,undefined,float-cast-overflow and no recovery: any
    out-of-bounds access, leak or undefined behaviour fails the run."""
    need("cc")
    build = tmp_path / "asan"
    build_core(build, "-DCMAKE_BUILD_TYPE=Debug", SANITIZE)
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=1", UBSAN_OPTIONS="print_stacktrace=1")
    for test in ("test_core", "test_estimator", "test_load"):  # (the estimator's and the load's: core/tests/)
        out = subprocess.run([str(build / test)], capture_output=True, text=True, env=env)
        assert out.returncode == 0 and " 0 failed" in out.stdout, out.stdout + out.stderr
    for replay, folder, least in (("fuzz_replay", CORPUS, 100), ("fuzz_replay_realtime", CORPUS_REALTIME, 100),
                                  ("fuzz_replay_fmu", CORPUS_FMU, 30)):
        files = corpus(folder, least)
        rep = subprocess.run([str(build / replay), *files], capture_output=True, text=True, env=env)
        assert rep.returncode == 0 and f"replayed {len(files)} inputs" in rep.stdout, rep.stdout + rep.stderr[-3000:]


def test_c_tests_and_fuzz_corpus_are_valgrind_clean(tmp_path):
    """valgrind (memcheck): no invalid read or write, no use of uninitialised memory and no leak
    in the C tests and a replay of the fuzz corpus (an uninstrumented build, unlike ASan's)."""
    need("valgrind")
    build = tmp_path / "plain"
    build_core(build, "-DCMAKE_BUILD_TYPE=RelWithDebInfo")
    vg = ["valgrind", "--error-exitcode=99", "--leak-check=full", "--errors-for-leak-kinds=definite,indirect", "-q"]
    for test in ("test_core", "test_estimator", "test_load"):
        out = subprocess.run([*vg, str(build / test)], capture_output=True, text=True)
        assert out.returncode == 0 and " 0 failed" in out.stdout, out.stdout + out.stderr
    files = corpus()[::4]  # valgrind is ~50x slower: a quarter of the corpus
    rep = subprocess.run([*vg, str(build / "fuzz_replay"), *files], capture_output=True, text=True)
    assert rep.returncode == 0, rep.stdout + rep.stderr[-3000:]
    files = corpus(CORPUS_REALTIME)  # the real-time programs are short: all of them (~2 s)
    rep = subprocess.run([*vg, str(build / "fuzz_replay_realtime"), *files], capture_output=True, text=True)
    assert rep.returncode == 0 and f"replayed {len(files)} inputs" in rep.stdout, rep.stdout + rep.stderr[-3000:]
    files = corpus(CORPUS_FMU, 30)[::4]  # a quarter, as for the models' corpus
    rep = subprocess.run([*vg, str(build / "fuzz_replay_fmu"), *files], capture_output=True, text=True)
    assert rep.returncode == 0 and f"replayed {len(files)} inputs" in rep.stdout, rep.stdout + rep.stderr[-3000:]


def run_fuzzer(tmp_path, target, corpus, default_seconds):
    """Builds the libFuzzer targets with ASan and UBSan, fuzzes ``target`` from a copy of ``corpus``
    for TF_FUZZ_SECONDS (else ``default_seconds``) and fails on any finding (crash or timeout file)."""
    need("clang")
    build = tmp_path / "fuzz"
    build_core(build, "-DCMAKE_C_COMPILER=clang", "-DCMAKE_BUILD_TYPE=RelWithDebInfo", "-DTF_BUILD_FUZZERS=ON",
               SANITIZE, "-DTF_BUILD_TESTS=OFF")
    work = tmp_path / "corpus"
    shutil.copytree(corpus, work)
    seconds = int(os.environ.get("TF_FUZZ_SECONDS", str(default_seconds)))
    out = subprocess.run([str(build / target), f"-max_total_time={seconds}", "-timeout=10",
                          "-rss_limit_mb=2048", f"-artifact_prefix={tmp_path}/", str(work)],
                         capture_output=True, text=True, timeout=seconds + 300)
    assert out.returncode == 0 and "Done" in out.stderr, out.stderr[-4000:]
    assert not list(tmp_path.glob("crash-*")) and not list(tmp_path.glob("timeout-*"))


def test_fuzz_target_runs_30_seconds_without_a_finding(tmp_path):
    """Coverage-guided fuzzing (libFuzzer, with ASan and UBSan) of the C entry points that take
    user data: a model decoded from bytes is checked (tf_model_check) and, if accepted, solved by
    each method. A crash, sanitiser report, hang (10 s) or broken contract (unknown status, a
    sample emitted twice or skipped, a non-finite state on TF_OK, a corner not after t, a refusal
    that names no field) fails the run. CI runs 30 s; docs/hardening.md says how to run longer."""
    run_fuzzer(tmp_path, "fuzz_simulate", CORPUS, default_seconds=30)


def test_realtime_fuzz_target_runs_20_seconds_without_a_finding(tmp_path):
    """Coverage-guided fuzzing (libFuzzer, ASan, UBSan) of the real-time and control APIs
    (core/fuzz/fuzz_realtime.c): programs of up to 64 calls -- init, from_model, set_model_i / _ii,
    set_param, reset, params_at, steps, observer steps, advance, PID, loop -- with NULLs, unknown
    kinds, unordered or duplicate breakpoints, NaN, inf and huge values. A crash, sanitiser report,
    hang (10 s) or broken contract (an unknown status; a refused call that changed the object, the
    PID or a loop output; TF_OK with a non-finite force, state or output; a NaN force that does not
    match the status) fails the run. 20 s on CI (TF_FUZZ_SECONDS changes it, as for the other)."""
    run_fuzzer(tmp_path, "fuzz_realtime", CORPUS_REALTIME, default_seconds=20)


def test_fmu_fuzz_target_runs_10_seconds_without_a_finding(tmp_path):
    """Coverage-guided fuzzing (libFuzzer, ASan, UBSan with float-cast-overflow) of the FMI 2.0 wrapper
    (core/fuzz/fuzz_fmu.c): a resource file (model.tfm) from the fuzzer's bytes, then up to 48 FMI calls --
    set-up, initialisation, setting and reading values (undeclared references, NULL arrays), input
    derivatives, steps from 1e-9 s to 1e300 s, FMU states, reset, terminate. A crash, sanitiser report,
    hang (10 s) or broken contract (a status other than OK, Warning, Error; fmi2Error without a logged
    message; a step answered OK that did not move the time by h or left a non-finite output; a refused
    call that changed a variable, the time or an output; fmi2OK for an undeclared reference: 13-15, 7-11 without
    an estimator, 12 without a load input)
    fails the run. 10 s on CI (TF_FUZZ_SECONDS changes it, as for the others)."""
    run_fuzzer(tmp_path, "fuzz_fmu", CORPUS_FMU, default_seconds=10)


# ---------------------------------------------------------------------------------------------
# Installed library (issue 8): cmake --install, find_package(thermofriction), the C example
# ---------------------------------------------------------------------------------------------

EXAMPLE = CORE.parent / "examples" / "c"


def test_installed_library_builds_the_c_example_and_it_matches_python(tmp_path):
    """The core installs (static and shared libraries, headers, a CMake package config); the example
    under examples/c finds it with find_package(thermofriction), links the shared library, runs the
    10 kHz loop, and prints the same tracking errors as thermofriction.control.compare_compensation
    on the same loop (oracle: the Python package through its binding; agreement to 1e-9)."""
    import numpy as np

    import thermofriction as tf
    from thermofriction import control as C

    build_core(tmp_path / "build", "-DCMAKE_BUILD_TYPE=Release")
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", str(tmp_path / "build"), "--prefix", str(prefix)], check=True,
                   capture_output=True)
    libdir = next(p for p in (prefix / "lib", prefix / "lib64") if p.exists())
    assert (libdir / "libthermofriction.a").exists() and any(libdir.glob("libthermofriction.so*"))
    assert (libdir / "cmake" / "thermofriction" / "thermofrictionConfig.cmake").exists()
    assert (prefix / "include" / "thermofriction" / "realtime.h").exists()
    ex = tmp_path / "example"
    subprocess.run(["cmake", "-S", str(EXAMPLE), "-B", str(ex), f"-DCMAKE_PREFIX_PATH={prefix}"], check=True,
                   capture_output=True)
    subprocess.run(["cmake", "--build", str(ex)], check=True, capture_output=True)
    out = subprocess.run([str(ex / "closed_loop")], capture_output=True, text=True,
                         env=dict(os.environ, LD_LIBRARY_PATH=str(libdir)))
    assert out.returncode == 0, out.stderr
    printed = {}
    for line in out.stdout.splitlines()[1:]:
        T, rest = line.split(maxsplit=1)
        name, rms, mx = rest.rsplit(maxsplit=2)
        printed[(float(T), name.strip())] = (float(rms), float(mx))
    assert len(printed) == 10
    stage = tf.load_model("stage-model-i")
    for row in C.compare_compensation(stage, [C.sine_reference(1e-3, 0.5, 4.0)]):
        rms, mx = printed[(row["temperature"], row["compensation"])]
        np.testing.assert_allclose([rms, mx], [row["rms_error"], row["max_error"]], rtol=1e-9)
