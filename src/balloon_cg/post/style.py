"""The journal style of every figure: ``journal.mplstyle``, shipped with the package (8 pt serif text readable at
one column, 3.5 in; TrueType fonts embedded in PDF and PostScript, ``pdf.fonttype = ps.fonttype = 42``: no Type 3
fonts, which journals reject). ``journal_style()`` applies it to a block without touching matplotlib's global
state; a ``JournalFigure`` is saved in it, wherever ``savefig`` is called from.
"""
from pathlib import Path

import matplotlib.style
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

#: The journal style sheet (``journal.mplstyle``, shipped with the package): ``plt.style.use(bc.JOURNAL_STYLE)``
#: applies it for good; 8 pt serif text, TrueType fonts in PDF and EPS.
JOURNAL_STYLE = Path(__file__).with_name("journal.mplstyle")


def journal_style():
    """The journal style for a block of code (``matplotlib.style.context``; for good:
    ``plt.style.use(balloon_cg.JOURNAL_STYLE)``).

    Returns
    -------
    contextlib.AbstractContextManager
        Applies the style inside its ``with`` block only.

    Examples
    --------
    >>> with bc.journal_style():
    ...     fig, ax = plt.subplots(figsize=(3.5, 2.6))
    ...     fig.savefig("own.pdf")
    """
    return matplotlib.style.context(JOURNAL_STYLE)


class JournalFigure(Figure):
    """A matplotlib Figure on the Agg canvas (a renderer to measure text with, no pyplot) that saves itself in
    the journal style (fonts embedded as TrueType)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        FigureCanvasAgg(self)

    def savefig(self, *args, **kwargs):
        with journal_style():
            return super().savefig(*args, **kwargs)
