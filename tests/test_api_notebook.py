"""docs/api.md's example (a run, its tables and plots, a sweep and a two-parameter curve) runs as a notebook in a
Jupyter kernel (nbclient): every paragraph a cell, no error, no terminal control codes in any output (progress and
notices are plain text or widgets there), results show as HTML tables, and what it computes is what the page says.
About 20 s (the run, a three-member sweep and the curve of critical α1), so it is in the default suite."""
import json
import re
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

ROOT = Path(__file__).resolve().parents[1]
ANSI = "\x1b["  # an escape sequence: colour, cursor movement (tqdm's terminal bars; they also write "\r")


def texts(output) -> list[str]:
    """Every text an output holds: a stream's, an error's traceback, each mime type's data."""
    found = [output.get("text", ""), *output.get("traceback", [])]
    found += [value if isinstance(value, str) else "" for value in output.get("data", {}).values()]
    return found


def executed(sources: list[str], folder) -> nbformat.NotebookNode:
    """A notebook of one cell per source, run in a fresh Jupyter kernel in ``folder``."""
    notebook = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(source) for source in sources])
    client = nbclient.NotebookClient(notebook, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(folder)}})
    client.execute()  # CellExecutionError on the first cell that raises
    return notebook


def example() -> str:
    """The Python block of docs/api.md."""
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "api.md").read_text(encoding="utf-8"), re.S)
    assert len(blocks) == 1
    return blocks[0]


# what the example's objects hold, printed as one JSON line by a cell after it
FACTS = """import json
left, right = fig.axes[:2]
members = sweep.to_dataframe()
print(json.dumps({"labels": [left.get_xlabel(), left.get_ylabel(), right.get_xlabel()],
                  "lines": len(left.get_lines()), "branches": len(result.branches), "M": list(members["field.M"]),
                  "complete": bool(members["complete"].all()), "P_cr1": bool(members["P_cr1"].notna().all()),
                  "P_LP": bool(members["P_LP"].notna().all()), "parameter": curve.parameter,
                  "pear": curve.critical["pear"]}))"""
PHASE_LINE = re.compile(r"^\S+: [a-z -]+: \d+ points \[\d\d:\d\d\]$")  # a finished phase (app.progress)


def test_the_documented_example_runs_as_a_notebook(tmp_path):
    """Its objects as the page says (until session 31 also checked by running the example in the test's own process,
    tests/test_api.py, the same computation a second time): the figure's Axes drawn with every branch, the run printed
    first, the sweep's members complete with their pressures, the pear pitchfork's α1 (docs/numerics.md)."""
    sources = [block.strip() for block in example().split("\n\n") if block.strip()]
    notebook = executed(sources + [FACTS, "result", "result.special_points", "sweep", "curve"], tmp_path)
    outputs = [output for cell in notebook.cells for output in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    assert not [text for o in outputs for text in texts(o) if ANSI in text or "\r" in text]
    phases = [o["data"]["text/plain"] for o in outputs if o.output_type == "display_data"
              and PHASE_LINE.match(o["data"].get("text/plain", ""))]
    assert len(phases) >= 3  # the analysis' phases: each widget replaced by its finished line
    shown = {cell.source: cell.outputs[-1] for cell in notebook.cells[-4:]}
    for name in ("result", "result.special_points", "sweep", "curve"):
        html = shown[name]["data"]["text/html"]
        assert html.startswith("<p>") and "<table" in html, name
        assert "\n" not in shown[name]["data"]["text/plain"], name
    assert (tmp_path / "two_coils_sweep_M.h5").exists() and (tmp_path / "spom1.png").stat().st_size > 10_000
    assert (tmp_path / "spom1.h5").exists()
    printed = "".join(o.get("text", "") for cell in notebook.cells[:len(sources)] for o in cell.outputs
                      if o.get("name") == "stdout")
    assert printed.startswith("Result('spom1'") and "long_name" not in printed
    facts = json.loads("".join(o.get("text", "") for o in notebook.cells[len(sources)].outputs
                               if o.get("name") == "stdout"))
    left_x, left_y, right_x = facts["labels"]
    assert "pole stretch" in left_x and "pressure" in left_y and "rho" in right_x
    assert facts["lines"] >= facts["branches"]  # every branch drawn into the caller's Axes
    assert facts["M"] == [0.0, 0.001, 0.002] and facts["complete"] and facts["P_cr1"] and facts["P_LP"]
    assert facts["parameter"] == "alpha1" and facts["pear"] == pytest.approx(1.739619649392, abs=1e-9)


SMALL = ("import balloon_cg as bc\nscene = bc.Scene.from_toml('spom1').with_overrides("
         "{'continuation.stop_stretch': 2.0, 'surface.branches': 'none'})\nresult = bc.analyse(scene, progress=True)")


def phase_outputs(notebook) -> tuple[list[str], list[str]]:
    """(the display outputs', the stderr streams' lines) of the notebook's last cell."""
    outputs = notebook.cells[-1].outputs
    shown = [o["data"].get("text/plain", "") for o in outputs if o.output_type == "display_data"]
    return shown, "".join(o.get("text", "") for o in outputs if o.get("name") == "stderr").splitlines()


def test_progress_in_a_notebook_is_one_record_per_phase(tmp_path):
    """With ipywidgets: a widget per phase, replaced in place by its finished line (a saved notebook shows each phase
    once, never a stale '0 points' snapshot beside a stderr line); without (the kernel cannot import it): a text
    bar per phase in an output of its own, replaced in place by its finished line, nothing on stderr (no 'IProgress
    not found' warning, no carriage returns or cursor codes: tqdm.auto's text bars garbled there)."""
    phases = ("spom1: primary branch", "spom1: stability", "spom1: pear branches")
    for setup in ([], ["import sys\nsys.modules['ipywidgets'] = None"]):
        notebook = executed(setup + [SMALL], tmp_path)
        shown, stderr = phase_outputs(notebook)
        assert sorted(line.rsplit(": ", 1)[0] for line in shown) == sorted(phases), shown
        assert all(PHASE_LINE.match(line) for line in shown) and stderr == [], (shown, stderr)
        assert not [t for o in notebook.cells[-1].outputs for t in texts(o) if ANSI in t or "\r" in t]
