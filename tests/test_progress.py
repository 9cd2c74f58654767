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
    """progress=True into a stream that is no terminal (a log file, a pipe): no live bar, no carriage return or
    cursor code, a line per finished phase (the unfinished one at the end too), in the order they finish."""
    log = io.StringIO()
    monkeypatch.setattr("sys.stderr", log)
    with PhaseBars("spom1", True) as bars:
        assert bars.display == Display.LINES
        overlapping(bars, 40)
    assert log.getvalue() == "spom1: stability: 40 points [00:00]\nspom1: pear branches: 41 points [00:00]\n"


def overlapping(bars, count: int, step=lambda: None) -> None:
    """Two overlapping phases: stability (40 points expected) and pear branches ticked in turn ``count`` times (then
    ``step()``), stability finished, pear branches ticked once more and left unfinished (its line at the end)."""
    bars.expect(Phase.STABILITY, 40)
    for _ in range(count):
        bars.tick(Phase.STABILITY)
        bars.tick(Phase.PEAR)
        step()
    bars.finish(Phase.STABILITY, count)
    bars.tick(Phase.PEAR)


class Outputs:
    """A notebook's outputs as IPython's ``display(..., display_id=True)`` makes them: each a list of the texts it
    showed, in turn (``update``)."""

    def __init__(self):
        self.shown = []

    def display(self, data, raw=False, display_id=False):
        assert raw and display_id and set(data) == {"text/plain"}
        texts = [data["text/plain"]]
        self.shown.append(texts)

        class Handle:
            def update(self, data, raw=False):
                assert raw and set(data) == {"text/plain"}
                texts.append(data["text/plain"])

        return Handle()


def test_a_notebook_without_ipywidgets_gets_a_text_bar_per_phase_replaced_by_its_line(monkeypatch):
    """A Jupyter kernel without ipywidgets (tqdm.auto's text bar there writes carriage returns and cursor moves to
    stderr, which garble stacked bars): one output per phase, tqdm's meter in it (its fraction where a total is
    known), updated in place at most every TEXT_INTERVAL, and at the end the finished line only, nothing on
    stderr; two overlapping phases each in their own output (the kernel in test_api_notebook.py)."""
    import IPython.display

    from balloon_cg.app import progress

    outputs, stderr, clock = Outputs(), io.StringIO(), [100.0]
    monkeypatch.setattr(IPython.display, "display", outputs.display)
    monkeypatch.setattr(progress, "jupyter_kernel", lambda: True)
    monkeypatch.setattr(progress.time, "monotonic", lambda: clock[0])
    monkeypatch.setattr("sys.stderr", stderr)
    with PhaseBars("spom1", True) as bars:
        assert bars.display == Display.TEXT
        overlapping(bars, 16, step=lambda: clock.append(clock.pop() + 0.125))  # 2 s: an update every 0.5 s
    stability, pear = outputs.shown
    assert re.fullmatch(r"spom1: stability:\s+0%\|.*\| 0/40 \[00:00<\?, \? points/s\]", stability[0])
    assert [re.search(r"\| (\d+)/40 \[00:0(\d)<", text).groups() for text in stability[1:-1]] == [
        ("5", "0"), ("9", "1"), ("13", "1")]  # at 0.5, 1 and 1.5 s: fraction, elapsed and time left
    assert stability[-1] == "spom1: stability: 16 points [00:02]" and pear[-1] == "spom1: pear branches: 17 points [00:02]"
    assert [re.fullmatch(r"spom1: pear branches: (\d+) points \[00:0\d, .*\]", text)[1] for text in pear[1:-1]] == [
        "5", "9", "13", "17"]  # no total: the count (the last tick at 2 s)
    assert not [t for texts in outputs.shown for t in texts if "\r" in t or "\x1b" in t or "\n" in t]
    assert stderr.getvalue() == ""


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
