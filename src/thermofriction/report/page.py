"""The building blocks every report page shares: the style sheet, figures rendered as inline SVG,
tables, number formatting, the footer's versions, and writing a page atomically."""

from __future__ import annotations

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
thead th{background:#f0f2f7}
figure{margin:8px 0 18px}
figure svg{max-width:100%;height:auto}
figcaption{font-size:13px;color:#4a5266;margin-top:4px}
.warn{background:#fff6e0;border-left:4px solid #f0a500;padding:8px 12px;font-size:13px;margin:6px 0}
footer{font-size:12px;color:#6b7389;padding:0 40px 30px}
code{background:#eef0f5;padding:1px 4px;border-radius:3px}
"""



def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.rcParams.update({"svg.fonttype": "none", "font.size": 9, "axes.grid": True, "grid.alpha": 0.3,
                         "axes.spines.top": False, "axes.spines.right": False})
    return plt


class Figures:
    """Renders figures as inline SVG (unique ids per figure) and, on request, SVG and PNG files."""

    def __init__(self, folder=None):
        self.folder = Path(folder) if folder else None
        self.count = 0
        if self.folder:
            self.folder.mkdir(parents=True, exist_ok=True)

    def render(self, fig, name, caption) -> str:
        plt = _plt()
        self.count += 1
        plt.rcParams["svg.hashsalt"] = f"thermofriction-{self.count}-{name}"  # no id clashes between figures
        buf = io.StringIO()
        fig.savefig(buf, format="svg", bbox_inches="tight")
        svg = buf.getvalue()
        svg = svg[svg.index("<svg"):]
        svg = re.sub(r"<metadata>.*?</metadata>", "", svg, flags=re.S)  # RDF boilerplate, a date: noise
        if self.folder:
            with atomic_write(self.folder / f"{name}.svg", "w") as fh:
                fh.write(svg)
            with atomic_write(self.folder / f"{name}.png", "wb") as fh:
                fig.savefig(fh, format="png", dpi=150, bbox_inches="tight")
        plt.close(fig)
        return f'<figure id="fig-{name}">{svg}<figcaption>{html.escape(caption)}</figcaption></figure>'


def _thin(t, y, n=1200):
    """At most ~2n points that keep each bucket's minimum and maximum, so that a 20 000-sample curve
    draws the same in a figure a few hundred pixels wide, in a fraction of the file size."""
    t, y = np.asarray(t), np.asarray(y)
    if len(t) <= 2 * n:
        return t, y
    edges = np.linspace(0, len(t), n + 1).astype(int)
    idx = []
    for a, b in zip(edges[:-1], edges[1:]):
        seg = y[a:b]
        i, j = a + int(np.argmin(seg)), a + int(np.argmax(seg))
        idx.extend(sorted({i, j}))
    idx = np.array(idx)
    return t[idx], y[idx]


def _colors(temps):
    plt = _plt()
    lo, hi = min(temps), max(temps)
    cmap = plt.get_cmap("plasma")
    return {T: cmap(0.1 + 0.75 * ((T - lo) / (hi - lo) if hi > lo else 0.5)) for T in temps}


def _table(head, rows):
    h = "".join(f"<th>{html.escape(c)}</th>" for c in head)
    b = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><thead><tr>{h}</tr></thead><tbody>{b}</tbody></table>"


def _fmt(x, f="{:.3g}"):
    try:
        x = float(x)
    except (TypeError, ValueError):
        return "—"
    return f.format(x) if math.isfinite(x) else "—"


def _versions():
    import matplotlib
    import scipy

    return {"thermofriction": __version__, "python": platform.python_version(), "numpy": np.__version__,
            "scipy": scipy.__version__, "matplotlib": matplotlib.__version__}


def _write_page(path, title, subtitle, parts, command=None) -> str:
    """A standalone report page (the main report's style) written atomically; returns the HTML."""
    name = html.escape(title)
    footer = " · ".join(f"{k} {v}" for k, v in _versions().items()) + (
        f"<br>command: <code>{html.escape(command)}</code>" if command else "")
    text = (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{name}</title>"
            f"<meta name='viewport' content='width=device-width, initial-scale=1'><style>{_CSS}</style></head>"
            f"<body><header><h1>{name}</h1><p>{html.escape(subtitle)}</p></header>"
            f"<main>{''.join(parts)}</main><footer>{footer}</footer></body></html>")
    with atomic_write(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    return text

