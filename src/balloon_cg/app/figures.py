"""The paper's figures from the command line: ``balloon-cg figure NAME -o FILE`` and ``make paper``
(``balloon-cg figure all -o FOLDER``), docs/paper.md.

Each figure's runs (post.paper: shipped scenes with overrides) are computed with ``analyse`` (the whole
picture) and kept as run files in a runs folder, ``<name of the scene>.h5``; a run file there is reused when
the scene it was computed for (its normalised TOML) is the one asked for and it was not interrupted (a signal
stopped it: recomputed, said on stderr), and recomputed otherwise.
Figures are drawn and saved in the journal style (post.style): no global matplotlib state changes.
"""
import sys
from pathlib import Path

from ..io.output import IMAGE_FORMATS, check_output, replacing
from ..io.run_file import read_run, stored_scene
from ..post.fit import MAX_WIDTH, MIN_WIDTH
from ..post.paper import TWO_COLUMNS, draw_figure, figures
from ..post.plotting import Reading
from .api import analyse
from .progress import shown

ALL_FOLDER = "paper-figures"  # figure all's default output folder (the Makefile's PAPER_OUT)


class FigureError(ValueError):
    """Bad input to ``figure``: an unknown figure name, image suffix or width (exit code 2)."""


def run_path(scene, runs: Path, quick: bool = False) -> Path:
    """Where the run of ``scene`` is kept: ``runs``/<scene name>.h5 (``_quick`` before the suffix for reduced
    runs)."""
    return Path(runs) / f"{scene.name}{'_quick' * quick}.h5"


def incomplete_runs(names, runs: Path, quick: bool = False) -> list[Path]:
    """The run files of the figures ``names`` in ``runs`` that are flagged incomplete."""
    cases = dict.fromkeys(case for name in names for case in figures(quick)[name].cases)
    paths = [run_path(case.load(quick), runs, quick) for case in cases]
    return [path for path in paths if not read_run(path)["attrs"].get("complete", False)]


def run_for(case, runs: Path, quick: bool = False, progress: bool = False) -> dict:
    """The run of ``case`` (read_run() output): the file in ``runs`` if it holds this scene and was not
    interrupted, else computed and written there (incomplete or not: ``incomplete_runs``; an interrupted one is
    recomputed, saying so on stderr); KeyboardInterrupt after writing a run a signal stopped (the CLI exits
    130)."""
    scene = case.load(quick)
    path = run_path(scene, runs, quick)
    run = read_run(path) if path.exists() else None
    interrupted = run is not None and "interrupted" in list(run["attrs"].get("incomplete_gaps", []))
    if interrupted:
        print(f"balloon-cg: {path}: the run kept there was interrupted; computing it again", file=sys.stderr)
    stale = run is None or stored_scene(run).to_toml() != scene.to_toml()
    if stale or interrupted:
        runs.mkdir(parents=True, exist_ok=True)
        result = analyse(scene, progress=progress)
        result.save(path, force=True)
        if result.interrupted:  # the partial run is kept (flagged); no further run or figure is started
            raise KeyboardInterrupt
        run = read_run(path)
    return run


def make_figure(name: str, output, runs=None, width: float = TWO_COLUMNS, reading: Reading = Reading.PRESSURE,
                quick: bool = False, progress: bool = False, force: bool = False) -> Path:
    """Draw the paper's figure ``name`` (post.paper.figures) into the image ``output`` (IMAGE_FORMATS),
    ``width`` inches wide; runs kept in ``runs`` (default: a folder ``runs`` next to the image). An existing
    ``output`` is replaced only with ``force`` (io.output), checked before any run is computed."""
    catalogue = figures(quick)
    if name not in catalogue:
        raise FigureError(f"figure {name!r}: not a figure of the paper (choose one of {', '.join(catalogue)}, or all)")
    output = Path(output)
    if output.suffix.lower() not in IMAGE_FORMATS:
        raise FigureError(f"--output {output}: the suffix must be one of {', '.join(IMAGE_FORMATS)}")
    if not MIN_WIDTH <= width <= MAX_WIDTH:
        raise FigureError(f"--width {width:g}: must be in [{MIN_WIDTH:g}, {MAX_WIDTH:g}] inches (3.5 one column, "
                          "7.2 two)")
    figure = catalogue[name]
    runs = output.parent / "runs" if runs is None else Path(runs)
    output.parent.mkdir(parents=True, exist_ok=True)
    check_output(output, force)
    loaded = [run_for(case, runs, quick, progress) for case in figure.cases]
    with replacing(output, force) as tmp:
        draw_figure(figure, loaded, width, reading).savefig(tmp, format=output.suffix.lower()[1:])
    return output


def make_all(folder, runs=None, width: float = TWO_COLUMNS, reading: Reading = Reading.PRESSURE,
             quick: bool = False, suffix: str = ".pdf", progress: bool = False, force: bool = False) -> list[Path]:
    """Every figure of the paper into ``folder`` as ``<name><suffix>``; the runs shared through ``runs``
    (default: ``folder``/runs)."""
    folder = Path(folder)
    runs = folder / "runs" if runs is None else runs
    folder.mkdir(parents=True, exist_ok=True)
    for name in figures(quick):  # every image checked before the first run is computed
        check_output(folder / f"{name}{suffix}", force)
    return [make_figure(name, folder / f"{name}{suffix}", runs, width, reading, quick, progress, force)
            for name in figures(quick)]


def command(args) -> int:
    """``balloon-cg figure NAME|all [-o FILE|FOLDER] [--width IN] [--stability READING] [--runs FOLDER] [--quick]
    [--allow-partial]``: prints the image paths. Exit 1 when a run drawn is incomplete (the figures are still
    written; ``--allow-partial``: 0), as for ``run``."""
    reading = Reading.parse(args.stability)
    progress = shown(args.quiet)
    if args.output is None:
        args.output = ALL_FOLDER if args.name == "all" else f"{args.name}.pdf"
    if args.name == "all":
        names = list(figures(args.quick))
        paths = make_all(args.output, args.runs, args.width, reading, args.quick, progress=progress, force=args.force)
        runs = Path(args.output) / "runs" if args.runs is None else Path(args.runs)
    else:
        names = [args.name]
        paths = [make_figure(args.name, args.output, args.runs, args.width, reading, args.quick, progress, args.force)]
        runs = Path(args.output).parent / "runs" if args.runs is None else Path(args.runs)
    for path in paths:
        print(path)
    partial = incomplete_runs(names, runs, args.quick)
    if partial:
        print(f"balloon-cg: incomplete runs drawn: {', '.join(map(str, partial))}", file=sys.stderr)
    return 1 if partial and not args.allow_partial else 0
