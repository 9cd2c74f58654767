"""Every ``plot --what`` kind at the journal widths (issue 40): drawn ``width`` inches wide (``plot --width``,
``bc.plot(..., width=)``), every text inside the figure, no text over another or over a legend, no warning."""
import warnings

import pytest

from balloon_cg.app.cli import main
from balloon_cg.post.plotting import KINDS, PlotError, plot
from balloon_cg.scene import load_scene
from test_surface_store import basis, primary, run_path, scene, surface_branch  # noqa: F401 (fixtures)
from test_voltage_branches import voltage_file, voltage_picture  # noqa: F401 (fixtures)

WIDTHS = (3.5, 7.2)


@pytest.fixture(scope="module")
def sources(tmp_path_factory, run_path, voltage_file):  # noqa: F811
    """A file per kind: SPOM1 at M = 0 (its isola: special points, pear branches, normal forms, natural
    frequencies and mode shapes), two coils
    (primary only, for the field), the α1 curve of pitchforks (phase), a surface branch, a voltage run; and
    ``cusp``, the Gent fold curve in Jm to its cusp (phase of a fold curve only)."""
    folder = tmp_path_factory.mktemp("sizes")
    spom1, coils, curve = folder / "spom1.h5", folder / "coils.h5", folder / "curve.h5"
    scene = load_scene("spom1").with_overrides({"surface.branches": "none", "dynamics.frequencies": True,
                                                "dynamics.modes": True})
    (folder / "spom1.toml").write_text(scene.to_toml())
    assert main(["run", str(folder / "spom1.toml"), "-o", str(spom1), "--quiet"]) == 0
    assert main(["run", "spom1_two_coils_M0.002", "--stop-stretch", "1.6", "--primary-only", "-o", str(coils),
                 "--quiet"]) == 0
    assert main(["critical", str(folder / "spom1.toml"), "--parameter", "alpha1", "--stop-stretch", "3", "-o",
                 str(curve), "--quiet"]) == 0
    assert main(["critical", "spom1", "--set", "material.preset=Gent", "--of", "LP", "--parameter",
                 "material.parameters.Jm", "--direction", "-1", "-o", str(folder / "cusp.h5"), "--quiet"]) == 0
    files = {kind: spom1 for kind in KINDS} | {"field": coils, "phase": curve, "surface": run_path,
                                              "stretch-map": run_path}
    return files | {"voltage-pole": voltage_file, "voltage-equator": voltage_file, "cusp": folder / "cusp.h5"}


@pytest.mark.parametrize("width", WIDTHS)
@pytest.mark.parametrize("kind", [*KINDS, "cusp"])  # cusp: phase of a fold curve
def test_every_kind_fits_a_journal_width(kind, width, sources, drawn_texts):
    """Every text inside the figure, each annotation of an Axes inside that Axes, no formula broken by wrapping (each
    line's $ paired), no text over another or under a legend, every colour bar labelled, no warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = plot([sources[kind]], "phase" if kind == "cusp" else kind, width=width)
        drawn_texts.clear()
        fig.canvas.draw()
    assert tuple(fig.get_size_inches())[0] == pytest.approx(width)
    renderer, box = fig.canvas.get_renderer(), fig.bbox
    texts = [t for t in drawn_texts if t.get_visible() and t.get_text().strip()]
    extents = [t.get_window_extent(renderer) for t in texts]
    for text, extent in zip(texts, extents):
        assert (extent.x0 >= box.x0 - 0.5 and extent.x1 <= box.x1 + 0.5 and extent.y0 >= box.y0 - 0.5
                and extent.y1 <= box.y1 + 0.5), f"{kind} at {width} in: {text.get_text()!r} is cut off"
        lines = text.get_text().replace(r"\$", "").splitlines()
        assert all(line.count("$") % 2 == 0 for line in lines), f"{kind} at {width} in: {text.get_text()!r} broken"
    bars = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    assert len(bars) == 2 * (kind == "stretch-map")  # λ1 and λ2
    for ax in bars:  # every colour bar says what its colours are
        assert (ax.get_ylabel() or ax.get_xlabel()).strip(), f"{kind} at {width} in: a colour bar without label"
    for ax in fig.axes:
        frame = ax.get_window_extent(renderer)
        for text in (t for t in ax.texts if t in texts):
            extent = text.get_window_extent(renderer)
            assert (extent.x0 >= frame.x0 - 0.5 and extent.x1 <= frame.x1 + 0.5 and extent.y0 >= frame.y0 - 0.5
                    and extent.y1 <= frame.y1 + 0.5), f"{kind} at {width} in: {text.get_text()!r} leaves its axes"
    for i, (a, box_a) in enumerate(zip(texts, extents)):
        for b, box_b in zip(texts[:i], extents[:i]):
            assert not box_a.overlaps(box_b), f"{kind} at {width} in: {a.get_text()!r} over {b.get_text()!r}"
    legends = [*fig.legends, *(ax.get_legend() for ax in fig.axes if ax.get_legend())]
    for legend in legends:
        frame, own = legend.get_window_extent(renderer), set(legend.get_texts()) | {legend.get_title()}
        for text, extent in zip(texts, extents):
            assert text in own or not frame.overlaps(extent), f"{kind} at {width} in: the legend covers {text!r}"
    import os
    if os.environ.get("SAVE_FIGS"):
        fig.savefig(f"{os.environ['SAVE_FIGS']}/{kind}_{width}.png")


def test_a_width_is_for_a_new_figure_only(sources):
    """``bc.plot(..., width=)`` lays a new figure out at that width; the Axes given have their figure's size."""
    import matplotlib.figure

    import balloon_cg as bc

    assert tuple(bc.plot(sources["pressure-pole"], "pressure-pole", width=3.5).get_size_inches())[0] == 3.5
    ax = matplotlib.figure.Figure().add_subplot()
    with pytest.raises(PlotError, match="width: the figure of the Axes given has its own size"):
        bc.plot(sources["pressure-pole"], "pressure-pole", ax=ax, width=3.5)
    with pytest.raises(PlotError, match="width: the figure of the Axes given has its own size"):
        plot([sources["pressure-pole"]], "pressure-pole", axes=ax, width=3.5)
    with pytest.raises(PlotError, match=r"width 0.5: must be in \[1, 40\] inches"):
        plot([sources["pressure-pole"]], "pressure-pole", width=0.5)


def png_size(path) -> tuple[int, int]:
    """(width, height) in pixels from a PNG's IHDR chunk."""
    data = path.read_bytes()
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


def test_plot_width_and_dpi_from_the_command_line(sources, tmp_path, capsys):
    """`plot --width 3.5 --dpi 100`: a 350-pixel-wide PNG; without --dpi the journal style's 300 dpi; a width out of
    range is one line, exit 2."""
    out = tmp_path / "p.png"
    assert main(["plot", str(sources["pressure-pole"]), "--what", "pressure-pole", "--width", "3.5", "--dpi", "100",
                 "-o", str(out)]) == 0
    assert png_size(out)[0] == 350
    assert main(["plot", str(sources["pressure-pole"]), "--what", "pressure-pole", "--width", "3.5", "-o", str(out),
                 "--force"]) == 0
    assert png_size(out)[0] == 1050
    capsys.readouterr()
    assert main(["plot", str(sources["pressure-pole"]), "--what", "pressure-pole", "--width", "100", "-o",
                 str(tmp_path / "q.png")]) == 2
    assert "width 100: must be in [1, 40] inches" in capsys.readouterr().err


def test_a_fold_curves_phase_diagram_names_only_what_it_draws(sources):
    """The Gent fold curve in Jm to its cusp (issue 40: its title spoke of pitchforks, its cusp value was text beside
    the point that left the axes): title and y label name the fold, the cusp is in the legend, no text in the Axes."""
    fig = plot([sources["cusp"]], "phase")
    ax = fig.axes[0]
    assert "pitchfork" not in ax.get_title() + ax.get_ylabel() and "fold (LP)" in ax.get_title() + ax.get_ylabel()
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any(text.startswith("cusp Jm = 17.638") for text in legend) and not ax.texts
