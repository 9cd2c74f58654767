"""docs/api.md's example (a run, its tables and plots, a sweep and a two-parameter curve) runs as a notebook in a
Jupyter kernel (nbclient): every paragraph a cell, no error, no terminal control codes in any output (progress and
notices are plain text or widgets there), and results show as HTML tables. About 20 s (the run, a three-member sweep
and the curve of critical α1), so it is in the default suite."""
import pytest

from test_api import example

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

ANSI = "\x1b["  # an escape sequence: colour, cursor movement (tqdm's terminal bars; they also write "\r")


def texts(output) -> list[str]:
    """Every text an output holds: a stream's, an error's traceback, each mime type's data."""
    found = [output.get("text", ""), *output.get("traceback", [])]
    found += [value if isinstance(value, str) else "" for value in output.get("data", {}).values()]
    return found


def test_the_documented_example_runs_as_a_notebook(tmp_path):
    cells = [nbformat.v4.new_code_cell(block.strip()) for block in example().split("\n\n") if block.strip()]
    cells += [nbformat.v4.new_code_cell(name) for name in ("result", "result.special_points", "sweep", "curve")]
    notebook = nbformat.v4.new_notebook(cells=cells)
    client = nbclient.NotebookClient(notebook, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()  # CellExecutionError on the first cell that raises
    outputs = [output for cell in notebook.cells for output in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    assert not [text for o in outputs for text in texts(o) if ANSI in text or "\r" in text]
    widgets = [o for o in outputs if "application/vnd.jupyter.widget-view+json" in o.get("data", {})]
    assert len(widgets) >= 3  # the progress bars of the analysis' phases, as widgets
    shown = {cell.source: cell.outputs[-1] for cell in notebook.cells[-4:]}
    for name in ("result", "result.special_points", "sweep", "curve"):
        html = shown[name]["data"]["text/html"]
        assert html.startswith("<p>") and "<table" in html, name
        assert "\n" not in shown[name]["data"]["text/plain"], name
    assert (tmp_path / "two_coils_sweep_M.h5").exists() and (tmp_path / "spom1.png").stat().st_size > 10_000
