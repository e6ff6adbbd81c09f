"""examples/your_data.ipynb runs top to bottom in a fresh Jupyter kernel (nbclient), so it cannot rot;
its results show as tables (_repr_html_) and its figures inline, and what it prints is right: the
fit is adequate, Model I predicts the held-out run better than the model without temperature."""

import re
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

NOTEBOOK = Path(__file__).resolve().parents[1] / "examples" / "your_data.ipynb"


@pytest.fixture(scope="module")
def executed(tmp_path_factory):
    nb = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path_factory.mktemp("nb"))}})
    client.execute()
    return nb


def outputs(nb, kind):
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            if kind in out.get("data", {}):
                yield cell.source, out["data"][kind]


def test_notebook_runs_and_shows_tables_and_figures(executed):
    errors = [o for c in executed.cells for o in c.get("outputs", []) if o.get("output_type") == "error"]
    assert not errors, errors
    html = dict(outputs(executed, "text/html"))
    fit_html = next(v for k, v in html.items() if k.strip().endswith("\nfit"))
    assert "<table>" in fit_html and "fc.b" in fit_html and "adequate" in fit_html and "sha256" in fit_html
    metrics_html = next(v for k, v in html.items() if k.strip().endswith("\nmetrics"))
    assert "max error [%]" in metrics_html and "validate" in metrics_html and "NRMSE = RMSE" in metrics_html
    assert len(list(outputs(executed, "image/png"))) >= 3  # sim.plot(), fit.plot(data), metrics.plot()


def test_notebook_results_say_what_the_text_claims(executed):
    text = "".join(o.get("text", "") for c in executed.cells for o in c.get("outputs", [])
                   if o.get("output_type") == "stream")
    assert "adequate: True" in text
    m = re.search(r"held-out max error: Model I ([\d.e+-]+) %, no thermal model ([\d.e+-]+) %", text)
    assert m, text
    assert float(m.group(1)) < 5 < float(m.group(2)) or float(m.group(1)) < float(m.group(2)) / 2
