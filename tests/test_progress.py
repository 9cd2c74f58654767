"""Progress bars: overlapping phases end in clean finished lines, one per phase, on a terminal; none elsewhere."""
import io
import re

from balloon_cg.analysis.picture import Phase
from balloon_cg.app.progress import ON_TERMINAL, Display, PhaseBars


class Terminal(io.StringIO):
    def isatty(self):
        return True


def screen(written: str) -> list[str]:
    """The lines a terminal shows after ``written`` (carriage return, newline, cursor up), right-stripped."""
    lines, row, col = [""], 0, 0
    for token in re.split(r"(\r|\n|\x1b\[A)", written):
        if token == "\r":
            col = 0
        elif token == "\n":
            row, col = row + 1, 0
            lines += [""] * (row + 1 - len(lines))
        elif token == "\x1b[A":
            row = max(0, row - 1)
        elif token:
            line = lines[row].ljust(col)
            lines[row], col = line[:col] + token + line[col + len(token):], col + len(token)
    return [line.rstrip() for line in lines if line.strip()]


def test_overlapping_phases_end_in_clean_lines(monkeypatch):
    terminal = Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    with PhaseBars("spom1", ON_TERMINAL) as bars:
        for _ in range(1000):
            bars.tick(Phase.STABILITY)  # a long bar first, then a shorter one below it, finished first
        for _ in range(3):
            bars.tick(Phase.PEAR)
        bars.finish(Phase.PEAR, 3)
        bars.finish(Phase.STABILITY, 1000)
        bars.tick(Phase.PRIMARY)  # an unfinished phase (an interrupt) gets its line at the end
    assert screen(terminal.getvalue()) == ["spom1: pear branches: 3 points [00:00]",
                                           "spom1: stability: 1000 points [00:00]",
                                           "spom1: primary branch: 1 points [00:00]"]


def test_no_bars_into_a_pipe(monkeypatch):
    pipe = io.StringIO()
    monkeypatch.setattr("sys.stderr", pipe)
    with PhaseBars("spom1", ON_TERMINAL) as bars:
        bars.tick(Phase.PRIMARY)
        bars.finish(Phase.PRIMARY, 1)
    assert pipe.getvalue() == ""


def test_progress_asked_for_where_bars_garble_is_the_finished_lines(monkeypatch):
    """progress=True into a stream that is no terminal (a log file; a notebook without ipywidgets, whose kernel is
    tested in test_api_notebook.py): no live bar, no carriage return or cursor code, a line per finished phase
    (the unfinished one at the end too), in the order they finish."""
    log = io.StringIO()
    monkeypatch.setattr("sys.stderr", log)
    with PhaseBars("spom1", True) as bars:
        assert bars.display == Display.LINES
        bars.expect(Phase.STABILITY, 40)
        for _ in range(40):
            bars.tick(Phase.STABILITY)
        bars.tick(Phase.PEAR)
        bars.finish(Phase.STABILITY, 40)
        bars.tick(Phase.PEAR)
    assert log.getvalue() == "spom1: stability: 40 points [00:00]\nspom1: pear branches: 2 points [00:00]\n"


def test_a_phase_with_a_known_total_shows_its_fraction_and_eta(monkeypatch):
    terminal = Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    with PhaseBars("spom1", ON_TERMINAL) as bars:
        bars.expect(Phase.STABILITY, 40)
        assert re.search(r"stability:\s+0%\|.*\| 0/40 \[00:00<", terminal.getvalue())  # <: the time left
        bars.finish(Phase.STABILITY, 40)


def test_a_budgeted_trace_shows_a_total_and_gives_back_what_it_did_not_use(monkeypatch):
    """The non-axisymmetric branches (the longest phase): each trace's max_points are expected ahead, so its bar
    has a total and a time left while it runs; the budget a branch did not use is taken back when it ends, so the
    total is then the points traced. Its name is the one the run's timing stores (Step.SURFACE_BRANCHES)."""
    from balloon_cg.analysis.timing import Step

    terminal = Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    assert Phase.SURFACE.value == Step.SURFACE_BRANCHES.value == "non-axisymmetric branches"
    with PhaseBars("spom1", ON_TERMINAL) as bars:
        with bars.budget(Phase.SURFACE, 300) as tick:
            for _ in range(5):
                tick(None)
            bar = bars.bars[Phase.SURFACE]
            assert bar.total == 300 and bar.n == 5
            assert re.search(r"non-axisymmetric branches:\s+0%\|.*\| 0/300 \[00:00<", terminal.getvalue())
        assert bar.total == 5
        with bars.budget(Phase.SURFACE, 300) as tick:
            tick(None)
        assert bar.total == bar.n == 6
        bars.finish(Phase.SURFACE, 6)
