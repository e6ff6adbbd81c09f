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
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "gallery/*.ipynb", "gallery/*.py", "gallery/*.zip",
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
    "image_scrapers": ("matplotlib",),
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
# The package's docstrings are plain text: "name: what it is" with indented continuation lines, and
# |x| for absolute values. Read as reStructuredText, the former is a definition list whose items must be
# separated by blank lines and the latter a substitution reference. These two rewrites (the only ones)
# make them valid reStructuredText without changing what they say.

_ITEM = re.compile(r"[A-Za-z_][\w ,.*()\[\]\"'=-]{0,40}: ")


def _docstring_as_rst(app, what, name, obj, options, lines):
    if what == "data" and type(obj).__doc__ and lines and "\n".join(lines).strip() == type(obj).__doc__.strip():
        lines[:] = []  # a constant without a docstring of its own: not its type's (dict's, tuple's) docstring
        return
    out, prev_indent, in_literal = [], None, False
    for line in lines:
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if stripped and in_literal and indent <= literal_indent:
            in_literal = False
        if stripped and not in_literal:
            if out and out[-1].strip() and prev_indent is not None and (
                    indent < prev_indent or (indent == prev_indent and _ITEM.match(stripped))):
                out.append("")  # a dedent or a new "name: ..." item ends the previous one
            line = line.replace("|", r"\|")
            if stripped.endswith("::"):
                in_literal, literal_indent = True, indent
        if stripped:
            prev_indent = indent
        out.append(line)
    lines[:] = out


def setup(app):
    app.connect("autodoc-process-docstring", _docstring_as_rst)
