"""The tutorial notebook (examples/python/tutorial.ipynb) runs headless from top to
bottom (nbclient, the Python kernel of this environment), as a reader would run it."""

import pytest

from conftest import REPO

NOTEBOOK = REPO / "examples" / "python" / "tutorial.ipynb"


def test_the_tutorial_runs_headless():
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(
        nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}
    )
    client.execute()
    printed = "".join(
        o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
    )
    assert "IMU samples" in printed and "through the outage" in printed
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []) if o.output_type == "error"]
    assert not errors
