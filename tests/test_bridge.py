"""The contract between Python and the C core has one source: the headers. These tests walk both
sides: every enum constant of the core's headers is exported by the binding and every exported name
is in a header; the bridge is the only Python module that touches the compiled core."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from child_signals import default_signals
from thermofriction import _bridge, _core
from thermofriction.simulation import SOLVERS

ROOT = Path(__file__).resolve().parents[1]
HEADERS = sorted((ROOT / "core" / "include").rglob("*.h"))
PACKAGE = ROOT / "src" / "thermofriction"


def header_parameter_list() -> list:
    """The entries X(symbol, "name", "unit", ...) of friction.h's TF_PARAMETERS list."""
    text = (ROOT / "core" / "include" / "thermofriction" / "friction.h").read_text()
    block = re.search(r"#define TF_PARAMETERS\(X\)(.*?)\n\s*\n", text, flags=re.S).group(1)
    return re.findall(r'X\((\w+),\s*"([^"]+)",\s*"([^"]+)"', block)


def header_friction_model_list() -> list:
    """The entries X(symbol, "name", ...) of domains.h's TF_FRICTION_MODELS list."""
    text = (ROOT / "core" / "include" / "thermofriction" / "domains.h").read_text()
    block = re.search(r"#define TF_FRICTION_MODELS\(X\)(.*?)\n\s*\n", text, flags=re.S).group(1)
    return re.findall(r'X\((\w+),\s*"([^"]+)"', block)


def header_enum_constants() -> dict:
    """Every enumerator of every ``typedef enum { ... }`` in the public headers (the parameter and friction
    model enums expanded from their lists): name -> header."""
    found = {f"TF_P_{sym}": "friction.h" for sym, _, _ in header_parameter_list()}
    found.update({f"TF_FRICTION_{sym}": "friction.h" for sym, _ in header_friction_model_list()})
    for h in HEADERS:
        text = re.sub(r"/\*.*?\*/", "", h.read_text(), flags=re.S)  # comments may mention names
        for body in re.findall(r"enum\s*\w*\s*\{(.*?)\}", text, flags=re.S):
            body = re.sub(r"TF_(PARAMETERS|FRICTION_MODELS)\(\w+\)", "", body)  # the lists, expanded above
            for item in body.split(","):
                m = re.match(r"\s*(TF_[A-Z0-9_]+)", item)
                if m:
                    found[m.group(1)] = h.name
    return found


def test_headers_are_found():
    """Guard for the walk itself: the parser sees the enums it must (a regex that matched nothing
    would make the comparison below pass vacuously)."""
    consts = header_enum_constants()
    for name in ("TF_P_SIGMA0", "TF_PLANT_MASS", "TF_OUT_TEMPERATURE", "TF_ERR_MAX_STEPS", "TF_LAW_TABLE"):
        assert name in consts
    assert len(consts) > 50


def test_every_header_constant_is_exported_and_nothing_else():
    headers = set(header_enum_constants())
    # the counts that close an enum are exported as limits, with the capacities defined by macro
    exported = set(_core.C_NAMES)
    missing = sorted(headers - exported)
    extra = sorted(exported - headers - {"TF_MAX_FRICTION_STATES", "TF_MAX_STATES", "TF_MAX_TARGETS"})
    assert not missing, f"header constants the binding does not export (add them to _core.c): {missing}"
    assert not extra, f"exported names that are in no header: {extra}"


def test_parameter_names_and_units_come_from_the_header_list():
    entries = header_parameter_list()
    assert len(entries) == _core.CONSTANTS["limit"]["parameters"] >= 11
    assert _bridge.PARAMETERS == tuple(name for _, name, _ in entries)
    assert tf.models.PARAMETER_UNITS == {name: unit for _, name, unit in entries}


def test_macro_limits_match_headers():
    text = "\n".join(h.read_text() for h in HEADERS)
    for name in ("TF_MAX_FRICTION_STATES", "TF_MAX_TARGETS"):
        m = re.search(rf"#define\s+{name}\s+(\d+)", text)
        assert m and int(m.group(1)) == _core.C_NAMES[name]


def test_groups_are_dense_and_match_python_names():
    """Every group's codes are 0..n-1, and the names Python uses elsewhere are the groups' names."""
    for group, codes in _core.CONSTANTS.items():
        if group == "limit":
            continue
        assert sorted(codes.values()) == list(range(len(codes))), group
    assert set(_bridge.FRICTION_CODES) == set(tf.models.FRICTION_MODELS)
    assert set(_bridge.PLANT_CODES) == set(tf.models.PLANTS)
    assert set(_bridge.LAW_CODES) == set(tf.models.LAWS) | {"none"}
    assert len(_bridge.PARAMETERS) == _core.CONSTANTS["limit"]["parameters"]
    assert len(_bridge.OUTPUTS) == _core.CONSTANTS["limit"]["fixed_outputs"]
    assert set(tf.models.PARAMETER_UNITS) == set(_bridge.PARAMETERS)
    assert set(_bridge.METHOD_CODES) == set(SOLVERS)
    for cls in tf.models.FRICTION_MODELS.values():  # every field of a friction model is a core parameter
        names = {f for f in cls.__dataclass_fields__ if f not in cls.arrays}
        assert names <= set(_bridge.PARAMETERS), (cls.model, names - set(_bridge.PARAMETERS))


def test_only_the_bridge_imports_the_core():
    offenders = []
    for py in PACKAGE.rglob("*.py"):
        if py.name == "_bridge.py":
            continue
        if re.search(r"^\s*from\s+\.+\s+import\s+.*\b_core\b|^\s*import\s+.*\b_core\b|\b_core\.", py.read_text(),
                     flags=re.M):
            offenders.append(str(py.relative_to(PACKAGE)))
    assert not offenders, f"modules that call the compiled core directly: {offenders}"


def test_output_columns_are_where_the_bridge_says():
    """The displacement column of a run is the end effector's displacement (checked through a state
    the core also reports: relative displacement = x_e - x_p)."""
    model = tf.load_model("li2009-base")
    res = tf.simulate(model, 0.05, input=tf.Sawtooth(30, 50, 0.99), sample_rate=2000)
    np.testing.assert_allclose(res.relative_displacement, res.displacement - res.stage_displacement,
                               rtol=0, atol=1e-12 * np.ptp(res.displacement))


def test_failure_status_is_named():
    """A run that hits its step limit is reported with the status's name, not a number."""
    model = tf.load_model("li2009-base")
    spec = _bridge.model_spec(model, None, tf.Sawtooth(30, 50, 0.99))
    t = np.linspace(0, 0.1, 11)
    out = np.empty((t.size, _bridge.n_outputs(model, False)))
    with pytest.raises(_bridge.CoreFailure) as e:
        _bridge.run(spec, t, out, method="dopri5", rtol=1e-8, max_steps=5)
    assert e.value.status == "max_steps"
    with pytest.raises(tf.SolverError, match="raise max_steps"):
        tf.simulate(model, 0.1, input=tf.Sawtooth(30, 50, 0.99), controller=tf.StepSizeController(max_steps=5))


# ---------------------------------------------------------------------------------------------
# Issue 32, item 7: Ctrl-C during one long C integration took effect 48-67 s late (the binding runs
# tf_solve without the GIL, so Python's handlers waited for it). The core now polls the binding
# every TF_POLL_STEPS steps, and the binding runs the pending signal handlers every 50 ms.
# ---------------------------------------------------------------------------------------------

def test_ctrl_c_stops_a_long_simulation_within_a_second(tmp_path):
    """`thermofriction simulate` of 1e5 s (minutes of integration) gets SIGINT once it is integrating: it
    exits within 2 s with the command line's interrupted status (130) and message, no traceback and no
    output file."""
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "long.csv"
    cmd = [sys.executable, "-m", "thermofriction", "simulate", "li2009-model-i", "--temperature", "35",
           "--duration", "1e5", "--sample-rate", "1", "--max-steps", "1000000000", "-o", str(out)]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=default_signals)
    try:
        time.sleep(4.0)  # start-up is 0.3-2 s: by now it integrates (the whole run takes minutes)
        assert p.poll() is None, p.communicate()
        sent = time.monotonic()
        p.send_signal(signal.SIGINT)
        stdout, stderr = p.communicate(timeout=30)
        late = time.monotonic() - sent
    finally:
        p.kill()
        p.wait()
    assert p.returncode == 130, stderr
    assert "interrupted" in stderr and "Traceback" not in stderr, stderr
    assert late < 2.0, f"exited {late:.1f} s after SIGINT"
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_a_signal_handler_that_raises_stops_the_integration():
    """In the library: a Python signal handler that raises (here on SIGALRM, 0.3 s into a simulation of
    minutes) ends tf.simulate within a second with that exception, not a SolverError; a later
    simulation runs normally."""
    import signal
    import time

    class Alarm(Exception):
        pass

    def handler(signum, frame):
        raise Alarm

    model = tf.load_model("li2009-model-i")
    old = signal.signal(signal.SIGALRM, handler)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.3)
        start = time.monotonic()
        with pytest.raises(Alarm):
            tf.simulate(model, 1e5, temperature=35.0, sample_rate=1.0, solver=None, max_samples=None)
        assert time.monotonic() - start < 1.5
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert np.isfinite(tf.simulate(model, 0.01, temperature=35.0).displacement).all()


def test_friction_domains_are_the_header_table_and_cover_every_model():
    """One domain rule per parameter, written once (domains.h's X-macro): the binding exports the rows
    the C checks walk, in their order, for every friction model, naming parameters of the list."""
    text = (ROOT / "core" / "include" / "thermofriction" / "domains.h").read_text()
    block = re.search(r"#define TF_FRICTION_DOMAINS\(X\)(.*?)\n\s*\n", text, flags=re.S).group(1)
    rows = re.findall(r"X\((\w+),\s*(\w+),\s*(\w+),\s*(\w+),\s*(\w+)\)", block)
    assert len(rows) > 30
    code = {sym: value for sym, value in _core.C_NAMES.items()}
    names = {group: {v: k for k, v in codes.items()} for group, codes in _core.CONSTANTS.items()}
    expected = {}
    for model, param, rule, other, when in rows:
        expected.setdefault(names["friction"][code[f"TF_FRICTION_{model}"]], []).append(
            (names["parameter"][code[f"TF_P_{param}"]], names["domain_rule"][code[f"TF_DOMAIN_{rule}"]],
             None if other == "NONE" else names["parameter"][code[f"TF_P_{other}"]],
             names["domain_when"][code[f"TF_DOMAIN_{when}"]]))
    assert _bridge.FRICTION_DOMAINS == {k: tuple(v) for k, v in expected.items()}
    assert set(_bridge.FRICTION_DOMAINS) == set(tf.models.FRICTION_MODELS)
    for model, rows in _bridge.FRICTION_DOMAINS.items():
        fields = set(tf.models.FRICTION_MODELS[model].__dataclass_fields__)
        assert {row[0] for row in rows} <= fields | {"v_smooth"}, model  # v_smooth: Model II's offset form too


def test_friction_model_codes_come_from_the_header_list():
    """The friction models' ids and the binding's names are domains.h's TF_FRICTION_MODELS, in its order."""
    entries = header_friction_model_list()
    assert len(entries) == _core.CONSTANTS["limit"]["friction_models"] >= 6
    assert _bridge.FRICTION_CODES == {name: code for code, (_, name) in enumerate(entries)}
