"""The paper's figures (reduced: post.paper.QUICK, one M), the stability readings, and the journal conventions."""
import re
import warnings
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from matplotlib.figure import Figure

from balloon_cg import Scene
from balloon_cg.app import figures as app_figures
from balloon_cg.app.api import analyse
from balloon_cg.app.cli import main
from balloon_cg.app.figures import make_figure, run_for
from balloon_cg.analysis.picture import Curve, find_snaps
from balloon_cg.post.paper import (ONE_COLUMN, SNAP_READINGS, TWO_COLUMNS, Case, draw_figure, figures,
                                   numbered_configurations, snap_throughs)
from balloon_cg.post.plotting import Reading, load_branches, plot, robust_limits, stable_points

SCENES = Path(__file__).resolve().parent.parent / "scenes"
POLE = r"pole stretch $\lambda_2(0)$ (top)"
PRESSURE = r"pressure $P = \bar{P}R_0/(T_0\mu/2)$"
THETA = r"material coordinate $\theta$ (rad)"
EQUATOR_2 = r"equator stretch $\lambda_2(\pi/2)$ (circumferential)"
EQUATOR_1 = r"equator stretch $\lambda_1(\pi/2)$ (meridional)"
ENERGY = r"$\Delta\Pi = E(\Lambda) - E(u_s)$ (per $2\pi$)"
LABELS = {  # (x labels, y labels) the figure's axes must carry
    "fig2": ({POLE}, {PRESSURE}),
    "fig3": ({POLE}, {PRESSURE}), "fig6": ({POLE}, {PRESSURE}),
    "fig4": ({EQUATOR_2}, {PRESSURE}), "fig7": ({EQUATOR_2}, {PRESSURE}),
    "fig5": ({EQUATOR_1}, {PRESSURE}), "fig8": ({EQUATOR_1}, {PRESSURE}),
    "fig9": ({POLE, r"$\pm\rho/R_0$ (distance from the axis)", THETA},
             {PRESSURE, r"$\eta/R_0$ (height)", r"$\sigma_\theta$ / ($\mu$/2)", r"$\sigma_\phi$ / ($\mu$/2)"}),
    "fig11": ({THETA}, {r"$H_\theta$ / ($I/4\pi R_0$)", r"$H_\zeta$ / ($I/4\pi R_0$)"}),
    "fig12": ({THETA}, {r"Gaussian curvature $\kappa R_0^2$"}),
    "fig13": ({r"amplitude $\Lambda$ along the pear direction"}, {ENERGY}),
}
LABELS["fig10"] = LABELS["fig9"]
PANELS = {"fig2": 4, "fig3": 4, "fig4": 4, "fig5": 4, "fig6": 4, "fig7": 4, "fig8": 4, "fig9": 6, "fig10": 6,
          "fig11": 6, "fig12": 3, "fig13": 2}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The reduced runs of every figure, computed once into one runs folder."""
    folder = tmp_path_factory.mktemp("runs")
    catalogue = figures(quick=True)
    for figure in catalogue.values():
        for case in figure.cases:
            run_for(case, folder, quick=True)
    return folder


@pytest.fixture(scope="module")
def drawn(runs):
    """``drawn(name, width)``: the figure drawn from the reduced runs at ``width`` (its layout fitted, no warning
    allowed: one raised fails the first test to ask), drawn once and read by every test of this module that asks."""
    figures_drawn = {}

    def draw(name: str, width: float):
        if (name, width) not in figures_drawn:
            figure = figures(quick=True)[name]
            stored = [run_for(case, runs, quick=True) for case in figure.cases]
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                figures_drawn[name, width] = draw_figure(figure, stored, width)
        return figures_drawn[name, width]

    return draw


def test_every_paper_figure_is_listed():
    assert list(figures()) == [f"fig{n}" for n in range(2, 14)]
    assert set(LABELS) == set(figures(quick=True))


@pytest.mark.parametrize("name", list(LABELS))
def test_each_figure_is_written_with_its_labels(name, drawn, tmp_path):
    fig = drawn(name, TWO_COLUMNS)
    image = tmp_path / f"{name}.png"
    fig.savefig(image, dpi=60)
    assert image.read_bytes().startswith(b"\x89PNG")
    assert len(fig.axes) == PANELS[name]
    xlabels, ylabels = ({ax.get_xlabel() for ax in fig.axes}, {ax.get_ylabel() for ax in fig.axes})
    assert LABELS[name][0] <= xlabels and LABELS[name][1] <= ylabels
    assert fig.get_size_inches()[0] == pytest.approx(TWO_COLUMNS)
    titles = [ax.get_title(loc="left") for ax in fig.axes if ax.get_title(loc="left")]
    assert titles and all(t.startswith("(") for t in titles)  # panel letters


def test_figure_command_one_column(runs, tmp_path, capsys):
    """One column wide, the paper's reading; the paper style does not leak into matplotlib's global state."""
    output = tmp_path / "fig2.pdf"
    before = dict(matplotlib.rcParams)
    command = ["figure", "fig2", "-o", str(output), "--runs", str(runs), "--quick", "--quiet", "--width",
               str(ONE_COLUMN), "--stability", "axisymmetric"]
    assert main(command) == 1  # the reduced runs stop short: incomplete, named on stderr
    assert "incomplete runs drawn" in capsys.readouterr().err
    assert main(command + ["--allow-partial"]) == 2  # the figure exists: replaced only with --force
    assert "already exists" in capsys.readouterr().err
    assert main(command + ["--allow-partial", "--force"]) == 0
    assert output.read_bytes().startswith(b"%PDF") and str(output) in capsys.readouterr().out
    assert dict(matplotlib.rcParams) == before


def test_figure_command_bad_input(tmp_path, capsys):
    assert main(["figure", "fig99", "-o", str(tmp_path / "x.png"), "--quick"]) == 2
    assert "fig99" in capsys.readouterr().err
    assert main(["figure", "fig2", "-o", str(tmp_path / "x.txt"), "--quick"]) == 2
    assert main(["figure", "fig2", "-o", str(tmp_path / "x.png"), "--quick", "--stability", "mass"]) == 2
    assert "pressure, volume, free, free-volume, gas, free-gas, axisymmetric" in capsys.readouterr().err


def test_runs_are_reused_only_for_the_same_scene(runs, monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("recomputed a run that is in the runs folder")

    monkeypatch.setattr(app_figures, "analyse", refuse)
    case = figures(quick=True)["fig2"].cases[0]
    assert run_for(case, runs, quick=True)["scene_name"] == "spom1"
    changed = Case(case.scene, (("continuation.stop_stretch", 1.2),))
    with pytest.raises(AssertionError, match="recomputed"):
        run_for(changed, runs, quick=True)


def test_numbered_configurations_by_rule(runs):
    run = run_for(figures(quick=True)["fig9"].cases[0], runs, quick=True)
    numbered = numbered_configurations(run)
    primary = run["branches"]["primary"]
    assert numbered[1].branch == "primary" and numbered[3].index == len(primary["pressure"]) - 1
    if 2 in numbered:  # 1 and 2 at the same pressure, the middle of the pear branch's range
        pear = run["branches"][numbered[2].branch]["pressure"]
        middle = 0.5 * (pear.min() + pear.max())
        assert abs(primary["pressure"][numbered[1].index] - middle) <= np.ptp(primary["pressure"])


def test_snap_throughs_at_both_ends_of_a_stable_stretch_to_the_lowest_energy():
    """A stretch stable between points 2 and 4 ends at both (raising and lowering the control); each jumps to the
    stable interval of lowest energy that strictly brackets its control value, never to its mirror image."""
    a = Curve("pear_0", np.array([0.0, 1, 2, 3, 4, 5]), np.array([0, 0, 1, 1, 1, 0], dtype=bool), np.zeros(6))
    mirror = Curve("pear_0_mirror", a.control, a.stable, a.energy)
    low = Curve("primary", np.array([1.5, 4.5]), np.array([1, 1], dtype=bool), np.array([-1.0, -1.0]))
    high = Curve("other", np.array([1.5, 4.5]), np.array([1, 1], dtype=bool), np.array([5.0, 5.0]))
    snaps = [(s.from_branch, s.from_index, s.pressure, s.to_branch) for s in find_snaps([a, mirror, low, high])]
    assert snaps[:2] == [("pear_0", 2, 2.0, "primary"), ("pear_0", 4, 4.0, "primary")]
    assert ("pear_0_mirror", 2, 2.0, "primary") in snaps
    assert not any(s[0] != "pear_0" and s[3] == "pear_0" for s in snaps)  # the mirror is no target


def test_snap_throughs_from_stored_data_equal_the_analysis():
    """Under pressure control the search on a stored run (stored flags, energies from the stored unknowns) finds
    the snap-throughs the analysis stored (SPOM1, M = 0: the limit point, no stable target); under volume control
    the primary branch loses stability at the pitchfork P_cr1 instead (controls: volumes)."""
    scene = Scene.from_toml(SCENES / "spom1.toml").with_overrides({"continuation.stop_stretch": 2.0,
                                                                   "stability.m_max": 0})
    run = analyse(scene, pear=False).run
    stored = [(s["from_branch"], s["from_index"], s["to_branch"], s["to_index"]) for s in run["snap_throughs"]]
    found = [(s.from_branch, s.from_index, s.to_branch, s.to_index) for s in snap_throughs(run, Reading.PRESSURE)]
    assert found == stored and len(stored) == 1
    P = run["branches"]["primary"]["pressure"]
    between = lambda i, value: (P[i] - value) * (P[i + 1] - value) <= 0  # noqa: E731
    assert P[stored[0][1]] == pytest.approx(2.568464, abs=5e-3)  # the last stable point before the fold
    [fold] = [s for s in run["branches"]["primary"]["special_points"] if s["kind"] == "LP"]
    assert fold["status"] == "located" and P[stored[0][1]] < fold["pressure"]
    assert run["snap_throughs"][0]["pressure"] == snap_throughs(run, Reading.PRESSURE)[0].pressure == fold["pressure"]
    [volume] = snap_throughs(run, Reading.VOLUME)
    assert between(volume.from_index, 2.26473)  # P_cr1 lies between the last stable point and the next
    assert volume.pressure == pytest.approx(run["branches"]["primary"]["volume"][volume.from_index])
    assert [s.from_index for s in snap_throughs(run, Reading.AXISYMMETRIC)] == [stored[0][1]]
    # gas: SPOM1 is stable to uniform inflation under gas control everywhere ((Pλ³)′ > 0), so it too loses
    # stability at P_cr1; the control value is n = P V, and a run under gas control stores the same snap
    [gas] = snap_throughs(run, Reading.GAS)
    V = run["branches"]["primary"]["volume"]
    assert gas.from_index == volume.from_index and gas.pressure == pytest.approx(P[gas.from_index] * V[gas.from_index])
    gas_run = analyse(scene.with_overrides({"loading.control": "gas"}), pear=False).run
    assert [(s["from_branch"], s["from_index"], s["pressure"]) for s in gas_run["snap_throughs"]] == \
        [(gas.from_branch, gas.from_index, pytest.approx(gas.pressure))]


def _data(n, **blocks):
    return {"pressure": np.zeros(n), "stability": blocks}


def test_stability_readings():
    """Each reading is its stored flag; axisymmetric is every m = 0 block's lowest eigenvalue > 0 (an m = 1
    instability does not count in the paper's reading)."""
    even = np.array([[1.0, 2, 3], [1.0, 2, 3], [-1.0, 2, 3]])
    odd = np.array([[0.5, 2, 3], [-0.5, 2, 3], [0.5, 2, 3]])
    m1 = np.full((3, 3), -1.0)
    flags = {name: np.array([True, False, True]) for name in
             ("stable_pressure", "stable_volume", "stable_pressure_free", "stable_volume_free")}
    flags["stable_volume"] = np.array([False, False, True])
    data = _data(3, lowest_even=even, lowest_odd_held=odd, lowest_m1_held=m1, **flags)
    assert stable_points(data, Reading.AXISYMMETRIC).tolist() == [True, False, False]
    assert stable_points(data, Reading.VOLUME).tolist() == [False, False, True]
    general = _data(3, lowest_all_held=np.array([[1.0, 2, 3], [-1.0, 2, 3], [1.0, 2, 3]]))
    assert stable_points(general, Reading.AXISYMMETRIC).tolist() == [True, False, True]
    assert stable_points(_data(3), Reading.PRESSURE) is None


def test_plot_stability_reading_in_the_legend(runs):
    run = run_for(figures(quick=True)["fig2"].cases[0], runs, quick=True)
    for reading in Reading:
        fig = plot(run, "pressure-pole", stability=reading)
        assert reading.meaning in fig.legends[0].get_title().get_text()
        assert load_branches(run, reading=reading)[0].reading == reading


def test_mirror_branches_share_their_partners_colour(runs):
    run = run_for(figures(quick=True)["fig2"].cases[0], runs, quick=True)
    pear = run["branches"]["primary"]
    fake = run | {"branches": {"primary": pear, "pear_0": pear, "pear_0_mirror": pear, "pear_1": pear}}
    fig = plot(fake, "pressure-pole")
    handles = {t.get_text(): h for t, h in zip(fig.legends[0].get_texts(), fig.legends[0].legend_handles)}
    first, mirror, other = (handles[f"M = 0, {name}"] for name in ("pear 0", "pear 0 mirror", "pear 1"))  # no parents
    assert first.get_color() == mirror.get_color() != other.get_color()
    assert mirror.get_alpha() < 1 and mirror.get_linewidth() < first.get_linewidth()


def test_robust_limits_clip_a_spike_only():
    theta = np.linspace(0, np.pi, 721)
    smooth = np.sin(theta)
    ax = Figure().add_subplot()
    assert not robust_limits(ax, [smooth])
    spike = smooth + 1e3 * np.exp(-((theta - np.pi / 2) / 0.005) ** 2)
    assert robust_limits(ax, [spike])
    low, high = ax.get_ylim()
    assert low <= 0 and 1.0 < high < 10  # the bulk (0..1) fills the axes, the spike (1000) is clipped


def test_make_figure_output_folder_default(runs, tmp_path):
    path = make_figure("fig12", tmp_path / "out" / "fig12.svg", runs=runs, quick=True)
    assert path.read_text().lstrip().startswith("<?xml")


def test_one_column_uses_the_symbols(drawn):
    fig = drawn("fig2", ONE_COLUMN)
    assert {ax.get_xlabel() for ax in fig.axes} == {r"$\lambda_2(0)$"}
    assert {ax.get_ylabel() for ax in fig.axes} == {"$P$"}
    assert fig.get_size_inches()[0] == pytest.approx(ONE_COLUMN)


def test_an_interrupted_run_is_kept_and_stops_the_figures(tmp_path, monkeypatch):
    """SIGINT/SIGTERM during a figure's run: the partial run is written (flagged interrupted) and no further run
    starts (KeyboardInterrupt: the CLI exits 130)."""
    from balloon_cg.io.run_file import read_run
    from balloon_cg.numerics import interrupt

    def signalled(scene, **kwargs):
        interrupt.request()  # as the signal handler does, before the first point
        return analyse(scene, **kwargs)

    monkeypatch.setattr(app_figures, "analyse", signalled)
    case = figures(quick=True)["fig2"].cases[0]
    with pytest.raises(KeyboardInterrupt):
        run_for(case, tmp_path, quick=True)
    assert not interrupt.requested()
    (path,) = tmp_path.glob("*.h5")
    assert "interrupted" in list(read_run(path)["attrs"]["incomplete_gaps"])


def test_an_interrupted_run_is_computed_again_and_says_so(tmp_path, monkeypatch, capsys):
    """The next figure (``figure``, ``make paper``) recomputes a kept run that a signal stopped, saying so on
    stderr; the run it writes then is reused."""
    from balloon_cg.io.run_file import read_run
    from balloon_cg.numerics import interrupt

    calls = []

    def counted(scene, **kwargs):
        calls.append(scene.name)
        if len(calls) == 1:
            interrupt.request()
        return analyse(scene, **kwargs)

    monkeypatch.setattr(app_figures, "analyse", counted)
    case = figures(quick=True)["fig2"].cases[0]
    with pytest.raises(KeyboardInterrupt):
        run_for(case, tmp_path, quick=True)
    capsys.readouterr()
    run = run_for(case, tmp_path, quick=True)
    assert len(calls) == 2 and "interrupted" not in list(run["attrs"].get("incomplete_gaps", []))
    assert "was interrupted; computing it again" in capsys.readouterr().err
    run_for(case, tmp_path, quick=True)
    assert len(calls) == 2 and capsys.readouterr().err == ""
    assert read_run(next(tmp_path.glob("*.h5")))["scene_name"] == run["scene_name"]


INTERNAL_NAME = re.compile(r"pear_\d|_mirror|_rotated|_opposite|m\d+_bp\d")  # analysis.picture's branch names


@pytest.mark.parametrize("width", [ONE_COLUMN, TWO_COLUMNS])
def test_every_figure_keeps_its_text_inside_at_journal_widths(width, drawn, drawn_texts):
    """What ``figure all --width W --quick`` draws (the reduced runs): every text drawn (titles, tick and axis
    labels, legends, special-point labels) lies inside the figure, legends name branches readably, and no warning
    is raised, in the layout (``drawn``) or the drawing (a layout warning was printed three times at 3.5 in,
    issue 40)."""
    for name in figures(quick=True):
        fig = drawn(name, width)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            drawn_texts.clear()
            fig.canvas.draw()
        renderer, box = fig.canvas.get_renderer(), fig.bbox
        texts = [t for t in drawn_texts if t.get_visible() and t.get_text().strip()]
        assert texts
        for text in texts:
            extent = text.get_window_extent(renderer)
            assert (extent.x0 >= box.x0 - 0.5 and extent.x1 <= box.x1 + 0.5 and extent.y0 >= box.y0 - 0.5
                    and extent.y1 <= box.y1 + 0.5), f"{name} at {width} in: {text.get_text()!r} is cut off"
        legends = [*fig.legends, *(ax.get_legend() for ax in fig.axes if ax.get_legend())]
        assert not [t.get_text() for legend in legends for t in legend.get_texts()
                    if INTERNAL_NAME.search(t.get_text())]


def test_figure_pdfs_embed_truetype_fonts_only(runs, drawn, tmp_path, capsys, monkeypatch):
    """``figure all`` into PDFs and one figure into EPS: the fonts are embedded as TrueType (Type 42), never as
    Type 3 (which many journals reject); TIFF is written too. The command saves the figures ``drawn`` drew from the
    same runs at the same width (``draw_figure`` with the command's arguments: the laying out is checked there, the
    saving here), not drawn a second time."""
    def shared(figure, loaded, width, reading):
        assert reading == Reading.PRESSURE and [run["scene_name"] for run in loaded] == [
            case.load(quick=True).name for case in figure.cases]
        return drawn(figure.name, width)

    monkeypatch.setattr(app_figures, "draw_figure", shared)
    folder = tmp_path / "figures"
    assert main(["figure", "all", "-o", str(folder), "--runs", str(runs), "--quick", "--quiet", "--width",
                 str(ONE_COLUMN), "--allow-partial"]) == 0
    pdfs = sorted(folder.glob("*.pdf"))
    assert len(pdfs) == len(figures(quick=True))
    for pdf in pdfs:
        data = pdf.read_bytes()
        assert b"/Type3" not in data and b"/FontFile2" in data, pdf.name  # FontFile2: an embedded TrueType font
    for suffix, magic in ((".eps", b"%!PS-Adobe"), (".tiff", b"II*\x00")):
        image = tmp_path / f"fig2{suffix}"
        assert main(["figure", "fig2", "-o", str(image), "--runs", str(runs), "--quick", "--quiet",
                     "--allow-partial"]) == 0
        assert image.read_bytes().startswith(magic)
    eps = (tmp_path / "fig2.eps").read_bytes()
    assert b"FontType 3" not in eps and b"/FontType 42" in eps
    capsys.readouterr()
