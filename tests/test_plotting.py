"""Figures, the plot subcommand and the default run (reduced with --quick)."""
import contextlib
import io
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from balloon_cg.app import default_run
from balloon_cg.app.cli import main
from balloon_cg.io.run_file import STABILITY_FLAGS, read_run
from balloon_cg.io.schema import describe
from balloon_cg.post.plotting import KINDS, PlotError, plot
from balloon_cg.post.quantities import postprocess
from shared_pictures import two_coil_result
from test_surface_store import basis, primary, run_path, scene, surface_branch  # noqa: F401 (fixtures)

SCENES = Path(__file__).resolve().parents[1] / "scenes"
PER_POINT_KINDS = ("shapes", "stresses", "field", "curvature")


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    """The default run with --quick: (output folder, printed text)."""
    out = tmp_path_factory.mktemp("default")
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert default_run.main([str(out), "--quick", "--quiet"]) == 0
    return out, printed.getvalue()


@pytest.fixture(scope="module")
def files(quick_run):
    out, _ = quick_run
    return {name: out / f"{name}.h5" for name in default_run.SCENES}


@pytest.fixture(scope="module")
def bifurcation_file(files, tmp_path_factory):
    """The two-coil file with what the stability analysis adds: a stability flag per point, a branch point
    with normal-form coefficients, and a second branch (here a copy of the primary one)."""
    path = tmp_path_factory.mktemp("bp") / "with_bp.h5"
    shutil.copy(files["spom1_two_coils_M0.002"], path)
    with h5py.File(path, "r+") as f:
        group = f["branches/primary"]
        n = group["pressure"].shape[0]
        if "stability" in group:
            del group["stability"]
        stable = group.create_dataset("stability/stable_pressure", data=np.arange(n) < n // 2, fletcher32=True)
        stable.dims[0].attach_scale(group["point"])  # as the writer lays it out (io.run_file, checked on reading)
        describe(stable)
        stable.attrs["meaning"] = STABILITY_FLAGS["stable_pressure"]
        group["stability"].attrs["unsettled_points"] = np.zeros(0, dtype=np.int64)
        group.attrs["assessed"] = True
        special = group["special_points"]
        special["kind"][1] = "BP"
        special["classification"][1] = "pitchfork-super"
        for name, value in (("E2", -0.02), ("E3", 0.0), ("E4", 0.5)):
            special[name][1] = value
        for name in [b for b in f["branches"] if b != "primary"]:
            del f["branches"][name]
        f.copy(group, "branches/pear_0")
        f["branches/pear_0"].attrs.update({"parent_branch": "primary", "parent_branch_point": 0})
    return path


def test_default_run_writes_the_promised_files(quick_run):
    out, text = quick_run
    for scene in default_run.SCENES:
        assert read_run(out / f"{scene}.h5")["scene_name"] == scene
        for kind in ("pressure-pole", "pressure-equator", "shapes", "stresses", "curvature"):
            assert (out / f"{scene}_{kind}.png").stat().st_size > 0
        assert not (out / f"{scene}_energy.png").exists()  # no bifurcation data
    assert (out / "spom1_two_coils_M0.002_field.png").stat().st_size > 0
    assert not (out / "spom1_field.png").exists()  # no coils
    for kind in default_run.COMBINED:
        assert (out / f"all_{kind}.png").stat().st_size > 0
    for word in ("scene", "points", "P range", "special points", "max error est.", "trace time", "run time",
                 *default_run.SCENES):
        assert word in text


def test_packaged_default_scenes_match_the_scene_files():
    for scene in default_run.default_scenes():
        assert scene.text == (SCENES / f"{scene.name}.toml").read_text(encoding="utf-8")


PRESSURE = r"pressure $P = \bar{P}R_0/(T_0\mu/2)$"
LABELS = {
    "pressure-pole": (r"pole stretch $\lambda_2(0)$ (top)", PRESSURE),
    "pressure-equator": (r"equator stretch $\lambda_2(\pi/2)$ (circumferential)", PRESSURE),
    "shapes": (r"$\pm\rho/R_0$ (distance from the axis)", r"$\eta/R_0$ (height)"),
    "stresses": (r"material coordinate $\theta$ (rad)", r"$\sigma_\phi$ / ($\mu$/2)"),
    "field": (r"material coordinate $\theta$ (rad)", r"$H_\zeta$ / ($I/4\pi R_0$)"),
    "curvature": (r"material coordinate $\theta$ (rad)", r"Gaussian curvature $\kappa R_0^2$"),
    "energy": (r"amplitude $\Lambda$ along the critical mode",
               r"$E(\Lambda) - E_0$ (per $2\pi$, units of $T_0 R_0^2 \mu/2$)"),
}


# phase: tests/test_two_parameter.py; voltage-pole, voltage-equator (voltage continuations): test_voltage_branches.py;
# surface, stretch-map (states of surface branches): test_surface_store.py; frequencies, modes: test_dynamics.py
@pytest.mark.parametrize("kind", [k for k in KINDS if k not in ("phase", "voltage-pole", "voltage-equator",
                                                                "surface", "stretch-map", "frequencies", "modes")])
def test_every_kind_draws_with_labels(kind, files, bifurcation_file, tmp_path):
    paths = [bifurcation_file] if kind == "energy" else list(files.values())
    fig = plot(paths, kind, points=[0, -1] if kind in PER_POINT_KINDS else None)
    labelled = [ax for ax in fig.axes if ax.get_xlabel()]
    assert LABELS[kind][0] in [ax.get_xlabel() for ax in labelled]
    assert LABELS[kind][1] in [ax.get_ylabel() for ax in fig.axes]
    image = tmp_path / f"{kind}.png"
    fig.savefig(image)
    assert image.read_bytes().startswith(b"\x89PNG") and image.stat().st_size > 1000


def legend_texts(fig):
    return [t.get_text() for legend in [*fig.legends, *(ax.get_legend() for ax in fig.axes)] if legend
            for t in legend.get_texts()]


def test_several_files_are_labelled_by_M(files):
    fig = plot(list(files.values()), "pressure-pole")
    legend = fig.legends[0]
    assert [t.get_text() for t in legend.get_texts()] == ["M = 0", "M = 0.002"]
    assert "dashed: unstable" in legend.get_title().get_text()  # the default run assesses stability
    assert {t.get_text() for t in fig.axes[0].texts} >= {"1 EP", "2 EP"}  # special points: label and kind
    shapes = plot(list(files.values()), "shapes", points=[-1])
    assert any(text.startswith("M = 0.002: #") for text in legend_texts(shapes))


def test_several_files_give_each_branch_kind_its_own_colour_family(tmp_path_factory, run_path):  # noqa: F811
    """`plot A.h5 B.h5` with held pear, free pear and m = 1 branches (the two-coil picture; a file with a surface
    branch): each kind in one hue family, a shade per file, no two legend entries of one colour, and every drawn
    curve in its entry's colour (issue 40: they shared one colour per file)."""
    from matplotlib.colors import rgb_to_hsv, to_hex, to_rgb

    two_coils = two_coil_result(tmp_path_factory).save(tmp_path_factory.mktemp("families") / "two_coils.h5")
    fig = plot([two_coils, run_path], "pressure-pole")  # run_path: a primary branch and an m = 1 branch
    legend = fig.legends[0]
    entries = {t.get_text(): to_hex(h.get_color()) for t, h in zip(legend.get_texts(), legend.legend_handles)
               if t.get_text().startswith("M = ")}  # not the grey 'mirror-image branch' key
    kinds = {label.rpartition(", ")[2] for label in entries}
    assert {"primary", "pear", "free pear", "m = 1"} <= kinds, entries
    assert len(set(entries.values())) == len(entries), entries  # no two entries share a colour
    hue = {label: rgb_to_hsv(to_rgb(color))[0] for label, color in entries.items()}
    by_kind = {kind: [hue[label] for label in entries if label.endswith(f", {kind}")] for kind in kinds}
    primaries = [label for label in entries if label.endswith(", primary")]
    assert len(primaries) == 2 and rgb_to_hsv(to_rgb(entries[primaries[0]]))[2] < rgb_to_hsv(
        to_rgb(entries[primaries[1]]))[2]  # the first file the darker shade
    for kind, hues in by_kind.items():
        assert max(hues) - min(hues) < 0.05, (kind, hues)  # one family
        for other, others in by_kind.items():
            if other != kind:
                assert min(abs(a - b) for a in hues for b in others) > 0.08, (kind, other, entries)
    curves = {to_hex(line.get_color()) for line in fig.axes[0].get_lines() if len(line.get_xdata()) > 1}
    assert curves == set(entries.values())  # a mirror image: its partner's colour, lighter (alpha)


def test_stability_and_special_points(bifurcation_file):
    fig = plot([bifurcation_file], "pressure-pole")
    ax = fig.axes[0]
    assert "dashed: unstable" in fig.legends[0].get_title().get_text()
    styles = {line.get_linestyle() for line in ax.get_lines() if len(line.get_xdata()) > 1}
    assert {"-", "--"} <= styles
    assert "2 pitchfork-super" in {t.get_text() for t in ax.texts}  # its label in the file, and what it is
    assert legend_texts(fig) == ["M = 0.002, primary", "M = 0.002, pear from 2"]  # never the stored name
    assert legend_texts(plot([bifurcation_file], "pressure-pole", branch="pear_0")) == ["M = 0.002"]


def test_missing_data_is_a_clear_error(files):
    with pytest.raises(PlotError, match="no bifurcation data"):
        plot([files["spom1"]], "energy")
    with pytest.raises(PlotError, match="no coils"):
        plot([files["spom1"]], "field")
    with pytest.raises(PlotError, match="does not exist"):
        plot([files["spom1"]], "shapes", points=[10**6])
    with pytest.raises(PlotError, match="no branch 'pear'"):
        plot([files["spom1"]], "pressure-pole", branch="pear")


def test_field_identity_on_a_stored_two_coil_point(files):
    q = postprocess(read_run(files["spom1_two_coils_M0.002"]), points=[-1])
    np.testing.assert_allclose(q["H_theta"] ** 2 + q["H_zeta"] ** 2, q["H2"], rtol=1e-12)


def test_plot_subcommand(files, tmp_path, capsys):
    out = tmp_path / "both.pdf"
    assert main(["plot", *map(str, files.values()), "--what", "pressure-equator", "-o", str(out)]) == 0
    assert out.read_bytes().startswith(b"%PDF") and capsys.readouterr().out.strip() == str(out)
    assert main(["plot", str(files["spom1"]), "--what", "stresses", "--points", "0,-1", "-o",
                 str(tmp_path / "s.png")]) == 0
    capsys.readouterr()
    for argv, words in (
        (["--what", "energy", "-o", str(tmp_path / "e.png")], ["no bifurcation data"]),
        (["--what", "shapes", "--points", "999", "-o", str(tmp_path / "p.png")], ["point 999 does not exist"]),
        (["--what", "shapes", "-o", str(tmp_path / "x.gif")], ["suffix"]),
    ):
        assert main(["plot", str(files["spom1"]), *argv]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("balloon-cg: error: ")
        assert all(word in err for word in words)


def test_plot_and_bc_plot_draw_in_the_journal_style(files, tmp_path, capsys):
    """``plot`` (a new figure or the caller's Axes) draws in the journal style, a new figure saves in it (TrueType
    fonts in PDF: no Type 3), and the plot subcommand writes EPS and TIFF; matplotlib's global state is kept."""
    import matplotlib
    from matplotlib.figure import Figure

    from balloon_cg import plot as bc_plot

    before = dict(matplotlib.rcParams)
    fig = plot([files["spom1"]], "pressure-pole")
    assert fig.legends[0].get_texts()[0].get_fontsize() == 6.5  # journal.mplstyle's legend.fontsize
    ax = Figure().add_subplot()
    bc_plot(files["spom1"], "pressure-pole", ax=ax)
    assert ax.title.get_fontsize() == 8 and ax.get_legend().get_texts()[0].get_fontsize() == 6.5  # the Axes' own
    # tick and axis-label sizes are the caller's (set when the Axes was made), their family the journal's: one family
    families = {tuple(t.get_fontfamily()) for t in [ax.xaxis.label, ax.yaxis.label, *ax.get_xticklabels(),
                                                   *ax.get_yticklabels(), *ax.texts, *ax.get_legend().get_texts()]}
    assert families == {("serif",)}, families
    pdf = tmp_path / "p.pdf"
    fig.savefig(pdf)
    assert b"/Type3" not in pdf.read_bytes() and b"/FontFile2" in pdf.read_bytes()
    assert dict(matplotlib.rcParams) == before
    for suffix, magic in ((".eps", b"%!PS-Adobe"), (".tif", b"II*\x00")):
        image = tmp_path / f"p{suffix}"
        assert main(["plot", str(files["spom1"]), "--what", "pressure-pole", "-o", str(image)]) == 0
        assert image.read_bytes().startswith(magic)
    capsys.readouterr()
