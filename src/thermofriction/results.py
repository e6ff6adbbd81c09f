"""The protocol every result of the package follows (docs/architecture.md): one source, ``to_dict()``,
and the same views of it everywhere.

- ``to_dict()``: the result as JSON-able data (each result implements it);
- ``to_json(path=None)``: that as JSON, written atomically when a path is given;
- ``summary()``: a :class:`Summary`, the few things a reader looks at first (each result implements it);
- ``report()``: a text report, and ``_repr_html_()`` the same for notebooks, both from the result's structured
  fields (``_blocks()``: headings, label = value fields, tables and lines) through the one formatter here
  (:func:`as_text`, :func:`as_html`); by default the title and the summary;
- ``to_dataframe()``: the result's rows (samples, parameters, experiments) as a pandas DataFrame, from
  ``_frame()`` (each result implements it);
- ``plot()``: a matplotlib Figure (each result implements it; never pyplot's);
- ``findings``: what the reader should know (a temperature outside a law's range, a model that may create
  energy) as values, :class:`Finding`, turned into Python warnings where the public function returns
  (:func:`emit`), or kept as values by a caller that collects them (:func:`collecting`: validation, a sweep),
  never sent through the warnings module on the way.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import html
import warnings

from ._io import dump_json, jsonable


class Summary(dict):
    """What ``summary()`` returns for every result: an ordered mapping of label -> plain JSON value (text, a
    number, or a mapping of them: a validation's metrics per role, a fleet's per parameter). It is a dict, so it is
    its own JSON; ``rows()`` gives it as (label, text) for the formatter.

    Parameters
    ----------
    items : mapping or iterable of (str, object), optional
        The labels and their values, in order (as for ``dict``).
    """

    def rows(self) -> list:
        """The summary as (label, text) rows (a mapping value as "key value; key value")."""
        return [(str(k), _text(v)) for k, v in self.items()]


def _text(value) -> str:
    if isinstance(value, dict):
        return "; ".join(f"{k} {_text(v)}" for k, v in value.items())
    if isinstance(value, (list, tuple)):
        return ", ".join(_text(v) for v in value)
    return f"{value:.6g}" if isinstance(value, float) else str(value)


@dataclasses.dataclass(frozen=True)
class Finding:
    """One thing a result says the reader should know: a warning's category and its text, as a value.

    Parameters
    ----------
    category : type
        The Warning subclass it is emitted as (``TemperatureRangeWarning``, ``PassivityWarning``, ...).
    message : str
        What was found, in words.
    warning : Warning, optional
        The warning object emitted, where it carries more than its text (a ``MotionWarning``'s file and outcome,
        which the dataset's loader groups by); default None: a ``category`` made of ``message``.
    """

    category: type
    message: str
    warning: Warning | None = dataclasses.field(default=None, compare=False)

    def __str__(self) -> str:
        return self.message


#: the findings' list of the innermost :func:`collecting` block open in this context (a thread, a task), or None
_collector: contextvars.ContextVar = contextvars.ContextVar("thermofriction_findings", default=None)


@contextlib.contextmanager
def collecting():
    """Collects, as values, the findings that the functions called in the block emit (:func:`emit`), instead of
    warning: validation keeps its predictions' findings on its result, a sweep its points'. Blocks nest (an inner
    block's list is its own), and each thread or task has its own (a context variable: no global state, no lock).

    Yields
    ------
    list of Finding
        The findings emitted in the block, in order.

    Raises
    ------
    Exception
        Whatever the block raises, passed on (the collector is closed first).
    """
    found = []
    token = _collector.set(found)
    try:
        yield found
    finally:
        _collector.reset(token)


def emit(findings, stacklevel: int = 2):
    """Turns ``findings`` into Python warnings, in order: what a public function does with them as it returns
    (the edge), unless a caller collects them (:func:`collecting`): then they go into its list.

    Parameters
    ----------
    findings : iterable of Finding
        What to warn about.
    stacklevel : int, default 2
        As for ``warnings.warn``, counted from the caller of ``emit`` (2: the caller's caller).

    Returns
    -------
    None

    Raises
    ------
    Warning
        A finding's category, where the warnings filters turn it into an error (``-W error``).
    """
    sink = _collector.get()
    if sink is not None:
        sink.extend(findings)
        return
    for f in findings:
        warnings.warn(f.message if f.warning is None else f.warning, f.category, stacklevel=stacklevel + 1)


# -- the one formatter: structured blocks -> text or HTML ------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Block:
    """A piece of a report, as :func:`heading`, :func:`fields`, :func:`table` and :func:`lines` make them; the one
    formatter writes it as text (:func:`as_text`) or HTML (:func:`as_html`).

    Parameters
    ----------
    kind : {"heading", "fields", "table", "lines"}
        What it is.
    text : str, default ""
        A heading's text.
    note : str, default ""
        What follows a heading on its line.
    rows : tuple, default ()
        Fields: (label, text) pairs; a table: rows of text cells; lines: the lines.
    head : tuple, default ()
        A table's column headings.
    width : int, optional
        Fields: the labels' width; default the longest label's.
    strip : bool, default False
        A table: without its lines' trailing blanks.
    indent : str, default "    "
        In text, before each line of fields, a table or lines.
    """

    kind: str
    text: str = ""
    note: str = ""
    rows: tuple = ()
    head: tuple = ()
    width: int | None = None
    strip: bool = False
    indent: str = "    "


def heading(text: str, note: str = "") -> Block:
    """A heading: ``[[text]] note`` in text, bold (and the note plain) in HTML.

    Parameters
    ----------
    text : str
        The heading.
    note : str, default ""
        What follows it on its line.

    Returns
    -------
    Block

    Raises
    ------
    None
    """
    return Block("heading", text=text, note=note)


def fields(rows, width: int | None = None) -> Block:
    """Label = value rows.

    Parameters
    ----------
    rows : iterable of (str, str)
        The labels and their values, as text.
    width : int, optional
        The labels' width; default the longest label's.

    Returns
    -------
    Block

    Raises
    ------
    None
    """
    return Block("fields", rows=tuple(rows), width=width)


def table(head, rows, strip: bool = False, indent: str = "    ") -> Block:
    """A table of text cells under column headings.

    Parameters
    ----------
    head : sequence of str
        The column headings.
    rows : iterable of sequence of str
        The rows, a text cell per column.
    strip : bool, default False
        In text, the lines without their trailing blanks.
    indent : str, default "    "
        In text, before each line.

    Returns
    -------
    Block

    Raises
    ------
    None
    """
    return Block("table", rows=tuple(tuple(r) for r in rows), head=tuple(head), strip=strip, indent=indent)


def lines(rows) -> Block:
    """Lines of text (a note, a warning each): indented lines in text, a list in HTML.

    Parameters
    ----------
    rows : iterable of str
        The lines.

    Returns
    -------
    Block

    Raises
    ------
    None
    """
    return Block("lines", rows=tuple(rows))


def as_text(blocks) -> str:
    """The report's text: headings as ``[[...]]``, everything else indented (by the block's ``indent``).

    Parameters
    ----------
    blocks : iterable of Block
        The report's pieces, in order.

    Returns
    -------
    str

    Raises
    ------
    None
    """
    out = []
    for b in blocks:
        indent = b.indent
        if b.kind == "heading":
            out.append(f"[[{b.text}]]" + (f" {b.note}" if b.note else ""))
        elif b.kind == "fields":
            w = b.width if b.width is not None else max((len(k) for k, _ in b.rows), default=0)
            out += [f"{indent}{k.ljust(w)} = {v}" for k, v in b.rows]
        elif b.kind == "table":
            w = [max(len(r[i]) for r in b.rows + (b.head,)) for i in range(len(b.head))]
            for r in (b.head,) + b.rows:
                line = indent + "  ".join(c.ljust(w[i]) for i, c in enumerate(r))
                out.append(line.rstrip() if b.strip else line)
        else:
            out += [f"{indent}{t}" for t in b.rows]
    return "\n".join(out)


def as_html(blocks) -> str:
    """The same blocks as HTML for a notebook: headings bold, fields and tables as tables, lines as a list.

    Parameters
    ----------
    blocks : iterable of Block
        The report's pieces, in order.

    Returns
    -------
    str
        One ``<div>``, every text escaped.

    Raises
    ------
    None
    """
    e, out = html.escape, []
    for b in blocks:
        if b.kind == "heading":
            out.append(f"<b>{e(b.text)}</b>" + (f" {e(b.note)}" if b.note else ""))
        elif b.kind == "fields":
            out.append("<table>" + "".join(f"<tr><th style='text-align:left'>{e(k)}</th><td>{e(str(v))}</td></tr>"
                                           for k, v in b.rows) + "</table>")
        elif b.kind == "table":
            head = "".join(f"<th>{e(h)}</th>" for h in b.head)
            body = "".join("<tr>" + "".join(f"<td>{e(c)}</td>" for c in r) + "</tr>" for r in b.rows)
            out.append(f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")
        elif b.rows:
            out.append("<ul>" + "".join(f"<li>{e(t)}</li>" for t in b.rows) + "</ul>")
    return "<div>" + "".join(out) + "</div>"


class Result:
    """The results protocol; subclasses implement ``to_dict``, ``summary``, ``_frame`` and ``plot``, and
    ``_blocks`` where the report says more than the summary."""

    #: what the result is, in words (the report's title)
    title = "result"

    def to_dict(self) -> dict:
        raise NotImplementedError

    def to_json(self, path=None) -> str:
        """The result as JSON, written atomically to ``path`` when given."""
        return dump_json(jsonable(self.to_dict()), path)

    def summary(self) -> Summary:
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

    def _blocks(self) -> list:
        """The report's structured fields: by default the title and the summary."""
        return [heading(self.title), fields(self.summary().rows())]

    def report(self) -> str:
        """The report as text (the one formatter, :func:`as_text`)."""
        return as_text(self._blocks())

    def _html_blocks(self) -> list:
        """The blocks of the notebook's table: the report's, unless a result shows more there."""
        return self._blocks()

    def _repr_html_(self) -> str:
        return as_html(self._html_blocks())

    def plot(self, *args, **kwargs):
        raise NotImplementedError

    def __str__(self) -> str:
        return self.report()


__all__ = ["Result", "Summary", "Finding", "emit", "collecting", "Block", "heading", "fields", "table", "lines", "as_text",
           "as_html"]
