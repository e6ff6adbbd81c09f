"""The README and the documentation say what the code does (issue 33): the lists they give (presets,
friction models, identification methods, commands, the API reference's entries) are compared with the
code's own registries, every relative link resolves, the README quotes no measured figure (those live
in docs/performance.md, beside the benchmark scripts that produce them), and every gallery example runs.

The documentation site itself is built, with warnings as errors, by ``make docs`` (CI runs it)."""

import os
import re
import runpy
from pathlib import Path

import pytest

import thermofriction as tf
from thermofriction.cli import build_parser
from thermofriction.identification import METHODS
from thermofriction.models import FRICTION_MODELS

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
DOCS = ROOT / "docs"


def _section(text, heading):
    """The body of the Markdown section ``## heading`` (up to the next heading of level <= 2)."""
    m = re.search(rf"^## {re.escape(heading)}\n(.*?)(?=^## |\Z)", text, re.S | re.M)
    assert m, f"no section '## {heading}'"
    return m.group(1)


def _subcommands():
    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return set(sub.choices)


# --- lists the code knows ---------------------------------------------------------------------------

def test_readme_presets_are_the_shipped_presets():
    box = _section(README, "What is in the box")
    listed = re.findall(r"^- `([\w.-]+)`:", box, re.M)
    assert listed == list(tf.PRESETS)


def test_readme_friction_models_and_methods_are_the_registries():
    box = _section(README, "What is in the box")
    friction = re.search(r"Friction models: (.*?);", box, re.S).group(1)
    assert re.findall(r"`([\w-]+)`", friction) == list(FRICTION_MODELS)
    methods = re.search(r"Identification methods \(`thermofriction identify --method`\): (.*?)\(", box, re.S).group(1)
    assert re.findall(r"`([\w-]+)`", methods) == list(METHODS)


def test_readme_and_cli_reference_list_every_command():
    commands = _subcommands()
    box = _section(README, "What is in the box")
    listed = re.search(r"Commands: (.*?)\(", box, re.S).group(1)
    assert set(re.findall(r"`([\w-]+)`", listed)) == commands
    cli = (DOCS / "cli.md").read_text()
    table = re.findall(r"^\| \[`([\w-]+)`\]\(#([\w-]+)\) \|", cli, re.M)
    assert {name for name, _ in table} == commands
    for name, anchor in table:  # each row's link is the command's own section
        assert name == anchor and re.search(rf"^## {name}$", cli, re.M), name


def test_cli_reference_lists_the_presets():
    cli = (DOCS / "cli.md").read_text()
    common = re.search(r"\*\*`MODEL`\*\* is a model file .*? preset:\n(.*?)\(`thermofriction presets`", cli, re.S)
    assert re.findall(r"`([\w.-]+)`", common.group(1)) == list(tf.PRESETS)


def test_friction_model_tables_are_the_registry():
    """docs/models.md and docs/formats.md#model-files each have one row per friction model: the
    registry's names (models.md with their classes), and their required keys are the classes' fields
    that have no default."""
    import dataclasses
    models = re.findall(r"^\| `\"(\w+)\"` \| `tf\.(\w+)` \|", (DOCS / "models.md").read_text(), re.M)
    assert sorted(models) == sorted((name, cls.__name__) for name, cls in FRICTION_MODELS.items())
    table = re.search(r"^\| `model` \| required keys \|.*?\n\n", (DOCS / "formats.md").read_text(), re.M | re.S)
    formats = re.findall(r"^\| `\"(\w+)\"` \| (.*?) \|", table.group(0), re.M)
    assert sorted(name for name, _ in formats) == sorted(FRICTION_MODELS)
    for name, required in formats:
        listed = set(re.findall(r"`(\w+)(?: = \[\.\.\.\])?`", required))
        fields = {f.name for f in dataclasses.fields(FRICTION_MODELS[name])
                  if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING}
        assert listed == fields, name


def test_cli_reference_lists_the_methods():
    cli = (DOCS / "cli.md").read_text()
    synopsis = re.search(r"thermofriction identify DATASET \[--method \{([\w,-]+)\}\]", cli).group(1)
    assert synopsis.split(",") == list(METHODS)
    table = re.search(r"^\| `--method` \| `model-i` \| (.*)$", cli, re.M).group(1)
    assert re.findall(r"(?:: |, )`([\w-]+)` \(", table) == list(METHODS)


def _autosummary_entries(rst):
    names, inside = [], False
    for line in rst.splitlines():
        if line.startswith(".. autosummary::"):
            inside = True
        elif inside and line.startswith("   ") and not line.strip().startswith(":"):
            names.append(line.strip())
        elif inside and line.strip() and not line.startswith("   "):
            inside = False
    return names


def test_api_reference_covers_the_public_api():
    """Every name of ``thermofriction.__all__`` on the index page, once; every name a subpackage's
    ``__all__`` adds on that subpackage's page; and every subpackage page in the index's toctree."""
    index = (DOCS / "api" / "index.rst").read_text()
    top = _autosummary_entries(index)
    assert sorted(top) == sorted(tf.__all__) and len(top) == len(set(top))
    pages = re.search(r"\.\. toctree::\n(?:   :.*\n)*\n((?:   \S+\n)+)", index).group(1).split()
    assert pages and all((DOCS / "api" / f"{p}.rst").is_file() for p in pages)
    import importlib
    for page in pages:
        module = importlib.import_module(f"thermofriction.{page}")
        entries = _autosummary_entries((DOCS / "api" / f"{page}.rst").read_text())
        assert sorted(entries) == sorted(n for n in module.__all__ if n not in tf.__all__), page


def test_every_guide_is_in_the_site():
    index = (DOCS / "index.md").read_text()
    in_toc = set(re.findall(r"^([\w-]+)$", index, re.M))
    guides = {p.stem for p in DOCS.glob("*.md") if p.name != "index.md"}
    assert guides <= in_toc, guides - in_toc


# --- the README as a newcomer's page -------------------------------------------------------------------

def test_readme_is_short_and_starts_with_what_a_newcomer_needs():
    lines = README.splitlines()
    assert len(lines) <= 150
    order = [README.index(s) for s in ("make demo", "make test", "source .venv/bin/activate",
                                       ".venv/bin/thermofriction", "docs/your-data.md", "## In Python")]
    assert order == sorted(order), "set-up, running the CLI, then your own data, before the rest"


def test_readme_quotes_no_measured_figures():
    """Speed and accuracy figures live in docs/performance.md, next to the benchmarks that measure them."""
    figure = re.compile(r"\d[\d.,]*\s*(?:ms|µs|us|ns|s|MB|GB|%|×|x faster|x slower)\b|\d[\d.]*\s*×")
    assert not figure.findall(README), figure.findall(README)
    assert "docs/performance.md" in README


def test_performance_page_names_its_machine_date_and_scripts():
    page = (DOCS / "performance.md").read_text()
    assert re.search(r"\b20\d\d-\d\d-\d\d\b", page), "the date of the measurements"
    assert "2 cores" in page
    scripts = set(re.findall(r"benchmarks/(\w+\.py)", page))
    assert {"bench_simulate.py", "bench_identify.py"} <= scripts
    assert all((ROOT / "benchmarks" / s).is_file() for s in scripts), scripts


# --- links -------------------------------------------------------------------------------------------

def _slugs(markdown):
    """GitHub's heading anchors (as myst_heading_anchors makes them in the site)."""
    out = set()
    for h in re.findall(r"^#{1,6} (.+)$", re.sub(r"```.*?```", "", markdown, flags=re.S), re.M):
        s = re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-")
        out.add(s)
    return out


@pytest.mark.parametrize("page", ["README.md"] + [f"docs/{p.name}" for p in sorted(DOCS.glob("*.md"))])
def test_relative_links_resolve(page):
    path = ROOT / page
    text = re.sub(r"```.*?```", "", path.read_text(), flags=re.S)
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target):
            continue
        file, _, anchor = target.partition("#")
        if page.startswith("docs/") and file.startswith("gallery/"):  # written by `make docs` from examples/gallery
            assert GALLERY, f"{page}: {target}: no examples/gallery/plot_*.py to build it from"
            continue
        dest = (path.parent / file).resolve() if file else path
        assert dest.exists(), f"{page}: {target}"
        assert ROOT in dest.parents or dest == ROOT, f"{page}: {target} points outside the repository"
        if anchor and dest.suffix == ".md":
            assert anchor in _slugs(dest.read_text()), f"{page}: {target}: no such heading"


# --- the gallery ---------------------------------------------------------------------------------------

GALLERY = sorted((ROOT / "examples" / "gallery").glob("plot_*.py"))


def test_gallery_has_the_issues_examples():
    assert {p.stem for p in GALLERY} >= {"plot_paper_workflow", "plot_your_data", "plot_force_data", "plot_fmu",
                                         "plot_sweep"}


@pytest.mark.parametrize("script", GALLERY, ids=lambda p: p.stem)
def test_gallery_example_runs(script, tmp_path, monkeypatch):
    """Each example runs on its own, as the docs build runs it (which also shows its output)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    monkeypatch.chdir(tmp_path)
    names = runpy.run_path(str(script), run_name="__main__")
    from matplotlib.figure import Figure
    assert plt.get_fignums() or any(isinstance(v, Figure) for v in names.values()), "draws a figure"
    plt.close("all")
    assert not os.listdir(tmp_path), "writes nothing into the current folder"


def test_readme_python_runs(tmp_path, monkeypatch):
    """The README's Python block runs as written, on a small stand-in for the demo's dataset (the same
    preset and held-out design as ``thermofriction demo``, shorter runs), and writes its report."""
    import matplotlib
    matplotlib.use("Agg")
    block = re.search(r"```python\n(.*?)```", README, re.S).group(1)
    monkeypatch.chdir(tmp_path)
    data = tf.synthesize(tf.load_model("li2009-model-i"), [30.8, 35.7, 38.4, 41.5], validate=[33.0],
                         duration=0.4, sample_rate=5000, seed=3)
    tf.save_dataset(data, tmp_path / "thermofriction-demo" / "data")
    names = {}
    exec(compile(block, "README.md", "exec"), names)
    assert names["fit"].method == "model-i" and (tmp_path / "report.html").stat().st_size > 0
    assert names["res"].displacement[-1] > 0
