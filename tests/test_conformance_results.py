"""Conformance of every result (issue 39, item 6) to the results protocol (``thermofriction.results.Result``),
parametrized over the protocol's subclasses -- found after importing every module of the package -- and the result
classes issue 39 says should follow it and do not yet (conformance_cases.NOT_YET_ON_THE_PROTOCOL: a strict xfail
while they are not ``Result`` subclasses). A new result class is tested by subclassing ``Result`` once it has a case
in tests/conformance_cases.py (RESULT_CASES: one small instance, made cheaply).

Each aspect of the protocol is a test of its own, on one instance of each kind:

- ``to_dict()``: JSON-able (plain types, NumPy arrays and scalars as the lists and numbers they hold, a non-finite
  number as the string docs/formats.md gives it) and the same after a round trip through ``json``;
- ``to_json()``: that same JSON, and ``to_json(path)`` writes the same text;
- ``summary()``: of the type ``Result.summary`` declares, its rows labelled;
- ``report()``: a str that names the result's title (and ``str()`` is it);
- ``_repr_html_()``: HTML whose tags balance, that shows every summary label;
- ``to_dataframe()``: a pandas DataFrame with columns (where pandas is installed);
- ``plot()``: a matplotlib Figure of its own, not one pyplot manages (nor its current figure).
"""

from __future__ import annotations

import functools
import html
import html.parser
import importlib
import json
import math
import pkgutil
import sys
import typing
import warnings
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from conformance_cases import NOT_YET_ON_THE_PROTOCOL, RESULT_CASES, case_of  # noqa: E402

import thermofriction  # noqa: E402
from thermofriction.results import Result  # noqa: E402


def _package_classes() -> dict:
    """Every class defined in the package, by name, after importing every module (``__main__`` aside: it runs the
    command line)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (at collection: what a module says on import is its own tests' business)
        for info in pkgutil.walk_packages(thermofriction.__path__, "thermofriction."):
            if info.name.rsplit(".", 1)[-1] != "__main__":
                importlib.import_module(info.name)
    out = {}
    for name, module in list(sys.modules.items()):
        if name == "thermofriction" or name.startswith("thermofriction."):
            for obj in vars(module).values():
                if isinstance(obj, type) and getattr(obj, "__module__", "").startswith("thermofriction"):
                    out.setdefault(obj.__name__, obj)
    return out


def _subclasses(cls) -> list:
    out = []
    for sub in cls.__subclasses__():
        out += [sub, *_subclasses(sub)]
    return out


CLASSES = _package_classes()
#: the package's classes on the protocol (a private base, ``_Name``, is not a result of its own; a test's own
#: subclass is not the package's)
ON_THE_PROTOCOL = sorted({c.__name__ for c in _subclasses(Result) if not c.__name__.startswith("_")
                          and c.__module__.startswith("thermofriction")})
KINDS = ON_THE_PROTOCOL + [n for n in NOT_YET_ON_THE_PROTOCOL if n not in ON_THE_PROTOCOL]

#: (kind, aspect) -> why it does not conform yet (found by this suite; strict: the day it does, the mark goes)
KNOWN = {}


def _params(aspect):
    for kind in KINDS:
        marks = []
        cls = CLASSES.get(kind)
        if kind in NOT_YET_ON_THE_PROTOCOL and not (cls is not None and issubclass(cls, Result)):
            marks.append(pytest.mark.xfail(strict=True, reason="issue 39: not yet on the protocol"))
        elif (kind, aspect) in KNOWN:
            marks.append(pytest.mark.xfail(strict=True, reason=KNOWN[kind, aspect]))
        yield pytest.param(kind, marks=marks, id=kind)


@functools.cache
def _made(kind):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (what the small cases' fits and runs say of themselves)
        return case_of(RESULT_CASES, kind, "result class")()


def result(kind):
    """The case's instance of ``kind``, checked to be one and to follow the protocol (a ``Result``)."""
    res = _made(kind)
    assert type(res).__name__ == kind, f"the case of {kind} made a {type(res).__name__}"
    assert isinstance(res, Result), f"{kind} is not a thermofriction.results.Result"
    return res


def plain(obj):
    """``obj`` as plain JSON types, as docs/formats.md states the results' JSON: arrays as lists, NumPy scalars
    as Python numbers, non-finite numbers as "inf", "-inf", "nan"; anything else is not JSON-able (TypeError)."""
    if isinstance(obj, dict):
        return {str(k): plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return plain(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        return x if math.isfinite(x) else ("inf" if x > 0 else "-inf" if x < 0 else "nan")
    if obj is None or isinstance(obj, str):
        return obj
    raise TypeError(f"not JSON-able: {type(obj).__name__} {obj!r:.80}")


@pytest.mark.parametrize("kind", KINDS)
def test_every_result_kind_has_a_case(kind):
    """A result class without a case in tests/conformance_cases.py fails here, by name."""
    case_of(RESULT_CASES, kind, "result class")
    assert kind in CLASSES, f"no class {kind} in the package"


@pytest.mark.parametrize("kind", list(_params("to_dict")))
def test_to_dict_is_json_and_round_trips(kind):
    """Round trip: to_dict() in plain JSON types (plain()) dumps as strict JSON (no NaN) and loads back equal."""
    d = result(kind).to_dict()
    assert isinstance(d, dict) and d
    p = plain(d)
    assert json.loads(json.dumps(p, allow_nan=False)) == p


@pytest.mark.parametrize("kind", list(_params("to_json")))
def test_to_json_is_to_dict_and_writes_the_same(kind, tmp_path):
    """to_json() is to_dict() as JSON; to_json(path) writes that text."""
    res = result(kind)
    text = res.to_json()
    assert isinstance(text, str) and json.loads(text) == plain(res.to_dict())
    res.to_json(tmp_path / "result.json")
    assert (tmp_path / "result.json").read_text().strip() == text.strip()


def _summary_type():
    return typing.get_type_hints(Result.summary)["return"]


def _labels(summary) -> list:
    """The labels of a summary's rows: (label, value) pairs, rows with a ``label``, or a mapping's keys."""
    if isinstance(summary, dict):
        return list(summary)
    rows = summary.rows if hasattr(summary, "rows") else summary
    return [row[0] if isinstance(row, (tuple, list)) else row.label for row in rows]


@pytest.mark.parametrize("kind", list(_params("summary")))
def test_summary_is_of_the_protocols_type(kind):
    """summary() is of the type Result.summary declares, with labelled rows (non-empty strings)."""
    summary = result(kind).summary()
    expected = _summary_type()
    assert isinstance(summary, typing.get_origin(expected) or expected), (
        f"{kind}.summary() is a {type(summary).__name__}, the protocol's is {expected}")
    labels = _labels(summary)
    assert labels and all(isinstance(k, str) and k for k in labels)


@pytest.mark.parametrize("kind", list(_params("report")))
def test_report_is_text_naming_the_title(kind):
    """report() is a str naming the result's title; str() is the report."""
    res = result(kind)
    text = res.report()
    assert isinstance(text, str) and res.title and res.title in text
    assert str(res) == text


#: HTML elements without an end tag, and those whose end tag may be left out (the next sibling closes them)
VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}
OPTIONAL_END = {"p", "li", "dt", "dd", "tr", "td", "th", "thead", "tbody", "tfoot", "option", "colgroup"}


class _Balance(html.parser.HTMLParser):
    """Checks that the tags of a fragment balance (void elements and optional end tags allowed)."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack, self.errors = [], []

    def handle_starttag(self, tag, attrs):
        if tag not in VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag):
        if tag in VOID:
            return
        while self.stack and self.stack[-1] != tag and self.stack[-1] in OPTIONAL_END:
            self.stack.pop()
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes {self.stack[-1] if self.stack else 'nothing'}")
            return
        self.stack.pop()


@pytest.mark.parametrize("kind", list(_params("html")))
def test_html_balances_and_shows_the_summary_labels(kind):
    """_repr_html_() is HTML whose tags balance and which shows every label of the report (the same blocks through
    the one formatter; the summary's labels where the report is the summary)."""
    res = result(kind)
    page = res._repr_html_()
    assert isinstance(page, str) and page.lstrip().startswith("<")
    checker = _Balance()
    checker.feed(page)
    checker.close()
    assert not checker.errors, checker.errors[:3]
    assert not [t for t in checker.stack if t not in OPTIONAL_END], f"unclosed: {checker.stack}"
    text = html.unescape(page)
    missing = [k for k in _shown_labels(res) if k not in text]
    assert not missing, f"the HTML does not show {missing}"


def _shown_labels(res) -> list:
    """What the notebook's table must show: the report's own labels (its headings, field labels and table headings,
    from the blocks the one formatter writes as text and as HTML); for a result whose report is its summary (the
    protocol's default blocks), the summary's labels."""
    if type(res)._blocks is Result._blocks:
        return _labels(res.summary())
    out = []
    for block in res._blocks():
        if block.kind == "heading":
            out.append(block.text)
        elif block.kind == "fields":
            out += [label for label, _ in block.rows]
        elif block.kind == "table":
            out += list(block.head)
    return out


@pytest.mark.parametrize("kind", list(_params("to_dataframe")))
def test_to_dataframe_is_a_dataframe(kind):
    """to_dataframe() is a pandas DataFrame with columns (pandas installed; else nothing to check)."""
    res = result(kind)
    try:
        import pandas as pd
    except ImportError:  # pragma: no cover - depends on the environment
        return
    frame = res.to_dataframe()
    assert isinstance(frame, pd.DataFrame) and len(frame.columns) > 0


@pytest.mark.parametrize("kind", list(_params("plot")))
def test_plot_returns_its_own_figure(kind):
    """plot() returns a matplotlib Figure that pyplot does not manage: not pyplot's current figure, and no new
    pyplot figure is left open."""
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure
    res = result(kind)
    before = set(plt.get_fignums())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fig = res.plot()
    assert isinstance(fig, Figure)
    assert set(plt.get_fignums()) == before, "plot() left a pyplot figure open"
    assert getattr(fig.canvas, "manager", None) is None, "plot() returned a figure pyplot manages"
    assert not before or plt.gcf() is not fig
