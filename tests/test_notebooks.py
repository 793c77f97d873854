"""The notebooks in notebooks/ execute from top to bottom, on small grids.

Each notebook reads ``SCREWKIT_NOTEBOOK_QUICK=1`` in its first cell and then uses coarse grids
and sweeps (the first four together take about a minute and a half). The kernel is the interpreter running the
tests (a kernel spec written for this run), its working directory a temporary folder, so files
the notebooks write (HTML exports) land there. Notebooks are committed without outputs.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
KERNEL_NAME = "screwkit-tests"


@pytest.fixture(scope="module")
def kernel_folder(tmp_path_factory) -> Path:
    """A Jupyter data folder holding one kernel spec: this interpreter running ipykernel."""
    folder = tmp_path_factory.mktemp("jupyter")
    spec = folder / "kernels" / KERNEL_NAME
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "screwkit tests", "language": "python"}))
    return folder


def test_notebooks_exist():
    assert [path.name for path in NOTEBOOKS] == [
        "01_reproduce_the_paper.ipynb", "02_plug_in_a_mechanism.ipynb", "03_meshcat_inspection.ipynb",
        "04_any_mobility.ipynb", "05_design_search.ipynb", "06_trajectory.ipynb"]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_notebook_is_committed_without_outputs(path):
    notebook = nbformat.read(path, as_version=4)
    nbformat.validate(notebook)
    for cell in notebook.cells:
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None, f"{path.name}: a cell has outputs"


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_notebook_runs(path, tmp_path, kernel_folder, monkeypatch):
    monkeypatch.setenv("SCREWKIT_NOTEBOOK_QUICK", "1")
    monkeypatch.setenv("JUPYTER_PATH", str(kernel_folder))
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    notebook = nbformat.read(path, as_version=4)
    client = NotebookClient(notebook, timeout=600, kernel_name=KERNEL_NAME,
                            resources={"metadata": {"path": str(tmp_path)}})
    client.execute()
    first = next(cell for cell in notebook.cells if cell.cell_type == "code")
    printed = "".join(output.get("text", "") for output in first.outputs)
    assert "quick mode" in printed, f"{path.name}: the first cell did not pick up SCREWKIT_NOTEBOOK_QUICK"
