"""The free balloon in a field without equator symmetry (issue 41): one coil off the equator (r = 2, h = 0.5,
M = 0.002). Its held states carry the field's net axial force (the hold's reaction), so the free balloon has its own
primary branch, traced with the axial translation an unknown (``trace_primary(held=False)``), and its own m = 1
points and branches. A single loop's H² is symmetric about the loop's plane, so the net force on a balloon centred
there vanishes: the free balloon is the balloon of the coil at h = 0 moved up by 0.5, which the tests use as an
independent check (a state moved by −0.5 must be an equilibrium of the h = 0 scene, with its spectrum)."""
import numpy as np
import pytest

from balloon_cg.analysis.points import azimuthal_points, free_pitchforks
from balloon_cg.analysis.stability import azimuthal
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.results import Block, Classification, Gauge, Status
from balloon_cg.analysis.stability.axisymmetric import SecondVariation, assess_branch, assessed_degrees
from balloon_cg.analysis.surface.branches import SurfaceTrace, trace_surface
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.surface.basis import MIRROR_Y, SphericalBasis
from balloon_cg.surface.embedding import axisymmetric_coefficients
from balloon_cg.surface.loads import loads
from balloon_cg.surface.equilibrium import SurfaceEquilibrium
from test_off_equator import coil_at



def coil(height: float):
    """SPOM1, one coil r = 2 at ``height``, M = 0.002 (``test_off_equator``'s), to λ2(0) = 1.7 (past the free
    m = 1 point, λ2(0) = 1.66, at a third of the issue's scene's points) at the default wire_gap."""
    return coil_at(height).with_overrides({"continuation.stop_stretch": 1.7, "continuation.wire_gap": 0.02},
                                          name=f"coil_at_{height:g}")


HELD_FREE_READING = 2.202508818  # the free-reading m = 1 point of the held branch (the 'free m = 1 point')


@pytest.fixture(scope="module")
def free_primary():
    """The free balloon's primary branch up from the start to λ2(0) = 1.7, assessed, its m ≥ 1 points located."""
    scene = coil(0.5)
    branch = trace_primary(scene, down=False, held=False, name="primary_free")
    branch.stability, branch.unsettled = assess_branch(branch, scene.stability.degree, False, check=True,
                                                       m_max=scene.stability.m_max)
    branch.special += azimuthal_points.find(branch, assessed_degrees(branch), scene.stability.m_max)
    return branch


def moved_down(branch, X) -> tuple:
    """(the h = 0 scene's Equilibrium, the point X = (u, P) of ``branch`` moved down by 0.5 on its
    discretisation: b_0 − 0.5)."""
    at_zero = coil(0.0)
    disc = branch.disc
    eq = Equilibrium(at_zero, Discretisation(disc.degree, False, False, disc.quadrature, disc.mapping))
    a, b = disc.split(X[:-1])
    b[0] -= 0.5
    return eq, np.append(disc.join(a, b), X[-1])


def test_the_free_primary_branch_centres_where_the_net_force_vanishes(free_primary):
    """Every point: the centre (b_0) at the coil's plane z = 0.5 to 1e-10, the net axial force by the whole-sphere
    quadrature of ∇H² (surface.loads, not the residual) ≤ 1e-10 at every tenth point, and the point moved down by
    0.5 has on the coil at h = 0 the residual it has here (to 1e-13, every entry): the free balloon is that
    balloon moved up (the solver's residual record ≤ 1e-10)."""
    branch = free_primary
    assert branch.gauge == Gauge.FREE and not branch.disc.pin_translation and branch.residual.max() <= 1e-10
    for X in branch.X:
        a, b = branch.disc.split(X[:-1])
        assert abs(b[0] - 0.5) <= 1e-10
    surface = SurfaceEquilibrium(branch.scene, SphericalBasis(branch.disc.degree, (MIRROR_Y,), order=2,
                                                              mapping=branch.disc.mapping))
    for X in branch.X[::10]:
        c = axisymmetric_coefficients(surface.basis, branch.disc, X[:-1])
        assert np.abs(loads(surface, c, branch.params_at(X))["force"]).max() <= 1e-10
    own = equilibrium_of(branch)
    for X in branch.X:
        at_zero, Y = moved_down(branch, X)
        difference = at_zero.residual(Y[:-1], branch.params_at(X)) - own.residual(X[:-1], branch.params_at(X))
        assert np.abs(difference).max() <= 1e-13


def test_the_free_m1_point_is_the_translated_balloons_and_not_the_held_branchs(free_primary):
    """The free reading's m = 1 point of the free branch (located, P = 2.253168747) is the free m = 1 point of the
    coil at h = 0 moved up: the lowest free m = 1 eigenvalue of the moved-down state on the h = 0 scene vanishes
    (≤ 1e-9 of the spectrum's scale). The free-reading zero the held branch carries (P = 2.202508818) is another P:
    a zero of the free second variation of states that are no free equilibria."""
    bp = next(s for s in free_primary.special if s.block == Block.M1_FREE)
    assert bp.status == Status.LOCATED and abs(bp.X[-1] - 2.253168747) < 1e-8
    at_zero, Y = moved_down(free_primary, bp.X)
    degree = free_primary.stability[bp.index].degree
    values = azimuthal.spectrum(at_zero, Y[:-1], free_primary.params_at(bp.X), 1, degree, 3, held=False)
    assert np.abs(values).min() <= 1e-9 * np.abs(values).max()
    assert abs(bp.X[-1] - HELD_FREE_READING) > 0.05


def test_the_free_m1_branch_has_zero_net_force_at_every_point(free_primary):
    """The branch born at the free m = 1 point, traced on the whole sphere (mirror y → −y only, the translation
    an unknown), 6 points: the net field force by surface.loads' quadrature ≤ 1e-10 at every point, the residual of
    the free problem ≤ 1e-10 (point 0 solved, not embedded), the centre at the coil's plane and moving sideways."""
    k, bp = next((k, bp) for k, bp in enumerate(free_primary.branch_points()) if bp.block == Block.M1_FREE)
    branch = trace_surface(free_primary, k, bp, 1.0, "primary_free_m1", 6)
    assert branch.basis.symmetry == (MIRROR_Y,) and not branch.held and len(branch.values) == 6
    assert branch.residual.max() <= 1e-10
    trace = SurfaceTrace(branch.scene, branch.basis, branch.params, held=False)
    for c, P in zip(branch.coefficients, branch.values):
        assert np.abs(loads(trace.eq, c, branch.params.with_value("P", P))["force"]).max() <= 1e-10
    centroid = branch.measures["centroid"]
    assert np.abs(centroid[:, 2] - 0.5).max() <= 1e-10
    assert abs(centroid[0, 0]) < 1e-12 and np.all(np.diff(np.abs(centroid[:, 0])) > 0)


@pytest.fixture(scope="module")
def all_branches():
    """The issue's scene (tests/data/off_equator.toml) analysed with ``[surface] branches = "all"``, 4 points a
    surface branch (~4 min on a loaded 2-core machine: the slow tests below)."""
    from pathlib import Path

    from balloon_cg.analysis.picture import analyse
    from balloon_cg.scene import load_scene

    scene = load_scene(Path(__file__).parent / "data" / "off_equator.toml").with_overrides(
        {"surface.branches": "all", "surface.max_points": 4}, name="off_equator")
    return scene, analyse(scene)


@pytest.mark.slow
def test_the_free_pitchfork_is_the_moved_balloons_free_pear_point(all_branches):
    """The free primary branch's m = 0 zero of the all_free block (P = 2.246446021) is a pitchfork of the symmetry
    about the coil's plane: on the h = 0 scene the moved-down state's lowest free pear (odd_free) eigenvalue vanishes
    (≤ 1e-9 of the block's scale), the zeros of the volume and gas controls' blocks are the same point (classified
    alike), the reduced energy along the critical mode is even there (|E3| δ ≤ 1e-6 |E4| δ², δ = 0.02) and
    supercritical, and the pear branches born there (the balloon free, both ways) leave it: every point a free
    equilibrium (residual ≤ 1e-10) whose net axial force by the whole-sphere quadrature is ≤ 1e-10, its
    translation b_0 leaving the coil's plane as the pear grows."""
    from balloon_cg.analysis.picture import FREE_PRIMARY

    _, picture = all_branches
    branch = next(b for b in picture.branches if b.name == FREE_PRIMARY)
    m0 = [s for s in branch.branch_points() if s.m == 0]
    n, bp = next((n, s) for n, s in enumerate(m0) if s.block == Block.ALL_FREE)
    assert bp.status == Status.LOCATED and abs(bp.X[-1] - 2.246446021) < 1e-8
    same = [s for s in m0 if s.index == bp.index]
    assert {s.block for s in same} == set(free_pitchforks.FREE_BLOCKS)
    assert {s.classification for s in same} == {Classification.PITCHFORK_SUPER}
    E2, E3, E4 = bp.E
    assert abs(E3) * 0.02 <= 1e-6 * abs(E4) * 0.02**2
    at_zero, Y = moved_down(branch, bp.X)
    degree = max(assessed_degrees(branch)[bp.index:bp.index + 2])
    variation = SecondVariation(at_zero, degree)
    values = variation.lowest(Y[:-1], branch.params_at(bp.X), True, "odd_free")  # the moved state is symmetric
    scale = np.abs(variation.lowest(Y[:-1], branch.params_at(bp.X), False, "all_free")).max()
    assert np.abs(values).min() <= 1e-9 * scale
    pears = [b for b in picture.branches if b.parent == (FREE_PRIMARY, n)]
    assert [b.name for b in pears] == [f"{FREE_PRIMARY}_pear_{n}", f"{FREE_PRIMARY}_pear_{n}_mirror"]
    for pear in pears:
        assert pear.gauge == Gauge.FREE and pear.residual.max() <= 1e-10 and len(pear.X) > 5
        surface = SurfaceEquilibrium(pear.scene, SphericalBasis(pear.disc.degree, (MIRROR_Y,), order=2,
                                                                mapping=pear.disc.mapping))
        for X in pear.X:
            c = axisymmetric_coefficients(surface.basis, pear.disc, X[:-1])
            assert np.abs(loads(surface, c, pear.params_at(X))["force"]).max() <= 1e-10
        poles = pear.pole_values()
        assert abs(poles["lam2_top"][-1] - poles["lam2_bottom"][-1]) > 0.1
        assert abs(pear.disc.split(pear.X[-1, :-1])[1][0] - 0.5) > 1e-3


@pytest.mark.slow
def test_the_verdict_names_every_branch_not_traced(all_branches, tmp_path, capsys):
    """The issue's scene (tests/data/off_equator.toml) with ``[surface] branches = "all"`` (4 points a branch): no
    not_searched entry; the free balloon's primary branch traced (primary_free) with its pear branches (its m = 0
    points classified) and its free m = 1 branches; the m = 1 points of the other reading on each branch (the held branch's free-reading zero, primary_free's held
    one) named as not switched with why; the free balloon named once in the summary line. The result is complete:
    the free primary branch's end near the wire (degree 320 on its way to the balloon folded flat about the wire at
    P = 0) is a flattening stop, a limited entry (``test_flattening``)."""
    from balloon_cg.analysis.picture import FREE_PRIMARY
    from balloon_cg.analysis.verdict import Gap, failing
    from balloon_cg.app.cli import main
    from balloon_cg.io.run_file import write_run

    scene, picture = all_branches
    found = picture.incomplete
    assert Gap.NOT_SEARCHED not in {item.gap for item in found} and picture.not_searched == ""
    assert not failing(found), failing(found)
    flat = [item for item in found if item.gap == Gap.LIMITED and item.branch == FREE_PRIMARY]
    assert len(flat) == 1 and flat[0].message.startswith("up leg: flattening") and "max_degree = 320" in flat[0].message
    names = [b.name for b in picture.branches]
    assert names[:3] == ["primary", "broken_pear", FREE_PRIMARY]
    assert names[3:] and all(name.startswith(f"{FREE_PRIMARY}_pear_") for name in names[3:])
    assert Gap.UNCLASSIFIED not in {item.gap for item in found}
    surface = {b.name: b for b in picture.surface_branches}
    held = [name for name, b in surface.items() if b.held]
    free = [name for name, b in surface.items() if not b.held]
    assert held == ["m1_bp0", "m1_bp0_rotated"] and free and all(n.startswith(FREE_PRIMARY) for n in free)
    switched = {item.branch: item.message for item in found if item.gap == Gap.NOT_SWITCHED}
    primary_free_reading = [k for k, s in enumerate(picture.primary.branch_points()) if s.block == Block.M1_FREE]
    assert f"m1_bp{primary_free_reading[0]}" in switched and "no free equilibria" in switched[
        f"m1_bp{primary_free_reading[0]}"]
    assert any(name.startswith(FREE_PRIMARY) and "held-reading points of free states" in message
               for name, message in switched.items())
    path = write_run(tmp_path / "off.h5", scene, picture.branches + picture.surface_branches, snaps=picture.snaps,
                     found=found)
    assert main(["inspect", str(path)]) == 0
    verdict = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("result"))
    assert verdict.split()[1].startswith("complete") and "not_searched" not in verdict
    assert verdict.count("free balloon") <= 1


@pytest.mark.slow
def test_a_refined_basis_resolves_the_last_point_across_the_branch_not_at_fixed_p(all_branches):
    """The branch from the free primary branch's second free m = 1 point (P = 1.6756, near the wire) refines its
    basis one point off the branch point, where it is nearly tangent to P = const: there the Jacobian bordered by
    the P row is nearly singular (smallest singular value 1.3e-6, measured), bordered by the branch's tangent it is
    not (1.0e-3): ``follow`` re-solves the point across the branch, and the branch reaches its max_points (at
    fixed P that Newton failed and the branch stopped after 2 points)."""
    from balloon_cg.analysis.picture import FREE_PRIMARY
    from balloon_cg.numerics import continuation

    _, picture = all_branches
    free = [b for b in picture.surface_branches if b.name.startswith(f"{FREE_PRIMARY}_m1")]
    assert len(free) == 4 and all(len(b.values) == 4 for b in free)
    branch = min(free, key=lambda b: b.values[0])
    assert abs(branch.values[0] - 1.675642) < 1e-6 and branch.basis.degree > branch.scene.surface.degree
    trace = SurfaceTrace(branch.scene, branch.basis, branch.params, held=False)
    X = trace.system.point(branch.coefficients[1], branch.values[1])
    J, pressure = trace.system.jacobian(X), np.eye(X.size)[-1]
    smallest = {name: np.linalg.svd(np.vstack([J, row]), compute_uv=False)[-1]
                for name, row in (("P", pressure), ("tangent", continuation.tangent(trace.system, X, pressure)))}
    assert smallest["P"] < 1e-2 * smallest["tangent"], smallest


def test_a_free_pitchfork_the_chord_misses_is_located_on_the_scene_moved_to_the_coils_plane():
    """Traced to λ2(0) = 1.7 the free primary branch's pear pitchfork is missed by the general layout's root search
    (the chord corrector is singular there: APPROXIMATE, P = 2.2464763); the coil pairs with itself about its plane
    z = 0.5, so it is located on the scene moved down by 0.5 (equator-symmetric: the extended system) and moved up
    (``free_pitchforks.located_by_symmetry``): the zeros of every control's free block LOCATED at the point the
    issue's scene (traced to λ2(0) = 3) locates directly, P = 2.246446021 (1e-8), its state a free equilibrium
    of the scene (residual ≤ 1e-9) centred at z = 0.5, and on the h = 0 scene the moved-down state's lowest free
    pear eigenvalue vanishes (≤ 1e-9 of the block's scale); classified a supercritical pitchfork."""
    from balloon_cg.analysis.points import control_points
    from balloon_cg.analysis.branches.problem import branch_system

    scene = coil(0.5)
    assert free_pitchforks.symmetry_plane(scene.field.coils) == 0.5
    branch = trace_primary(scene, down=False, held=False, name="primary_free")
    branch.stability, branch.unsettled = assess_branch(branch, scene.stability.degree, False)
    branch.special += control_points.find(branch)
    missed = [s for s in branch.special if s.block in free_pitchforks.FREE_BLOCKS]
    assert len(missed) == 3 and {s.status for s in missed} == {Status.APPROXIMATE}
    [(n, bp)] = free_pitchforks.classified(branch)
    same = [s for s in branch.special if s.block in free_pitchforks.FREE_BLOCKS]
    assert {s.status for s in same} == {Status.LOCATED} and {s.X[-1] for s in same} == {bp.X[-1]}
    assert abs(bp.X[-1] - 2.246446021) < 1e-8 and bp.classification == Classification.PITCHFORK_SUPER
    assert np.abs(branch_system(branch).residual(bp.X)).max() <= 1e-9
    assert abs(branch.disc.split(bp.X[:-1])[1][0] - 0.5) <= 1e-10
    at_zero, Y = moved_down(branch, bp.X)
    variation = SecondVariation(at_zero, max(assessed_degrees(branch)[bp.index:bp.index + 2]))
    values = variation.lowest(Y[:-1], branch.params_at(bp.X), True, "odd_free")
    scale = np.abs(variation.lowest(Y[:-1], branch.params_at(bp.X), False, "all_free")).max()
    assert np.abs(values).min() <= 1e-9 * scale
