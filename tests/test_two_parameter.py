"""Two-parameter continuation of pear pitchforks (two_parameter): the SPOM1 isola at M = 0 followed in α1
(Σ μ_i α_i = 4 kept through μ1) against the closed-form sphere condition of sphere_modes; the single-coil isola
followed in M, its critical M bracketed by plain primary-branch sweeps."""
from pathlib import Path

import h5py
import numpy as np
import pytest

import balloon_cg as bc
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.points import branch_points as bifurcation
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.results import Status, StopCode
from balloon_cg.scene.materials import get_preset
from balloon_cg.scene import load_scene, parse_scene
from balloon_cg.analysis.stability.axisymmetric import SecondVariation
from balloon_cg.io.run_file import read_run
from balloon_cg.analysis.critical.pitchfork_curve import (CurveEnd, TwoParameterError, alpha1_material,
                                       continue_branch_point, land_on_q, sphere_critical_alpha1,
                                       sphere_pear_stretches)
from balloon_cg.analysis.critical import pitchfork_curve as codim2
from balloon_cg.numerics.continuation import Fold, Path as TracePath, Point, RootStatus, Stop, TraceStop
from balloon_cg.io.curve_file import read_curve, write_curve
from pitchforks import isola, jacobian_error

SPOM1 = get_preset("SPOM1")


@pytest.fixture(scope="module")
def located():
    return isola(parse_scene('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 4.0\n', name="SPOM1"))


@pytest.fixture(scope="module")
def curve(located):
    _, branch, bps = located
    return continue_branch_point(branch, bps[0], "alpha1")


def test_jacobian_matches_differences_of_the_residual(located):
    """The assembled Jacobian (generated Hessians + central differences for the third-derivative and α1 terms)
    against central differences of the exact extended residual."""
    _, branch, bps = located
    for parameter, q0 in (("alpha1", 1.3), ("M", 0.0)):  # (no coils: the M column is zero, still consistent)
        assert jacobian_error(branch, bps[0], parameter, q0) < 1e-8


def test_critical_alpha1_matches_closed_form(curve):
    """The fold of the curve in α1 (the two pear points merge) against the closed form: α1 where the minimum
    over λ of the sphere pear condition Φ11 + Φ12 − Φ1/λ touches zero."""
    assert len(curve.merges) == 1
    q, P, stretch = curve.critical
    expected, lam = sphere_critical_alpha1(SPOM1, 1.3, 2.5)
    assert q == pytest.approx(expected, rel=1e-6)
    assert stretch == pytest.approx(lam, rel=1e-4)  # λ is flat (a double root) at the merge


def test_curve_joins_the_two_pitchforks(curve, located):
    """Started at the lower SPOM1 pitchfork, the curve comes back to α1 = 1.3 at the upper one."""
    _, branch, bps = located
    assert curve.stop.code == StopCode.PARTNER and curve.end == CurveEnd.ISOLA_MERGE
    assert curve.merge is curve.merges[0] and curve.merges[0].status == Status.LOCATED
    assert np.all(curve.pressure > 0)
    upper = branch.pole_values(bps[1].X)["lam2_top"][0]
    assert curve.pole_stretch[-1] > 0.9 * upper and curve.q[-1] < 1.5


def test_intermediate_pear_points_match_sphere_modes(curve):
    """Points of the curve away from the merge: the pole stretch is a root of the closed-form pear condition
    of that α1 (sphere_modes.bifurcation_stretches) to 1e-8."""
    critical = curve.critical[0]
    checked = 0
    for q, stretch in zip(curve.q, curve.pole_stretch):
        if critical - q < 0.02:  # the roots are ill-conditioned in α1 next to the double root
            continue
        roots = sphere_pear_stretches(SPOM1, q)
        assert len(roots) == 2
        nearest = roots[np.argmin(np.abs(roots - stretch))]
        assert stretch == pytest.approx(nearest, rel=1e-8)
        checked += 1
    assert checked >= 6


def test_material_family_keeps_the_modulus_sum():
    material = alpha1_material(SPOM1, 1.7)
    assert material.shear_modulus_sum == pytest.approx(4.0, abs=1e-14)
    assert material.alpha[0] == 1.7 and material.mu[1:] == SPOM1.mu[1:]


def test_curve_round_trips_through_hdf5(curve, located, tmp_path):
    scene = located[0]
    path = write_curve(tmp_path / "curve.h5", scene, curve)
    data = read_curve(path)
    np.testing.assert_array_equal(data["q"], curve.q)
    np.testing.assert_array_equal(data["pressure"], curve.pressure)
    np.testing.assert_array_equal(data["lam2_top"], curve.pole_stretch)
    special = data["special_points"]
    assert [s["kind"] for s in special] == ["LP"] and data["attrs"]["stop_code"] == "partner"
    assert data["special_q"][0] == curve.critical[0] == data["attrs"]["critical_q"]
    assert special[0]["lam2_top"] == pytest.approx(curve.critical[2], rel=1e-14)
    assert data["attrs"]["parameter"] == "alpha1" and data["attrs"]["end"] == "isola_merge"
    assert special[0]["status"] == "located" and "merge" in data["attrs"]["end_description"]
    assert read_run(path)["branches"] == {}  # also a readable run file (provenance attributes)
    with pytest.raises(FileExistsError):
        write_curve(path, scene, curve)
    loaded = bc.load(path)  # a curve object named after its parameter
    assert isinstance(loaded, bc.CurveResult) and loaded.parameter == "alpha1"
    assert loaded.critical == {"pear": curve.critical[0]} and "critical alpha1 = " in repr(loaded)
    assert "<th>critical alpha1</th>" in loaded._repr_html_() and "\n" not in repr(loaded)
    table = loaded.to_dataframe()
    assert list(table.columns[:3]) == ["curve", "alpha1", "pressure"] and len(table) == len(curve.q)
    with h5py.File(path, "r") as f:  # q stored under its parameter's name, a coordinate of the quantities
        group = f["two_parameter/pear"]
        assert "q" not in group and group["alpha1"].attrs["units"] == "1"
        assert "α1" in group["alpha1"].attrs["long_name"] and group["pressure"].attrs["coordinates"] == "alpha1"
        np.testing.assert_array_equal(group["special_points/alpha1"][()], data["special_q"])


SINGLE_COIL = Path(__file__).resolve().parent.parent / "scenes" / "spom1_single_coil.toml"


def _pear_points(branch):
    """Located pear points of a primary branch from the odd block alone (cheaper than the full assessment)."""
    variation = SecondVariation(equilibrium_of(branch), branch.disc.degree)
    odd = bifurcation.block_indices(variation, "odd_held", False)
    lowest = np.array([variation._lowest(variation.matrices(X[:-1], branch.params.with_value("P", X[-1]))[0],
                                         odd)[0] for X in branch.X])
    changes = np.flatnonzero(np.sign(lowest[:-1]) != np.sign(lowest[1:]))
    return [bifurcation.locate(branch, int(i), "odd_held", 0) for i in changes]


def _probe(M):
    """Primary branch of the single-coil scene at M over pole stretches [1.5, 2.8] (started at 2: the field
    cannot be switched on at the default start stretch 1.01 for M ≈ 4)."""
    scene = load_scene(SINGLE_COIL).with_overrides({
        "field.M": M, "continuation.start_stretch": 2.0, "continuation.min_stretch": 1.5,
        "continuation.stop_stretch": 2.8, "continuation.step_max": 0.05, "solver.max_degree": 80})
    return trace_primary(scene)


@pytest.fixture(scope="module")
def field_curve():
    scene = load_scene(SINGLE_COIL).with_overrides({"continuation.stop_stretch": 2.0, "solver.degree": 60})
    branch = trace_primary(scene, down=False)
    return branch, continue_branch_point(branch, _pear_points(branch)[0], "M")


def test_critical_field_of_the_single_coil_isola(field_curve):
    """Continued in M, the lower pitchfork of the single-coil scene merges with the upper one at M* ≈ 4.1877 (this
    coil, a = 4 at h = 0, is far from the balloon: the paper's ≈ 0.004 is for its unstated coil). A plain sweep
    brackets it: the primary branch has two pear points at M = 4.17 (where they lie on the curve) and none at
    4.20."""
    branch, curve = field_curve
    assert len(curve.merges) == 1 and curve.stop.code == StopCode.PARTNER and curve.end == CurveEnd.ISOLA_MERGE
    assert curve.merges[0].status == Status.LOCATED and np.all(curve.pressure > 0)
    q, P, stretch = curve.critical
    assert 4.17 < q < 4.20
    assert q == pytest.approx(4.1876946802, abs=1e-9)
    merge = curve.merges[0].X
    assert branch.disc.tail(merge[:branch.disc.size]) < 1e-9
    below, above = _pear_points(_probe(4.17)), _pear_points(_probe(4.20))
    assert len(below) == 2 and len(above) == 0
    upward = int(np.argmax(curve.q))  # the curve's two crossings of M = 4.17, on either side of the merge
    for near, bp in zip((upward - 1, upward + 1), below):
        X = land_on_q(curve, 4.17, near)
        assert X is not None
        assert X[branch.disc.size] == pytest.approx(bp.X[-1], rel=1e-7)


def test_continuation_in_M_without_coils_is_refused(located):
    _, branch, bps = located
    with pytest.raises(TwoParameterError, match="needs coils"):
        continue_branch_point(branch, bps[0], "M")


def test_phase_diagram_plot(curve, tmp_path):
    from balloon_cg.post.plotting import PlotError, plot
    from balloon_cg.scene import parse_scene

    path = write_curve(tmp_path / "phase.h5", parse_scene('[material]\npreset = "SPOM1"\n'), curve)
    fig = plot([path], "phase")
    ax = fig.axes[0]
    assert "alpha_1" in ax.get_xlabel() and "bifurcation pressure" in ax.get_ylabel()
    assert "critical alpha1 = 1.73962" in [t.get_text() for t in fig.legends[0].get_texts()]  # marked, in the key
    [shaded] = ax.patches  # the isola region, bounded by the smoothed curve (not the chords of its points)
    assert len(shaded.get_xy()) >= 400 > len(read_curve(path)["q"])
    fig.savefig(tmp_path / "phase.png")
    assert (tmp_path / "phase.png").stat().st_size > 1000
    for kind in ("pressure-pole", "shapes", "energy"):  # a curve file has no branches: no empty figure
        with pytest.raises(PlotError, match="no branches to draw .* its kind is phase"):
            plot([path], kind)
    assert "alpha_1" in plot([path], None).axes[0].get_xlabel()  # no kind: a curve file's, phase


def test_smooth_curve_follows_a_sparse_arc():
    """Nine points on a half circle (its apex among them, as the located fold is on a curve): the curve through
    them stays within 6e-3 of the circle where the chords between the points sag by 1 − cos(π/16) ≈ 0.019,
    passes through every point and never leaves the points' range (no overshoot)."""
    from balloon_cg.post.plotting import smooth_curve

    t = np.linspace(0.0, np.pi, 9)
    q0, P0 = 1e-3 * (1 + np.cos(t)), 2.0 + np.sin(t)
    q, P = smooth_curve(q0, P0)
    assert np.abs(np.hypot(q / 1e-3 - 1, P - 2.0) - 1).max() < 6e-3
    assert all(np.hypot((q - a) / 1e-3, P - b).min() < 1e-2 for a, b in zip(q0, P0))
    assert q.min() >= q0.min() and q.max() <= q0.max() and P.max() <= P0.max()


# -- how a curve ends (CurveEnd) ------------------------------------------------------------------------------
def _path(code, fold_pressures, n=2):
    """A stand-in trace: points with (u, P, φ, q), folds at the given pressures, a stop with ``code``."""
    def point(P, q):
        return Point(np.array([1.0] * n + [P, 0.5, q]), np.zeros(n + 3), 1, 0.0)
    points = [point(1.0, 0.1 * i) for i in range(5)]
    folds = [Fold("LP", point(P, 0.45), 2, RootStatus.LOCATED) for P in fold_pressures]
    return TracePath(points, folds, Stop(code, "test stop"), point(0.5, 0.0))


@pytest.mark.parametrize("code, folds, end", [
    (StopCode.PARTNER, [1.5], CurveEnd.ISOLA_MERGE),
    (StopCode.PARTNER, [-1.8], CurveEnd.FOLD),  # the two-coil turn: at negative pressure
    (StopCode.PARTNER, [], CurveEnd.FOLD),  # back at q0 but no located fold
    (TraceStop.MAX_POINTS, [1.5], CurveEnd.FOLD),  # turned but never came back to the partner
    (StopCode.NONPOSITIVE_PRESSURE, [0.2], CurveEnd.FOLD),
    (StopCode.NONPOSITIVE_PRESSURE, [], CurveEnd.NONPOSITIVE_PRESSURE),
    (StopCode.WIRE_GAP, [], CurveEnd.WIRE),
    (TraceStop.MAX_POINTS, [], CurveEnd.BUDGET),
    (TraceStop.STEP_MIN, [], CurveEnd.STEP_MIN),
    (StopCode.ALPHA1_ZERO, [], CurveEnd.ALPHA1_ZERO),
    (StopCode.REJOINED, [], CurveEnd.OTHER),  # a caller's stop rule
])
def test_curve_end_classification(code, folds, end):
    assert codim2._classify(_path(code, folds), 2) == end


TWO_COILS = Path(__file__).resolve().parent.parent / "scenes" / "spom1_two_coils_M0.002.toml"


@pytest.fixture(scope="module")
def two_coils():
    branch = trace_primary(load_scene(TWO_COILS))
    return branch, _pear_points(branch)[0]


def test_two_coil_curve_reaches_zero_pressure_without_a_merge(two_coils):
    """Issue 11: the two-coil pitchfork continued in M turns back only at P ≈ −1.8 (M ≈ 0.416); the curve now
    stops where P reaches 0 (M ≈ 0.28) and gives no critical M."""
    curve = continue_branch_point(*two_coils, "M")
    assert curve.stop.code == StopCode.NONPOSITIVE_PRESSURE and curve.end == CurveEnd.NONPOSITIVE_PRESSURE
    assert curve.critical is None and curve.merge is None and curve.merges == []
    assert np.all(curve.pressure > 0) and np.all(np.diff(curve.q) > 0)
    assert 0.25 < curve.q[-1] < 0.3 and len(curve.q) < 100
    assert "P reached 0 at M = 0.27" in curve.stop.message and "before the curve turned back" in curve.describe()


def test_two_coil_curve_in_alpha1_reaches_the_wire(two_coils):
    """Continued in α1, the two-coil pitchfork moves up in pressure and pole stretch until the membrane comes
    within continuation.wire_gap (0.1) of a coil: end WIRE, no critical α1."""
    curve = continue_branch_point(*two_coils, "alpha1")
    assert curve.stop.code == StopCode.WIRE_GAP and curve.end == CurveEnd.WIRE and curve.critical is None
    assert curve.merges == [] and np.all(curve.pressure > 0) and curve.q[-1] > 3


@pytest.mark.parametrize("of", ["BP", "LP"])
def test_a_curve_in_M_stops_where_M_reaches_zero(two_coils, of):
    """M = I²/(16π²R0²μ) is never negative (the scene's range is [0, 1000]): the two-coil pitchfork and the fold of
    P, continued in M downward, stop where M falls below 0 (end ALPHA1_ZERO, the stop of a parameter leaving its
    range) instead of tracing on into M < 0 (they did: a 'cusp' at M = −0.78 was printed as the critical M)."""
    from balloon_cg.analysis.critical.fold_curve import continue_fold
    from balloon_cg.analysis.results import Kind

    branch, bp = two_coils
    if of == "BP":
        curve = continue_branch_point(branch, bp, "M", direction=-1.0)
    else:
        curve = continue_fold(branch, next(s for s in branch.special if s.kind == Kind.LP), "M", direction=-1.0)
    assert curve.stop.code == StopCode.ALPHA1_ZERO and curve.end == CurveEnd.ALPHA1_ZERO
    assert curve.critical is None and np.all(curve.q >= 0) and np.all(np.diff(curve.q) < 0)
    assert "M fell below 0" in curve.stop.message


def test_fold_without_the_partner_is_not_a_merge():
    """A coil of radius 2.2 in the equatorial plane: the curve turns back in M at P > 0 (M ≈ 0.030) but reaches the
    wire gap before it comes back to the scene's M: end FOLD, the fold APPROXIMATE, no critical M."""
    scene = parse_scene('[material]\npreset = "SPOM1"\n[field]\nM = 0.002\n[[field.coils]]\nradius = 2.2\n'
                        'height = 0.0\ncurrent = 1.0\n[continuation]\nstop_stretch = 2.0\nwire_gap = 0.1\n',
                        name="coil_2.2")
    branch = trace_primary(scene, down=False)
    curve = continue_branch_point(branch, _pear_points(branch)[0], "M")
    assert curve.stop.code == StopCode.WIRE_GAP and curve.end == CurveEnd.FOLD
    assert curve.critical is None and curve.merge is None
    assert len(curve.merges) == 1 and curve.merges[0].status == Status.APPROXIMATE
    assert "not verified" in curve.merges[0].reason and curve.merges[0].X[curve.n] > 0
    assert 0.02 < curve.merges[0].X[-1] < 0.04 and curve.q[-1] > curve.q0
    assert "turns back in M" in curve.describe()
