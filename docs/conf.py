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
# outside inline literals, without changing what the docstrings say.

_ITEM = re.compile(r"([A-Za-z_][\w ,.*()\[\]\"'=-]{0,40}): (\S.*)")


def _bars(text):
    """``|`` escaped outside the ``inline literals``."""
    parts = text.split("``")
    return "``".join(p if i % 2 else p.replace("|", r"\|") for i, p in enumerate(parts))


def _docstring_as_rst(app, what, name, obj, options, lines):
    if what == "data" and type(obj).__doc__ and lines and "\n".join(lines).strip() == type(obj).__doc__.strip():
        lines[:] = []  # a constant without a docstring of its own: not its type's (dict's, tuple's) docstring
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
    lines[:] = out


def setup(app):
    app.connect("autodoc-process-docstring", _docstring_as_rst)
