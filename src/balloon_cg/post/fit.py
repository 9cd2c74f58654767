"""Text that stays inside a figure at a journal width (3.5 in one column, 7.2 in two), measured rather than
guessed: ``fit_titles`` wraps each panel title to the room it has and the figure's title to the figure's width;
``fitted_legend`` gives a figure legend as many columns as fit across the figure (one column: its labels
wrapped); ``fit_with_legend`` keeps a panel's legend inside it only where it hides nothing drawn. All need a figure
with a renderer (``style.JournalFigure``: the Agg canvas).
"""
import re
import textwrap
import warnings

import numpy as np
from matplotlib.path import Path
from matplotlib.text import Text

from .labels import relabel

MIN_CHARS = 12  # the narrowest wrap tried, characters per line
MIN_WIDTH, MAX_WIDTH = 1.0, 40.0  # inches: a figure's width (as ``figure --width``)


def wrap_to(text: Text, width: float, along: str = "width") -> None:
    """Wrap ``text`` at spaces (each of its lines; none inside $…$ math: ``wrapped``) until it is at most ``width``
    display units long ``along`` its extent's width (or height: a rotated y label), or its lines are MIN_CHARS
    characters."""
    renderer = text.figure.canvas.get_renderer()
    original = text.get_text()
    chars = max(map(len, original.splitlines()), default=0)
    while getattr(text.get_window_extent(renderer), along) > width and chars > MIN_CHARS:
        length = getattr(text.get_window_extent(renderer), along)
        chars = max(MIN_CHARS, min(chars - 1, int(chars * width / length)))
        text.set_text(wrapped(original, chars))


KEPT_SPACE = "\ue000"  # a private-use character: a space inside $…$ while wrapping (textwrap breaks ASCII spaces)


def wrapped(text: str, chars: int) -> str:
    """``text`` filled to ``chars`` characters a line (each of its lines; no word broken), never inside $…$ math
    (mathtext is parsed line by line: a broken formula would be drawn as its source)."""
    pieces = re.split(r"(?<!\\)(\$[^$]*(?<!\\)\$)", text)  # odd pieces: the formulas
    kept = "".join(piece.replace(" ", KEPT_SPACE) if n % 2 else piece for n, piece in enumerate(pieces))
    return "\n".join(textwrap.fill(line, chars, break_long_words=False)
                     for line in kept.splitlines()).replace(KEPT_SPACE, " ")


def fit_titles(fig) -> None:
    """Wrap every panel title to the room it has (``room``) and the figure's texts (its suptitle) to the
    figure's width, after laying the figure out."""
    fig.draw_without_rendering()
    for ax in fig.axes:
        for title in (c for c in ax.get_children() if isinstance(c, Text) and c not in ax.texts):
            wrap_to(title, room(ax))
    for text in fig.texts:
        wrap_to(text, fig.bbox.width)
    fig.draw_without_rendering()


def room(ax) -> float:
    """The width a panel's title may take: from the panel's left edge to the next panel on its right in the
    same row, or to the figure's edge."""
    box = ax.get_window_extent()
    others = [other.get_window_extent() for other in ax.figure.axes if other is not ax]
    right = [o.x0 for o in others if o.x0 >= box.x1 and o.y1 > box.y0 and o.y0 < box.y1]
    return min(right, default=ax.figure.bbox.x1) - box.x0


def fitted_legend(fig, handles, labels, ncols: int, **options):
    """A figure legend of as many columns (at most ``ncols``) as fit across the figure with its labels wrapped to
    no narrower than MIN_LABEL_SHARE of the widest (one column: wrapped as far as needed)."""
    renderer = fig.canvas.get_renderer()
    for n in range(ncols, 0, -1):
        legend = fig.legend(handles, labels, ncols=n, **options)
        texts = legend.get_texts()
        widest = max(text.get_window_extent(renderer).width for text in texts)
        for _ in range(3):  # the columns' widths follow their widest labels: measure again after wrapping
            overflow = legend.get_window_extent(renderer).width - fig.bbox.width
            if overflow <= 0:
                return legend
            width = max(text.get_window_extent(renderer).width for text in texts) - overflow / n
            if width < MIN_LABEL_SHARE * widest and n > 1:
                break
            for text, label in zip(texts, labels):  # from the label: wrap_to keeps the lines it is given
                text.set_text(label)
                wrap_to(text, width)
        if n == 1:
            return legend
        legend.remove()


MIN_LABEL_SHARE = 0.5  # a legend label is wrapped to no less than this share of the widest before a column goes


NARROW = 5.0  # inches: below this width a figure is at least NARROW_ASPECT times as tall as wide
NARROW_ASPECT = 0.8


def fitted_size(figsize, width: float) -> tuple:
    """(width, height) of a figure drawn at ``figsize``: its height in proportion, at least NARROW_ASPECT of the
    width below NARROW inches."""
    w, h = figsize
    return width, max(h * width / w, NARROW_ASPECT * width if width < NARROW else 0.0)


def fit_width(fig, width: float) -> None:
    """Make a figure drawn at its own size ``width`` inches wide, its height in proportion (at least NARROW_ASPECT
    of the width below NARROW inches: room for the legend), each figure legend moved under the panels in as many
    columns as fit (``fitted_legend``), the axis labels wrapped to their panels and the titles to their room
    (``fit_titles``), the special points labelled again at that size (``labels.relabel``)."""
    fig.set_size_inches(*fitted_size(fig.get_size_inches(), width))
    for legend in list(fig.legends):
        handles, labels = legend.legend_handles, [t.get_text() for t in legend.get_texts()]
        title = legend.get_title().get_text()
        legend.remove()
        fitted_legend(fig, handles, labels, len(labels), loc="outside lower center", title=title or None)
    fig.draw_without_rendering()
    for ax in fig.axes:  # axis labels to their panel's size
        box = ax.get_window_extent()
        wrap_to(ax.xaxis.label, box.width)
        wrap_to(ax.yaxis.label, box.height, along="height")
    fit_titles(fig)
    relabel(fig)


def fit_with_legend(fig, ax, width: float, **options) -> None:
    """Fit ``fig`` to ``width`` inches (``fit_width``) with ``ax``'s legend (its handles and labels, ``options``) at
    matplotlib's best place inside the panel, or, where that place hides anything drawn there after the layout
    (``covers``: a curve, a marker, a special point's label), under the panels (``fit_width``'s figure legend)."""
    handles, labels = ax.get_legend_handles_labels()
    for other in fig.axes:  # a twin's curves (twinx) belong to the same legend
        if other is not ax and other.bbox.bounds == ax.bbox.bounds:
            more = other.get_legend_handles_labels()
            handles, labels = handles + more[0], labels + more[1]
    if not labels:
        fit_width(fig, width)
        return
    legend = ax.legend(handles, labels, loc="best", **options)
    fit_width(fig, width)
    if covers(legend, ax):
        legend.remove()
        fig.legend(handles, labels, **options)
        fit_width(fig, width)


def covers(legend, ax) -> bool:
    """Whether ``legend``, drawn in ``ax`` (laid out first), reaches out of it or covers a vertex or a segment of a
    line drawn in it or in its twins (the Axes at its place: twinx), curves, markers and leaders, or one of their
    texts (the special points' labels)."""
    with warnings.catch_warnings():  # a trial layout of a figure the caller is still building (a panel grid half
        warnings.simplefilter("ignore", UserWarning)  # drawn may collapse): its warnings are theirs when they draw it
        ax.figure.draw_without_rendering()
    frame, box = legend.get_window_extent(), ax.get_window_extent()
    if frame.x0 < box.x0 or frame.x1 > box.x1 or frame.y0 < box.y0 or frame.y1 > box.y1:
        return True
    twins = [other for other in ax.figure.axes if other.bbox.bounds == ax.bbox.bounds]
    for line in (line for other in twins for line in other.get_lines()):
        xy = line.get_transform().transform(line.get_xydata())
        gaps = ~np.isfinite(xy).all(axis=1)  # NaN: a break in the line (an unstable part drawn by another)
        for piece in (piece[~gap] for piece, gap in zip(np.split(xy, np.flatnonzero(gaps)),
                                                         np.split(gaps, np.flatnonzero(gaps)))):
            x, y = piece.T
            if ((x > frame.x0) & (x < frame.x1) & (y > frame.y0) & (y < frame.y1)).any():
                return True
            if len(piece) > 1 and Path(piece).intersects_bbox(frame, filled=False):
                return True
    return any(frame.overlaps(text.get_window_extent()) for other in twins for text in other.texts
               if text.get_visible() and text.get_text())
