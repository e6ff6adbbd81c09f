"""The gallery's image scraper for the library's own figures (docs/conf.py, sphinx-gallery).

The library draws without pyplot (``fit.plot()``, ``metrics.plot()`` return a
``matplotlib.figure.Figure`` that no pyplot window manages), so sphinx-gallery's matplotlib scraper,
which collects pyplot's figures, does not see them. This scraper collects every such figure that an
example binds to a name, once, after the code block that made it.
"""

from matplotlib.figure import Figure
from sphinx_gallery.scrapers import figure_rst


def figures(block, block_vars, gallery_conf, **kwargs):
    names = block_vars["example_globals"]
    seen = names.setdefault("__gallery_figures__", [])  # the figures already shown, kept alive (unique ids)
    new = [v for v in list(names.values()) if isinstance(v, Figure) and v.canvas.manager is None
           and not any(v is s for s in seen)]
    paths = []
    for fig, path in zip(new, block_vars["image_path_iterator"]):
        fig.savefig(path, **kwargs)
        seen.append(fig)
        paths.append(path)
    return figure_rst(paths, gallery_conf["src_dir"]) if paths else ""
