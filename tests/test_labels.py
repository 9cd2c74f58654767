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
    assert {"LP", "TP", "EP", "pitchfork-super", "BP m=1"} <= {t.get_text() for t in labels}
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
