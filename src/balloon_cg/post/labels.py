"""Labels of the special points of branch curves (LP, TP, EP, BP m=1, pitchfork-super, …), placed by textalloc
(a maintained library: a greedy search over candidate positions around each point) clear of one another, of every
curve drawn in the Axes and of the markers; a label away from its marker gets a thin leader line. Labels of
coincident points that read the same are one label. Every label and leader carries the gid ``GID`` (the paper's
figures remove them: their key is in the legend).
"""
import contextlib
import io

import textalloc

GID = "special-point-label"
LABEL_SIZE = 6.5  # points: the journal style's legend size
SAME_PLACE = 1.0  # display units: coincident points


def label_points(marks) -> None:
    """Label the marked points ``marks`` (Axes, text, x, y, colour): call after every curve is drawn."""
    by_axes = {}
    for ax, text, x, y, color in marks:
        by_axes.setdefault(ax, []).append((text, x, y, color))
    for ax, points in by_axes.items():
        ax.margins(x=0.06)
        ax.autoscale_view()
        _allocate(ax, _kinds_first(_distinct(ax, points)))


def _distinct(ax, points) -> list:
    """``points`` without repeats: the same text within SAME_PLACE of a point kept already."""
    kept = []
    for text, x, y, color in points:
        here = ax.transData.transform((x, y))
        if not any(t == text and abs(ax.transData.transform((u, v)) - here).max() < SAME_PLACE
                   for t, u, v, _ in kept):
            kept.append((text, x, y, color))
    return kept


def _kinds_first(points) -> list:
    """``points`` with the first of each text before any repeat: textalloc places labels greedily in order, so a
    crowded plot drops repeats (a second "BP m=1") rather than a kind (the only "TP")."""
    repeat = []
    for i, (text, *_) in enumerate(points):
        repeat.append(sum(other == text for other, *_ in points[:i]))
    return [point for _, point in sorted(zip(repeat, points), key=lambda pair: pair[0])]


def _allocate(ax, points) -> None:
    """Place the labels of ``points`` in ``ax`` (textalloc.allocate) avoiding the curves and markers drawn."""
    curves = [line for line in ax.get_lines() if len(line.get_xdata()) > 1]
    markers = [line for line in ax.get_lines() if len(line.get_xdata()) == 1]
    texts, x, y, colors = (list(column) for column in zip(*points))
    with contextlib.redirect_stdout(io.StringIO()):  # textalloc prints when no label fits (stdout is the CLI's)
        _, _, labels, leaders = textalloc.allocate(
            ax, x, y, texts, x_scatter=[float(m.get_xdata()[0]) for m in markers],
            y_scatter=[float(m.get_ydata()[0]) for m in markers], x_lines=[c.get_xdata() for c in curves],
            y_lines=[c.get_ydata() for c in curves], textsize=LABEL_SIZE, textcolor=colors, linecolor=colors,
            linewidth=0.4, draw_all=False, avoid_label_lines_overlap=True, avoid_crossing_label_lines=True)
    for artist in [*labels, *leaders]:
        if artist is not None:  # a label with no free place (draw_all=False): none drawn
            artist.set_gid(GID)
