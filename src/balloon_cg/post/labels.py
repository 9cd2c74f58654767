"""Labels of the special points of branch curves, AUTO style: each point's label in the file (what ``continue``
takes and ``inspect`` lists) and what it is ("3 LP", "5 pitchfork-super", "7 BP m=1"), placed by textalloc (a
maintained library: a greedy search over candidate positions around each point) clear of one another, of every
curve drawn in the Axes and of the markers; a label away from its marker gets a thin leader line. Coincident
points of one kind share a label ("7,9 EP": a pear branch's end and its mirror image's). Every label and leader
carries the gid ``GID``; the paper's figures draw none (``unlabelled``: their key is in the legend).
"""
import contextlib
import contextvars
import io
import weakref

import textalloc

GID = "special-point-label"
LABEL_SIZE = 6.5  # points: the journal style's legend size
SAME_PLACE = 1.0  # display units: coincident points


def label_points(marks) -> None:
    """Label the marked points ``marks`` (Axes, label number, kind text, x, y, colour): call after every curve is
    drawn; nothing inside ``unlabelled``."""
    if not LABELLED.get():
        return
    by_axes = {}
    for ax, number, kind, x, y, color in marks:
        by_axes.setdefault(ax, []).append((number, kind, x, y, color))
    for ax, points in by_axes.items():
        ax.margins(x=0.06)
        ax.autoscale_view()
        PLACED[ax] = points
        _allocate(ax, _kinds_first(_distinct(ax, points)))


LABELLED = contextvars.ContextVar("labelled", default=True)


@contextlib.contextmanager
def unlabelled():
    """Draw the special points' markers only, without their labels (the paper's figures: the markers' key is in
    the legend); placing labels lays a figure out, which a half-drawn panel grid cannot be at a journal column."""
    token = LABELLED.set(False)
    try:
        yield
    finally:
        LABELLED.reset(token)


PLACED = weakref.WeakKeyDictionary()  # Axes -> the points labelled in it (``relabel``)


def relabel(fig) -> None:
    """Place the labels of every Axes of ``fig`` again (after its size or layout changed: the labels were placed
    clear of one another and of the curves in display units), laid out first."""
    fig.draw_without_rendering()
    for ax in fig.axes:
        if ax in PLACED:
            for artist in [*ax.texts, *ax.lines]:
                if artist.get_gid() == GID:
                    artist.remove()
            _allocate(ax, _kinds_first(_distinct(ax, PLACED[ax])))


def _distinct(ax, points) -> list:
    """(text, kind, x, y, colour) of ``points``, coincident points of one kind (within SAME_PLACE) one label with
    their numbers ("7,9 EP")."""
    kept = []
    for number, kind, x, y, color in points:
        here = ax.transData.transform((x, y))
        same = next((k for k in kept if k[1] == kind and abs(ax.transData.transform(k[2:4]) - here).max()
                     < SAME_PLACE), None)
        if same is None:
            kept.append([[number], kind, x, y, color])
        elif number not in same[0]:
            same[0].append(number)
    return [(f"{','.join(map(str, numbers))} {kind}", kind, x, y, color) for numbers, kind, x, y, color in kept]


def _kinds_first(points) -> list:
    """(text, x, y, colour) of ``points`` with the first of each kind before any repeat: textalloc places labels
    greedily in order, so a crowded plot drops repeats (a second "BP m=1") rather than a kind (the only "TP")."""
    repeat = []
    for i, (_, kind, *_) in enumerate(points):
        repeat.append(sum(other == kind for _, other, *_ in points[:i]))
    return [(text, x, y, color) for _, (text, _, x, y, color) in sorted(zip(repeat, points), key=lambda p: p[0])]


def _allocate(ax, points) -> None:
    """Place the labels of ``points`` in ``ax`` (textalloc.allocate) avoiding the curves and markers drawn."""
    curves = [line for line in ax.get_lines() if len(line.get_xdata()) > 1]
    markers = [line for line in ax.get_lines() if len(line.get_xdata()) == 1]
    texts, x, y, colors = (list(column) for column in zip(*points))
    with contextlib.redirect_stdout(io.StringIO()):  # textalloc prints when no label fits (stdout is the CLI's)
        _, _, labels, leaders = textalloc.allocate(
            ax, x, y, texts, x_scatter=[float(m.get_xdata()[0]) for m in markers],
            y_scatter=[float(m.get_ydata()[0]) for m in markers], x_lines=[_in_data(ax, c)[:, 0] for c in curves],
            y_lines=[_in_data(ax, c)[:, 1] for c in curves], textsize=LABEL_SIZE, textcolor=colors, linecolor=colors,
            linewidth=0.4, draw_all=False, avoid_label_lines_overlap=True, avoid_crossing_label_lines=True)
    for artist in [*labels, *leaders]:
        if artist is not None:  # a label with no free place (draw_all=False): none drawn
            artist.set_gid(GID)


def _in_data(ax, line):
    """The points of ``line`` in ``ax``'s data coordinates (textalloc reads them so): a line drawn in other
    coordinates (``axhline``'s x in the Axes' fraction: Maxwell's pressure) moved into them."""
    if line.get_transform() is ax.transData:
        return line.get_xydata()
    return ax.transData.inverted().transform(line.get_transform().transform(line.get_xydata()))
