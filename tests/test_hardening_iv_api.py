"""Issue 41, the Python API's numbers: NumPy scalars are taken where an int or a float is; an int too large
for a float (10**400), NaN and infinities where a finite number is meant, and strings for numbers are one
InputError naming the argument (and the key inside a dict) -- never an OverflowError, a ValueError or a
TypeError from inside; and a series of bad schedulers does not leave Dask to hang the next run.

The property runs over every numeric argument of every public function that test_api_types.calls lists
(the package's public functions and constructors), with every other argument valid."""

import gc
import os
import subprocess
import sys
import textwrap
import threading
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import thermofriction as tf
from test_api_types import FILE_KEYS, calls, things  # noqa: F401 - the fixture, shared

#: the kinds of argument that take numbers (test_api_types.TAKES), and the NumPy scalar each takes
NUMERIC = {"number": np.float64(0.5), "number?": np.float64(0.5), "whole": np.int64(2), "whole?": np.int64(2),
           "numbers": np.float32(35.0), "numbers?": np.float32(35.0), "numbers*": np.float32(35.0),
           "temperature?": np.float32(35.0), "array": None}
#: the arguments the list in test_api_types leaves out, with their kinds
MORE = {"simulate": {"t_eval": "numbers*"}, "export_fmu": {"fmi": "whole"}}
#: where a NumPy scalar of the right kind is still out of the argument's range: a value in it
IN_RANGE = {("identify", "starts"): np.int64(1), ("identify", "max_evaluations"): np.int64(5),
            ("synthesize", "temperatures"): np.float64(35.0), ("synthesize", "validate"): np.float64(36.0),
            ("synthesize", "duration"): np.float64(0.02), ("synthesize", "sample_rate"): np.float64(1000.0),
            ("synthesize", "drift"): np.float64(0.0), ("synthesize", "noise"): np.float64(1e-9),
            ("synthesize", "quantization"): np.float64(0.0), ("synthesize", "temperature_noise"): np.float64(0.0),
            ("simulate", "duration"): np.float64(0.02), ("simulate", "sample_rate"): np.float64(1000.0),
            ("simulate", "max_samples"): np.int64(1000), ("simulate", "t_eval"): np.float64(0.0),
            ("sweep", "duration"): np.float64(0.02), ("sweep", "sample_rate"): np.float64(1000.0),
            ("sweep", "temperature"): np.float64(35.0), ("propagate", "draws"): np.int64(2),
            ("propagate", "duration"): np.float64(0.02), ("propagate", "sample_rate"): np.float64(1000.0),
            ("propagate", "temperatures"): np.float64(35.0), ("export_fmu", "fmi"): np.int64(2),
            ("export_fmu", "temperature"): np.float64(35.0), ("simulate_heating", "duration"): np.float32(0.25),
            ("simulate_heating", "samples"): np.int64(10), ("simulate_heating", "temperature"): np.float64(25.0),
            ("cycle_table", "temperatures"): np.float64(35.0), ("cycle_table", "warmup_cycles"): np.int64(1),
            ("cycle_table", "measure_cycles"): np.int64(1), ("simulate_loop", "temperature"): np.float64(35.0),
            ("simulate_loop", "substeps"): np.int64(2), ("friction_steps", "temperature"): np.float64(35.0),
            ("friction_steps", "dt"): np.float64(1e-4), ("sine_reference", "duration"): np.float64(0.01),
            ("sine_reference", "dt"): np.float64(1e-4), ("sine_reference", "frequency"): np.float64(5.0),
            ("point_to_point", "move_time"): np.float64(0.01), ("point_to_point", "dwell"): np.float64(0.01),
            ("point_to_point", "dt"): np.float64(1e-4), ("compare_compensation", "temperatures"): np.float64(35.0),
            ("compare_compensation", "calibration"): np.float64(35.0),
            ("StepSizeController", "rtol"): np.float64(1e-6), ("StepSizeController", "max_steps"): np.int64(1000),
            ("Sawtooth", "direction"): np.int64(-1), ("Sawtooth", "rise"): np.float64(0.9),
            ("Square", "duty"): np.float64(0.5), ("Heat", "heat_fraction"): np.float64(0.5)}
#: too slow to run here with a valid NumPy scalar (seconds to minutes): only the refusals are drawn
RUNS_LONG = {"identify", "identify_fleet", "compare_compensation", "export_fmu", "cycle_table", "simulate_loop"}

HUGE = st.sampled_from([10 ** 400, -10 ** 400, 2 ** 1024])
NON_FINITE = st.sampled_from([float("nan"), float("inf"), -float("inf"), np.float64("nan"), np.float32("inf")])
TEXT = st.sampled_from(["0.01", "1", "35", "1e-5", "nan", " 2 "])


def _numeric(t):
    """(function name, function, valid keywords, argument, kind) for every numeric argument."""
    out = []
    for name, (fn, valid, kinds) in calls(t).items():
        for arg, kind in {**kinds, **MORE.get(name, {})}.items():
            if kind in NUMERIC:
                out.append((name, fn, valid, arg, kind))
    return out


def _named(arg, message):
    return arg in message or f"'{FILE_KEYS.get(arg)}'" in message


def _refused_naming(name, fn, valid, arg, value):
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fn(**{**valid, arg: value})
    except tf.InputError as e:
        assert _named(arg, str(e)), f"{name}({arg}={value!r}): the message does not name {arg!r}: {e}"
    except Exception as e:  # noqa: BLE001 - the property: nothing else
        raise AssertionError(f"{name}({arg}={value!r}) raised {type(e).__name__}: {e}") from e
    else:
        raise AssertionError(f"{name}({arg}={value!r}) was accepted")


def test_the_property_covers_the_numeric_arguments_of_the_reported_functions(things):
    """The numeric arguments the attack found (19 with an OverflowError among them) are all drawn below."""
    covered = {(name, arg) for name, _, _, arg, _ in _numeric(things)}
    for name, arg in [("simulate", "duration"), ("simulate", "t_eval"), ("simulate", "temperature"),
                      ("identify", "starts"), ("identify", "seed"), ("identify", "max_evaluations"),
                      ("identify", "rtol"), ("identify", "reference_temperature"), ("propagate", "temperatures"),
                      ("propagate", "level"), ("sweep", "duration"), ("export_fmu", "step"),
                      ("export_fmu", "fmi"), ("synthesize", "drift"), ("synthesize", "seed")]:
        assert (name, arg) in covered, (name, arg)


def test_huge_ints_non_finite_and_text_for_numbers_are_input_errors_naming_the_argument(things):
    """Every numeric argument: 10**400 (was OverflowError in 36 arguments), NaN and infinities where the
    argument is a finite number, and its value as a string, each one InputError naming the argument."""
    cases = _numeric(things)

    @settings(max_examples=6 * len(cases), deadline=None, database=None,
              suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
    @given(st.data())
    def check(draw):
        name, fn, valid, arg, kind = draw.draw(st.sampled_from(cases), label="argument")
        wrong = draw.draw(st.one_of(HUGE, TEXT) if kind.startswith("whole") else st.one_of(HUGE, TEXT, NON_FINITE),
                          label="value")
        _refused_naming(name, fn, valid, arg, wrong)
        if kind in ("numbers", "numbers?", "numbers*", "array") and not isinstance(wrong, str):
            _refused_naming(name, fn, valid, arg, [wrong])  # inside a list too
    check()


def test_numpy_scalars_are_taken_where_an_int_or_a_float_is(things):
    """np.int64 where an int is, np.float64 and np.float32 where a float is: the call gives what the
    plain Python number gives (a result or the same refusal) -- never a TypeError or a ValueError."""
    failures = []
    for name, fn, valid, arg, kind in _numeric(things):
        value = IN_RANGE.get((name, arg), NUMERIC[kind])
        if value is None or name in RUNS_LONG:
            continue
        plain = value.item()
        outcomes = []
        for v in (value, plain):
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    fn(**{**valid, arg: v})
                outcomes.append("ok")
            except tf.InputError as e:
                outcomes.append(f"InputError: {e}".replace(repr(value), repr(plain)).replace(
                    type(value).__name__, type(plain).__name__))
            except Exception as e:  # noqa: BLE001
                outcomes.append(f"{type(e).__name__}: {e}")
        if outcomes[0].split(":")[0] != outcomes[1].split(":")[0]:
            failures.append(f"{name}({arg}={value!r}): {outcomes[0]} / with {plain!r}: {outcomes[1]}")
    assert not failures, "\n".join(failures)


def test_identify_takes_numpy_integers_for_starts_seed_and_max_evaluations(things):
    """Before: identify(data, method='base', starts=np.int64(1)) ran the fit, then raised ValueError ('the truth
    value of an empty array is ambiguous') in provenance.py, comparing the option with (). The options are
    written to the fitted model's provenance as plain ints."""
    fit = tf.identify(things["data"], method="base", init="li2009-base", starts=np.int64(1), seed=np.int64(3),
                      max_evaluations=np.int64(20))
    options = fit.model.provenance["options"]
    assert options["starts"] == 1 and options["seed"] == 3 and options["max_evaluations"] == 20
    assert all(type(options[k]) is int for k in ("starts", "seed", "max_evaluations"))


@pytest.mark.parametrize("laws, words", [
    ({"fc": 3}, ["laws['fc']", "int 3", "linear, exp, const"]),
    ({"fc": "cubic"}, ["laws['fc']", "str 'cubic'"]),
    ({"fc": ["linear", None]}, ["laws['fc']"]),
    ({"fc": []}, ["laws['fc']"]),
    ({3: "linear"}, ["laws", "int 3"]),
])
def test_wrong_values_in_the_laws_dict_name_the_key(things, laws, words):
    """Before: identify(data, laws={'fc': 3}) raised TypeError from inside the fit."""
    with pytest.raises(tf.InputError) as info:
        tf.identify(things["data"], method="model-i", laws=laws, starts=1)
    for w in words:
        assert w in str(info.value), (w, str(info.value))


def test_strings_for_numbers_are_refused_in_t_eval_and_step(things):
    """Before: simulate(t_eval='0.01') ran on the grid [0.01]; export_fmu(step='1e-5') took the string."""
    m = things["model"]
    with pytest.raises(tf.InputError, match=r"t_eval must be .*got str '0\.01'"):
        tf.simulate(m, temperature=35.0, t_eval="0.01")
    with pytest.raises(tf.InputError, match=r"t_eval must be .*got list"):
        tf.simulate(m, temperature=35.0, t_eval=["0", "0.01"])
    out = things["folder"] / "x.fmu"
    with pytest.raises(tf.InputError, match=r"step must be a number \[s\] or None, got str '1e-5'"):
        tf.export_fmu(m, out, solver="realtime", step="1e-5")
    assert not out.exists()
    # a NumPy grid and a NumPy step are numbers
    res = tf.simulate(m, temperature=35.0, t_eval=np.linspace(0.0, 0.01, 11, dtype=np.float32))
    assert res.time.size == 11


def test_huge_whole_numbers_are_refused_with_their_range(things):
    """A seed of 10**400 ran, then could not be written to a model file; samples=-10**400 was NumPy's
    ValueError, warmup_cycles=10**400 'Maximum allowed size exceeded'."""
    with pytest.raises(tf.InputError, match=r"seed must be a whole number, 0 or more, got int 1000.*beyond a 64-bit integer"):
        tf.synthesize(things["model"], [35.0], duration=0.02, sample_rate=1000.0, seed=10 ** 400)
    with pytest.raises(tf.InputError, match="samples must be a positive whole number"):
        tf.heating.simulate_heating(things["heated"], 0.2, samples=-10 ** 400)
    with pytest.raises(tf.InputError, match="warmup_cycles must be a whole number from 0 to"):
        tf.heating.cycle_table(things["model"], tf.Sine(amplitude=30.0, frequency=5.0), [35.0],
                               warmup_cycles=10 ** 30)


def _io_loops():
    return sum(t.name == "IO loop" and t.is_alive() for t in threading.enumerate())


def test_a_failed_connection_leaves_no_dask_client_behind(things):
    """A Client that fails to connect is garbage in a reference cycle with its IO loop running; its __del__,
    when a later collection runs it inside the next Client's start, waits on the lock that start holds (Dask's
    LoopRunner class lock): the run after a few bad schedulers hung for ever. Now it is collected at once:
    with the automatic collection off, no IO loop is left running after the refusals."""
    _, valid, _ = calls(things)["propagate"]
    valid = {k: v for k, v in valid.items() if k != "scheduler"}
    tf.propagate(**valid, scheduler="sequential")
    gc.collect()
    before = _io_loops()
    gc.disable()
    try:
        for bad in ("inproc://x", "x:y", "tcp://[::1", "inproc://"):
            with pytest.raises(tf.InputError, match="scheduler"):
                tf.propagate(**valid, scheduler=bad)
        assert _io_loops() == before, f"{_io_loops() - before} Dask IO loop(s) of failed clients left running"
    finally:
        gc.enable()


SERIES = textwrap.dedent("""
    import numpy as np, thermofriction as tf
    if __name__ == "__main__":
        m = tf.load_model("li2009-base")
        p = tf.Parameters(); p.add("fc", m.friction.fc, min=0.0); p["fc"].stderr = 0.01 * m.friction.fc
        fit = tf.FitResult(method="base", model=m, parameters=p, correlation=np.eye(1), cost=0.0, rmse=0.0,
                           n_points=1, nfev=0, njev=0, starts=1, wall_time=0.0, success=True, message="")
        kw = dict(result=fit, temperatures=[35.0], draws=2, duration=0.02, sample_rate=1000.0)
        for bad in [3, "not-a-scheduler", object(), "inproc://x", "x:y", "tcp://[::1", "inproc://", "threads:1"]:
            try:
                tf.propagate(**kw, scheduler=bad)
            except tf.InputError:
                pass
        for good in [None, "sequential", "threads"]:
            tf.propagate(**kw, scheduler=good)
        print("done")
""")


def test_a_series_of_bad_schedulers_then_a_good_one_does_not_hang(tmp_path):
    """The attack's series: an int, a string that is not a scheduler, an object, addresses Dask cannot use,
    then good ones: before, the run hung in Dask (the failed clients' close waiting on a lock); now it ends."""
    script = tmp_path / "series.py"
    script.write_text(SERIES)
    env_timeout = {"DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "2s"}
    r = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120,
                       env={**os.environ, **env_timeout})
    assert r.returncode == 0 and "done" in r.stdout, r.stderr[-2000:]
