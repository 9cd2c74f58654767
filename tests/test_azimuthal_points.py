"""Branch points of the non-axisymmetric blocks (m ≥ 1): located on a field scene, stored with their m, none of
their own at M = 0 (there the m = 1 crossing is the tilted copy of the pear point)."""
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.analysis.points import azimuthal_points
from balloon_cg.analysis.stability.azimuthal import spectrum
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.results import Block, Classification, Kind, Status
from balloon_cg.analysis.stability.axisymmetric import assessed_degrees, point_degrees
from balloon_cg.app.cli import main
from balloon_cg.io.run_file import read_run, write_run
from balloon_cg.scene import load_scene, parse_scene

SCENES = Path(__file__).resolve().parents[1] / "scenes"


@pytest.fixture(scope="module")
def field_scene():
    return load_scene(SCENES / "spom1_two_coils_M0.002.toml").with_overrides({"continuation.stop_stretch": 2.0})


@pytest.fixture(scope="module")
def field_picture(field_scene):
    return analyse(field_scene, pear=False)


def azimuthal(branch) -> list:
    return [s for s in branch.special if s.m >= 1]


def location_degree(branch, s, scene) -> int:
    """The perturbation degree a point was located at: the larger of its bracketing points' assessment degrees (at
    least stability.degree; on the branch's wire map by default, below the degree in x that holds the state next
    to the wire, which the tests below check the location at as well)."""
    degrees = assessed_degrees(branch)
    assert min(degrees[s.index: s.index + 2]) >= scene.stability.degree
    return max(degrees[s.index], degrees[s.index + 1])


def test_held_m1_crossing_is_located(field_scene, field_picture):
    branch = field_picture.primary
    held = [s for s in azimuthal(branch) if s.block == Block.M1_HELD]
    assert held, "the held m = 1 eigenvalue crosses zero on this branch"
    s = held[0]
    assert (s.kind, s.m, s.status, s.classification) == (Kind.BP, 1, Status.LOCATED, Classification.NONE)
    for degree in (location_degree(branch, s, field_scene), max(point_degrees(branch, 20)[s.index: s.index + 2])):
        mu = spectrum(equilibrium_of(branch), s.X[:-1], branch.params.with_value("P", s.X[-1]), 1, degree, 3, held=True)
        assert abs(mu[0]) <= 1e-8, degree
    P0, P1 = branch.X[s.index, -1], branch.X[s.index + 1, -1]
    assert min(P0, P1) < s.X[-1] < max(P0, P1)
    north = branch.pole_values()["lam2_top"][s.index: s.index + 2]
    assert north.min() < branch.pole_values(s.X)["lam2_top"][0] < north.max()
    # before the pear pitchfork (P = 2.2527) along the branch; located at the degree that holds the branch there
    # (100): 2.2642302776 at perturbation degrees 60, 90 and 135 alike, 2.2642244744 at the old fixed degree 20
    assert s.X[-1] == pytest.approx(2.2642302776, abs=1e-9)


def test_every_m1_point_is_a_zero_of_its_block(field_scene, field_picture):
    branch = field_picture.primary
    eq = equilibrium_of(branch)
    for s in azimuthal(branch):
        held = s.block == Block.azimuthal(s.m, held=True)
        for degree in (location_degree(branch, s, field_scene), max(point_degrees(branch, 20)[s.index: s.index + 2])):
            mu = spectrum(eq, s.X[:-1], branch.params.with_value("P", s.X[-1]), s.m, degree, 3, held=held)
            assert np.abs(mu).min() <= 1e-8 and s.status == Status.LOCATED, degree


def test_m1_points_stay_on_the_branch_only(field_picture):
    branch = field_picture.primary
    assert not any(bp.m for bp in field_picture.branch_points)
    assert [s.index for s in branch.special] == sorted(s.index for s in branch.special)


def test_run_file_round_trips_m(tmp_path, field_scene, field_picture):
    branch = field_picture.primary
    stored = read_run(write_run(tmp_path / "run.h5", field_scene, [branch]))["branches"]["primary"]
    assert [s["m"] for s in stored["special_points"]] == [s.m for s in branch.special]
    assert [s["block"] for s in stored["special_points"]] == [s.block.value for s in branch.special]
    assert any(s["m"] == 1 for s in stored["special_points"])


def test_inspect_shows_m(tmp_path, field_scene, field_picture, capsys):
    path = write_run(tmp_path / "run.h5", field_scene, [field_picture.primary])
    assert main(["inspect", str(path)]) == 0
    assert "BP m=1" in capsys.readouterr().out


def test_no_m1_point_of_its_own_at_zero_field():
    scene = parse_scene('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 2.0\n', "sphere")
    picture = analyse(scene, pear=False)
    branch = picture.primary
    assert not azimuthal(branch)
    # the m = 1 eigenvalue does cross, at the pear point: its tilted copy on the sphere (the zero modes are
    # removed), an exact zero there
    crossings = azimuthal_points.crossings(branch.stability, scene.stability.m_max)
    assert crossings and {c[0] for c in crossings} == {bp.index for bp in picture.branch_points}
    assert all(azimuthal_points.is_copy(branch, c[0]) for c in crossings)
    eq = equilibrium_of(branch)
    for bp in picture.branch_points:
        mu = spectrum(eq, bp.X[:-1], branch.params.with_value("P", bp.X[-1]), 1, scene.stability.degree, 3,
                      held=True)
        assert np.abs(mu).min() <= 1e-8


def test_under_resolved_m1_crossings_are_refined_away():
    """TPOM1 between the two coils at M = 0.003, stability degree 20: the held m = 1 eigenvalue is under-resolved
    at the far end of the pear branches, where at a fixed degree two spurious crossings were stored APPROXIMATE.
    The degree follows the mode (crossings.follow_modes): those points are raised, their eigenvalue there agrees
    with an independent computation at three times the degree (sign, and to half its size), no spurious crossing
    is left and the result is complete, with the special points of the run at degree 40 (the shipped scene): the
    same kinds, blocks and intervals, the primary branch's m = 1 points at the same P (located at the degree that
    holds the equilibrium there), the pear branch's within 1e-4 (at its degree 20 against 40)."""
    from balloon_cg.analysis.stability.crossings import resolved
    from balloon_cg.analysis.verdict import failing

    scene = load_scene(SCENES / "tpom1_two_coils_M0.003.toml").with_overrides({"surface.branches": "none"})
    coarse = analyse(scene.with_overrides({"stability.degree": 20}))
    fine = analyse(scene)
    assert not failing(coarse.incomplete) and not failing(fine.incomplete)
    pear = coarse.branches[1]
    raised = [n for n, a in enumerate(pear.stability) if a.degree > 20]
    assert raised
    eq = equilibrium_of(pear)
    for n in raised[::3]:
        a, X = pear.stability[n], pear.X[n]
        mu = spectrum(eq, X[:-1], pear.params.with_value("P", X[-1]), 1, 3 * a.degree, 1, held=True)[0]
        assert resolved(a.blocks[Block.M1_HELD][0], mu), (n, a.degree, a.blocks[Block.M1_HELD][0], mu)
    for b, reference in zip(coarse.branches, fine.branches):
        found, expected = azimuthal(b), azimuthal(reference)
        assert [(s.block, s.index, s.status) for s in found] == [(s.block, s.index, s.status) for s in expected]
        tolerance = 1e-9 if b.name == "primary" else 1e-4
        assert all(abs(s.X[-1] - r.X[-1]) <= tolerance for s, r in zip(found, expected))
