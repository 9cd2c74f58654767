"""The capsule over (θ, φ) (tube/surface/capsule.py, the engine of tube/surface/meridian.py on a capsule's meridian).

Checked against the capsule's axisymmetric discretisation (its orders (0,) restriction: galerkin/equilibrium.py with
the capsule's own kernels, which take the pole limits symbolically where the engine divides by R at interior nodes)
and against its m ≥ 1 blocks (analysis/stability/azimuthal.py on capsule_basis.py: the second-variation kernels
derived for the capsule's meridian, another code path from the surface kernels' 9 node variables)."""
import sys
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.analysis.stability import azimuthal
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.model import meridian
from balloon_cg.tube.surface.capsule import CapsuleSurfaceBasis
from balloon_cg.tube.surface.equilibrium import MeridianSurfaceEquilibrium

sys.path.insert(0, str(Path(__file__).parent))
from test_capsule_azimuthal import capsule, random_state  # noqa: E402

LENGTHS = (0.0, 3.0)
FINE_RULE = 120  # Gauss nodes per piece of the axisymmetric discretisation (module docstring of the first test)


def setting(length: float, degree: int = 16, orders: tuple = (0, 1, 2, 3), quadrature: int = FINE_RULE):
    """(scene, Equilibrium, basis, engine, u: a random smooth state about λ = 1.4, neither uniform nor
    mirror-symmetric, params at P = 0.9)."""
    scene = capsule(length)
    disc = Discretisation(degree, symmetric=False, pin_translation=False, joins=meridian.joins(scene.geometry),
                          quadrature=quadrature)
    basis = CapsuleSurfaceBasis(disc, scene.geometry, degree, orders)
    return (scene, Equilibrium(scene, disc), basis, MeridianSurfaceEquilibrium(scene, basis),
            random_state(disc, scene.geometry, 1.4, seed=7), Parameters(0.9))


def close(a, b, tol):
    return np.max(np.abs(np.asarray(a) - b)) <= tol * max(np.max(np.abs(b)), 1.0)


@pytest.mark.parametrize("length", LENGTHS)
def test_restricted_to_m0_it_is_the_capsules_axisymmetric_discretisation(length):
    """At a random axisymmetric state (orders 0..3): E/(2π), V/(2π), the residual, ∂R/∂P and the Jacobian on the
    m = 0 unknowns are the axisymmetric discretisation's (1e-10 relative), the m ≥ 1 residual vanishes and no two
    orders couple (1e-12). The axisymmetric side runs on FINE_RULE nodes per piece: on its default rule (32 Gauss
    nodes in x at length 0, degree 16) its own Jacobian is 2e-7 off its value on 60 or 120 nodes, where it meets the
    engine's (Gauss in θ per element) to 3e-14: the engine's rule is the converged one."""
    scene, eq, basis, surface, u, params = setting(length)
    c, axis = basis.axisymmetric(u), basis.block(0)
    assert close(surface.energy(c, params), eq.energy(u, params), 1e-10)
    assert close(surface.volume(c), eq.volume(u), 1e-10)
    R = surface.residual(c, params)
    assert close(R[axis], eq.residual(u, params), 1e-10)
    assert np.max(np.abs(R[axis.stop:])) <= 1e-12 * np.max(np.abs(R))
    assert close(surface.parameter_derivative(c, params)[axis], eq.parameter_derivative(u, params, "P"), 1e-10)
    H = surface.hessian(c, params)
    assert close(H[axis, axis], eq.jacobian(u, params), 1e-10)
    for m in (1, 2, 3):
        assert np.max(np.abs(H[axis, basis.block(m)])) <= 1e-12 * np.max(np.abs(H))
    for m, n in ((1, 2), (1, 3), (2, 3)):
        assert np.max(np.abs(H[basis.block(m), basis.block(n)])) <= 1e-12 * np.max(np.abs(H))


@pytest.mark.parametrize("length", LENGTHS)
def test_order_m_blocks_are_the_capsules_azimuthal_blocks(length):
    """At a random axisymmetric state the Hessian's order-m block (m = 1, 2, 3) is the capsule's m-block
    (analysis/stability/azimuthal.azimuthal_hessian, in the same coefficients: the change of basis is the identity),
    1e-12 relative, and the eigenvalues of the pencil (H, G) are the block's (1e-9)."""
    scene, eq, basis, surface, u, params = setting(length)
    H = surface.hessian(basis.axisymmetric(u), params)
    for m in (1, 2, 3):
        expected, gram = azimuthal.azimuthal_hessian(eq, u, params, m, basis.mode_degree)
        block = H[basis.block(m), basis.block(m)]
        assert close(block, expected, 1e-12), m
        ours, theirs = (np.sort(np.real(np.linalg.eigvals(np.linalg.solve(gram, A)))) for A in (block, expected))
        assert np.max(np.abs(ours - theirs)) <= 1e-9 * np.max(np.abs(theirs)), m


def test_what_it_does_not_take_is_refused_in_one_line():
    """A disc without the capsule's joins, a scene of another capsule: one line each, naming the key, its value and
    what is allowed."""
    scene = capsule(3.0)
    plain = Discretisation(8, symmetric=False, pin_translation=False)
    right = Discretisation(8, symmetric=False, pin_translation=False, joins=meridian.joins(scene.geometry))
    cases = [(lambda: CapsuleSurfaceBasis(plain, scene.geometry, 8), "disc"),
             (lambda: MeridianSurfaceEquilibrium(capsule(2.0), CapsuleSurfaceBasis(right, scene.geometry, 8)),
              "basis geometry")]
    for call, key in cases:
        with pytest.raises(ValueError) as error:
            call()
        message = str(error.value)
        assert message.startswith(key) and "allowed" in message and "\n" not in message, message
