"""Start-up stays light: ``import thermofriction`` and a whole ``thermofriction simulate`` run load
neither SciPy's optimize or stats nor matplotlib (together most of a second to import); they load
when identification, reports or heating first use them. Checked on ``sys.modules`` of a fresh
interpreter, not on wall time (the machine's load would make a timed test flaky; the timings are in
benchmarks/bench_simulate.py, part iv)."""

from __future__ import annotations

import json
import subprocess
import sys

HEAVY = ("scipy.optimize", "scipy.stats", "scipy.signal", "scipy.integrate", "matplotlib", "rich")


def loaded_after(code: str) -> list[str]:
    """The heavy modules in sys.modules after running ``code`` in a fresh interpreter."""
    probe = (f"{code}\nimport json, sys\n"
             f"print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] in ('scipy', 'matplotlib', 'rich')"
             f" and any(m == h or m.startswith(h + '.') for h in {HEAVY!r}))))")
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout.strip().splitlines()[-1])


def test_import_thermofriction_loads_no_heavy_module():
    assert loaded_after("import thermofriction") == []


def test_whole_simulate_command_loads_no_heavy_module(tmp_path):
    out = tmp_path / "run.csv"
    code = ("import sys\nfrom thermofriction.cli import main\n"
            f"sys.argv = ['thermofriction', 'simulate', 'li2009-model-i', '--temperature', '35.7', '--duration', "
            f"'0.05', '-o', {str(out)!r}]\n"
            "status = main()\nassert not status, status")
    assert loaded_after(code) == []
    assert out.stat().st_size > 0  # the run did happen


def test_heavy_module_loads_when_first_used():
    """The lazy stand-in imports the real module at its first use, and answers as it does."""
    code = ("import importlib, sys\nengine = importlib.import_module('thermofriction.fitting.optimiser')\n"
            "assert 'scipy.stats' not in sys.modules\n"
            "assert abs(engine.stats.norm.cdf(0.0) - 0.5) < 1e-15\n"
            "assert 'scipy.stats' in sys.modules")
    assert "scipy.stats" in loaded_after(code)


def test_every_lazy_name_of_the_package_resolves_and_loads_its_module_only_then():
    """The package's lazily loaded names (scale-out and FMU export) each resolve to the real thing on first
    use; Dask and the FMU module are not loaded before."""
    code = ("import sys, thermofriction as tf\n"
            "assert 'distributed' not in sys.modules and 'thermofriction.fmu' not in sys.modules\n"
            "missing = [n for n in tf.__all__ if not callable(getattr(tf, n, None)) and not isinstance(getattr(tf, n), "
            "(tuple, list, dict))]\n"
            "assert not missing, missing\n"
            "from thermofriction.scale import propagate\nfrom thermofriction.fmu import export_fmu\n"
            "assert tf.propagate is propagate and tf.export_fmu is export_fmu")
    loaded_after(code)
