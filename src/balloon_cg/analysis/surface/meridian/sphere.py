"""The sphere over (θ, φ): the engine of basis.py on the unit sphere's meridian (R = sin θ, R' = cos θ, S' = 1), its
poles included, for the branches of coaxial scenes near an axisymmetric state (a few azimuthal orders in place of
the whole-sphere harmonics of surface/: issue 37).

Order 0 is the sphere's axisymmetric state u of its Discretisation (galerkin/discretisation.py, on its wire map):
ρ = λ2 sin θ, ρ' = λ2' sin θ + λ2 cos θ, η, η'. Each m ≥ 1 order holds the amplitudes of the sphere's own perturbation
basis (analysis/stability/azimuthal.AzimuthalBasis: U = R + T on P̄_k^(m+1), D = R − T on P̄_k^(m−1), Z on P̄_k^m of
the mapped coordinate s, pole-regular) of degree N + m − 1 for ``mode_degree`` N, so that every order has 3N
unknowns (basis.py's one mode size) and order m = 1 is the m = 1 block's basis of degree N. Every order shares the
Gauss rule in s of ``quadrature`` nodes (default: azimuthal.default_quadrature of the highest order's degree and the
disc's): on it an order's block of the Hessian at an axisymmetric state is azimuthal.py's m-block in the same
coefficients. The engine's rule, axis rows, gauge, raising and resolution are the capsule's (capsule.py: a sphere is
its case of no cylinder, on another perturbation basis; capsule_resolution.py reads the tails through
``perturbations``).

Not wired into a run: on the two-coil scene's m = 1 branch the orders' content decays by only ~0.65 per order where
the membrane nears a wire at one azimuth, K ≈ 36 orders at its last point for 1e-9 (the harmonics' order 36 there),
4988 unknowns against the harmonics' 2584 (benchmarks/results/sphere_meridian_branch.txt, surface_meridian_cost.txt).
"""
from dataclasses import dataclass

import numpy as np

from .capsule import CapsuleSurfaceBasis, switched_point as _switched_point, traced_branch as _traced_branch
from .capsule_resolution import projected
from ...stability import azimuthal
from ....scene.tables import Shape


@dataclass(frozen=True)
class SphereSurfaceBasis(CapsuleSurfaceBasis):
    """The sphere's state on ``disc`` and, per order m ≥ 1 in ``orders``, azimuthal.basis(m, ``mode_degree`` + m − 1)
    on the disc's wire map and ``quadrature`` Gauss nodes in s (module docstring); ``equator`` as the capsule's
    (every order's reflection class 0: R, T even, Z odd under z → −z)."""

    quadrature: int = 0
    shape = Shape.SPHERE

    def check_reference(self) -> None:
        """ValueError where ``geometry`` and ``disc`` are not the sphere's."""
        if self.geometry.shape != Shape.SPHERE or self.disc.joins:
            raise ValueError(f"geometry: {self.geometry.describe()} (allowed: the sphere, a disc without joins)")

    def settle(self) -> None:
        """The default ``quadrature`` (module docstring), from the highest order."""
        if not self.quadrature:
            top = self.mode_degree + self.orders[-1] - 1
            object.__setattr__(self, "quadrature", azimuthal.default_quadrature(top, self.disc.degree))

    def perturbations(self, m: int, degree: int | None = None):
        """The order's AzimuthalBasis of degree N + m − 1 (N = ``degree``, default ``mode_degree``)."""
        degree = self.mode_degree if degree is None else degree
        return azimuthal.basis(m, degree + m - 1, self.quadrature, self.disc.mapping, self.geometry)

    def carried(self, m: int, perturbation, vector: np.ndarray) -> np.ndarray:
        """The order-m coefficients ``vector`` of the AzimuthalBasis ``perturbation`` on the order's basis: the same
        where its functions are (degree and map), else its field's L² projection."""
        own = self.perturbations(m)
        if (perturbation.degree, perturbation.mapping) == (own.degree, own.mapping):
            return np.array(vector, dtype=float)
        return projected(vector, perturbation.displacement, own)


def switched_point(scene, branch, bp, amplitude: float, orders: tuple | None = None, n_phi: int = 0,
                   tol: float = 1e-12, max_iter: int = 30, whole: bool = False):
    """capsule.switched_point on the sphere's basis."""
    return _switched_point(scene, branch, bp, amplitude, orders, n_phi, tol, max_iter, whole, SphereSurfaceBasis)


def traced_branch(scene, branch, bp, direction: float = 1.0, max_points: int | None = None,
                  orders: tuple | None = None, parent: tuple | None = None, progress=None):
    """capsule.traced_branch on the sphere's basis (refined by capsule_resolution through its ``perturbations``)."""
    return _traced_branch(scene, branch, bp, direction, max_points, orders, parent, progress, SphereSurfaceBasis)
