"""Special-point labels of the two-coil pressure–pole plot at one journal column (3.5 in): placed by textalloc
clear of one another, of the curves and inside the axes, none of the kinds lost."""
import numpy as np
import pytest

import balloon_cg as bc
from balloon_cg.post.labels import GID
from balloon_cg.post.style import JournalFigure, journal_style
from shared_pictures import two_coil_result


@pytest.fixture(scope="module")
def two_coils(tmp_path_factory):
    """SPOM1 between the paper's two coils at M = 0.002, the axisymmetric picture (four BP m=1 labels, a
    pitchfork, TP and EP crowd λ2(0) ≈ 1.65–1.8), shared with other files (tests/shared_pictures.py)."""
    return two_coil_result(tmp_path_factory)


def densified(points: np.ndarray, step: float = 0.5) -> np.ndarray:
    """The polyline through ``points`` (display units) sampled every ``step`` or closer."""
    pieces = [np.linspace(a, b, max(2, int(np.ceil(np.abs(b - a).max() / step)) + 1))
              for a, b in zip(points[:-1], points[1:])]
    return np.concatenate(pieces)


def test_labels_at_one_column_do_not_overlap_or_cross_curves(two_coils):
    with journal_style():
        fig = JournalFigure(figsize=(3.5, 2.8), layout="constrained")
        ax = fig.add_subplot()
        bc.plot(two_coils, "pressure-pole", ax=ax)
        fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    labels = [t for t in ax.texts if t.get_gid() == GID]
    assert {"LP", "TP", "EP", "pitchfork-super", "BP m=1"} <= {t.get_text().partition(" ")[2] for t in labels}
    boxes = [t.get_window_extent(renderer) for t in labels]
    frame = ax.get_window_extent(renderer)
    for i, box in enumerate(boxes):
        assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
        for j, other in enumerate(boxes[:i]):
            assert not box.overlaps(other), f"{labels[i].get_text()!r} overlaps {labels[j].get_text()!r}"
    curves = [line for line in ax.get_lines() if line.get_gid() != GID and len(line.get_xdata()) > 1]
    assert curves
    for line in curves:
        xy = densified(ax.transData.transform(np.column_stack([line.get_xdata(), line.get_ydata()])))
        for label, box in zip(labels, boxes):
            inside = ((xy[:, 0] > box.x0) & (xy[:, 0] < box.x1) & (xy[:, 1] > box.y0) & (xy[:, 1] < box.y1))
            assert not inside.any(), f"{label.get_text()!r} crosses a curve"


def test_every_marker_is_numbered_with_a_label_continue_takes(two_coils, tmp_path, capsys):
    """The acceptance test of issue 40: in the two-coil figure every special-point label starts with numbers that
    are labels of the file (what `inspect` lists and `continue` takes: each restarts), every marked point's label
    is drawn unless textalloc found no room, and the legend names each pear branch by its parent's label."""
    import re

    from balloon_cg.app.cli import main
    from balloon_cg.app.restart import find_label
    from balloon_cg.io.run_file import read_run

    path = tmp_path / "two_coils.h5"
    two_coils.save(path)
    run = read_run(path)
    labels = {s["label"]: s for b in run["branches"].values() for s in b["special_points"]}
    assert main(["inspect", str(path)]) == 0
    listed = capsys.readouterr().out
    fig = bc.plot(path, "pressure-pole")
    texts = [t.get_text() for ax in fig.axes for t in ax.texts if t.get_gid() == GID]
    numbered = [re.fullmatch(r"(\d+(?:,\d+)*) (.+)", text) for text in texts]
    assert texts and all(numbered)
    for match in numbered:
        for number in map(int, match[1].split(",")):
            point = labels[number]
            assert match[2] == (point["classification"] or point["kind"]) + (f" m={point['m']}" if point["m"] else "")
            assert re.search(rf"^\s+{number} {point['kind']}\b", listed, re.M)  # inspect lists it
    assert len({n for m in numbered for n in m[1].split(",")}) >= 0.8 * len(labels)
    legend = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    pears = [text for text in legend if "pear" in text]
    assert pears and all(re.search(r"pear from (\d+)", text) for text in pears)
    for text in pears:
        parent = labels[int(re.search(r"pear from (\d+)", text)[1])]
        assert parent["kind"] == "BP" and parent["block"] in ("odd_held", "odd_free")
    for number in labels:  # continue finds each (restarting from them: tests/test_restart.py)
        assert find_label(run, number).point.kind.value == labels[number]["kind"]


@pytest.mark.parametrize("width", (3.5, 7.2))
@pytest.mark.parametrize("kind", ("pressure-pole", "shapes"))
def test_a_legend_in_the_callers_axes_hides_no_curve_and_no_label(two_coils, kind, width):
    """Drawn into the caller's own Axes (issue 40: at one column the shapes legend lay over the outlines and out of
    the Axes): the legend covers no vertex of a curve and no text of the Axes, and stays inside the figure."""
    with journal_style():
        fig = JournalFigure(figsize=(width, 0.7 * width), layout="constrained")
        ax = fig.add_subplot()
        bc.plot(two_coils, kind, ax=ax)
        fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    frame = ax.get_legend().get_window_extent(renderer)
    assert frame.x0 >= fig.bbox.x0 and frame.x1 <= fig.bbox.x1 and frame.y0 >= fig.bbox.y0
    for line in ax.get_lines():
        x, y = ax.transData.transform(np.column_stack([line.get_xdata(), line.get_ydata()]).astype(float)).T
        assert not ((x > frame.x0) & (x < frame.x1) & (y > frame.y0) & (y < frame.y1)).any(), line.get_label()
    assert not [t.get_text() for t in ax.texts if frame.overlaps(t.get_window_extent(renderer))]
