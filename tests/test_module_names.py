"""One vocabulary (issue 28): every module is reachable under its name, next to the function of the same
task; the earlier module names and the FMU's ``integrator=`` still work, with a DeprecationWarning."""

import importlib
import subprocess
import sys
import types
import warnings

import pytest

import thermofriction as tf

RENAMED = {"identify": "identification", "validate": "validation", "simulate": "simulation", "report": "reporting"}


@pytest.mark.parametrize("function, module", sorted(RENAMED.items()))
def test_modules_are_reachable_beside_their_functions(function, module):
    """``import thermofriction.validation; thermofriction.validation.ValidationResult`` works (before, the
    module was ``thermofriction.validate``, shadowed by the function: AttributeError), and the function stays."""
    mod = importlib.import_module(f"thermofriction.{module}")
    assert isinstance(mod, types.ModuleType) and getattr(tf, module) is mod
    assert callable(getattr(tf, function)) and getattr(tf, function) is getattr(mod, function)


def test_validation_result_by_its_module_path():
    import thermofriction.validation
    assert thermofriction.validation.ValidationResult.__name__ == "ValidationResult"


@pytest.mark.parametrize("old, new", sorted(RENAMED.items()))
def test_old_module_names_import_the_same_module_with_a_warning(old, new):
    """In a fresh interpreter (the first import is the one that warns): the old name gives the same module
    object, submodules included, and the package's function is not replaced by the module."""
    sub = {"identify": "procedures", "validate": None, "simulate": "solvers", "report": "entries"}[old]
    lines = ["import warnings, importlib, types",
             "warnings.simplefilter('error', DeprecationWarning)",
             "import thermofriction as tf",
             "try:",
             f"    importlib.import_module('thermofriction.{old}')",
             "    raise SystemExit('no warning')",
             "except DeprecationWarning as e:",
             f"    assert 'thermofriction.{new}' in str(e), e",
             "warnings.simplefilter('ignore')",
             f"old = importlib.import_module('thermofriction.{old}')",
             f"assert old is importlib.import_module('thermofriction.{new}')",
             f"assert callable(tf.{old}) and not isinstance(tf.{old}, types.ModuleType)",
             f"assert old.__spec__.name == 'thermofriction.{new}'"]
    if sub:
        lines += [f"from thermofriction.{old}.{sub} import __name__ as n",
                  f"assert importlib.import_module('thermofriction.{old}.{sub}') is "
                  f"importlib.import_module('thermofriction.{new}.{sub}')"]
    out = subprocess.run([sys.executable, "-c", "\n".join(lines)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr + out.stdout


def test_export_fmu_integrator_is_solvers_earlier_name(tmp_path):
    """``integrator=`` still selects the solver, with a DeprecationWarning; contradicting ``solver=`` is refused."""
    from thermofriction.fmu import SOLVERS, export_fmu
    assert SOLVERS == ("adaptive", "realtime")
    with pytest.warns(DeprecationWarning, match="solver="):
        path = export_fmu("li2009-model-i", tmp_path / "rt.fmu", integrator="realtime", step=1e-5)
    import zipfile
    assert "integrator realtime" in zipfile.ZipFile(path).read("resources/model.tfm").decode()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        with pytest.raises(tf.InputError, match="contradict"):
            export_fmu("li2009-model-i", tmp_path / "x.fmu", integrator="adaptive", solver="realtime", step=1e-5)


def test_cli_fmu_integrator_is_solvers_earlier_name(tmp_path):
    """``thermofriction fmu --integrator realtime`` still writes the real-time FMU, with a note naming --solver."""
    out = subprocess.run([sys.executable, "-m", "thermofriction", "fmu", "li2009-model-i", "-o",
                          str(tmp_path / "rt.fmu"), "--integrator", "realtime", "--step", "1e-5"],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "--integrator is now --solver" in out.stderr and "fixed step 1e-05 s" in out.stdout
