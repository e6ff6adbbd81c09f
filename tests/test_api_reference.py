"""The API reference documents every argument (issue 44 item 4): for every public callable -- each name of
``thermofriction.__all__`` and of the ``__all__`` of every subpackage the reference has a page for
(docs/api/index.rst) -- each parameter of its signature (a class's: its ``__init__``'s, a dataclass's fields)
is named in the numpydoc ``Parameters`` section of its docstring, and a function's docstring has ``Returns``
and ``Raises`` sections. The sections are read with a small parser of numpydoc's layout (a title underlined
with dashes; ``name : type`` at the section's indent, ``a, b : type`` for several), written here, not taken
from the package. The ``Examples`` of the main entry points run as doctests; and the site's own rewrites of the
docstrings (docs/conf.py: attributes kept from napoleon's misreading, repository paths as links, the source pages'
links back) do what they say."""

from __future__ import annotations

import dataclasses
import doctest
import importlib
import inspect
import re
from pathlib import Path

import pytest

import thermofriction as tf

ROOT = Path(__file__).resolve().parents[1]
API = ROOT / "docs" / "api"

#: public callables whose docstrings are not yet in numpydoc form (none: every one is). The test fails when one
#: of them is documented (take it off the list) or when a callable outside it is not.
NOT_YET: set[str] = set()


def _pages():
    index = (API / "index.rst").read_text()
    return re.search(r"\.\. toctree::\n(?:   :.*\n)*\n((?:   \S+\n)+)", index).group(1).split()


def _public():
    """{qualified name: object} of every public callable the reference lists."""
    out = {f"thermofriction.{n}": getattr(tf, n) for n in tf.__all__}
    for page in _pages():
        module = importlib.import_module(f"thermofriction.{page}")
        out.update({f"thermofriction.{page}.{n}": getattr(module, n) for n in module.__all__})
    seen, unique = set(), {}
    for name, obj in out.items():  # the same object under two names: checked once, under its shorter name
        if callable(obj) and id(obj) not in seen:
            seen.add(id(obj))
            unique[name] = obj
    return unique


PUBLIC = _public()

_TITLE = re.compile(r"^(\w[\w ]*)\n-{3,}\n", re.M)


def sections(doc: str) -> dict[str, str]:
    """{title: body} of a numpydoc docstring (``inspect.getdoc``'s, dedented)."""
    out = {}
    heads = list(_TITLE.finditer(doc or ""))
    for i, m in enumerate(heads):
        end = heads[i + 1].start() if i + 1 < len(heads) else len(doc)
        out[m.group(1).strip()] = doc[m.end():end]
    return out


def documented(body: str) -> set[str]:
    """The names a Parameters section documents: ``name : type`` or ``a, b : type`` at column 0
    (``*args``, ``**kwargs`` with or without their stars)."""
    names = set()
    for line in body.splitlines():
        m = re.match(r"([*\w][\w*, ]*?)\s*(?::|$)", line)
        if m and line[:1].strip():
            names.update(n.strip().lstrip("*") for n in m.group(1).split(",") if n.strip())
    return names


def _signature_names(obj) -> list[str]:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    return [p.name for p in sig.parameters.values() if p.name != "self"
            and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]


def _is_exception(obj) -> bool:
    return inspect.isclass(obj) and issubclass(obj, BaseException)


def problems(name: str, obj) -> list[str]:
    """What ``obj``'s docstring misses: the parameters its Parameters section does not name; for a
    function, a missing Returns (or Yields) or Raises section."""
    if _is_exception(obj):
        return []  # an error or warning class takes its message only
    doc = inspect.getdoc(obj) or ""
    own = sections(doc)
    if inspect.isclass(obj) and not dataclasses.is_dataclass(obj) and "__init__" in vars(obj):
        own = {**sections(inspect.getdoc(obj.__init__) or ""), **own}
    wanted = _signature_names(obj)
    out = []
    if wanted:
        missing = [p for p in wanted if p not in documented(own.get("Parameters", ""))]
        if missing:
            out.append(f"{name}: Parameters does not document {', '.join(missing)}")
    if not inspect.isclass(obj):
        if not ({"Returns", "Yields"} & set(own)):
            out.append(f"{name}: no Returns section")
        if "Raises" not in own:
            out.append(f"{name}: no Raises section")
    return out


# --- the parser itself ----------------------------------------------------------------------------------

SAMPLE = '''What it does.

Parameters
----------
duration : float
    The time [s].
a, b : int, optional
    Two at once.
**options
    Passed on.

Returns
-------
float
'''


def test_the_parser_reads_numpydoc_sections():
    s = sections(SAMPLE)
    assert set(s) == {"Parameters", "Returns"}
    assert documented(s["Parameters"]) == {"duration", "a", "b", "options"}


def test_the_check_finds_an_undocumented_argument():
    def f(duration, temperature=20.0):
        """What it does.

        Parameters
        ----------
        duration : float
            The time [s].

        Returns
        -------
        float
        """
    assert problems("f", f) == ["f: Parameters does not document temperature", "f: no Raises section"]


# --- the package -------------------------------------------------------------------------------------------

def test_there_are_public_callables_to_check():
    assert {"thermofriction.identify", "thermofriction.simulate", "thermofriction.FitResult"} <= set(PUBLIC)


@pytest.mark.parametrize("name", sorted(PUBLIC))
def test_every_argument_of_every_public_callable_is_documented(name):
    found = problems(name, PUBLIC[name])
    if name in NOT_YET:
        assert found, f"{name} is documented now: take it off NOT_YET"
        pytest.skip(f"not yet in numpydoc form: {found[0]}")
    assert not found, found


def test_not_yet_names_only_public_callables():
    assert NOT_YET <= set(PUBLIC), NOT_YET - set(PUBLIC)


#: the entry points whose Examples run here (their examples need no files or long fits)
EXAMPLES = ["load_model", "simulate", "synthesize", "parse_waveform", "Sine", "Sawtooth", "LuGre", "Const", "Linear",
            "StepSizeController", "Model"]


@pytest.mark.parametrize("name", EXAMPLES)
def test_examples_run(name):
    obj = getattr(tf, name)
    doc = inspect.getdoc(obj)
    assert "Examples" in sections(doc), f"{name}: no Examples section"
    parser, runner = doctest.DocTestParser(), doctest.DocTestRunner(optionflags=doctest.ELLIPSIS
                                                                    | doctest.NORMALIZE_WHITESPACE)
    test = parser.get_doctest(doc, {"tf": tf, "np": __import__("numpy")}, name, None, 0)
    assert test.examples, f"{name}: its Examples have no >>> lines"
    result = runner.run(test, out=lambda s: None)
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} examples failed"


# --- the site's rendering of the docstrings (docs/conf.py) --------------------------------------------------

def _conf():
    pytest.importorskip("sphinx")
    ns = {"__file__": str(ROOT / "docs" / "conf.py"), "__name__": "conf"}
    exec(compile((ROOT / "docs" / "conf.py").read_text(), "conf.py", "exec"), ns)
    return ns


def test_attribute_comments_are_not_read_as_type_and_text():
    """napoleon reads an attribute's first line "force data: the sensor's offset" as the type "force data" (the
    FitResult.sensor_offset and .removed entries of issue 44); the site keeps such docstrings as written."""
    conf = _conf()  # (skips without Sphinx, before its import)
    from sphinx.ext.napoleon import Config, _process_docstring

    class App:
        config = Config(napoleon_use_param=False)

    text = "force data: the sensor's offset (value, stderr, ci95, unit, fitted); empty where there is none"
    lines = [text]
    conf["_keep_as_written"](App, "attribute", "FitResult.sensor_offset", None, {}, lines)
    _process_docstring(App, "attribute", "FitResult.sensor_offset", None, {}, lines)
    conf["_docstring_as_rst"](App, "attribute", "FitResult.sensor_offset", None, {}, lines)
    assert lines == [text]


def test_repository_paths_become_links_outside_literals():
    conf = _conf()
    out = conf["_linked_paths"](["See docs/models.md#friction-models and identification/front.py; not ``docs/cli.md``",
                                 "or docs/no-such-guide.md.", "Code::", "", "    x = |v|  # docs/models.md"],
                                bars=True)
    assert out[0] == ("See :tfpath:`docs/models.md#friction-models` and :tfpath:`identification/front.py`; "
                      "not ``docs/cli.md``")
    assert out[1] == "or docs/no-such-guide.md."  # names no guide: left as text
    assert out[4] == "    x = |v|  # docs/models.md"  # a literal block: as written


def test_source_pages_link_back_to_the_anchor_the_page_has():
    """viewcode's "[docs]" link is the page + "#" + one module name per source file + the name: for an object
    documented under another module (thermofriction.simulation.output_grid, while simulate is
    thermofriction.simulate) that anchor does not exist (31 such links were broken); the site writes the id the
    object's page has."""
    conf = _conf()
    module, doc = "thermofriction.simulation", "api/generated/thermofriction.simulation.output_grid"

    class Env:
        _viewcode_modules = {module: ("code", {}, {"output_grid": doc}, "thermofriction")}
        tf_object_ids = {(module, "output_grid", doc): "thermofriction.simulation.output_grid"}

    class App:
        env = Env()

        class builder:
            @staticmethod
            def get_relative_uri(frm, to):
                return "../../" + to + ".html"

    page = "../../" + doc + ".html"
    context = {"body": f'<a class="viewcode-back" href="{page}#thermofriction.output_grid">[docs]</a>'}
    conf["_fix_backlinks"](App, "_modules/thermofriction/simulation", "page.html", context, None)
    assert context["body"] == f'<a class="viewcode-back" href="{page}#thermofriction.simulation.output_grid">[docs]</a>'
