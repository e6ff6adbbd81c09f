"""The subpackages' earlier names, kept importable with a DeprecationWarning.

``thermofriction.identify``, ``.validate``, ``.simulate`` and ``.report`` were both modules and the functions
the package exports, so the function shadowed its module (``thermofriction.validate.ValidationResult`` raised
AttributeError). The modules are now ``identification``, ``validation``, ``simulation`` and ``reporting``;
an import under an old name (``from thermofriction.identify import Parameter``, ``import
thermofriction.identify.procedures as p``) still works, warns, and returns the new module, while
``thermofriction.identify`` stays the function -- so ``import thermofriction.identify as m``, which binds that
attribute, gives the function, and the warning says so. ``python -m`` with an old name names the new one (the
modules are no programs)."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import types
import warnings

#: old module name -> new module name, under ``thermofriction.``
RENAMED = {"identify": "identification", "validate": "validation", "simulate": "simulation",
           "report": "reporting"}


def _new_name(fullname: str) -> str | None:
    """``thermofriction.<new>[.sub]`` for ``thermofriction.<old>[.sub]``, else None."""
    parts = fullname.split(".")
    if len(parts) < 2 or parts[0] != "thermofriction" or parts[1] not in RENAMED:
        return None
    return ".".join(["thermofriction", RENAMED[parts[1]], *parts[2:]])


class _OldNames(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds ``thermofriction.<old>[.sub]`` and loads it as the module under its new name."""

    def find_spec(self, fullname, path=None, target=None):
        new = _new_name(fullname)
        if new is None or importlib.util.find_spec(new) is None:
            return None
        return importlib.util.spec_from_loader(fullname, self, origin=new)

    def create_module(self, spec):
        package, _, name = spec.name.rpartition(".")
        # ``import thermofriction.simulate as s`` binds the package's attribute, the function: say so
        note = (f" ({spec.name} is the function {name}: 'import {spec.name} as ...' gives the function, not the "
                f"module)" if package == "thermofriction" else "")
        warnings.warn(f"module {spec.name} is now {spec.origin}; the old name will be removed{note}",
                      DeprecationWarning, stacklevel=2)
        module = importlib.import_module(spec.origin)
        spec.loader_state = module.__spec__
        return module

    def exec_module(self, module):
        old = module.__spec__.name
        # the import system has set the old name's spec on the real module: put its own back
        module.__spec__ = module.__spec__.loader_state
        package, _, name = old.rpartition(".")
        function = sys.modules["thermofriction"].__dict__.get(package.rpartition(".")[2])
        if package.count(".") == 1 and callable(function) and not isinstance(function, types.ModuleType):
            # ``import thermofriction.identify.procedures as p`` takes p from attributes: thermofriction.identify
            # (the function), then its ``problem``
            setattr(function, name, module)

    def get_code(self, fullname):
        """``python -m thermofriction.simulate`` (runpy asks for the code): the modules are no programs."""
        raise ImportError(f"{fullname} is now {_new_name(fullname)}, which is not a program either; the command "
                          f"line is 'thermofriction --help' (or python -m thermofriction)")


class Package(types.ModuleType):
    """The package's module type: importing a submodule sets it as an attribute of its parent, which
    would replace ``thermofriction.identify`` (the function) with the module found under the old name."""

    def __setattr__(self, name, value):
        if name in RENAMED and isinstance(value, types.ModuleType) and callable(self.__dict__.get(name)):
            return
        super().__setattr__(name, value)


def install(package_name: str) -> None:
    """Make ``package_name`` (``thermofriction``) keep its functions and find the old module names."""
    sys.modules[package_name].__class__ = Package
    if not any(isinstance(f, _OldNames) for f in sys.meta_path):
        sys.meta_path.insert(0, _OldNames())  # before the path finder, which would load a second copy
