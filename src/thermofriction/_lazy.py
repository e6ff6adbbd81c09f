"""Heavy modules loaded on first use, so that ``import thermofriction`` stays light: SciPy's
``optimize`` and ``stats`` alone take most of a second to import, and a simulation needs neither.

    optimize = lazy("scipy.optimize")   # at module level; nothing is imported yet
    optimize.least_squares(...)         # the first attribute access imports scipy.optimize
"""

from __future__ import annotations

import importlib


class _LazyModule:
    """Stands for the module ``name`` and imports it at the first attribute access (not placed in
    ``sys.modules`` until then, so ``"scipy.optimize" in sys.modules`` tells whether it was used)."""

    __slots__ = ("_name",)

    def __init__(self, name: str):
        self._name = name

    def __getattr__(self, attr):
        return getattr(importlib.import_module(self._name), attr)

    def __repr__(self):
        return f"<lazily imported module {self._name!r}>"


def lazy(name: str) -> _LazyModule:
    """The module ``name``, imported when an attribute of it is first used."""
    return _LazyModule(name)
