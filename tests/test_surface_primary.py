"""The primary branch of a field that is not axisymmetric, traced on the whole sphere from the start
(analysis/surface/primary.py): the field's reflections, the two-coil scene turned as a whole (an exact rotation of
the axisymmetric problem: the axisymmetric solver is the reference), a loop tilted by δ (the convergence in δ)."""
import math
from dataclasses import replace

import numpy as np
import pytest

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import branch_system
from balloon_cg.analysis.surface.branches import SurfaceTrace
from balloon_cg.analysis.surface.primary import MIRROR_X, field_reflections, trace_surface_primary
from balloon_cg.app.summaries import format_run
from balloon_cg.galerkin.equilibrium import Parameters
from balloon_cg.io.run_file import read_run, write_run
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import Coil, load_scene
from balloon_cg.surface.basis import EQUATOR, INVERSION, MIRROR_Y, SphericalBasis
from balloon_cg.surface.embedding import axisymmetric_coefficients
from balloon_cg.surface.gauge import FieldSymmetry
from balloon_cg.surface.loads import loads
from balloon_cg.surface.measures import measures

TWO_COILS = "scenes/spom1_two_coils_M0.002.toml"


def _turned(coil: Coil, angle: float, about=(0.0, 0.0, 0.0)) -> Coil:
    """The loop turned by ``angle`` about the axis e_y through the point ``about``."""
    c, s = math.cos(angle), math.sin(angle)
    turn = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    centre = turn @ (np.array(coil.centre) - about) + about
    return Coil(coil.radius, coil.current, tuple(centre.tolist()), tuple((turn @ np.array(coil.normal)).tolist()))


def _scene(coils, **overrides):
    scene = load_scene(TWO_COILS).with_overrides(overrides)
    return replace(scene, field=replace(scene.field, coils=tuple(coils)))


def test_the_reflections_of_the_field_are_those_of_its_loops():
    upper, lower = load_scene(TWO_COILS).field.coils
    assert set(field_reflections((upper, lower))) >= {MIRROR_Y, MIRROR_X}  # coaxial: every plane through the axis
    assert EQUATOR in _group(field_reflections((upper, lower)))  # the opposed pair: z → −z
    turned = [_turned(c, math.radians(30)) for c in (upper, lower)]
    assert _group(field_reflections(turned)) == _group((MIRROR_Y, INVERSION))
    tilted = _turned(upper, 0.1, about=upper.centre)  # about its own centre: only the plane y = 0 survives
    assert field_reflections((tilted, lower)) == (MIRROR_Y,)
    anywhere = Coil(1.5, 1.0, (0.2, 0.5, 1.5), tuple(np.array([0.3, 0.4, 1.0]) / np.linalg.norm([0.3, 0.4, 1.0])))
    assert field_reflections((anywhere,)) == ()


def _group(reflections) -> set:
    group = {(1, 1, 1)}
    for S in reflections:
        group |= {tuple(a * b for a, b in zip(S, g)) for g in group}
    return group


def _axisymmetric_volume(branch, P: float) -> float:
    """V/2π of the axisymmetric state at the pressure P, Newton from the branch's nearest point below it."""
    system = branch_system(branch)
    below = np.flatnonzero(branch.pressure <= P)
    X0 = branch.X[below[np.argmax(branch.pressure[below])]].copy()
    X0[-1] = P
    result = newton(system.residual, system.jacobian, X0, np.eye(X0.size)[-1], P, 1e-13, 30)
    assert result.converged
    return system.eq.volume(result.x[:-1])


@pytest.fixture(scope="module")
def turned():
    """The two coils turned by 30° about e_y through the centre, traced on the whole sphere to λ = 1.06."""
    coils = [_turned(c, math.radians(30)) for c in load_scene(TWO_COILS).field.coils]
    scene = _scene(coils, **{"continuation.stop_stretch": 1.06, "continuation.max_points": 20})
    return scene, trace_surface_primary(scene)


def test_the_turned_two_coil_scene_is_the_axisymmetric_branch_turned(turned):
    """The two coils turned by 30° about e_y through the centre: the field is the coaxial one turned, so every state
    is an axisymmetric state turned; traced from the start on the whole sphere (field on at the start pressure, then
    in P), each point's volume is the axisymmetric solver's at its P to 1e-10, the net force vanishes (the pair is
    symmetric under the inversion) and so does the torque about the centre (the balloon is free to turn)."""
    scene, surface = turned
    assert len(surface.values) >= 5 and surface.legs[0].stop.code.value == "stop_stretch"
    axisymmetric = trace_primary(load_scene(TWO_COILS).with_overrides({"continuation.stop_stretch": 1.2}))
    errors = [abs(V - _axisymmetric_volume(axisymmetric, P)) / V
              for V, P in zip(surface.measures["volume"], surface.values)]
    assert max(errors) < 1e-10, errors
    assert np.abs(surface.measures["force"]).max() < 1e-12
    assert np.abs(surface.measures["torque"]).max() < 1e-12
    assert surface.residual.max() < 1e-10 and surface.error_estimate.max() < scene.solver.max_error
    assert set(surface.stability) == {"held", "held_volume", "held_gas"}  # no free reading: module docstring


def test_a_whole_sphere_primary_is_stored_and_shown(turned, tmp_path):
    """The run file of a field that is not axisymmetric: its primary branch is a surface branch (m = 0, no parent)
    with the force and torque columns; inspect says how it was traced and shows the pull."""
    scene, surface = turned
    path = tmp_path / "turned.h5"
    write_run(path, scene, [surface])
    run = read_run(path)
    stored = run["branches"]["primary"]
    assert np.array_equal(stored["force"], surface.measures["force"])
    assert np.array_equal(stored["coefficients"], surface.coefficients)
    text = format_run(run)
    assert "surface branch primary   (traced on the whole sphere from the start" in text
    assert "field force" in text and "field torque" in text
    assert f"(of {len(surface.values)}; centre free: not read)" in text  # no free reading (it printed 'centre free: )')


@pytest.mark.slow
def test_the_fold_of_the_turned_scene_is_the_axisymmetric_fold():
    """Past the pressure maximum: the located LP of the turned scene on the whole sphere is the axisymmetric LP
    (measured: 5e-14 in P)."""
    coils = [_turned(c, math.radians(30)) for c in load_scene(TWO_COILS).field.coils]
    surface = trace_surface_primary(_scene(coils, **{"continuation.stop_stretch": 1.6}))
    axisymmetric = trace_primary(load_scene(TWO_COILS).with_overrides({"continuation.stop_stretch": 1.6}))
    (fold,) = [s.X[-1] for s in surface.special if s.kind.value == "LP"]
    (reference,) = [s.X[-1] for s in axisymmetric.special if s.kind.value == "LP"]
    assert abs(fold - reference) < 1e-10


def _tilted_state(delta: float, P: float, start):
    """(volume/2π, force, torque) of the held balloon at the pressure P with the upper coil of the two-coil scene
    tilted by δ about e_y through its own centre, Newton from the embedded axisymmetric state ``start``."""
    upper, lower = load_scene(TWO_COILS).field.coils
    scene = _scene((_turned(upper, delta, about=upper.centre), lower))
    basis = SphericalBasis(scene.surface.degree, field_reflections(scene.field.coils))
    trace = SurfaceTrace(scene, basis, Parameters(P, scene.field.M, scene.field.chi))
    assert trace.gauge.field_symmetry == (FieldSymmetry.GENERAL if delta else FieldSymmetry.AXIAL)
    disc, u = start
    X0 = trace.system.point(axisymmetric_coefficients(basis, disc, u), P)
    result = newton(trace.system.residual, trace.system.jacobian, X0, np.eye(X0.size)[-1], P, 1e-13, 30)
    assert result.converged
    c = trace.system.coefficients(result.x)
    out = loads(trace.eq, c, trace.system.params)
    return measures(basis, c)["volume"], out["force"], out["torque"]


def test_a_loop_tilted_by_delta_changes_the_volume_by_delta_squared_and_pulls_sideways_by_delta():
    """The upper coil tilted by δ about e_y through its centre: at fixed P the volume differs from the coaxial
    one by O(δ²) (tilting by −δ is the mirror image x → −x of tilting by δ) and the lateral pull F_x is O(δ):
    doubling δ multiplies the first by 4 and the second by 2, to the next order."""
    axisymmetric = trace_primary(load_scene(TWO_COILS).with_overrides({"continuation.stop_stretch": 1.2}))
    P = 2.0
    system = branch_system(axisymmetric)
    near = int(np.argmin(np.abs(axisymmetric.pressure - P)))
    X0 = axisymmetric.X[near].copy()
    X0[-1] = P
    start = (axisymmetric.disc, newton(system.residual, system.jacobian, X0, np.eye(X0.size)[-1], P, 1e-13, 30).x[:-1])
    V0, F0, _ = _tilted_state(0.0, P, start)
    assert np.abs(F0).max() < 1e-12
    deltas = (0.01, 0.02, 0.04)
    states = [_tilted_state(d, P, start) for d in deltas]
    dV = np.array([V - V0 for V, _, _ in states])
    Fx = np.array([F[0] for _, F, _ in states])
    assert np.all(dV != 0) and np.all(Fx != 0)
    assert abs(dV[1] / dV[0] - 4) < 0.05 and abs(dV[2] / dV[1] - 4) < 0.05
    assert abs(Fx[1] / Fx[0] - 2) < 0.01 and abs(Fx[2] / Fx[1] - 2) < 0.01
    for _, F, T in states:  # the pull has no y part (the plane y = 0 is kept); the balloon turns until T = 0
        assert abs(F[1]) < 1e-14
        assert np.abs(T).max() < 1e-10 * np.abs(F).max()
