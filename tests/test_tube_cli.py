"""Tubes from the command line: ``balloon-cg run`` on a tube scene writes a tube run file (io/tube_file.py) holding
what tube/picture.py computes, ``inspect`` shows it, ``plot`` draws P against V/V0 with Maxwell's line and the
bulge's profiles; bad requests exit 2 with one line and leave no file."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.app.cli import main
from balloon_cg.io.tube_file import read_tube_run
from balloon_cg.model import tube
from balloon_cg.scene import load_scene
from balloon_cg.tube.picture import tube_picture
from documented import inspect_json_keys
from shared_pictures import TUBE_COIL_FAST as COIL_FAST, TUBE_FAST as FAST, shared_file, tube_critical_file, tube_run_file

SCENE = Path(__file__).resolve().parents[1] / "scenes" / "tube_spom1_L10.toml"


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    """`balloon-cg run` of SCENE at FAST, written once per session (tests/shared_pictures.py)."""
    return tube_run_file(tmp_path_factory)


BULGED = ["--set", "solver.degree=16", "--set", "continuation.stop_stretch=6"]  # FAST with a front (~5 s of CPU)


@pytest.fixture(scope="module")
def bulged_file(tmp_path_factory):
    """`balloon-cg run` of SCENE at BULGED: FAST's bulge stops at a hoop stretch of 3, before its profile has a front
    (post/tube_measures.front); to 6 it has one over its last points."""
    return shared_file(tmp_path_factory, "tube_bulged.h5",
                       lambda path: main(["run", str(SCENE), "-o", str(path), "--quiet", *BULGED]) == 0)


@pytest.fixture(scope="module")
def laid_out(bulged_file, tmp_path_factory):
    """``laid_out(kind, width)``: the tube figure of ``kind`` (post/tube_plots.TUBE_KINDS; "onset" from the session's
    ``critical`` file, the others from ``bulged_file``) at ``width`` inches, laid out (``draw_without_rendering``)
    once and read by every test of this module that asks (the fit tests only measure it)."""
    from balloon_cg.post.tube_plots import tube_figure

    run, critical = read_tube_run(bulged_file), read_tube_run(tube_critical_file(tmp_path_factory))
    figures = {}

    def draw(kind: str, width: float):
        if (kind, width) not in figures:
            fig = tube_figure(critical if kind == "onset" else run, kind, width=width)
            fig.draw_without_rendering()
            figures[kind, width] = fig
        return figures[kind, width]

    return draw


def test_run_writes_what_the_tube_pipeline_computes(run_file):
    """The file holds the primary and the bulge branch of tube_picture at the same settings, number for number;
    the shape and its parameters as attributes; Maxwell's pressure model/tube's."""
    scene = load_scene(SCENE).with_overrides({"solver.degree": 16, "continuation.stop_stretch": 3})
    picture = tube_picture(scene)
    run = read_tube_run(run_file)
    a = run["attrs"]
    assert (a["shape"], a["length"], a["ends"], a["degree"]) == ("tube", 10.0, "sliding", 16)
    assert math.isnan(a["axial_stretch"]) and a["format"] == "balloon-cg-tube/1"
    assert a["maxwell_pressure"] == tube.maxwell_pressure(scene.material)[0]
    assert set(run["branches"]) == set(picture.branches) == {"primary", "bulge", "bulge_2", "bulge_3", "bulge_4",
                                                              "bulge_5"}  # every branch point of labels 1..5
    for name, branch in picture.branches.items():
        stored = run["branches"][name]
        assert np.array_equal(stored["unknowns"], branch.states) and np.array_equal(stored["pressure"], branch.pressure)
        assert np.array_equal(stored["volume"], branch.volume)
        assert np.array_equal(stored["unstable_volume"], branch.unstable["volume"])
        assert [s["kind"] for s in stored["special_points"]] == [s.kind.value for s in branch.special]
        assert [s["pressure"] for s in stored["special_points"]] == [s.pressure for s in branch.special]
        assert stored["attrs"]["stop_code"] == branch.stop.code.value
        assert np.array_equal(stored["smallest_stress"], branch.smallest_stress)
        modes = picture.modes[name]  # the m = 1 block (stability.m_max = 1: the default)
        assert set(stored["azimuthal"]) == {1} and np.array_equal(stored["azimuthal"][1]["lowest"], modes.lowest[1])
        assert np.array_equal(stored["azimuthal"][1]["unstable"], modes.unstable[1])
        assert [(p["index"], p["pressure"]) for p in stored["azimuthal"][1]["points"]] == \
            [(c.index, c.pressure) for c in modes.crossings]
        assert branch.smallest_stress.min() > -1e-8  # a closed sliding tube stays taut (no point flagged)
    kinds = [(s["kind"], s["block"]) for s in run["branches"]["primary"]["special_points"]]
    assert kinds[:2] == [("LP", ""), ("BP", "odd")] and ("LV", "") in [(s["kind"], s["block"]) for s in
                                                                        run["branches"]["bulge"]["special_points"]]


def test_inspect_names_the_shape_and_its_points(run_file, capsys):
    assert main(["inspect", str(run_file)]) == 0
    text = capsys.readouterr().out
    assert "tube of length 10, sliding ends, end distance free (closed)" in text
    assert "Maxwell        P_M = 0.445022155" in text and "branch bulge (from label 1 of primary):" in text
    assert " LV " in text and "branch bulge_4 (from label 4 of primary):" in text
    assert "m = 0 (pressure, volume and gas control); m = 1 (the same under all three" in text and "  m = 1: lowest" in text
    assert main(["inspect", str(run_file), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["kind"] == "tube" and set(summary) == inspect_json_keys("tube run file")  # docs/hdf5.md's keys
    assert summary["geometry"] == {"shape": "tube", "length": 10.0, "ends": "sliding", "axial_stretch": None}
    assert summary["branches"]["primary"]["special_points"][0]["kind"] == "LP"


def test_plot_draws_every_tube_kind(bulged_file, tmp_path, capsys):
    out = tmp_path / "t.png"
    kinds = ("pressure-volume", "profiles", "front", "stretches", "modes")
    assert main(["plot", str(bulged_file), "--what", ",".join(kinds), "-o", str(out)]) == 0
    for kind in kinds:
        assert (tmp_path / f"t_{kind}.png").stat().st_size > 10_000
    assert main(["plot", str(bulged_file), "--what", "shapes", "-o", str(tmp_path / "s.png")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].endswith("--what shapes: not drawn for a tube run file; allowed: " + ", ".join((*kinds, "onset")))
    assert not (tmp_path / "s.png").exists()
    assert main(["plot", str(bulged_file), "--what", "front", "--branch", "primary", "-o", str(tmp_path / "f.png")]) == 2
    assert capsys.readouterr().err.strip().endswith("--what front: the primary branch's profiles have no front at the "
                                                     "points drawn (uniform, a bump, or no part as long as the front "
                                                     "is wide)")
    assert not (tmp_path / "f.png").exists()
    assert main(["plot", str(bulged_file), "--what", "profiles", "--width", "0.2", "-o", str(tmp_path / "w.png")]) == 2
    assert capsys.readouterr().err.strip().endswith("--width 0.2: must be in [1, 40] inches (3.5 one column, 7.2 two)")
    assert not (tmp_path / "w.png").exists()


def test_modes_plot_draws_the_stored_critical_modes(run_file):
    """``plot --what modes`` of the bulge branch: R, T, Z of each located m ≥ 1 zero's stored critical mode, as
    tube/azimuthal.mode_profile evaluates it on the branch's own discretisation (1e-12), ½ ∫ (R² + T² + Z²) dS = 1 (1e-4, the trapezoid on the drawn
    points); the primary branch (no m ≥ 1 zero) has none: one line."""
    from balloon_cg.io.tube_file import discretisation
    from balloon_cg.post.tube_plots import TubePlotError, tube_figure
    from balloon_cg.tube.azimuthal import mode_profile

    run = read_tube_run(run_file)
    (point,) = run["branches"]["bulge"]["azimuthal"][1]["points"]
    lines = tube_figure(run, "modes").axes[0].get_lines()
    assert len(lines) == 3
    s = lines[0].get_xdata()
    expected = mode_profile(discretisation(run["attrs"], run["branches"]["bulge"]["attrs"]), point["mode"], s)
    for line, values in zip(lines, expected):
        assert np.max(np.abs(line.get_ydata() - values)) <= 1e-12
    squared = sum(np.asarray(v) ** 2 for v in expected)
    assert abs(0.5 * np.sum((squared[1:] + squared[:-1]) / 2 * np.diff(s)) - 1) <= 1e-4
    with pytest.raises(TubePlotError, match="the primary branch has no located m ≥ 1 zero with a stored mode"):
        tube_figure(run, "modes", branch="primary")


def test_stretches_of_the_uniform_tube_are_its_radius_and_its_length_ratio(run_file):
    """On the primary branch (the uniform closed tube) the drawn hoop stretch is the radius ρ and the axial stretch
    the deformed length over L, η(0) − η(L), both read from the profile (not from its derivative), at every sample."""
    from balloon_cg.io.tube_file import discretisation
    from balloon_cg.post.tube_plots import tube_figure

    run = read_tube_run(run_file)
    fig = tube_figure(run, "stretches", branch="primary", points=[-1])
    hoop, axial = (line.get_ydata() for line in fig.axes[0].lines)
    disc, u = discretisation(run["attrs"]), run["branches"]["primary"]["unknowns"][-1]
    rho, eta = disc.profile(u, np.array([0.0, disc.length]))
    assert rho[0] > 1.5 and np.abs(hoop - rho[0]).max() < 1e-12
    assert np.abs(axial - (eta[0] - eta[1]) / disc.length).max() < 1e-12


def test_front_moves_away_from_the_bulge_as_it_widens(bulged_file):
    """The bulge forms at the tube's end S = 0 (sliding ends: half a bulge there); past its volume fold, once its
    profile has a front (post/tube_measures.front: before, the profile is the onset's cos(πS/L) turning into a
    localised bump), the front moves away along the axis as V/V0 grows: every drawn position rises, by more than 0.1
    radius here; the points with none are not drawn but shaded "no front" (they drew a spike of position and width
    near the onset, the volume hardly changing)."""
    from balloon_cg.post.tube_plots import tube_figure

    run = read_tube_run(bulged_file)
    b = run["branches"]["bulge"]
    fold = next(s for s in b["special_points"] if s["kind"] == "LV")
    after = np.arange(int(fold["index"]) + 1, len(b["volume"]))
    ax = tube_figure(run, "front", points=after).axes[0]
    position = ax.lines[0].get_ydata()
    moving = position[np.isfinite(position)]
    assert after.size > 5 and moving.size > 5 and np.all(np.diff(moving) > 0) and moving[-1] - moving[0] > 0.1
    assert np.isnan(position[0]) and "no front" in ax.get_legend_handles_labels()[1]
    everything = tube_figure(run, "front").axes
    width = everything[1].lines[0].get_ydata()
    assert np.nanmax(width) < 0.3 * run["attrs"]["length"]  # the onset's mode drew 2ℓ/π, 0.64 of the length


def test_no_front_shading_covers_only_the_points_without_one(bulged_file, monkeypatch):
    """Front-less points on both sides of points with a front (a front reaching an end, a V folding back, --points)
    are shaded each where they are: one band from the lowest to the highest of their V/V0 hid the fronts between."""
    import dataclasses

    from balloon_cg.post import tube_plots
    from balloon_cg.post.tube_plots import tube_figure

    run = read_tube_run(bulged_file)
    b = run["branches"]["bulge"]
    fold = next(s for s in b["special_points"] if s["kind"] == "LV")
    after = np.arange(int(fold["index"]) + 1, len(b["volume"]))
    measured = tube_plots.fronts

    def last_without(disc, states):  # the last point's front taken away: front-less points at both ends
        reference, deformed = measured(disc, states)
        return reference, deformed[:-1] + [dataclasses.replace(deformed[-1], position=np.nan, width=np.nan)]

    monkeypatch.setattr(tube_plots, "fronts", last_without)
    ax = tube_figure(run, "front", points=after).axes[0]
    position = ax.lines[0].get_ydata()
    volume = b["volume"][after]
    with_front = volume[np.isfinite(position)]
    assert np.isnan(position[0]) and np.isnan(position[-1]) and with_front.size > 5
    (band,) = [c for c in ax.collections if c.get_label() == "no front"]
    spans = [(p.vertices[:, 0].min(), p.vertices[:, 0].max()) for p in band.get_paths() if len(p.vertices)]
    assert len(spans) >= 2
    assert not any(lo < v < hi for v in with_front for lo, hi in spans)


def test_profiles_stretches_and_front_share_one_axis(bulged_file):
    """The profiles, the stretches and the front read one axial coordinate, z from the end S = 0, on the same side:
    at a bulge point the profile r(z) and the hoop stretch λ2(z) (= ρ on the tube) both start at z = 0 with ρ(0), the
    bulged end, and end at the deformed length with ρ(L) (the profile was drawn against the height η, the bulge on
    the right, and the stretches from the end S = 0, the bulge on the left); the front's drawn position is where the
    drawn profile crosses its mid level (1e-3: the profile's 401 samples), and no axis text names "the branch's
    end" (a branch's end is its last point)."""
    from balloon_cg.io.tube_file import discretisation
    from balloon_cg.post.tube_plots import tube_figure

    run = read_tube_run(bulged_file)
    i = len(run["branches"]["bulge"]["volume"]) - 1
    u = run["branches"]["bulge"]["unknowns"][i]
    disc = discretisation(run["attrs"], run["branches"]["bulge"]["attrs"])  # the branch's own: spectral elements
    rho, eta = disc.profile(u, np.array([0.0, run["attrs"]["length"]]))
    drawn = tube_figure(run, "profiles", points=[i]).axes[0].lines[0].get_xydata()
    hoop = tube_figure(run, "stretches", points=[i]).axes[0].lines[0].get_xydata()
    for line in (drawn, hoop):
        assert np.abs(line[0] - (0.0, rho[0])).max() < 1e-12 and rho[0] > 2 * rho[1]
        assert np.abs(line[-1] - (eta[0] - eta[1], rho[1])).max() < 1e-12
    front = tube_figure(run, "front", points=[i]).axes[0].lines[0].get_ydata()[0]
    middle = 0.5 * (drawn[:, 1].max() + drawn[:, 1].min())
    assert abs(np.interp(-middle, -drawn[:, 1], drawn[:, 0]) - front) < 1e-3
    for kind in ("profiles", "front", "stretches"):
        texts = [t.get_text() for ax in tube_figure(run, kind).axes for t in (ax.title, ax.xaxis.label, ax.yaxis.label)]
        assert not any("branch's end" in text for text in texts), (kind, texts)


@pytest.mark.parametrize("width", [3.5, 7.2])
def test_tube_figures_at_a_journal_width_keep_their_texts_apart(laid_out, width):
    """At one and two columns, every tube figure laid out at its width: the special points' labels clear of one
    another, of the title, the axis labels and the legend; a legend left inside its panel hides no curve, marker or
    label (post/fit.covers; P against V/V0 at 3.5 in had its legend over the primary branch); every legend entry and
    axis label writes V/V0 as the axis does, $V/V_0$, never a plain "V/V0"; no label box crosses a curve, Maxwell's
    line included (textalloc read its x, the Axes' fraction, as data: "6 BP odd" lay on it); the onset curve of a
    ``critical`` file likewise."""
    from matplotlib.path import Path as Segments

    from balloon_cg.post.fit import covers
    from balloon_cg.post.labels import GID
    from balloon_cg.post.tube_plots import TUBE_KINDS

    for kind in TUBE_KINDS:
        fig = laid_out(kind, width)
        legends = [*fig.legends, *(ax.get_legend() for ax in fig.axes if ax.get_legend() is not None)]
        for legend in (ax.get_legend() for ax in fig.axes if ax.get_legend() is not None):
            assert not covers(legend, legend.axes), (kind, width)
        texts = [t for ax in fig.axes for t in (ax.title, ax.xaxis.label, ax.yaxis.label) if t.get_text()]
        others = [t.get_window_extent() for t in texts] + [legend.get_window_extent() for legend in legends]
        labels = [t.get_window_extent() for ax in fig.axes for t in ax.texts if t.get_gid() == GID and t.get_text()]
        for k, box in enumerate(labels):
            assert not any(box.overlaps(other) for other in labels[k + 1:] + others), (kind, width)
        written = [t.get_text() for legend in legends for t in legend.get_texts()] + [t.get_text() for t in texts]
        assert not any("V/V0" in text for text in written), (kind, width, written)
        curves = [line for ax in fig.axes for line in ax.get_lines()
                  if line.get_gid() != GID and len(line.get_xdata()) > 1]
        for box in labels:
            for line in curves:
                xy = line.get_transform().transform(line.get_xydata())
                pieces = np.split(xy, np.flatnonzero(~np.isfinite(xy).all(axis=1)))
                assert not any(Segments(p[np.isfinite(p).all(axis=1)]).intersects_bbox(box, filled=False) for p in pieces
                               if np.isfinite(p).all(axis=1).sum() > 1), (kind, width, line.get_label())


def test_legend_follows_the_labels_of_the_branch_points(bulged_file):
    """The branches switched at labels 2..8 of the primary branch are named bulge_2..bulge_8 (``continue``'s labels:
    never renumbered); a file where one is bulge_10 (born at label 10) lists it after bulge_8 in the legend, not
    after bulge (the file's, alphabetical, order), while the labels stay the file's (tube_labels)."""
    from balloon_cg.io.tube_file import tube_labels
    from balloon_cg.post.tube_plots import tube_figure

    run = read_tube_run(bulged_file)
    moved = dict(run["branches"]["bulge_2"], attrs=dict(run["branches"]["bulge_2"]["attrs"], parent_label=10))
    branches = {name: b for name, b in run["branches"].items() if name != "bulge_2"} | {"bulge_10": moved}
    renamed = dict(run, branches=dict(sorted(branches.items())))
    maxwell = run["attrs"]["maxwell_pressure"]
    fig = tube_figure(renamed, "pressure-volume")
    legend = (fig.legends or [fig.axes[0].get_legend()])[0]
    entries = [t.get_text().replace("\n", " ") for t in legend.get_texts()]  # wrapped to the figure's width
    assert entries == ["primary", "bulge", "bulge_3", "bulge_4", "bulge_5", "bulge_8", "bulge_10",
                       f"Maxwell $P_M$ = {maxwell:.5g}"]
    assert [name for name, _, _ in tube_labels(renamed)][:3] == ["primary"] * 3


def test_pressure_volume_figure_has_the_maxwell_line(run_file):
    from balloon_cg.post.tube_plots import tube_figure

    run = read_tube_run(run_file)
    fig = tube_figure(run, "pressure-volume")
    maxwell = [line for line in fig.axes[0].lines if line.get_linestyle() == ":"]
    assert len(maxwell) == 1 and maxwell[0].get_ydata()[0] == run["attrs"]["maxwell_pressure"]


def test_tube_figures_keep_their_text_inside_and_label_the_points_by_their_continue_labels(bulged_file, laid_out):
    """At the default width every title and axis label of every tube figure lies inside the figure (the stretches'
    title ran past both edges; the onset curve's of a ``critical`` file, the run's having none); on P against V/V0 every located point is marked and its label is the number
    ``inspect`` lists and ``continue`` takes with its kind ("1 BP odd"), the labels clear of one another (they were
    drawn over one another, without numbers, where branch points crowd the pressure maximum)."""
    import inspect

    from balloon_cg.io.tube_file import tube_labels
    from balloon_cg.post.labels import GID
    from balloon_cg.post.tube_plots import TUBE_KINDS, tube_figure

    default = inspect.signature(tube_figure).parameters["width"].default  # the figures the journal test reads at it
    run = read_tube_run(bulged_file)
    for kind in TUBE_KINDS:
        fig = laid_out(kind, default)
        box = fig.bbox
        for ax in fig.axes:
            for text in (ax.title, ax.xaxis.label, ax.yaxis.label):
                extent = text.get_window_extent()
                assert box.x0 - 0.5 <= extent.x0 and extent.x1 <= box.x1 + 0.5, (kind, text.get_text())
                assert box.y0 - 0.5 <= extent.y0 and extent.y1 <= box.y1 + 0.5, (kind, text.get_text())
    fig = laid_out("pressure-volume", default)
    labels = [t for t in fig.axes[0].texts if t.get_gid() == GID and t.get_text()]
    located = tube_labels(run)
    markers = [line for line in fig.axes[0].lines if len(line.get_xdata()) == 1]
    assert len(markers) == len(located) and len(labels) >= 3
    for text in (t.get_text() for t in labels):  # a crowded plot drops a label with no free place (post/labels.py)
        numbers, kind = text.split(maxsplit=1)
        for n in map(int, numbers.split(",")):
            assert kind == " ".join(filter(None, (located[n][2]["kind"], located[n][2]["block"]))), text
    extents = [t.get_window_extent() for t in labels]
    for i, a in enumerate(extents):
        assert not any(a.overlaps(b) for b in extents[i + 1:]), labels[i].get_text()


def test_an_existing_file_is_kept_without_force(run_file, capsys):
    before = run_file.read_bytes()
    assert main(["run", str(SCENE), "-o", str(run_file), "--quiet", *FAST]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1 and run_file.read_bytes() == before


COIL_SCENE = SCENE.with_name("tube_spom1_L10_coil.toml")


def test_critical_follows_the_onset_in_the_field_of_a_coil(tmp_path, capsys):
    """``critical --parameter M`` on the coil scene: the onset curve of tube/onset.py in the file's /onset group
    (the same numbers), the fold in M printed, exit 1 with one line on stderr (its state not resolved at degree 30:
    tail 3.1e-3 above solver.max_error 1e-9; docs/tubes.md's convergence table: M_c off by 6.5e-4 relative there);
    ``inspect`` shows the field, the curve and the crests; downwards it lands on M = 0 (no fold: exit 1, the file
    written); other kinds and parameters exit 2."""
    from balloon_cg.galerkin.interval import Mirror
    from balloon_cg.tube.onset import onset_curve
    from balloon_cg.tube.primary import primary_branch

    path = tmp_path / "onset.h5"
    assert main(["critical", str(COIL_SCENE), "--parameter", "M", "-o", str(path), "--quiet", *COIL_FAST]) == 1
    out, err = capsys.readouterr()
    assert err.count("\n") == 1 and "the fold's state is not resolved at solver.degree = 30: its Legendre tail" in err
    scene = load_scene(COIL_SCENE).with_overrides({"continuation.stop_stretch": 1.75, "continuation.max_points": 60})
    primary = primary_branch(scene)
    curve = onset_curve(scene, primary, primary.branch_points(Mirror.ODD)[0], "M")
    stored = read_tube_run(path)["onset"]
    assert np.array_equal(stored["q"], curve.q) and np.array_equal(stored["pressure"], curve.pressure)
    assert np.array_equal(stored["unknowns"], curve.states) and stored["attrs"]["parameter"] == "M"
    assert out.startswith(f"critical M = {curve.fold_q[0]:.12g} (P = ")
    assert np.abs(stored["crest_height"][:-1]).max() < 1e-6  # the crest at the coil, on the primary branch's states
    assert main(["inspect", str(path)]) == 0
    text = capsys.readouterr().out
    assert "field          1 coil(s), M = 0.01" in text and "onset in M (from M = 0.01)" in text
    assert "fold in M at M = " in text and "crest at" in text
    down = tmp_path / "down.h5"
    assert main(["critical", str(COIL_SCENE), "--parameter", "M", "--direction", "-1", "-o", str(down), "--quiet",
                 *COIL_FAST]) == 1
    err = capsys.readouterr().err
    assert "no critical M: the onset curve does not turn back in M" in err
    assert "traced down from M = 0.01 only, as every critical curve: --direction 1 traces the other side" in err
    assert read_tube_run(down)["onset"]["q"][-1] == 0.0
    for extra in (["--parameter", "M", "--of", "LP"], ["--parameter", "chi"]):
        assert main(["critical", str(COIL_SCENE), "-o", str(tmp_path / "x.h5"), "--quiet", *extra]) == 2
        assert "critical on a tube follows the onset of bulging (--of BP) in M" in capsys.readouterr().err
    assert not (tmp_path / "x.h5").exists()


TRIAL_COIL = """[material]
preset = "SPOM1"
[geometry]
shape = "tube"
length = 8.0
ends = "sliding"
[field]
M = 0.0005
[[field.coils]]
radius = 2.0
height = 0.0
current = 1.0
[solver]
degree = 30
[continuation]
stop_stretch = 4.0
step_max = 0.5
max_points = 150
"""


def test_critical_reports_the_first_fold_of_the_onset_curve_and_exit_1_where_it_is_unresolved(tmp_path, capsys):
    """Issue 38's trial: L = 8, a coil of radius 2, from M = 0.0005 upwards. The onset curve turns back at M = 0.00175,
    touches M ≈ 0 (a fold: the field-free middle bulge) and turns again at 0.00436; the critical field is the first
    turning point (before: the largest fold, 0.00436, exit 0). A second method: the primary branch traced at fixed M
    has an odd branch point near the fold's pressure 1 % below the first fold, none 1 % above it. Its state's tail
    (7.8e-3) is above solver.max_error: exit 1, the value printed and the file written."""
    from balloon_cg.galerkin.interval import Mirror
    from balloon_cg.tube.primary import primary_branch

    scene_path, path = tmp_path / "trial_coil.toml", tmp_path / "trial.h5"
    scene_path.write_text(TRIAL_COIL)
    assert main(["critical", str(scene_path), "--parameter", "M", "-o", str(path), "--quiet"]) == 1
    out, err = capsys.readouterr()
    folds = read_tube_run(path)["onset"]["folds"]
    first = folds[0]["q"]
    assert len(folds) >= 2 and max(f["q"] for f in folds) > 2 * first  # the largest fold is a later one
    assert out.startswith(f"critical M = {first:.12g} (P = ") and "the fold's state is not resolved" in err
    assert folds[0]["tail"] > 1e-9
    scene = load_scene(scene_path)
    near = lambda M: [b for b in primary_branch(scene.with_overrides({"field.M": M})).branch_points(Mirror.ODD)  # noqa: E731
                      if abs(b.pressure - folds[0]["pressure"]) < 0.05]
    assert len(near(0.99 * first)) >= 1 and len(near(1.01 * first)) == 0
