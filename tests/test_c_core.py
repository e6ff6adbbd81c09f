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
