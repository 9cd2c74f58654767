"""Surface branches (analysis.results.SurfaceBranch) stored, inspected, drawn and returned like every branch: a
synthetic branch of spheres of radius λ on SphericalBasis(6, (MIRROR_Y, EQUATOR)) beside a traced primary branch."""
import json
import shutil
from dataclasses import replace

import h5py
import numpy as np
import pytest
from matplotlib.collections import QuadMesh
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

import balloon_cg as bc
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.surface.branches import rotated
from balloon_cg.analysis.results import (Block, Classification, Kind, Leg, SpecialPoint, Stop, StopCode,
                                         SurfaceBranch)
from balloon_cg.app.api import Result
from balloon_cg.app.cli import PLOT_KINDS, main
from balloon_cg.galerkin.coordinate_map import WireMap
from balloon_cg.galerkin.equilibrium import Parameters
from balloon_cg.io.run_file import FORMAT, read_run, stored_basis, write_run
from balloon_cg.post.labels import GID
from balloon_cg.post.plotting import plot, principal_stretches
from balloon_cg.scene import parse_scene
from balloon_cg.surface.basis import EQUATOR, MIRROR_Y, SphericalBasis
from balloon_cg.surface.embedding import displacement_coefficients
from balloon_cg.surface.measures import MEASURES, measures
from netcdf_groups import uncoordinated

SCENE = '[material]\npreset = "neo-Hookean"\n[continuation]\nstop_stretch = 1.6\n'
STRETCHES = np.linspace(1.1, 1.5, 5)


def sphere_pressure(lam):
    """P of the neo-Hookean sphere of radius λ (nondimensional, MODEL.md §2)."""
    return 4.0 * (1.0 / lam - lam ** -7)


@pytest.fixture(scope="module")
def scene():
    return parse_scene(SCENE, "neo")


@pytest.fixture(scope="module")
def basis():
    return SphericalBasis(6, (MIRROR_Y, EQUATOR))


@pytest.fixture(scope="module")
def surface_branch(scene, basis):
    c = np.array([displacement_coefficients(basis, (lam - 1.0) * basis.nodes["reference"][:3])
                  for lam in STRETCHES])
    P = sphere_pressure(STRETCHES)
    per_point = [measures(basis, row) for row in c]
    rows = np.column_stack([c, P])
    n = len(P)
    end = Stop(StopCode.STOP_STRETCH, "the north pole stretch reached 1.5")
    rng = np.random.default_rng(1)
    lowest = {"held": np.sort(rng.normal(size=(n, 4)), axis=1), "free": np.sort(rng.normal(size=(n, 4)), axis=1)}
    return SurfaceBranch(
        "m1_bp0", scene, basis, "surface_ogden_neo_hookean", "0123abcd", Parameters(P=float(P[0])), c, P,
        np.arange(n) + 2, np.full(n, 1e-12), np.full(n, 1e-10),
        {name: np.array([m[name] for m in per_point]) for name in MEASURES}, 1, ("primary", 0),
        legs=(Leg("forward", end),),
        special=[SpecialPoint(Kind.BP, 0, rows[0].copy(), Classification.PITCHFORK_SUB, Block.M1_HELD, m=1,
                              E=(0.2, 0.0, -0.5), note="born here: branch point 0 of primary (m = 1)"),
                 SpecialPoint(Kind.EP, n - 1, rows[-1].copy(), stop=end)],
        stability=lowest, wall_time=0.25)


@pytest.fixture(scope="module")
def primary(scene):
    return trace_primary(scene)


@pytest.fixture(scope="module")
def run_path(tmp_path_factory, scene, primary, surface_branch):
    return write_run(tmp_path_factory.mktemp("surface") / "run.h5", scene, [primary, surface_branch])


def test_round_trip_is_bit_exact(run_path, surface_branch, basis):
    run = read_run(run_path)
    assert run["attrs"]["format"] == FORMAT
    assert list(run["branches"]) == ["primary", "m1_bp0"]
    assert run["branches"]["primary"]["attrs"]["m"] == 0
    d, b = run["branches"]["m1_bp0"], surface_branch
    assert d["attrs"]["gauge"] == b.gauge.value  # the reading (issue 27)
    assert np.array_equal(d["coefficients"], b.coefficients)
    assert np.array_equal(d["pressure"], b.values)
    assert np.array_equal(d["lam2_top"], b.measures["lam_top"])
    assert np.array_equal(d["lam2_bottom"], b.measures["lam_bottom"])
    assert np.array_equal(d["volume"], 2 * np.pi * b.measures["volume"])  # V / R0³ like every branch
    assert np.allclose(d["volume"], 4 * np.pi / 3 * STRETCHES ** 3, rtol=1e-12)
    assert np.array_equal(d["centroid"], b.measures["centroid"]) and d["centroid"].shape == (5, 3)
    assert np.array_equal(d["tilt"], b.measures["tilt"])
    assert np.array_equal(d["amount"], d["pressure"] * d["volume"])
    for name, values in (("residual", b.residual), ("error_estimate", b.error_estimate),
                         ("newton_iterations", b.iterations)):
        assert np.array_equal(d[name], values)
    for reading in ("held", "free"):
        assert np.array_equal(d["stability"][f"lowest_{reading}"], b.stability[reading])
    assert np.array_equal(d["stability"]["stable_pressure"], b.stability["held"][:, 0] > 0)
    assert np.array_equal(d["stability"]["stable_pressure_free"], b.stability["free"][:, 0] > 0)
    attrs = d["attrs"]
    assert (attrs["m"], attrs["parent_branch"], attrs["parent_branch_point"]) == (1, "primary", 0)
    assert attrs["leg_stop_codes"] == ["stop_stretch"] and attrs["stop_reason"] == b.stop_reason
    assert attrs["surface_degree"] == 6 and np.array_equal(attrs["symmetry"], [MIRROR_Y, EQUATOR])
    assert stored_basis(attrs) == basis and stored_basis(attrs).blocks == basis.blocks
    special = d["special_points"]
    assert [s["kind"] for s in special] == ["BP", "EP"] and special[0]["m"] == 1
    assert special[1]["stop_code"] == "stop_stretch"
    assert np.array_equal(d["special_unknowns"], np.array([s.X for s in b.special]))
    assert np.allclose([s["lam2_top"] for s in special], STRETCHES[[0, -1]], rtol=1e-13)
    assert np.allclose([s["eta_bottom"] for s in special], -STRETCHES[[0, -1]], rtol=1e-13)


def _same(a, b) -> bool:
    """Whether two read runs (nested dicts, lists, arrays, scalars) hold the same values of the same types."""
    if isinstance(a, dict):
        return isinstance(b, dict) and list(a) == list(b) and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and a.dtype == b.dtype and np.array_equal(a, b, equal_nan=True)
    return type(a) is type(b) and (a == b or a != a and b != b)


def test_a_read_opens_each_member_once_and_reads_what_h5py_reads(run_path, monkeypatch):
    """io.layout.opened's file opens each member once (``_OpenedOnce``): the run read through it is the run read
    through a plain h5py.File, value for value, with under a third of the opens (~2 per object: the rest are
    ``.parent`` lookups, which h5py makes from the file's root; the plain file ~9)."""
    from balloon_cg.io import layout

    opens = []
    get = h5py.Group._get
    monkeypatch.setattr(h5py.Group, "_get", lambda self, name, lapl=None: opens.append(name) or get(self, name, lapl))
    cached = read_run(run_path)
    cached_opens = len(opens)
    opens.clear()
    monkeypatch.setattr(layout, "_ReadFile", h5py.File)
    plain = read_run(run_path)
    assert _same(cached, plain)
    assert cached_opens < len(opens) / 3


def test_a_mapped_order_capped_basis_is_rebuilt(tmp_path, scene, primary, surface_branch):
    """The attributes rebuild a basis with an azimuthal order cap and a polar coordinate map (whose functions are
    orthonormalised in its own quadrature) exactly: the same node states from the stored coefficients."""
    basis = SphericalBasis(6, (MIRROR_Y, EQUATOR), order=3, mapping=WireMap((0.4,), (0.2,)))
    c = np.array([displacement_coefficients(basis, (lam - 1.0) * basis.nodes["reference"][:3]) for lam in STRETCHES])
    mapped = replace(surface_branch, name="m1_mapped", basis=basis, coefficients=c,
                     special=[replace(s, X=np.append(c[s.index], s.X[-1])) for s in surface_branch.special])
    data = read_run(write_run(tmp_path / "mapped.h5", scene, [primary, mapped]))["branches"]["m1_mapped"]
    rebuilt = stored_basis(data["attrs"])
    assert rebuilt == basis and (rebuilt.order, rebuilt.mapping) == (3, WireMap((0.4,), (0.2,)))
    assert np.array_equal(rebuilt.node_state(data["coefficients"][2]), basis.node_state(c[2]))


def test_a_special_point_on_another_basis_is_not_written(tmp_path, scene, surface_branch):
    stale = replace(surface_branch, special=[replace(surface_branch.special[0], X=np.zeros(7))])
    with pytest.raises(ValueError, match="special points BP after point 0 .7. are not rows of its 41"):
        write_run(tmp_path / "stale.h5", scene, [stale])
    assert not (tmp_path / "stale.h5").exists()


def test_a_rotated_image_shares_its_partners_entry(tmp_path, scene, primary, surface_branch, capsys):
    """The other direction of the pitchfork (analysis.surface.branches.rotated): stored with origin reflected and
    reflection_of, drawn in its partner's colour under the same legend entry, named in inspect."""
    image = rotated(surface_branch, "m1_bp0_rotated")
    path = write_run(tmp_path / "rotated.h5", scene, [primary, surface_branch, image])
    attrs = read_run(path)["branches"]["m1_bp0_rotated"]["attrs"]
    assert (attrs["origin"], attrs["reflection_of"]) == ("reflected", "m1_bp0")
    fig = plot([path], "pressure-pole")
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels.count("m = 1") == 1 and len(labels) == 2  # its parent point is not in this file: no label
    colours = {line.get_color() for line in fig.axes[0].lines if len(line.get_xdata()) > 1}
    assert len(colours) == 2  # the primary branch's and the pair's
    assert main(["inspect", str(path)]) == 0
    assert "(the rotation by π about the axis of m1_bp0)" in capsys.readouterr().out


def test_files_without_m_read_as_axisymmetric(run_path, tmp_path):
    """A balloon-cg/3 file (no m attribute, no surface branch) still reads: every branch m = 0."""
    old = tmp_path / "old.h5"
    shutil.copy(run_path, old)
    with h5py.File(old, "a") as f:
        f.attrs["format"] = "balloon-cg/3"
        del f["branches/m1_bp0"]
        del f["branches/primary"].attrs["m"]
    run = read_run(old)
    assert run["branches"]["primary"]["attrs"]["m"] == 0
    assert bc.load(old).branches["primary"].m == 0


def test_inspect_text_and_json(run_path, capsys):
    assert main(["inspect", str(run_path)]) == 0
    text = capsys.readouterr().out
    assert "surface branch m1_bp0   (m = 1, from primary branch point 0" in text  # a parent point not in the file
    assert "stop reason          forward: the north pole stretch reached 1.5" in text
    assert main(["inspect", str(run_path), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    branches = summary["branches"]
    assert branches["primary"]["m"] == 0 and branches["primary"]["parent"] is None
    surface = branches["m1_bp0"]
    assert surface["m"] == 1 and surface["parent"] == ["primary", 0] and surface["points"] == 5
    assert surface["pressures"] == sphere_pressure(STRETCHES).tolist()
    assert surface["stop_codes"] == {"forward": "stop_stretch"}


@pytest.mark.parametrize("kind", [k for k in PLOT_KINDS if k not in ("phase", "voltage-pole", "voltage-equator",
                                                                      "field", "frequencies", "modes")])
def test_every_kind_draws_a_file_with_a_surface_branch(run_path, kind):
    fig = plot([run_path], kind)
    axes = fig.axes
    if kind == "pressure-pole":
        legend = {t.get_text(): h for t, h in zip(fig.legends[0].get_texts(), fig.legends[0].legend_handles)}
        name = "m = 1"  # by its mode (its parent point, with the label it would be named by, is not in the file)
        assert name in legend and not any("m1_bp0" in label for label in legend)
        color = legend[name].get_color()
        drawn = [line.get_xdata() for line in axes[0].lines if line.get_color() == color
                 and len(line.get_xdata()) > 1 and line.get_gid() != GID]  # not the labels' leader lines
        assert np.allclose(np.unique(np.concatenate(drawn).round(12)), STRETCHES)  # P against lam2_top
    elif kind == "energy":  # the normal form at the branch point the surface branch is born at
        labels = [t.get_text() for t in fig.legends[0].get_texts()]  # under the panel, not over the curves
        assert len(labels) == 1 and labels[0].startswith("m = 1: pitchfork-sub m=1 at P = ")
    elif kind == "surface":
        assert axes[0].name == "3d" and len(axes) == 2  # the surface and its section by y = 0
        assert any(isinstance(c, Poly3DCollection) for c in axes[0].collections)
        assert f"#{len(STRETCHES) - 1}" in fig.get_suptitle()  # the last point: what the branch reaches
        sections = [line for line in axes[1].lines if len(line.get_xdata()) > 1]  # point 0 and the last, round
        assert len(sections) == 2 and all(np.allclose(np.hypot(line.get_xdata(), line.get_ydata()), STRETCHES[-1])
                                          for line in sections[1:])
    elif kind == "stretch-map":
        meshes = [c for ax in axes[:2] for c in ax.collections if isinstance(c, QuadMesh)]  # then colour bars
        assert len(meshes) == 2 and len(axes) == 4
        for mesh in meshes:  # a sphere of radius 1.5 (the last point): both stretches 1.5 at every node
            assert np.allclose(mesh.get_array(), STRETCHES[-1], rtol=1e-12)
    else:  # the axisymmetric kinds draw the primary branch only
        assert axes and not any("m = 1" in t.get_text() for leg in fig.legends for t in leg.get_texts())


def test_principal_stretches_of_a_sphere(basis):
    for lam in (0.8, 1.3):
        c = displacement_coefficients(basis, (lam - 1.0) * basis.nodes["reference"][:3])
        lam1, lam2 = principal_stretches(basis.node_state(c))
        assert np.allclose(lam1, lam, rtol=1e-12) and np.allclose(lam2, lam, rtol=1e-12)


def test_cli_plot_surface_point_and_refusals(run_path, tmp_path, capsys):
    assert main(["plot", str(run_path), "--what", "surface,stretch-map", "--points", "-1",
                 "-o", str(tmp_path / "s.png")]) == 0
    assert (tmp_path / "s_surface.png").exists() and (tmp_path / "s_stretch-map.png").exists()
    capsys.readouterr()
    for argv in (["--what", "surface", "--points", "0,1"], ["--what", "shapes", "--branch", "m1_bp0"],
                 ["--what", "stretch-map", "--branch", "primary"]):
        assert main(["plot", str(run_path), *argv, "-o", str(tmp_path / "x.png")]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("balloon-cg: error: "), err


def test_xarray_opens_the_surface_group(run_path):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    with xr.open_dataset(run_path, engine="h5netcdf", group="branches/m1_bp0") as ds:
        assert ds.coefficients.dims == ("point", "coefficient") and ds.centroid.dims == ("point", "axis")
        assert ds.tilt.attrs["units"] == "degree" and ds.pressure.attrs["long_name"] == "pressure P"
    with xr.open_dataset(run_path, engine="h5netcdf", group="branches/m1_bp0/stability") as ds:
        assert ds.lowest_held.dims == ("point", "eigenvalue") and ds.point.size == ds.sizes["point"]
    assert uncoordinated(run_path) == []  # stability, special_points/state of a surface branch opened alone


DAMAGE = {
    "missing surface_degree": lambda g: g.attrs.__delitem__("surface_degree"),
    "missing symmetry": lambda g: g.attrs.__delitem__("symmetry"),
    "symmetry not 3 wide": lambda g: g.attrs.__setitem__("symmetry", np.ones((2, 2), dtype=np.int64)),
    "wrong degree": lambda g: g.attrs.__setitem__("surface_degree", 5),
    "missing parent": lambda g: g.attrs.__delitem__("parent_branch"),
    "m as text": lambda g: g.attrs.__setitem__("m", "one"),
    "missing m": lambda g: g.attrs.__delitem__("m"),  # then read as axisymmetric: no degree, no unknowns
    "missing centroid": lambda g: g.__delitem__("centroid"),
}


@pytest.mark.parametrize("damage", DAMAGE)
def test_damaged_surface_branch_is_exit_2(run_path, tmp_path, capsys, damage):
    path = tmp_path / "damaged.h5"
    shutil.copy(run_path, path)
    with h5py.File(path, "a") as f:
        DAMAGE[damage](f["branches/m1_bp0"])
    assert main(["inspect", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("balloon-cg: error: ") and "m1_bp0" in err, err


def test_result_has_m_and_parent(run_path, scene, primary, surface_branch):
    pytest.importorskip("pandas")
    for result in (bc.load(run_path), Result.of(scene, [primary, surface_branch])):
        branch = result.branches["m1_bp0"]
        assert (branch.m, branch.parent) == (1, ("primary", 0))
        assert (result.branches["primary"].m, result.branches["primary"].parent) == (0, None)
        table = result.to_dataframe()
        assert list(table.columns[:3]) == ["branch", "m", "point"]
        assert set(table.groupby("branch").m.first().items()) == {("primary", 0), ("m1_bp0", 1)}
        rows = table[table.branch == "m1_bp0"]
        assert np.array_equal(rows.pressure, surface_branch.values) and "centroid_x" in table
    points = bc.load(run_path).to_xarray("m1_bp0")
    assert points.coefficients.shape == (5, surface_branch.basis.size)


def test_analyse_stores_the_pictures_surface_branches(monkeypatch, scene, primary, surface_branch):
    """bc.analyse (and `balloon-cg run`, through api.computed) hands the writers the picture's axisymmetric
    branches, then its surface branches."""
    from balloon_cg.analysis import picture

    monkeypatch.setattr(picture, "analyse", lambda *args, **kwargs: picture.Picture(
        [primary], surface_branches=[surface_branch]))
    result = bc.analyse(scene)
    assert list(result.branches) == ["primary", "m1_bp0"] and result.branches["m1_bp0"].m == 1


def _with_secondary(surface_branch, sector, name="m1_sector"):
    """The branch with a secondary branch point between points 2 and 3 in the symmetry sector ``sector``."""
    rows = np.column_stack([surface_branch.coefficients, surface_branch.values])
    bp = SpecialPoint(Kind.BP, 2, rows[2].copy(), m=1, sector=sector,
                      note=f"secondary branch point: held eigenvalue 0 of the symmetry sector {sector} crosses zero")
    special = [surface_branch.special[0], bp, surface_branch.special[1]]
    return replace(surface_branch, name=name, special=special)


def test_a_secondary_branch_points_sector_round_trips(tmp_path, scene, primary, surface_branch, capsys):
    """SpecialPoint.sector is stored (special_points/state/sector, one character per reflection of the basis, zeros
    for the points without one), read back by read_run and bc.load, shown by inspect under the basis's reflections
    (text and JSON) and opens in xarray; a file without it (written before) still reads, without sectors."""
    branch = _with_secondary(surface_branch, (1, -1))
    path = write_run(tmp_path / "sector.h5", scene, [primary, branch])
    special = read_run(path)["branches"]["m1_sector"]["special_points"]
    assert [s["sector"] for s in special] == [(), (1, -1), ()]
    assert [s["sector"] for s in bc.load(path).special_points if s["branch"] == "m1_sector"] == [(), (1, -1), ()]
    assert "sector" not in read_run(path)["branches"]["primary"]["special_points"][0]  # axisymmetric: none
    with h5py.File(path) as f:
        stored = f["branches/m1_sector/special_points/state/sector"]
        assert stored.shape == (3, 2) and stored.attrs["long_name"] == "symmetry sector"
    assert main(["inspect", str(path)]) == 0
    text = capsys.readouterr().out.split("surface branch m1_sector")[1]
    assert "BP m=1 sector (y → −y); (z → −z) odd  points 2-3" in text
    assert main(["inspect", str(path), "--json"]) == 0
    points = json.loads(capsys.readouterr().out)["branches"]["m1_sector"]["special_points"]
    assert [s["sector"] for s in points] == [[], [1, -1], []]
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    with xr.open_dataset(path, engine="h5netcdf", group="branches/m1_sector/special_points/state") as ds:
        assert ds.sector.dims == ("special", "reflection") and ds.sector.values.tolist()[1] == [1, -1]
    with h5py.File(path, "a") as f:
        state = f["branches/m1_sector/special_points/state"]
        del state["sector"], state["reflection"]
    old = read_run(path)["branches"]["m1_sector"]["special_points"]
    assert [s["kind"] for s in old] == ["BP", "BP", "EP"] and not any("sector" in s for s in old)


def test_a_sector_of_another_basis_is_not_written_nor_read(tmp_path, scene, primary, surface_branch, capsys):
    """A sector that is not one character ±1 per reflection of the branch's basis is refused by the writer
    (ValueError, nothing written) and, damaged in a file, by the reader (exit 2, one line naming the branch)."""
    for sector in ((-1,), (1, 2)):
        with pytest.raises(ValueError, match="have no symmetry sector of its 2 reflections"):
            write_run(tmp_path / "bad.h5", scene, [_with_secondary(surface_branch, sector)])
        assert not (tmp_path / "bad.h5").exists()
    path = write_run(tmp_path / "sector.h5", scene, [primary, _with_secondary(surface_branch, (1, -1))])
    for damage in (np.array([[0, 0], [1, 3], [0, 0]]), np.zeros((3, 1), dtype=np.int64)):
        damaged = tmp_path / "damaged.h5"
        shutil.copy(path, damaged)
        with h5py.File(damaged, "a") as f:
            state = f["branches/m1_sector/special_points/state"]
            del state["sector"]
            state.create_dataset("sector", data=damage)
        assert main(["inspect", str(damaged)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "m1_sector" in err and "sector" in err, err


@pytest.mark.parametrize("mapping", [None, WireMap((0.3,), (0.2,))])
def test_the_drawn_surface_is_the_series_at_every_grid_point(mapping):
    """``plotting.surface_grid`` (the series once per ring) equals ``SphericalBasis.point_values`` (per point, the
    poles included) on the drawn grid, on a plain and a wire-mapped basis, for a state with every block set."""
    from balloon_cg.post.plotting import SURFACE_SAMPLES, surface_grid

    basis = SphericalBasis(8, (MIRROR_Y,), mapping=mapping)
    c = np.random.default_rng(2).normal(scale=0.1, size=basis.size)
    theta, phi = np.meshgrid(np.linspace(0.0, np.pi, SURFACE_SAMPLES[0]),
                             np.linspace(0.0, 2 * np.pi, SURFACE_SAMPLES[1]), indexing="ij")
    x, _ = basis.point_values(c, theta.ravel(), phi.ravel())
    assert np.abs(surface_grid(basis, c) - x.reshape(3, *SURFACE_SAMPLES)).max() < 1e-13
