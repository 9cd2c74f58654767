"""The paper's figures from the command line: ``balloon-cg figure NAME -o FILE`` and ``make paper``
(``balloon-cg figure all -o FOLDER``), docs/paper.md.

Each figure's runs (post.paper: shipped scenes with overrides) are computed with ``analyse`` (the whole
picture) and kept as run files in a runs folder, ``<name of the scene>.h5``; a run file there is reused when
the scene it was computed for (its normalised TOML) is the one asked for, and recomputed otherwise.
Figures are drawn and saved inside ``matplotlib.rc_context(PAPER_STYLE)``: no global matplotlib state changes.
"""
from pathlib import Path

import matplotlib

from ..io.run_file import read_run
from ..post.paper import PAPER_STYLE, TWO_COLUMNS, draw_figure, figures
from ..post.plotting import Reading
from ..scene import parse_scene
from .api import analyse

IMAGE_FORMATS = (".png", ".pdf", ".svg")


class FigureError(ValueError):
    """Bad input to ``figure``: an unknown figure name, image suffix or width (exit code 2)."""


def run_for(case, runs: Path, quick: bool = False, progress: bool = False) -> dict:
    """The run of ``case`` (read_run() output): the file in ``runs`` if it holds this scene, else computed and
    written there."""
    scene = case.load(quick)
    path = runs / f"{scene.name}{'_quick' * quick}.h5"
    if path.exists():
        run = read_run(path)
        if parse_scene(run["attrs"]["scene_toml"], scene.name).to_toml() == scene.to_toml():
            return run
    runs.mkdir(parents=True, exist_ok=True)
    analyse(scene, progress=progress).save(path, force=True)
    return read_run(path)


def make_figure(name: str, output, runs=None, width: float = TWO_COLUMNS, reading: Reading = Reading.PRESSURE,
                quick: bool = False, progress: bool = False) -> Path:
    """Draw the paper's figure ``name`` (post.paper.figures) into the image ``output`` (.png, .pdf or .svg),
    ``width`` inches wide; runs kept in ``runs`` (default: a folder ``runs`` next to the image)."""
    catalogue = figures(quick)
    if name not in catalogue:
        raise FigureError(f"figure {name!r}: not a figure of the paper (choose one of {', '.join(catalogue)}, or all)")
    output = Path(output)
    if output.suffix.lower() not in IMAGE_FORMATS:
        raise FigureError(f"--output {output}: the suffix must be one of {', '.join(IMAGE_FORMATS)}")
    if not width > 0:
        raise FigureError(f"--width {width}: must be > 0 inches (3.5 one column, 7.2 two)")
    figure = catalogue[name]
    runs = output.parent / "runs" if runs is None else Path(runs)
    loaded = [run_for(case, runs, quick, progress) for case in figure.cases]
    output.parent.mkdir(parents=True, exist_ok=True)
    with matplotlib.rc_context(PAPER_STYLE):
        draw_figure(figure, loaded, width, reading).savefig(output)
    return output


def make_all(folder, runs=None, width: float = TWO_COLUMNS, reading: Reading = Reading.PRESSURE,
             quick: bool = False, suffix: str = ".pdf", progress: bool = False) -> list[Path]:
    """Every figure of the paper into ``folder`` as ``<name><suffix>``; the runs shared through ``runs``
    (default: ``folder``/runs)."""
    folder = Path(folder)
    runs = folder / "runs" if runs is None else runs
    return [make_figure(name, folder / f"{name}{suffix}", runs, width, reading, quick, progress)
            for name in figures(quick)]


def command(args) -> int:
    """``balloon-cg figure NAME|all -o FILE|FOLDER [--width IN] [--stability READING] [--runs FOLDER] [--quick]``:
    prints the image paths."""
    reading = Reading.parse(args.stability)
    progress = not args.quiet
    if args.name == "all":
        paths = make_all(args.output, args.runs, args.width, reading, args.quick, progress=progress)
    else:
        paths = [make_figure(args.name, args.output, args.runs, args.width, reading, args.quick, progress)]
    for path in paths:
        print(path)
    return 0
