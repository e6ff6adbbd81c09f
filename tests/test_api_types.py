"""Issue 32, item 5: every public function refuses an argument of the wrong type with the package's
InputError naming the argument -- never a TypeError, AttributeError or another traceback from inside, never
a silent coercion (`duration='2'`, `sample_rate=True`), and before any work (the calls below would take
seconds to minutes if they ran).

The property: for each public function (everything callable in `thermofriction.__all__` that a user calls
with arguments of their own, and the subpackages' public functions), with every other argument valid, one
argument replaced by a value of a type it does not take (drawn by hypothesis: None, booleans, numbers,
strings, bytes, lists, dicts, sets, complex numbers, arrays of text, arbitrary objects, minus the types the
argument does take) raises InputError whose message names that argument. The rule it checks is in
src/thermofriction/_args.py and docs/hardening.md#python-api-argument-types."""

import numbers
import os
import time

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import thermofriction as tf
from thermofriction import control, heating
from thermofriction.data import read_experiment_csv, read_experiment_mat
from thermofriction.reporting import control_report, heating_report
from thermofriction.scale import parse_axis


class Opaque:
    def __repr__(self):
        return "<Opaque>"


WRONG = st.one_of(
    st.none(), st.booleans(), st.integers(-10 ** 6, 10 ** 6), st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=6), st.binary(max_size=6), st.lists(st.integers(-5, 5), max_size=3),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=2), st.complex_numbers(max_magnitude=10),
    st.sets(st.integers(), max_size=2), st.just(np.array(["a", "b"])), st.builds(Opaque), st.just(np.bool_(True)))


def _number(v):
    return isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))


def _path(v):
    return isinstance(v, (str, os.PathLike))


#: kind of argument -> the values of the types it takes (these are not drawn: a valid type with an odd value
#: is another test's business, and a valid duration of 1e6 s would run)
TAKES = {
    "number": _number,
    "number?": lambda v: v is None or _number(v),
    "whole": lambda v: isinstance(v, numbers.Integral) and not isinstance(v, (bool, np.bool_)),
    "whole?": lambda v: v is None or (isinstance(v, numbers.Integral) and not isinstance(v, (bool, np.bool_))),
    "flag": lambda v: isinstance(v, (bool, np.bool_)),
    "flag?": lambda v: v is None or isinstance(v, (bool, np.bool_)),
    "text": lambda v: isinstance(v, str),
    "text?": lambda v: v is None or isinstance(v, str),
    "path": _path,
    "path?": lambda v: v is None or _path(v),
    "function?": lambda v: v is None or callable(v),
    "model": lambda v: isinstance(v, tf.Model),
    "model|path": lambda v: isinstance(v, tf.Model) or _path(v),
    "model|path?": lambda v: v is None or isinstance(v, tf.Model) or _path(v),
    "dataset": lambda v: isinstance(v, tf.Dataset),
    "names?": lambda v: v is None or isinstance(v, str) or (isinstance(v, (list, tuple, set, frozenset)) and
                                                            all(isinstance(x, str) for x in v)),
    "waveform": lambda v: isinstance(v, tf.Waveform),
    "waveform?": lambda v: v is None or isinstance(v, tf.Waveform),
    "temperature?": lambda v: v is None or _number(v) or isinstance(v, tf.Sampled),
    "numbers": lambda v: _number(v) or (isinstance(v, (list, tuple, np.ndarray)) and len(v) and
                                        all(_number(x) for x in v)),
    "numbers?": lambda v: v is None or _number(v) or (isinstance(v, (list, tuple, np.ndarray)) and len(v) and
                                                      all(_number(x) for x in v)),
    "numbers*": lambda v: v is None or _number(v) or (isinstance(v, (list, tuple, np.ndarray)) and
                                                      all(_number(x) for x in v)),  # may be empty
    "dict?": lambda v: v is None or isinstance(v, dict),
    "solver?": lambda v: v is None or isinstance(v, (tf.Dopri5, tf.Rodas4, tf.AutoSwitch, str)),
    "controller?": lambda v: v is None or isinstance(v, tf.StepSizeController),
    "scheduler?": lambda v: v is None or _path(v),
    "sequence": lambda v: isinstance(v, (list, tuple)) and len(v) > 0,
    "sequence?": lambda v: v is None or (isinstance(v, (list, tuple)) and len(v) > 0),
    "sequence|path": lambda v: _path(v) or (isinstance(v, (list, tuple)) and len(v) > 0),
    "grid": lambda v: isinstance(v, (dict, list, tuple)) and len(v) > 0,
    "fit": lambda v: isinstance(v, tf.FitResult),
    "reference": lambda v: isinstance(v, control.Reference),
    "pid": lambda v: isinstance(v, control.PID),
    "compensation?": lambda v: v is None or isinstance(v, (control.FeedForward, control.Observer)),
    "law": lambda v: isinstance(v, tf.Law),
    "laws": lambda v: isinstance(v, dict) and all(isinstance(k, str) and isinstance(x, tf.Law) for k, x in v.items()),
    "array": lambda v: isinstance(v, (list, tuple, np.ndarray)) and len(v) > 0 and all(_number(x) for x in v),
}


@pytest.fixture(scope="module")
def things(tmp_path_factory):
    folder = tmp_path_factory.mktemp("api")
    model = tf.load_model("li2009-model-i")
    data = tf.synthesize(model, [33.0, 37.0], duration=0.05, sample_rate=2000, seed=1)
    ds = tf.save_dataset(data, folder / "ds")
    base = tf.load_model("li2009-base")  # a fit as identify returns one, made here (identify takes seconds)
    params = tf.Parameters()
    params.add("fc", base.friction.fc, min=0.0)
    params["fc"].stderr = 0.01 * base.friction.fc
    fit = tf.FitResult(method="base", model=base, parameters=params, correlation=np.eye(1), cost=0.0, rmse=0.0,
                       n_points=1, nfev=0, njev=0, starts=1, wall_time=0.0, success=True, message="")
    heated = tf.load_model("li2009-self-heating")
    stage = tf.load_model("stage-model-i")
    ref = control.sine_reference(1e-6, 5.0, 0.01)
    return dict(folder=folder, model=model, data=data, ds=ds, fit=fit, heated=heated, stage=stage, ref=ref,
                csv=str(next(ds.glob("*.csv"))))


def calls(t):
    """name -> (function, valid keyword arguments, {argument: kind}) -- the arguments drawn wrong."""
    m, d, out = t["model"], t["data"], str(t["folder"] / "out")
    sine = tf.Sine(amplitude=30.0, frequency=5.0)
    return {
        "load_model": (tf.load_model, dict(source="li2009-model-i"), {"source": "path", "friction_from": "function?"}),
        "simulate": (tf.simulate, dict(model=m, duration=0.02, temperature=35.0, sample_rate=1000.0),
                     {"model": "model", "duration": "number?", "temperature": "temperature?", "input": "waveform?",
                      "sample_rate": "number", "solver": "solver?", "controller": "controller?",
                      "max_samples": "whole?", "friction_work": "flag"}),
        "parse_waveform": (tf.parse_waveform, dict(spec="sine:amplitude=1,frequency=2"), {"spec": "text"}),
        "identify": (tf.identify, dict(data=d, method="base", init="li2009-base", starts=1),
                     {"data": "dataset", "method": "text", "init": "model|path?", "friction": "text?",
                      "parameters": "names?", "free": "names?", "procedure": "text", "laws": "dict?",
                      "refine": "flag", "reference_temperature": "number?", "controller": "controller?",
                      "rtol": "number?", "starts": "whole", "seed": "whole", "progress": "function?", "offset": "flag",
                      "max_evaluations": "whole?"}),
        "load_dataset": (tf.load_dataset, dict(path=t["ds"]), {"path": "path"}),
        "save_dataset": (tf.save_dataset, dict(dataset=d, folder=out), {"dataset": "dataset", "folder": "path",
                                                                        "overwrite": "flag"}),
        "synthesize": (tf.synthesize, dict(model=m, temperatures=[35.0], duration=0.02, sample_rate=1000.0),
                       {"model": "model", "temperatures": "numbers", "validate": "numbers*", "duration": "number",
                        "sample_rate": "number", "input": "waveform?", "noise": "number", "quantization": "number",
                        "temperature_noise": "number", "drift": "number", "record_temperature": "flag?",
                        "record_stage": "flag", "seed": "whole", "name": "text?", "progress": "function?"}),
        "validate": (tf.validate, dict(model=m, data=d), {"model": "model", "data": "dataset",
                                                          "experiments": "sequence?"}),
        "report": (tf.report, dict(models=[m], data=d, path=out + ".html"),
                   {"models": "sequence", "data": "dataset", "path": "path", "figures_dir": "path?",
                    "command": "text?", "title": "text?", "truth": "dict?"}),
        "sweep": (tf.sweep, dict(model=m, grid={"temperature": [35.0]}, duration=0.02, sample_rate=1000.0,
                                 scheduler="sequential"),
                  {"model": "model|path", "grid": "grid", "input": "waveform?", "duration": "number",
                   "temperature": "number?", "metrics": "names?", "sample_rate": "number", "solver": "solver?",
                   "controller": "controller?", "scheduler": "scheduler?", "workers": "whole?",
                   "batch_size": "whole?", "progress": "function?"}),
        "identify_fleet": (tf.identify_fleet, dict(datasets=[d], method="base", init="li2009-base",
                                                   scheduler="sequential", starts=1),
                           {"datasets": "sequence|path", "method": "text", "init": "model|path?",
                            "scheduler": "scheduler?", "workers": "whole?", "progress": "function?"}),
        "propagate": (tf.propagate, dict(result=t["fit"], temperatures=[35.0], draws=2, duration=0.02,
                                         sample_rate=1000.0, scheduler="sequential"),
                      {"result": "fit", "temperatures": "numbers", "draws": "whole", "seed": "whole",
                       "input": "waveform?", "duration": "number", "sample_rate": "number", "level": "number",
                       "solver": "solver?", "controller": "controller?", "scheduler": "scheduler?",
                       "workers": "whole?", "batch_size": "whole?", "progress": "function?"}),
        "export_fmu": (tf.export_fmu, dict(model=m, path=out + ".fmu"),
                       {"model": "model|path", "path": "path", "temperature": "number?", "model_identifier": "text?",
                        "source": "text?", "solver": "text", "step": "number?", "integrator": "text?"}),
        "read_experiment_csv": (read_experiment_csv, dict(path=t["csv"]), {"path": "path", "with_headers": "flag"}),
        "read_experiment_mat": (read_experiment_mat, dict(path=out + ".mat"), {"path": "path", "struct": "text?",
                                                                               "units": "dict?"}),
        "parse_axis": (parse_axis, dict(text="temperature=30:40:1"), {"text": "text"}),
        "simulate_heating": (heating.simulate_heating, dict(model=t["heated"], duration=0.2, samples=10),
                             {"model": "model", "duration": "number", "input": "waveform?",
                              "temperature": "number?", "samples": "whole"}),
        "cycle_table": (heating.cycle_table, dict(model=m, input=sine, temperatures=[35.0]),
                        {"model": "model", "input": "waveform", "temperatures": "numbers", "warmup_cycles": "whole",
                         "measure_cycles": "whole"}),
        "heating_report": (heating_report, dict(runs=[{"label": "a run"}], path=out + "-h.html"),
                           {"runs": "sequence", "path": "path", "figures_dir": "path?", "title": "text?",
                            "command": "text?"}),
        "control_report": (control_report, dict(rows=[{"reference": "a run"}], path=out + "-c.html"),
                           {"rows": "sequence", "path": "path", "figures_dir": "path?", "title": "text?",
                            "command": "text?"}),
        "sine_reference": (control.sine_reference, dict(amplitude=1e-6, frequency=5.0, duration=0.01),
                           {"amplitude": "number", "frequency": "number", "duration": "number", "dt": "number"}),
        "point_to_point": (control.point_to_point, dict(distance=1e-6, move_time=0.01, dwell=0.01),
                           {"distance": "number", "move_time": "number", "dwell": "number", "dt": "number"}),
        "simulate_loop": (control.simulate_loop, dict(stage=t["stage"], reference=t["ref"], temperature=35.0),
                          {"stage": "model", "reference": "reference", "temperature": "number", "pid": "pid",
                           "compensation": "compensation?", "substeps": "whole"}),
        "friction_steps": (control.friction_steps, dict(model=m, velocity=[1e-6, 2e-6], dt=1e-4, temperature=35.0),
                           {"model": "model", "velocity": "array", "dt": "number", "temperature": "numbers?"}),
        "compare_compensation": (control.compare_compensation, dict(stage=t["stage"], references=[t["ref"]]),
                                 {"stage": "model", "references": "sequence", "temperatures": "numbers",
                                  "calibration": "number", "observer_gain": "number", "pid": "pid"}),
        # constructors of the objects a user builds a model and a run from
        "LuGre": (tf.LuGre, dict(sigma0=1e5, sigma1=300.0, fc=1.0), _numbers("sigma0", "sigma1", "fc", "sigma2",
                                                                            "fs", "vs", "vd", kind="number?")),
        "Coulomb": (tf.Coulomb, dict(fc=1.0), _numbers("fc", "sigma2", "v_smooth", kind="number?")),
        "Stribeck": (tf.Stribeck, dict(fc=1.0, fs=1.5, vs=1e-3), _numbers("fc", "fs", "vs", "delta", "sigma2",
                                                                           kind="number?")),
        "Dahl": (tf.Dahl, dict(sigma0=1e5, fc=1.0), _numbers("sigma0", "fc", "v_smooth", kind="number?")),
        "ElastoPlastic": (tf.ElastoPlastic, dict(sigma0=1e5, sigma1=300.0, fc=1.0, z_ba=1e-6),
                          _numbers("sigma0", "sigma1", "fc", "z_ba", "sigma2", kind="number?")),
        "Const": (tf.Const, dict(value=1.0), _numbers("value")),
        "Linear": (tf.Linear, dict(a=1.0, b=0.0), _numbers("a", "b")),
        "Exp": (tf.Exp, dict(a=1.0, b=0.0), _numbers("a", "b")),
        "ModelI": (tf.ModelI, dict(laws={"fc": tf.Const(1.0)}), {"laws": "laws"}),
        "ModelII": (tf.ModelII, dict(dF=tf.Const(0.0)), {"dF": "law", "form": "text"}),
        "Heat": (tf.Heat, dict(heat_capacity=1.0, thermal_resistance=1.0),
                 _numbers("heat_capacity", "thermal_resistance", "heat_fraction")),
        "MassPlant": (tf.MassPlant, dict(mass=1.0), _numbers("mass", "spring_stiffness", "pull_velocity")),
        "Sine": (tf.Sine, dict(amplitude=1.0, frequency=1.0), _numbers("amplitude", "frequency", "offset")),
        "Sawtooth": (tf.Sawtooth, dict(amplitude=1.0, frequency=1.0),
                     {**_numbers("amplitude", "frequency", "rise", "offset"), "direction": "whole"}),
        "Square": (tf.Square, dict(amplitude=1.0, frequency=1.0, slew=0.01),
                   _numbers("amplitude", "frequency", "slew", "offset", "duty")),
        "Step": (tf.Step, dict(amplitude=1.0), _numbers("amplitude", "time", "slew", "offset")),
        "Sampled": (tf.Sampled, dict(time=np.array([0.0, 1.0]), value=np.array([0.0, 1.0])),
                    {"time": "array", "value": "array"}),
        "StepSizeController": (tf.StepSizeController, dict(), {"rtol": "number", "atol": "numbers?",
                                                               "max_steps": "whole"}),
    }


#: a model object's field named by its model-file key (docs/models.md) in the message: [plant] 'm', [heat] 'C_th'
FILE_KEYS = {"mass": "m", "spring_stiffness": "k_s", "pull_velocity": "v_0", "heat_capacity": "C_th",
             "thermal_resistance": "R_th", "heat_fraction": "eta"}


def _numbers(*names, kind="number"):
    return {n: kind for n in names}


def test_every_public_function_of_the_package_is_covered(things):
    """The list above is the package's public functions: a new one in thermofriction.__all__ must be added."""
    covered = set(calls(things))
    constructors = {n for n in tf.__all__ if isinstance(getattr(tf, n), type)}
    functions = {n for n in tf.__all__ if n not in constructors}
    assert functions - {"PARAMETERS", "PRESETS"} <= covered, functions - covered


FUNCTIONS = ["load_model", "simulate", "parse_waveform", "identify", "load_dataset", "save_dataset", "synthesize",
             "validate", "report", "sweep", "identify_fleet", "propagate", "export_fmu", "read_experiment_csv",
             "read_experiment_mat", "parse_axis", "simulate_heating", "cycle_table", "heating_report",
             "control_report", "sine_reference", "point_to_point", "simulate_loop", "friction_steps",
             "compare_compensation"]
CONSTRUCTORS = ["LuGre", "Coulomb", "Stribeck", "Dahl", "ElastoPlastic", "Const", "Linear", "Exp", "ModelI", "ModelII",
                "Heat", "MassPlant", "Sine", "Sawtooth", "Square", "Step", "Sampled", "StepSizeController"]


@pytest.mark.parametrize("name", FUNCTIONS + CONSTRUCTORS)
def test_wrong_types_are_input_errors_naming_the_argument(things, name):
    fn, valid, kinds = calls(things)[name]

    @settings(max_examples=4 * len(kinds), deadline=None, database=None,
              suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.filter_too_much])
    @given(st.data())
    def check(draw):
        arg = draw.draw(st.sampled_from(sorted(kinds)), label="argument")
        wrong = draw.draw(WRONG.filter(lambda v: not TAKES[kinds[arg]](v)), label="value")
        t0 = time.perf_counter()
        try:
            fn(**{**valid, arg: wrong})
        except tf.InputError as e:
            named = arg in str(e) or f"'{FILE_KEYS.get(arg)}'" in str(e)
            assert named, f"{name}({arg}={wrong!r}): the message does not name {arg!r}: {e}"
        except Exception as e:  # noqa: BLE001 - the property: nothing else
            raise AssertionError(f"{name}({arg}={wrong!r}) raised {type(e).__name__}: {e}") from e
        else:
            raise AssertionError(f"{name}({arg}={wrong!r}) was accepted")
        assert time.perf_counter() - t0 < 2.0, f"{name}({arg}={wrong!r}) worked before refusing"
    check()


# -- the cases of the issue, each named -------------------------------------------------------------

def _refused(call, *words):
    with pytest.raises(tf.InputError) as info:
        call()
    for w in words:
        assert w in str(info.value), (w, str(info.value))


def test_the_reported_calls_are_input_errors_naming_argument_and_type(things):
    """Before: AttributeError / TypeError tracebacks from inside ('str' object has no attribute 'temperature')."""
    m, d = things["model"], things["data"]
    _refused(lambda: tf.identify("/path/to/data"), "data must be a Dataset", "str '/path/to/data'",
             "tf.load_dataset('/path/to/data')")
    _refused(lambda: tf.validate("li2009-model-i", d), "model must be a Model", "tf.load_model('li2009-model-i')")
    _refused(lambda: tf.load_dataset(None), "path must be a file name", "NoneType None")
    _refused(lambda: tf.load_model({"plant": {}}), "source must be a file name", "dict")
    _refused(lambda: tf.report(None, d, "r.html"), "models must be", "NoneType")
    _refused(lambda: tf.report([m], d, str(things["folder"] / "r.html"), title=123), "title must be a string",
             "int 123")
    _refused(lambda: tf.export_fmu(m, 42), "path must be a file name", "int 42")
    _refused(lambda: tf.save_dataset(d, 42), "folder must be a file name", "int 42")
    _refused(lambda: tf.identify_fleet(None), "datasets must be", "NoneType")
    assert not (things["folder"] / "r.html").exists()


def test_wrong_types_are_not_coerced(things):
    """Before: duration='2', temperature='35' and sample_rate=True (1 Hz) ran."""
    m = things["model"]
    _refused(lambda: tf.simulate(m, "2", temperature=35.0), "duration must be a number [s]", "str '2'")
    _refused(lambda: tf.simulate(m, 0.02, temperature="35"), "temperature must be", "str '35'")
    _refused(lambda: tf.simulate(m, 0.02, temperature=35.0, sample_rate=True), "sample_rate must be a number",
             "bool True")
    _refused(lambda: tf.synthesize(m, [35.0], duration="0.1"), "duration must be a number", "str '0.1'")


def test_a_solver_by_name_is_the_documented_exception(things):
    """solver='rodas4' is accepted on purpose (as --solver rodas4): it is the same run as Rodas4()."""
    m = things["model"]
    a = tf.simulate(m, 0.02, temperature=35.0, sample_rate=1000.0, solver="rodas4")
    b = tf.simulate(m, 0.02, temperature=35.0, sample_rate=1000.0, solver=tf.Rodas4())
    assert a.stats["solver"] == b.stats["solver"] == "rodas4"
    np.testing.assert_array_equal(a.displacement, b.displacement)
    _refused(lambda: tf.simulate(m, 0.02, temperature=35.0, solver="rk4"), "unknown solver 'rk4'")


def test_one_parameter_name_is_one_parameter(things, monkeypatch):
    """Before: parameters='sigma0' was read letter by letter ("'s' is not a parameter")."""
    import sys
    identify_module = sys.modules["thermofriction.identification.front"]  # where identify() calls the procedures
    seen = {}

    def capture(experiments, model, parameters, **kwargs):
        seen["parameters"] = parameters
        raise tf.InputError("stop here")
    monkeypatch.setattr(identify_module, "fit_friction", capture)
    with pytest.raises(tf.InputError, match="stop here"):
        tf.identify(things["data"], "base", init="li2009-base", parameters="sigma0")
    assert seen["parameters"] == ["sigma0"]
    with pytest.raises(tf.InputError, match="stop here"):
        tf.identify(things["data"], "base", init="li2009-base", parameters=("sigma0", "fc"))
    assert seen["parameters"] == ["sigma0", "fc"]
