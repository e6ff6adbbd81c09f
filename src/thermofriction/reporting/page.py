"""The building blocks every report page shares: the style sheet, figures rendered as inline SVG,
tables, number formatting, the footer's versions, and writing a page atomically."""

from __future__ import annotations

import functools
import html
import io
import math
import platform
import re
from pathlib import Path

import numpy as np

from .._io import atomic_write
from .._version import __version__

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:0;color:#1d2433;background:#f6f7fb}
header{background:#1d2433;color:#fff;padding:24px 40px}
header h1{margin:0 0 6px;font-size:24px}
header p{margin:0;color:#c9d1e3}
main{padding:24px 40px;max-width:1200px}
section{background:#fff;border-radius:10px;box-shadow:0 1px 3px rgba(0,0,0,.08);padding:20px 24px;margin:0 0 22px}
h2{font-size:18px;margin:0 0 12px}
.cards{display:flex;flex-wrap:wrap;gap:14px;margin-bottom:22px}
.card{background:#fff;border-radius:10px;box-shadow:0 1px 3px rgba(0,0,0,.08);padding:14px 18px;min-width:200px;flex:1}
.card .k{font-size:12px;text-transform:uppercase;color:#6b7389;letter-spacing:.04em}
.card .v{font-size:22px;font-weight:600;margin-top:4px}
.card .s{font-size:13px;color:#6b7389}
table{border-collapse:collapse;font-size:13px;width:100%}
th,td{padding:5px 9px;border-bottom:1px solid #e6e8ef;text-align:right}
th:first-child,td:first-child{text-align:left}
td{white-space:nowrap}
th.t,td.t{text-align:left}
th.w,td.w{text-align:left;white-space:normal}
thead th{background:#f0f2f7}
tr.held td{background:#fdf0ef}
figure{margin:8px 0 18px}
figure svg{max-width:100%;height:auto;display:block}
.pair{display:grid;grid-template-columns:1fr 1fr;gap:24px}
@media (max-width:900px){.pair{grid-template-columns:1fr}}
dl.defs{font-size:13px;color:#4a5266;display:grid;grid-template-columns:max-content 1fr;gap:4px 14px;margin:12px 0 0}
dl.defs dt{font-weight:600;color:#1d2433}dl.defs dd{margin:0}
h3{font-size:15px;margin:18px 0 8px}
p.note{font-size:13px;color:#4a5266}
details{margin-top:10px;font-size:13px}summary{cursor:pointer;color:#4a5266}
figcaption{font-size:13px;color:#4a5266;margin-top:6px}
.warn{background:#fff6e0;border-left:4px solid #f0a500;padding:8px 12px;font-size:13px;margin:6px 0}
footer{font-size:12px;color:#6b7389;padding:0 40px 30px}
code{background:#eef0f5;padding:1px 4px;border-radius:3px}
"""



#: the look of the force and study pages' figures (the others': plots.STYLE)
PAGE_STYLE = {"font.size": 9, "axes.grid": True, "grid.alpha": 0.3, "axes.spines.top": False,
              "axes.spines.right": False, "axes.formatter.useoffset": False}


def page_styled(function):
    """Runs a figure-drawing ``function`` in PAGE_STYLE, for it alone: the user's matplotlib settings and
    backend are left as they are."""
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        import matplotlib  # (heavy: loaded when a page is drawn, not with the package)
        with matplotlib.rc_context(PAGE_STYLE):
            return function(*args, **kwargs)
    return wrapper


def subplots(nrows=1, ncols=1, *, figsize=None, constrained_layout=None, **kwargs):
    """pyplot's ``subplots`` without pyplot: a ``matplotlib.figure.Figure`` and its axes; no backend is chosen
    and nothing is left open."""
    from matplotlib.figure import Figure
    fig = Figure(figsize=figsize, layout="constrained" if constrained_layout else None)
    return fig, fig.subplots(nrows, ncols, **kwargs)


class Figures:
    """Renders figures as inline SVG (unique ids per figure) and, on request, SVG and PNG files."""

    def __init__(self, folder=None):
        self.folder = Path(folder) if folder else None
        self.count = 0
        self.names = set()
        if self.folder:
            self.folder.mkdir(parents=True, exist_ok=True)

    def render(self, fig, name, caption) -> str:
        """The figure as inline SVG in a <figure> with its caption (and as files when asked)."""
        import matplotlib
        self.count += 1
        if name in self.names:  # a second figure of the kind (two Model I fits): its own id and files
            name = f"{name}-{self.count}"
        self.names.add(name)
        buf = io.StringIO()
        # unique ids per figure (clip paths, markers): no clashes between the page's inline SVGs
        with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": f"thermofriction-{self.count}-{name}"}):
            fig.savefig(buf, format="svg", bbox_inches="tight")
            svg = _compact(buf.getvalue())
            if self.folder:
                with atomic_write(self.folder / f"{name}.svg", "w") as fh:
                    fh.write(svg)
                with atomic_write(self.folder / f"{name}.png", "wb") as fh:
                    fig.savefig(fh, format="png", dpi=150, bbox_inches="tight")
        return f'<figure id="fig-{name}">{svg}<figcaption>{html.escape(caption)}</figcaption></figure>'


_NUMBER = re.compile(r"-?\d+\.\d+")


def _short(m):
    s = f"{float(m.group()):.1f}"
    return "0" if s in ("0.0", "-0.0") else s.removesuffix(".0")


def _compact(svg: str) -> str:
    """The SVG element alone, without matplotlib's metadata, with path coordinates to 0.1 pt (a tenth
    of a pixel: no visible change, about half the size)."""
    svg = svg[svg.index("<svg"):]
    svg = re.sub(r"<metadata>.*?</metadata>", "", svg, flags=re.S)  # RDF boilerplate, a date: noise
    return re.sub(r'(\s(?:d|x|y)=")([^"]*)(")', lambda m: m.group(1) + _NUMBER.sub(_short, m.group(2)) + m.group(3),
                  svg)


def html_table(head, rows, row_class=None, text=(), wrap=()):
    """An HTML table; columns ``text`` (indices) hold words and are left-aligned, ``wrap`` ones also
    wrap (numbers and units never do)."""
    def cell(tag, i, c):
        cls = "w" if i in wrap else "t" if i in text else ""
        return f'<{tag} class="{cls}">{html.escape(str(c))}</{tag}>' if cls else f"<{tag}>{html.escape(str(c))}</{tag}>"
    h = "".join(cell("th", i, c) for i, c in enumerate(head))

    def tr(r):
        cls = row_class(r) if row_class else ""
        return f'<tr class="{cls}">' if cls else "<tr>"
    b = "".join(tr(r) + "".join(cell("td", i, c) for i, c in enumerate(r)) + "</tr>" for r in rows)
    return f"<table><thead><tr>{h}</tr></thead><tbody>{b}</tbody></table>"


def fmt_number(x, f="{:.3g}"):
    try:
        x = float(x)
    except (TypeError, ValueError):
        return "—"
    return f.format(x) if math.isfinite(x) else "—"


def _versions():
    import matplotlib
    import scipy

    return {"thermofriction": __version__, "Python": platform.python_version(), "NumPy": np.__version__,
            "SciPy": scipy.__version__, "matplotlib": matplotlib.__version__}


def page_html(title, subtitle, parts, *, command=None, data=None) -> str:
    """A whole report page in the report's style: the title, a subtitle, the sections, and a footer
    with the versions, the data's SHA-256 and when it was written (when ``data`` is given: the hash
    the fitted models' provenance names) and the command line."""
    import datetime

    footer = " · ".join(f"{k} {v}" for k, v in _versions().items())
    if data is not None:
        from ..data.files import dataset_sha256
        footer += (f" · data SHA-256 <code>{dataset_sha256(data)[1]}</code> · written "
                   f"{datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d %H:%M UTC')}")
    if command:
        footer += f"<br>command: <code>{html.escape(command)}</code>"
    name = html.escape(title)
    return (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{name}</title>"
            f"<meta name='viewport' content='width=device-width, initial-scale=1'><style>{_CSS}</style></head>"
            f"<body><header><h1>{name}</h1><p>{html.escape(subtitle)}</p></header>"
            f"<main>{''.join(parts)}</main><footer>{footer}</footer></body></html>")


def write_page(path, title, subtitle, parts, command=None) -> str:
    """A standalone report page (the main report's style) written atomically; returns the HTML."""
    text = page_html(title, subtitle, parts, command=command)
    with atomic_write(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    return text

