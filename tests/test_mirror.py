"""The mirror image of a pear branch as its reflection z → −z (analysis.switching.mirror, Discretisation.reflect): the
reflection operator on plain and mapped bases, the residual check and its fallback to a traced mirror, and the
copied assessments against the traced mirror's own. The traced mirror's points, stops and special points are
compared in tests/test_bifurcation.py (six presets at M = 0) and tests/test_coordinate_map.py (two coils, mapped)."""
from dataclasses import replace

import numpy as np
import pytest

from balloon_cg.analysis.switching import mirror as mirror_module
from balloon_cg.analysis.switching.mirror import reflection, reflection_excess
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.branches.problem import branch_system
from balloon_cg.analysis.results import Kind, Leg, Origin, Stop, StopCode
from balloon_cg.analysis.stability.axisymmetric import FLAGS, assess_branch
from balloon_cg.analysis.switching.pear import mark_rejoin, trace_pear
from balloon_cg.galerkin.coordinate_map import WireMap
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.scene import parse_scene

SPOM1 = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 6.0\n'


@pytest.fixture(scope="module")
def picture():
    return analyse(parse_scene(SPOM1, "spom1"))


@pytest.mark.parametrize("disc", [
    Discretisation(24, False, True), Discretisation(24, False, False),
    Discretisation(48, False, True, mapping=WireMap((-0.3, 0.55), (0.07, 0.12))),
    Discretisation(48, False, False, mapping=WireMap((0.5,), (0.05,)))], ids=["held", "free", "map2", "map1-free"])
def test_reflection_is_x_to_minus_x_with_eta_odd(disc):
    """λ2̃(θ) = λ2(π − θ), η̃(θ) = −η(π − θ) (and their θ-derivatives with the opposite parities) to rounding, on the
    mirrored map for a mapped basis; on a map the same signs on the unmirrored map are not the reflection."""
    u = np.random.default_rng(3).normal(size=disc.size) / (1.0 + np.arange(disc.size)) ** 2
    theta = np.linspace(0.0, np.pi, 61)
    mirrored = disc.reflected()
    lam2, dlam2, eta, deta = disc.evaluate(u, theta)
    r_lam2, r_dlam2, r_eta, r_deta = mirrored.evaluate(disc.reflect(u), theta[::-1])
    np.testing.assert_allclose(r_lam2, lam2, atol=1e-14)
    np.testing.assert_allclose(r_eta, -eta, atol=1e-14)
    np.testing.assert_allclose(r_dlam2, -dlam2, atol=1e-13)
    np.testing.assert_allclose(r_deta, deta, atol=1e-13)
    if disc.mapping is not None:
        assert mirrored.mapping.centres == tuple(-c for c in reversed(disc.mapping.centres))
        assert np.abs(disc.evaluate(disc.reflect(u), theta[::-1])[0] - lam2).max() > 1e-4


def test_equator_symmetric_state_is_its_own_reflection(picture):
    primary = picture.primary
    general = Discretisation(40, False, True)
    X = primary.disc.transfer(primary.X[30], general)
    np.testing.assert_array_equal(general.reflect(X), X)


def test_reflected_pear_point_solves_its_own_system(picture):
    """A converged point of the pear branch (not symmetric), reflected: its residual on the mirrored system equals
    the point's own to rounding, and the reflection moved it (the pear amplitude λ2(0) − λ2(π) changes sign)."""
    pear = picture.branches[1]
    system = branch_system(pear)
    for X in pear.X[::20]:
        Y = pear.disc.reflect(X)
        assert np.abs(system.residual(Y)).max() <= np.abs(system.residual(X)).max() + 1e-14
        poles, reflected = pear.pole_values(X), pear.pole_values(Y)
        assert reflected["lam2_top"][0] == pytest.approx(poles["lam2_bottom"][0], abs=1e-14)
        assert reflected["eta_top"][0] == pytest.approx(-poles["eta_bottom"][0], abs=1e-14)
    assert np.abs(pear.disc.reflect(pear.X) - pear.X).max() > 0.1
    assert np.abs(reflection_excess(pear, picture.branches[2])).max() < 1e-13


def test_copied_assessments_match_the_traced_mirrors_own(picture):
    """The stored mirror's assessments (copied from the pear branch) against the traced mirror assessed on its own:
    every flag at every point, every block's lowest eigenvalues to 1e-9, the same unsettled points."""
    primary, pear, mirror = picture.branches
    bp = picture.branch_points[0]
    traced = trace_pear(primary, bp, -1.0, "traced")
    mark_rejoin(traced, primary, picture.branch_points[pear.rejoins])
    scene = primary.scene
    stability, unsettled = assess_branch(traced, scene.stability.degree, False, check=True, m_max=scene.stability.m_max)
    assert mirror.stability is not pear.stability and len(stability) == len(mirror.stability)
    assert mirror.unsettled == unsettled
    for ours, theirs in zip(mirror.stability, stability):
        assert ours.flags() == theirs.flags() and ours.degree == theirs.degree
        assert ours.blocks.keys() == theirs.blocks.keys()
        for name in ours.blocks:
            np.testing.assert_allclose(ours.blocks[name], theirs.blocks[name], rtol=1e-9, atol=1e-9)
    assert any(not a.flags()[FLAGS[0]] for a in mirror.stability)  # the isola has unstable points to compare


def test_not_reflected_where_the_trace_is_one_sided_or_the_check_fails(picture):
    """A pear branch stopped on min_stretch (a north-pole rule) is not reflected; in a scene that is not invariant
    under z → −z (one coil above the equator, M = 0.002) the reflected points fail the residual check."""
    pear = picture.branches[1]
    stopped = replace(pear, legs=(Leg("forward", Stop(StopCode.MIN_STRETCH, "reached min_stretch")),))
    assert reflection(stopped, [], "m") == Origin.TRACED_NOT_REFLECTABLE
    one_coil = parse_scene(SPOM1 + "[field]\nM = 0.002\n[[field.coils]]\nradius = 2.0\nheight = 0.5\n"
                                   "current = 1.0\n", "one_coil")
    lopsided = replace(pear, scene=one_coil, params=replace(pear.params, M=0.002))
    assert reflection(lopsided, [], "m") == Origin.TRACED_REFLECTION_FAILED
    assert reflection_excess(lopsided, replace(lopsided, disc=pear.disc, X=pear.disc.reflect(pear.X))).max() > 1e-6
    assert isinstance(reflection(pear, [], "m"), type(pear))


def test_failed_reflection_is_traced_and_recorded(monkeypatch):
    """When the reflection is refused the mirror is traced and assessed as before, its origin saying why."""
    monkeypatch.setattr(mirror_module, "reflection", lambda pear, turns, name: Origin.TRACED_REFLECTION_FAILED)
    picture = analyse(parse_scene(SPOM1, "spom1"))
    pear, traced = picture.branches[1:]
    assert traced.name == "pear_0_mirror" and traced.origin == Origin.TRACED_REFLECTION_FAILED
    assert traced.reflection_of == "" and traced.stability is not None and traced.rejoins == pear.rejoins == 1
    np.testing.assert_allclose(traced.pole_values()["lam2_top"], pear.pole_values()["lam2_bottom"], rtol=1e-9)


def test_every_special_point_of_a_mirror_on_a_map_is_the_reflected_state(picture):
    """On a wire-mapped basis (here the SPOM1 pear branch moved onto a map centred off the equator) each special
    point of the mirror, the rejoin BP included, evaluated on the mirror's (mirrored) map is its source's state
    reflected: λ2̃(θ) = λ2(π − θ), η̃(θ) = −η(π − θ), to rounding. (An equator-symmetric state's coefficients on a
    map are not their own reflection: the rejoin kept as it was read 1e-2 off on the mirrored map, the paper
    coil's pear_0_mirror BP that was not singular on its own system.)"""
    primary, pear = picture.branches[:2]
    mapped = Discretisation(pear.disc.degree, False, pear.disc.pin_translation, mapping=WireMap((0.5,), (0.05,)))
    rejoin = picture.branch_points[pear.rejoins]  # where mark_rejoin puts it (a fold candidate there at stretch 6)
    special = [replace(s, X=pear.disc.transfer(s.X, mapped)) for s in pear.special]
    special.append(replace(rejoin, index=len(pear.X) - 2, X=primary.disc.transfer(rejoin.X, mapped)))
    moved = replace(pear, disc=mapped, X=pear.disc.transfer(pear.X, mapped), special=special)
    image = reflection(moved, [], "m")
    theta = np.linspace(0.0, np.pi, 41)
    kinds = [s.kind for s in image.special]
    assert Kind.BP in kinds and len(image.special) >= 2
    sources = [s for s in moved.special if s.kind not in (Kind.TP, Kind.UZ)]
    for ours, theirs in zip(image.special, sorted(sources, key=lambda s: s.index)):
        lam2, _, eta, _ = image.disc.evaluate(ours.X[:-1], theta)
        source_lam2, _, source_eta, _ = mapped.evaluate(theirs.X[:-1], theta[::-1])
        np.testing.assert_allclose(lam2, source_lam2, atol=1e-12, err_msg=str(ours))
        np.testing.assert_allclose(eta, -source_eta, atol=1e-12, err_msg=str(ours))
        assert ours.X[-1] == theirs.X[-1]
