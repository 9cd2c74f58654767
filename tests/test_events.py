"""User events (``[[events]]``, analysis/branches/events.py): UZ points where a stored quantity reaches a value, on the
primary branch, the pear branches and their mirror images; the scene table's one-line errors."""
import numpy as np
import pytest

from balloon_cg.analysis.branches.control import control_value
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.branches.problem import branch_system
from balloon_cg.analysis.results import Kind, Status
from balloon_cg.galerkin.profiles import equator_values, fields
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import Control, SceneError, load_scene, parse_scene

VOLUME = 20.0  # the two-coil pear branches span V = 19.50 .. 20.14, the primary branch 4.2 .. 26.8
EQUATOR = 1.5  # the primary branch spans λ2(π/2) = 1.0001 .. 1.857
NODES, WEIGHTS = np.polynomial.legendre.leggauss(400)
THETA, QUADRATURE = 0.5 * np.pi * (NODES + 1), 0.5 * np.pi * WEIGHTS


def enclosed_volume(disc, X) -> float:
    """V = −π ∫ ρ² η'(θ) dθ (ρ = λ2 sin θ), 400-point Gauss quadrature of the profile: not the solver's formula."""
    lam2, _, _, deta = fields(disc, np.atleast_2d(X)[:, :-1], THETA)
    return float(-np.pi * QUADRATURE @ ((lam2[0] * np.sin(THETA)) ** 2 * deta[0]))


@pytest.fixture(scope="module")
def picture():
    scene = load_scene("spom1_two_coils_M0.002").with_overrides({"surface.branches": "none"})
    scene = parse_scene(scene.to_toml() + f'\n[[events]]\nquantity = "volume"\nvalue = {VOLUME}\n'
                        f'\n[[events]]\nquantity = "lam2_equator"\nvalue = {EQUATOR}\n', "two_coils_events")
    return analyse(scene)


def user_points(branch, note):
    return [s for s in branch.special if s.kind == Kind.UZ and s.note == note]


def test_volume_event_on_the_primary_and_the_pear_branches(picture):
    """Every interval where V − 20 changes sign holds one UZ point, located: V there is 20 to 1e-10 relative by
    an independent quadrature, the point is an equilibrium of the branch's system, and Newton at its north pole
    stretch from the nearest stored point (another solve) lands on the same state and volume."""
    names = [b.name for b in picture.branches]
    assert {"primary", "pear_0", "pear_0_mirror"} <= set(names)
    for branch in picture.branches:
        volumes = np.array([control_value(branch.disc, X, Control.VOLUME) for X in branch.X])
        crossings = np.flatnonzero(np.diff(np.sign(volumes - VOLUME)) != 0)
        located = user_points(branch, "volume = 20")
        assert [s.index for s in located] == list(crossings) and located, branch.name
        system = branch_system(branch)
        north = np.append(branch.disc.pole_rows()["lam2_top"], 0.0)
        for s in located:
            assert s.status == Status.LOCATED
            assert abs(enclosed_volume(branch.disc, s.X) / VOLUME - 1) < 1e-10
            assert np.abs(system.residual(s.X)).max() < 10 * branch.scene.solver.tol
            again = newton(system.residual, system.jacobian, branch.X[s.index], north, north @ s.X,
                           branch.scene.solver.tol, branch.scene.solver.max_newton)
            assert again.converged and np.abs(again.x - s.X).max() < 1e-9
            assert abs(enclosed_volume(branch.disc, again.x) / VOLUME - 1) < 1e-10


def test_equator_event_is_located_where_it_is_crossed(picture):
    """λ2(π/2) = 1.5 (a linear row in u): every crossing located to 1e-12 on every branch that has one."""
    found = 0
    for branch in picture.branches:
        stretches = equator_values(branch.disc, branch.X)["lam2_equator"]
        crossings = np.flatnonzero(np.diff(np.sign(stretches - EQUATOR)) != 0)
        located = user_points(branch, "lam2_equator = 1.5")
        assert [s.index for s in located] == list(crossings), branch.name
        for s in located:
            assert abs(equator_values(branch.disc, s.X)["lam2_equator"][0] - EQUATOR) < 1e-12
        found += len(located)
    assert found >= 1


def test_mirror_image_events_are_its_own(picture):
    """The mirror image of a pear branch has its UZ points located on it (not reflected copies of a pole event):
    the volume event at the same index and volume as on its partner."""
    pear, mirror = (next(b for b in picture.branches if b.name == name) for name in ("pear_0", "pear_0_mirror"))
    assert [s.index for s in user_points(pear, "volume = 20")] == [s.index for s in user_points(mirror, "volume = 20")]


@pytest.mark.parametrize("table, message", [
    ('[[events]]\nquantity = "volum"\nvalue = 20', 'events[0].quantity = "volum": must be one of "volume", "amount", '
                                                   '"pressure", "lam2_top", "lam2_bottom", "lam2_equator", '
                                                   '"volume_ratio", "lam2_max", "axial_stretch" (did you mean '
                                                   'volume?)'),
    ('[[events]]\nquantity = "volume"\nvalue = 0', "events[0].value = 0: must be > 0"),
    ('[[events]]\nquantity = "volume"\nvalue = "20"', 'events[0].value = "20": must be a number'),
    ('[[events]]\nquantity = "volume"', "events[0].value: missing (an event needs quantity and value)"),
    ('[[events]]\nquantity = "volume"\nvalue = 20\nat = 1', "events[0].at = 1: unknown key; allowed keys: quantity, "
                                                           "value"),
])
def test_events_table_errors_are_one_line(table, message):
    with pytest.raises(SceneError) as error:
        parse_scene(f'[material]\npreset = "SPOM1"\n{table}\n', "s")
    assert str(error.value) == f"s: {message}"


def test_events_round_trip_through_the_scene_text():
    scene = parse_scene('[material]\npreset = "SPOM1"\n[[events]]\nquantity = "volume"\nvalue = 20\n', "s")
    assert parse_scene(scene.to_toml(), "s").events == scene.events and scene.events[0].value == 20.0


def test_an_event_value_is_a_scene_key():
    """`--set events[0].value=30` (with_overrides) changes an event, re-validated; one that is not there is named."""
    scene = parse_scene('[material]\npreset = "SPOM1"\n[[events]]\nquantity = "volume"\nvalue = 20\n', "s")
    assert scene.with_overrides({"events[0].value": 30}).events[0].value == 30.0
    for key, value, message in (("events[1].value", 3, "s: events[1].value = 3: there is no events[1]"),
                                ("events[0].value", -3, "s: events[0].value = -3: must be > 0")):
        with pytest.raises(SceneError) as error:
            scene.with_overrides({key: value})
        assert str(error.value) == message


def test_volume_event_on_a_surface_branch_is_the_pear_branch_s():
    """SPOM1 at M = 0: the m = 1 branch (``picture.surface_pair``, 12 points) is the pear branch turned by 90°,
    so its UZ point at V = 19.8 lies at the P of the pear branch's (measured 1.0e-14 apart; 1e-9 allowed, the
    agreement of the two discretisations: tests/test_surface.py), with V at the landed state 19.8 to 1e-10
    relative (measured 3e-13) and a residual below the solver tolerance; its image under the rotation by π has it
    too. An event on λ2 at the equator is not located there, and the verdict says so."""
    from dataclasses import replace

    from balloon_cg.analysis.picture import Picture, Progress, surface_pair, unsearched_events
    from balloon_cg.analysis.results import Block
    from balloon_cg.analysis.surface.branches import SurfaceTrace
    from balloon_cg.surface.measures import body_moments

    base = load_scene("spom1").with_overrides({"continuation.stop_stretch": 4.0, "surface.branches": "none"})
    scene = parse_scene(base.to_toml() + '\n[[events]]\nquantity = "volume"\nvalue = 19.8\n')
    pear_picture = analyse(scene)
    primary, pear = pear_picture.primary, pear_picture.branches[1]
    bp = replace(primary.branch_points()[0], m=1, block=Block.M1_HELD)
    branch, image = surface_pair(primary, 0, bp, 12, Progress())
    [uz] = user_points(branch, "volume = 19.8")
    [turned] = user_points(image, "volume = 19.8")
    reference = user_points(pear, "volume = 19.8")[0].X[-1]
    assert uz.status == Status.LOCATED and abs(uz.X[-1] - reference) <= 1e-9 * reference
    assert turned.X[-1] == uz.X[-1]
    c = uz.X[:-1]
    assert abs(2 * np.pi * body_moments(branch.basis, branch.basis.node_state(c))[0] - 19.8) <= 1e-10 * 19.8
    system = SurfaceTrace(scene, branch.basis, branch.params).system
    assert np.abs(system.residual(system.point(c, uz.X[-1]))).max() <= scene.solver.tol
    equator = parse_scene(scene.to_toml() + '\n[[events]]\nquantity = "lam2_equator"\nvalue = 1.5\n')
    picture = Picture([primary], surface_branches=[branch, image])
    unsearched_events(picture, equator)
    assert picture.not_searched == ("the [[events]] on lam2_equator are not located on the non-axisymmetric "
                                    "branches")
    unsearched_events(picture := Picture([primary], surface_branches=[branch, image]), scene)
    assert picture.not_searched == ""
