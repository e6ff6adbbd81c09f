"""The protocol every result of the package follows (docs/architecture.md): one source, ``to_dict()``,
and the same views of it everywhere.

- ``to_dict()``: the result as JSON-able data (each result implements it);
- ``to_json(path=None)``: that as JSON, written atomically when a path is given;
- ``summary()``: the few (what, value) rows a reader looks at first (each result implements it);
- ``report()``: a text report (the title and the summary; fits and validations print more);
- ``_repr_html_()``: the same as an HTML table, for notebooks;
- ``to_dataframe()``: the result's rows (samples, parameters, experiments) as a pandas DataFrame, from
  ``_frame()`` (each result implements it);
- ``plot()``: a matplotlib Figure (each result implements it; never pyplot's).
"""

from __future__ import annotations

import html

from ._io import dump_json, jsonable


class Result:
    """The results protocol; subclasses implement ``to_dict``, ``summary``, ``_frame`` and ``plot``."""

    #: what the result is, in words (the report's title)
    title = "result"

    def to_dict(self) -> dict:
        raise NotImplementedError

    def to_json(self, path=None) -> str:
        """The result as JSON, written atomically to ``path`` when given."""
        return dump_json(jsonable(self.to_dict()), path)

    def summary(self) -> list:
        raise NotImplementedError

    def _frame(self) -> dict:
        raise NotImplementedError

    def to_dataframe(self):
        """The result's rows as a pandas DataFrame (pandas is an optional dependency)."""
        try:
            import pandas as pd
        except ImportError:  # pragma: no cover - depends on the environment
            raise ImportError("to_dataframe() needs pandas: pip install 'thermofriction[dataframe]'") from None
        return pd.DataFrame(self._frame())

    def report(self) -> str:
        rows = self.summary()
        width = max((len(k) for k, _ in rows), default=0)
        return "\n".join([f"[[{self.title}]]"] + [f"    {k.ljust(width)} = {v}" for k, v in rows])

    def _repr_html_(self) -> str:
        body = "".join(f"<tr><th style='text-align:left'>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>"
                       for k, v in self.summary())
        return f"<table><caption>{html.escape(self.title)}</caption>{body}</table>"

    def plot(self, *args, **kwargs):
        raise NotImplementedError

    def __str__(self) -> str:
        return self.report()


__all__ = ["Result"]
