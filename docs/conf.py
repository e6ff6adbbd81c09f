"""Sphinx configuration of the thermofriction documentation site (``make docs``).

The guides are the Markdown files of this folder (MyST), the API reference is generated from the
docstrings (autodoc, autosummary; docs/api/), and the gallery runs the scripts of examples/gallery/
(sphinx-gallery) at every build. ``make docs`` builds with warnings as errors into docs/_build/html.
"""

import os
import re
import sys
from pathlib import Path

import thermofriction

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent / "_ext"))  # tf_gallery: the gallery's figure scraper

project = "thermofriction"
author = "the thermofriction developers"
copyright = "2026, the thermofriction developers"
release = thermofriction.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "Thumbs.db", ".DS_Store", "gallery/*.ipynb", "gallery/*.py", "gallery/*.zip",
                    "gallery/*.md5", "gallery/*.json"]
templates_path = ["_templates"]

# --- MyST: the guides are GitHub-flavoured Markdown with GitHub's heading anchors ---------------
myst_enable_extensions = ["dollarmath", "deflist"]
myst_heading_anchors = 4
suppress_warnings = [
    # code fences in the guides name languages Pygments does not lex (e.g. ``console`` output tables)
    "misc.highlighting_failure",
]

# --- API reference ---------------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": True, "member-order": "bysource", "show-inheritance": True}
autodoc_typehints = "signature"
autodoc_preserve_defaults = True
napoleon_google_docstring = True
napoleon_numpy_docstring = True
# one entry per Parameters line: "fc_neg, fs_neg, vs_neg, sigma2_neg : float" stays one entry, not four copies
napoleon_use_param = False
add_module_names = False
# the docstrings use ``x`` for code and the ASCII names of the quantities; nothing else is a reference
default_role = "literal"

# --- Gallery of executed examples ------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples" / "gallery"),
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    # the library's own (pyplot-free) figures, then pyplot's (first: pyplot's scraper closes its figures)
    "image_scrapers": ("tf_gallery.figures", "matplotlib"),
    "show_memory": False,
    "min_reported_time": 1,
    "abort_on_example_error": True,
    "reference_url": {},
}
os.environ.setdefault("MPLBACKEND", "Agg")

# --- HTML ------------------------------------------------------------------------------------------
html_theme = "furo"
html_title = f"thermofriction {release}"
html_static_path = []
html_show_sourcelink = False


# --- The docstrings' own style -----------------------------------------------------------------------
# The package's docstrings are plain text: "name: what it is" items with indented continuation lines,
# indented code or equations after a plain paragraph, and |x| for absolute values. Read as
# reStructuredText, the items would run into each other, the code would be a quotation and |x| a
# substitution reference. These rewrites (the only ones) make each item a definition-list entry (term
# "name", the text as its definition) and each such indented block a literal block, and escape the bars
# outside inline literals, without changing what the docstrings say. Docstrings in numpydoc's form (Parameters,
# Returns, Raises, Examples: the API reference's) are napoleon's; they only get their bars escaped and their
# repository paths linked.

_ITEM = re.compile(r"([A-Za-z_][\w ,.*()\[\]\"'=-]{0,40}): (\S.*)")


def _bars(text):
    """``|`` escaped outside the ``inline literals``."""
    parts = text.split("``")
    return "``".join(p if i % 2 else p.replace("|", r"\|") for i, p in enumerate(parts))


def _docstring_as_rst(app, what, name, obj, options, lines):
    if what in _AS_WRITTEN:  # napoleon's reading undone (_keep_as_written)
        lines[:] = _KEPT.pop((what, name), lines)
    if what == "data" and type(obj).__doc__ and lines and "\n".join(lines).strip() == type(obj).__doc__.strip():
        lines[:] = []  # a constant without a docstring of its own: not its type's (dict's, tuple's) docstring
        return
    if what == "attribute" or _NUMPYDOC.search(getattr(obj, "__doc__", None) or ""):
        # numpydoc sections (napoleon has made them reStructuredText) and attributes' "#:" comments (one sentence,
        # never a list of "name: ..." items: "force data: the sensor's offset" is not an item) are left as written
        lines[:] = _linked_paths(lines, bars=True)
        return
    out, prev_indent, literal_indent, in_item, last = [], None, None, False, ""
    for k, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if stripped and literal_indent is not None and indent <= literal_indent:
            literal_indent = None
        if (stripped and literal_indent is None and indent > 0 and not in_item and out and not out[-1].strip()
                and last and not last[0].isspace()):
            out += ["::", ""]  # an indented block after a plain paragraph: code or an equation, verbatim
            literal_indent = 0
        if stripped and literal_indent is None:
            after = not out or not out[-1].strip() or in_item or out[-1].rstrip()[-1:] in ".:;"
            item = _ITEM.fullmatch(stripped) if indent == 0 and k > 0 and after else None
            if out and out[-1].strip() and prev_indent is not None and (indent < prev_indent or item):
                out.append("")  # a dedent or a new "name: ..." item ends the previous paragraph or item
            line = _bars(line)
            if item:  # "name: text" -> the term "name" and its definition "text"
                out.append(_bars(item.group(1)))
                line, indent, in_item = "    " + _bars(item.group(2)), 4, True
            elif in_item and (indent > 0 or out[-1].strip()):
                line = "    " + line.lstrip()  # the item's continuation lines, at its definition's indent
            else:
                in_item = False
            if line.rstrip().endswith("::"):
                literal_indent = len(line) - len(line.lstrip())
        if stripped:
            prev_indent = 0 if in_item else indent
            last = line
        out.append(line)
    lines[:] = _linked_paths(out)


# napoleon reads the first line of an attribute's, a constant's or a property's docstring as "type: text"
# (numpydoc's inline attribute form), which the package never writes: "force data: the sensor's offset" became the
# type "force data". Their docstrings are kept before napoleon runs and put back after it.
_AS_WRITTEN = ("attribute", "data", "property")
_KEPT = {}


def _keep_as_written(app, what, name, obj, options, lines):
    if what in _AS_WRITTEN:
        _KEPT[(what, name)] = list(lines)


_NUMPYDOC = re.compile(r"^\s*(Parameters|Returns|Attributes)\n\s*-{3,}\s*$", re.M)

# --- Repository paths in the docstrings as links ---------------------------------------------------------
# "docs/models.md#friction-models" links to that guide's page and heading, "identification/front.py" (a path
# in src/thermofriction) to its source page (viewcode's, generated for every module so named). Paths in
# ``literals`` and in literal blocks stay text.

PACKAGE = ROOT / "src" / "thermofriction"
_PATH = re.compile(r"(?<![\w/.`-])((docs/[\w-]+\.md)(#[\w-]+)?|(?:[a-z_]+/)*[a-z_]+\.py)(?![\w`/-])")


def _path_target(path: str):
    """(the page's docname, the module) of a repository path, or None where it names no guide or module."""
    if path.startswith("docs/"):
        return (path[5:-3], None) if (ROOT / path).is_file() else None
    if not (PACKAGE / path).is_file():
        return None
    parts = ["thermofriction", *path[:-3].split("/")]
    module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
    return "_modules/" + module.replace(".", "/"), module


def _linked_paths(lines, bars=False):
    """The lines with repository paths as :tfpath: links (and with ``bars``, |x| escaped as _bars does),
    outside inline literals and literal blocks."""
    out, literal = [], None
    for line in lines:
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if literal is not None and stripped and indent <= literal:
            literal = None
        if literal is None:
            parts = line.split("``")
            line = "``".join(p if i % 2 else _PATH.sub(_path_role, p.replace("|", r"\|") if bars else p)
                             for i, p in enumerate(parts))
            if line.rstrip().endswith("::"):
                literal = indent
        out.append(line)
    return out


def _docname(env):
    current = getattr(env, "current_document", None)  # Sphinx >= 8.2; env.docname before
    return current.docname if current is not None else env.docname


def _path_role(m):
    return f":tfpath:`{m.group(0)}`" if _path_target(m.group(2) or m.group(0)) else m.group(0)


def _tfpath(name, rawtext, text, lineno, inliner, options=None, content=None):
    """The role :tfpath:`docs/x.md#anchor` / :tfpath:`pkg/module.py`: the path as a link to its page."""
    from docutils import nodes
    env = inliner.document.settings.env
    path, _, anchor = text.partition("#")
    docname, module = _path_target(path)
    if module:
        env.tf_source_pages = getattr(env, "tf_source_pages", set()) | {module}
    uri = env.app.builder.get_relative_uri(_docname(env), docname) + (f"#{anchor}" if anchor else "")
    return [nodes.reference(rawtext, "", nodes.literal(text, text), refuri=uri, internal=True)], []


def _source_pages(app, doctree):
    """Every module a docstring names by its path gets its source page (viewcode makes pages only for the
    modules of documented objects)."""
    from sphinx.pycode import ModuleAnalyzer
    env = app.env
    modules = getattr(env, "_viewcode_modules", None)
    if modules is None:
        modules = env._viewcode_modules = {}
    for module in getattr(env, "tf_source_pages", ()):
        if module not in modules:
            try:
                analyzer = ModuleAnalyzer.for_module(module)
                analyzer.find_tags()
            except Exception:  # (as viewcode: a module whose source cannot be read has no page)
                modules[module] = False
                continue
            modules[module] = (analyzer.code, analyzer.tags, {}, module)


# --- Source pages' [docs] links -----------------------------------------------------------------------------
# viewcode writes each "[docs]" link of a source page as the object's page + "#" + ONE module name per source
# file (the first page's that documented anything from it) + the object's name: an object documented under
# another module (``thermofriction.simulation.output_grid``, while ``simulate`` is ``thermofriction.simulate``)
# gets an anchor its page does not have. The ids each page gave each object are recorded here and the links
# written with them.

def _record_ids(app, doctree):
    from sphinx import addnodes
    from sphinx.ext.viewcode import _get_full_modname
    ids = app.env.__dict__.setdefault("tf_object_ids", {})
    for sig in doctree.findall(addnodes.desc_signature):
        module, fullname = sig.get("module"), sig.get("fullname")
        if module and fullname and sig.get("ids"):
            real = _get_full_modname(module, fullname) or module
            ids[(real, fullname, _docname(app.env))] = sig["ids"][0]


def _fix_backlinks(app, pagename, templatename, context, doctree):
    if not pagename.startswith("_modules/") or "body" not in context:
        return
    module = pagename[len("_modules/"):].replace("/", ".")
    entry = getattr(app.env, "_viewcode_modules", {}).get(module)
    if not entry:
        return
    _, _, used, refname = entry
    ids, uri, body = getattr(app.env, "tf_object_ids", {}), app.builder.get_relative_uri, context["body"]
    for name, docname in used.items():
        right = ids.get((module, name, docname))
        if right:
            page = uri(pagename, docname)
            body = body.replace(f'href="{page}#{refname}.{name}"', f'href="{page}#{right}"')
    context["body"] = body


def setup(app):
    app.connect("autodoc-process-docstring", _keep_as_written, priority=400)  # before napoleon's
    app.connect("autodoc-process-docstring", _docstring_as_rst)  # after napoleon's (same priority, loaded first)
    app.add_role("tfpath", _tfpath)
    app.connect("doctree-read", _record_ids)
    app.connect("doctree-read", _source_pages, priority=600)
    app.connect("html-page-context", _fix_backlinks)
