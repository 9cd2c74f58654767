"""The free balloon's m = 1 branches (issue 41): born at the free reading's m = 1 points of the shipped two-coil
scene, traced on the whole sphere with the translation an unknown, so every state must be an equilibrium with
zero net force, which the held branches need not be (their reaction holds them)."""
import numpy as np
import pytest

from balloon_cg.analysis.results import Gauge
from balloon_cg.analysis.surface.branches import SurfaceTrace, rotated, trace_surface
from balloon_cg.surface.loads import loads
from shared_pictures import two_coil_picture


@pytest.fixture(scope="module")
def free_branch(tmp_path_factory):
    """The branch born at the first free m = 1 point of the two-coil primary branch (P = 2.237770863), 8 points."""
    primary = two_coil_picture(tmp_path_factory).primary
    k, bp = next((k, bp) for k, bp in enumerate(primary.branch_points()) if bp.m == 1 and not bp.block.held)
    assert abs(bp.X[-1] - 2.237770863) < 1e-8
    return primary, trace_surface(primary, k, bp, 1.0, "m1_free", 8)


def test_free_m1_branch_has_zero_net_force_and_moves_its_centre(free_branch):
    """Every point: the field's net force (surface.loads: a quadrature of ∇H², not the residual) ≤ 1e-10 and the
    residual of the unconstrained (free) whole-sphere problem on the basis it was solved on ≤ 1e-10 (the solver's
    record; the last point recomputed on the stored basis); the centre moves sideways (the m = 1 mode carries the
    translation a held balloon's reaction would stop) and grows with the amplitude."""
    primary, branch = free_branch
    assert branch.gauge == Gauge.FREE and not branch.held and len(branch.values) == 8
    trace = SurfaceTrace(branch.scene, branch.basis, branch.params, held=False)
    for c, P in zip(branch.coefficients, branch.values):
        assert np.abs(loads(trace.eq, c, branch.params.with_value("P", P))["force"]).max() <= 1e-10
    assert branch.residual.max() <= 1e-10
    last = branch.params.with_value("P", branch.values[-1])
    assert np.abs(trace.gauge.reduce(trace.eq.residual(branch.coefficients[-1], last))).max() <= 1e-10
    sideways = np.abs(branch.measures["centroid"][:, 0])
    assert sideways[0] < 1e-12 and np.all(np.diff(sideways) > 0)
    assert np.abs(branch.measures["centroid"][:, 1:]).max() < 1e-12


def test_free_m1_branch_is_not_a_held_equilibrium(free_branch):
    """Held at its centre the same states are no equilibria off the branch point (the held gauge's reaction would be
    needed to move the centre back): the held residual of the moved states is O(amplitude), not zero; and the
    rotated image is a free branch too."""
    _, branch = free_branch
    held = SurfaceTrace(branch.scene, branch.basis, branch.params, held=True)
    c = branch.coefficients[-1]
    assert np.abs(held.gauge.constraints @ c).max() > 1e-3  # the centre moved: outside the held subspace
    image = rotated(branch, "m1_free_rotated")
    assert image.gauge == Gauge.FREE
    free = SurfaceTrace(image.scene, image.basis, image.params, held=False)
    c, P = image.coefficients[-1], image.values[-1]
    assert np.abs(free.gauge.reduce(free.eq.residual(c, image.params.with_value("P", P)))).max() <= 1e-10
    assert np.abs(loads(free.eq, c, image.params.with_value("P", P))["force"]).max() <= 1e-10


def test_free_m1_branch_follows_its_normal_form(free_branch):
    """The branch's first points against its own second-order normal form: with the reduced energy
    E(Λ, P) = E2(P) Λ² + E4 Λ⁴ + … along the unit mode φ (Λ = φ·(a − a*)), the branch is P − P* = κ Λ² + O(Λ⁴),
    κ = −2 E4 / E2'(P*), E4 the located point's quartic coefficient (``classify``, stored with the origin) and E2'
    from the test: E2(P) = ½ (φᵀ H(P)⁻¹ φ)⁻¹ (the minimum of ½ aᵀ H a on φ·a = Λ) at the axisymmetric states
    P* ± 1e-4 solved on the whole sphere, by central difference. The first point (Λ = 0.02) reads κ to 1e-4
    relative (measured 8e-5: its Λ² term), and the intercept of (P − P*)/Λ² = κ + κ4 Λ² through the first three
    to 1e-4 (measured 2e-5)."""
    from balloon_cg.analysis.surface.branches import axisymmetric_solve, critical_mode, located_degree
    from balloon_cg.surface.embedding import mode_coefficients

    primary, branch = free_branch
    k, bp = next((k, bp) for k, bp in enumerate(primary.branch_points()) if bp.m == 1 and not bp.block.held)
    P_star = branch.values[0]
    trace = SurfaceTrace(branch.scene, branch.basis, branch.params.with_value("P", P_star), held=False)
    phi = trace.gauge.reduce(mode_coefficients(trace.basis, *critical_mode(primary, bp, located_degree(primary, bp))))
    phi /= np.linalg.norm(phi)

    def E2(P):
        c = axisymmetric_solve(trace, branch.coefficients[0], P)
        H = trace.gauge.reduce_matrix(trace.eq.hessian(c, branch.params.with_value("P", P)))
        return 0.5 / (phi @ np.linalg.solve(H, phi))

    h = 1e-4
    slope = (E2(P_star + h) - E2(P_star - h)) / (2 * h)
    kappa = -2 * branch.special[0].E[2] / slope
    amplitude = np.array([trace.gauge.reduce(c) for c in branch.coefficients[1:4]]) @ phi - \
        phi @ trace.gauge.reduce(branch.coefficients[0])
    ratio = (branch.values[1:4] - P_star) / amplitude**2
    assert abs(amplitude[0] - 0.02) < 1e-10  # the switch hyperplane φ·(X − X*) = 0.02, met to the solver's tol
    assert abs(ratio[0] / kappa - 1) <= 1e-4
    intercept = np.polynomial.polynomial.polyfit(amplitude**2, ratio, 1)[0]
    assert abs(intercept / kappa - 1) <= 1e-4


def test_a_switch_that_does_not_start_is_named_and_fails_the_verdict(tmp_path_factory, monkeypatch):
    """Issue 41: where switching at an m ≥ 1 point fails (here every one: the first correction made to fail), the
    picture names each branch not started (m1_bp<k>, the points of the reading the states are equilibria of: on the
    two-coil scene both readings, held and free) and the verdict fails on them: never silence."""
    from balloon_cg.analysis.surface import branches as surface_branches
    from balloon_cg.analysis.picture import Picture, Progress, _trace_surface, surface_name
    from balloon_cg.analysis.results import Status
    from balloon_cg.analysis.verdict import Gap, failing

    primary = two_coil_picture(tmp_path_factory).primary

    def fails(*args, **kwargs):
        raise surface_branches.SurfaceStartError("the first correction off the axisymmetric branch did not converge")

    monkeypatch.setattr(surface_branches, "trace_surface", fails)
    picture = Picture([primary])
    _trace_surface(primary.scene.with_overrides({"surface.branches": "all"}), primary, picture, Progress())
    expected = [surface_name(primary, k, bp) for k, bp in enumerate(primary.branch_points())
                if bp.m >= 1 and bp.status == Status.LOCATED and primary.reads(bp.block)]
    assert len(expected) >= 2 and {bp.block.held for bp in primary.branch_points() if bp.m == 1} == {True, False}
    assert [name for name, _ in picture.not_started] == expected and not picture.surface_branches
    assert [(item.gap, item.branch) for item in failing(picture.incomplete)] == [(Gap.NOT_STARTED, name)
                                                                                  for name in expected]
