"""Branch points, pear-shaped branches and isolas at M = 0 and with the paper's coils (MODEL.md §5)."""
import numpy as np
import pytest

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Block, Classification, Kind, Origin, Status, StopCode
from balloon_cg.analysis.switching.pear import mark_rejoin, trace_pear
from balloon_cg.scene.materials import get_preset
from balloon_cg.scene import parse_scene
from balloon_cg.model.sphere import sphere_pressure
from balloon_cg.model.sphere_modes import bifurcation_stretches
from shared_pictures import two_coil_picture

ISOLA = ["SPOM1", "SPOM2", "FPOM1", "FPOM2"]
SINGLE = ["TPOM1", "TPOM2"]


def scene_for(preset, stop=6.0):
    return parse_scene(f'[material]\npreset = "{preset}"\n[continuation]\nstop_stretch = {stop}\n', name=preset)


@pytest.fixture(scope="module", params=ISOLA + SINGLE)
def picture(request):
    return request.param, analyse(scene_for(request.param, stop=10.0 if request.param in ISOLA else 6.0))


def pear_points(picture):
    name, pic = picture
    primary = pic.branches[0]
    bps = [bp for bp in pic.branch_points if bp.block == Block.ODD_HELD]
    return name, pic, primary, bps


def test_pear_bifurcations_match_the_independent_sphere_condition(picture):
    """Stretches to 1e-8 (relative) against the closed-form mode-1 condition of sphere_modes; P against the
    exact sphere pressure."""
    name, pic, primary, bps = pear_points(picture)
    expected = bifurcation_stretches(get_preset(name), 1, lam_max=primary.pole_values()["lam2_top"].max())
    found = np.array([primary.pole_values(bp.X)["lam2_top"][0] for bp in bps])
    assert found.size == expected.size
    np.testing.assert_allclose(found, expected, rtol=1e-8)
    for bp, lam in zip(bps, found):
        assert bp.X[-1] == pytest.approx(sphere_pressure(get_preset(name), lam), rel=1e-10)
        assert bp.kind == Kind.BP and bp.status == Status.LOCATED
        assert bp.classification in (Classification.PITCHFORK_SUPER, Classification.PITCHFORK_SUB)


def test_isola_or_single_pitchfork(picture):
    """SPOM/FPOM: two pear branch points joined by a closed loop; TPOM: one, its branch leaves the range."""
    name, pic, primary, bps = pear_points(picture)
    pears = {b.name: b for b in pic.branches if b.name.startswith("pear")}
    if name in ISOLA:
        assert len(bps) == 2
        assert set(pears) == {"pear_0", "pear_0_mirror"}
        for branch in pears.values():
            assert branch.stopped(StopCode.REJOINED) and branch.rejoins == 1
            assert branch.pressure[-1] == pytest.approx(bps[1].X[-1], rel=1e-2)
    else:
        assert len(bps) == 1
        for branch in pears.values():
            assert not branch.stopped(StopCode.REJOINED) and branch.rejoins is None


def test_mirror_branch_swaps_the_poles(picture):
    """The traced mirror image (−φ: an independent continuation) has the pear branch's south pole stretch at its
    north pole, and the stored mirror (the pear branch reflected, analysis.switching.mirror) agrees with it point by point
    in P and both pole stretches, in its stops and in its special points."""
    _, pic, primary, bps = pear_points(picture)
    branches = {b.name: b for b in pic.branches}
    pear, mirror = branches["pear_0"], branches["pear_0_mirror"]
    traced = trace_pear(primary, bps[0], -1.0, "traced")
    if pear.rejoins is not None:
        mark_rejoin(traced, primary, bps[pear.rejoins])
    assert mirror.origin == Origin.REFLECTED and mirror.reflection_of == "pear_0"
    assert traced.origin == Origin.TRACED and len(traced.X) == len(mirror.X) == len(pear.X)
    np.testing.assert_allclose(traced.pole_values()["lam2_top"], pear.pole_values()["lam2_bottom"], rtol=1e-9)
    assert np.abs(pear.pole_values()["lam2_top"] - pear.pole_values()["lam2_bottom"]).max() > 0.5
    np.testing.assert_allclose(mirror.X[:, -1], traced.X[:, -1], rtol=1e-9)
    for pole in ("lam2_top", "lam2_bottom", "eta_top", "eta_bottom"):
        np.testing.assert_allclose(mirror.pole_values()[pole], traced.pole_values()[pole], rtol=1e-9, atol=1e-9)
    assert [leg.stop.code for leg in mirror.legs] == [leg.stop.code for leg in traced.legs]
    own = [s for s in mirror.special if s.m == 0]  # the m ≥ 1 points are found on each stored branch (analyse)
    assert [(s.kind, s.index) for s in own] == [(s.kind, s.index) for s in traced.special]
    for s, t in zip(own, traced.special):
        assert s.X[-1] == pytest.approx(t.X[-1], rel=1e-9)
        assert mirror.pole_values(s.X)["lam2_top"][0] == pytest.approx(traced.pole_values(t.X)["lam2_top"][0],
                                                                         rel=1e-9)


def test_every_point_has_stability(picture):
    _, pic, _, _ = pear_points(picture)
    for branch in pic.branches:
        assert len(branch.stability) == len(branch.X)


def test_tpom_bifurcation_pressure_decreases_with_alpha():
    pressures = []
    for name in SINGLE:
        lam = bifurcation_stretches(get_preset(name), 1, lam_max=6.0)[0]
        pressures.append(sphere_pressure(get_preset(name), lam))
    assert get_preset("TPOM2").alpha[0] > get_preset("TPOM1").alpha[0]
    assert pressures[1] < pressures[0]


def test_two_coils_have_one_pear_branch_point_and_no_isola(tmp_path_factory):
    pic = two_coil_picture(tmp_path_factory)  # the shipped scene's axisymmetric picture (tests/shared_pictures.py)
    bps = [bp for bp in pic.branch_points if bp.block == Block.ODD_HELD]
    assert len(bps) == 1
    assert not any(b.stopped(StopCode.REJOINED) for b in pic.branches if b.name.startswith("pear"))
