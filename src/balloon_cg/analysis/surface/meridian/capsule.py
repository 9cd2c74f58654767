"""The capsule over (θ, φ): the engine of basis.py on a capsule's meridian, its two poles included.

The coordinate is the polar angle θ ∈ [0, π] of model/meridian.py (S = κθ, κ = 1 + L/π: S' = κ; R = sin κd on the
caps, d the angle from the nearer pole, 1 on the cylinder). Order 0 is the capsule's axisymmetric state u of its
piecewise Discretisation (galerkin/elements.py, joined at model/meridian.joins): ρ = λ2 R, ρ' = λ2' R + λ2 R',
η, η' from ``Discretisation.evaluate``; each m ≥ 1 order the amplitudes of the order's perturbation basis
(analysis/stability/capsule_basis.CapsuleBasis of ``mode_degree``: caps in sin^j ψ × Jacobi, cylinder elements in
Legendre, C⁰ joined, pole-regular: U ∈ R^(m+1), D ∈ R^(m−1), Z ∈ R^m near a pole, so a_φ = ∂x/∂φ/R is finite there).
The quadrature is that basis' (Gauss in θ on every element, 3 n + NODE_MARGIN nodes): on it an order's block of the
Hessian at an axisymmetric state is the capsule's m-block of analysis/stability/azimuthal.py, in the same
coefficients. The volume is the whole enclosed one (volume.py's flux of x_h/2 through the closed
surface).
"""
import functools
from dataclasses import dataclass, replace

import numpy as np

from . import capsule_resolution
from .capsule_resolution import projected
from .basis import MeridianSurfaceBasis, default_phi_nodes, meridian_tables
from .trace import START_AMPLITUDE, trace_from
from .switching import SwitchedPoint, mode_row, point_at_amplitude
from ...stability.capsule_basis import capsule_basis
from ..branches import critical_mode, located_degree
from ....galerkin.discretisation import Discretisation
from ....model import meridian
from ....model.meridian import hoop, hoop_rate, joins, metric
from ....scene.tables import Geometry, Shape


@dataclass(frozen=True)
class CapsuleSurfaceBasis(MeridianSurfaceBasis):
    """The capsule ``geometry``'s state on ``disc`` (its joins the geometry's) and, per order m ≥ 1 in ``orders``,
    capsule_basis(m, ``mode_degree``) on ``n_phi`` uniform nodes in φ (module docstring); with ``equator`` only the
    states even under the reflection z → −z: the disc equator-symmetric and every order's reflection class 0
    (R, T even, Z odd under θ → π − θ: capsule_basis ``classes``), the subspace a branch born along a mode of that
    class keeps (the products of two class-0 fields are in class 0)."""

    disc: Discretisation
    geometry: Geometry
    mode_degree: int
    orders: tuple = (0, 1)
    n_phi: int = 0
    equator: bool = False
    shape = Shape.CAPSULE

    def __post_init__(self):
        self.check_reference()
        if self.disc.symmetric != self.equator:
            raise ValueError(f"disc: symmetric {self.disc.symmetric} (allowed: {self.equator}, as equator)")
        orders, n_phi = default_phi_nodes(self.orders, self.n_phi)
        object.__setattr__(self, "orders", orders)
        object.__setattr__(self, "n_phi", n_phi)
        self.settle()
        sizes = {self.kept(m).size for m in orders[1:]}
        if len(sizes) > 1:
            raise ValueError(f"orders: {orders} have perturbation bases of sizes {sorted(sizes)} (allowed: one size)")

    def check_reference(self) -> None:
        """ValueError where ``geometry`` and ``disc`` are not a capsule's."""
        if self.geometry.shape != Shape.CAPSULE or self.disc.joins != joins(self.geometry):
            raise ValueError(f"disc: joins {self.disc.joins} (allowed: a capsule's, {joins(self.geometry)})")

    def settle(self) -> None:
        """Set the fields derived from the orders (none here; the sphere's quadrature)."""

    def perturbations(self, m: int, degree: int | None = None):
        """The order's CapsuleBasis (its ``gram``, ``ops`` and ``displacement``), of ``degree`` (default
        ``mode_degree``)."""
        return capsule_basis(m, self.mode_degree if degree is None else degree, self.geometry)

    def rule(self) -> tuple:
        return _rule(self.perturbations(1))

    def axis(self) -> tuple:
        return _axis(self.disc, self.perturbations(1))

    def carried(self, m: int, perturbation, vector: np.ndarray) -> np.ndarray:
        """The order-m coefficients ``vector`` of ``perturbation`` (a crossing's critical mode: ``start``) on the
        order's basis: the same basis here."""
        return vector

    def kept(self, m: int) -> np.ndarray:
        """The columns of the order's CapsuleBasis in c: all, or with ``equator`` its class 0."""
        b = self.perturbations(m)
        return b.classes[0] if self.equator else np.arange(b.size)

    def mode(self, m: int) -> np.ndarray:
        return self.perturbations(m).ops[:, :, self.kept(m)]

    def tables(self) -> tuple:
        return _tables(self)

    def grid_values(self, c: np.ndarray, cos_theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """x on the grid of rings cos θ_j × angles φ_k (poles included), shape (3, n_rings, n_φ), in Cartesian
        components (surface.basis.SphericalBasis.grid_values' contract: the sphere's figures draw it)."""
        phi = np.asarray(phi, dtype=float)
        frame = self._frame(c, np.arccos(np.clip(np.asarray(cos_theta, dtype=float), -1.0, 1.0)), phi, True)
        return _cartesian(frame[[0, 2, 4]], phi)

    def point_values(self, c: np.ndarray, theta: np.ndarray, phi: np.ndarray) -> tuple:
        """(x, a_S) at the points (θ_i, φ_i), poles included, each (3, n) in Cartesian components, a_S = ∂x/∂θ / S'
        along the reference meridian's arclength (SphericalBasis.point_values' contract, whose a_θ is the unit
        sphere's: surface/measures.pole_stretch reads it)."""
        theta, phi = np.atleast_1d(np.asarray(theta, dtype=float)), np.atleast_1d(np.asarray(phi, dtype=float))
        frame = self._frame(c, theta, phi, False)
        rate = metric(self.geometry, np.cos(theta), np.sin(theta))
        return _cartesian(frame[[0, 2, 4]], phi), _cartesian(frame[[1, 3, 5]], phi) / rate

    def _frame(self, c: np.ndarray, theta: np.ndarray, phi: np.ndarray, grid: bool) -> np.ndarray:
        """(r, r', t, t', z, z') (primes d/dθ) on the grid θ × φ (``grid``: (6, n_θ, n_φ)) or at the points
        (θ_i, φ_i) ((6, n)): r, z = Σ_m (r_m, z_m)(θ) cos mφ, t = Σ_m t_m(θ) sin mφ (basis.py); order 0's
        ρ = λ2 R and η from the disc's series, each m ≥ 1 order's (R, Z, T) and their rates from its
        CapsuleBasis.displacement."""
        lam2, dlam2, eta, deta = self.disc.evaluate(c[self.block(0)], theta)
        R, dR = (np.asarray(f(self.geometry, np.cos(theta), np.sin(theta)), dtype=float) for f in (hoop, hoop_rate))
        zero = np.zeros_like(theta)
        fields = [(0, np.array([lam2 * R, dlam2 * R + lam2 * dR, zero, zero, eta, deta]))]
        for m in self.orders[1:]:
            full = np.zeros(self.perturbations(m).size)
            full[self.kept(m)] = c[self.block(m)]
            (R_m, Z_m, T_m), (dR_m, dZ_m, dT_m) = (self.perturbations(m).displacement(full, theta, rate)
                                                   for rate in (False, True))
            fields.append((m, np.array([R_m, dR_m, T_m, dT_m, Z_m, dZ_m])))
        out = 0.0
        for m, F in fields:
            cos, sin = np.cos(m * phi), np.sin(m * phi)
            trig = np.array([cos, cos, sin, sin, cos, cos])
            out = out + (np.einsum("in,ik->ink", F, trig) if grid else F * trig)
        return out

    def check_scene(self, scene) -> None:
        """ValueError where the scene's capsule is not the basis'."""
        if scene.geometry != self.geometry:
            raise ValueError(f"basis geometry: {self.geometry.describe()} (allowed: the scene's, "
                             f"{scene.geometry.describe()})")

    @property
    def axis_size(self) -> int:
        return self.disc.size

    def volume_ratio(self, volume: float) -> float:
        """V/V0 of V/(2π) = ``volume`` (V0 = πL + 4π/3)."""
        return 2 * np.pi * volume / self.geometry.reference_volume

    def raised(self, c: np.ndarray, to: "CapsuleSurfaceBasis") -> np.ndarray:
        """c as coefficients of ``to`` (the same capsule, degrees and orders at least this one's): order 0
        transferred (Discretisation.transfer: nested, exact), each m ≥ 1 order's field projected in L² on ``to``'s
        basis (nested spaces: exact to rounding), the orders ``to`` adds zero."""
        if not (to.geometry == self.geometry and set(self.orders) <= set(to.orders) and to.equator == self.equator
                and to.disc.degree >= self.disc.degree and to.mode_degree >= self.mode_degree):
            raise ValueError(f"to: degrees {to.disc.degree}, {to.mode_degree}, orders {to.orders} (allowed: the "
                             f"same capsule, degrees ≥ {self.disc.degree}, {self.mode_degree}, orders holding "
                             f"{self.orders})")
        out = np.zeros(to.size)
        out[to.block(0)] = self.disc.transfer(c[self.block(0)], to.disc)
        for m in self.orders[1:]:
            full = np.zeros(self.perturbations(m).size)
            full[self.kept(m)] = c[self.block(m)]
            out[to.block(m)] = projected(full, self.perturbations(m).displacement, to.perturbations(m))[to.kept(m)]
        return out

    @property
    def mode_size(self) -> int:
        return self.kept(self.orders[1]).size if len(self.orders) > 1 else 0

    @property
    def free(self) -> np.ndarray:
        return np.arange(self.size)

    def gram(self, m: int) -> np.ndarray:
        """The order's Gram matrix G of ‖δx‖² (capsule_basis.py)."""
        kept = self.kept(m)
        return self.perturbations(m).gram[np.ix_(kept, kept)]

    def gauge_rows(self, field: bool = False) -> np.ndarray:
        """(rows, size): G f of the m = 1 zero modes f held (system.py), as quadratures
        ½ ∫ f · δx dA of the order-1 rows: the translation along x, f = (R, T, Z) = (1, −1, 0) (the centroid held:
        without a field a zero mode, in a coil's ``field`` the held reading), and the rotation about y of the
        reference, f = (Z0, −Z0, −R0) (∫ (e_y × X) · x dA = 0): without a field the rigid rotation's phase, on a
        capsule of length 0 in a field the material rotation's (a relabelling of the sphere). ValueError for a
        capsule of length 0 without a field, where the rigid rotation and the relabelling are two zero modes this
        one reference row cannot tell apart (the sphere's surface/gauge.py refuses them too); a row that vanishes on
        the kept class is left out (``equator`` states hold no rotation about y)."""
        if 1 not in self.orders:
            return np.zeros((0, self.size))
        W, R, _, rate = self.rule()
        b, kept = self.perturbations(1), self.kept(1)
        height, ones = meridian.reference_height(self.geometry, b.theta), np.ones(R.size)
        translation, rotation = (0.5 * np.einsum("aq,q,aqj->j", np.array(f), W * R * rate, b.ops[[0, 4, 2]][:, :, kept])
                                 for f in ((ones, -ones, 0 * ones), (height, -height, -R)))
        sphere, turning = self.geometry.length == 0, np.abs(rotation).max() > 1e-12 * np.abs(translation).max()
        if sphere and turning and not field:
            raise ValueError("geometry.length = 0 without a field: the m = 1 rigid rotation and the relabelling "
                             "are both zero modes (allowed: length > 0, coils with M ≠ 0, or equator states)")
        modes = [translation] + ([rotation] if turning and (sphere or not field) else [])
        rows = np.zeros((len(modes), self.size))
        for row, mode in zip(rows, modes):
            row[self.block(1)] = mode
        return rows


def _cartesian(frame: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """The Cartesian components of a vector's frame components (r, t, z) along (e_ρ(φ), e_φ(φ), e_z) (φ broadcast
    against the last axis)."""
    r, t, z = frame
    return np.array([r * np.cos(phi) - t * np.sin(phi), r * np.sin(phi) + t * np.cos(phi), z])


@functools.lru_cache(maxsize=8)
def _rule(b) -> tuple:
    """(W per dθ, R, R', S') at the nodes of the perturbation basis ``b`` (the same for every order), read-only."""
    geometry = b.geometry
    out = (b.weights / b.sin_theta, np.asarray(hoop(geometry, b.x, b.sin_theta), dtype=float),
           np.asarray(hoop_rate(geometry, b.x, b.sin_theta), dtype=float), metric(geometry, b.x, b.sin_theta))
    for array in out:
        array.flags.writeable = False
    return out


@functools.lru_cache(maxsize=8)
def _axis(disc: Discretisation, b) -> tuple:
    """(rows of ρ, ρ', η, η' in u at the nodes of the perturbation basis ``b`` (module docstring), zero offset),
    read-only."""
    theta = b.theta
    lam2, dlam2, eta, deta = (values.T for values in disc.evaluate(np.eye(disc.size), theta))
    _, R, dR, _ = _rule(b)
    rows = np.array([R[:, None] * lam2, R[:, None] * dlam2 + dR[:, None] * lam2, eta, deta])
    offset = np.zeros((4, theta.size))
    rows.flags.writeable = offset.flags.writeable = False
    return rows, offset


@functools.lru_cache(maxsize=8)
def _tables(basis: CapsuleSurfaceBasis) -> tuple:
    return meridian_tables(basis)


def start(scene, branch, bp, orders: tuple | None = None, n_phi: int = 0, whole: bool = False,
          kind: type = CapsuleSurfaceBasis) -> tuple:
    """(the basis, the zero's c on it, the critical mode φ as c on it, G-unit) of the branch born at the located
    m ≥ 1 point ``bp`` of the axisymmetric ``branch`` (analysis/results.Branch) of a capsule (``kind``: its
    CapsuleSurfaceBasis) or a sphere (sphere.SphereSurfaceBasis): φ from
    analysis/surface/branches.critical_mode of its reading at the degree it was located at, the orders (0, m, 2m)
    unless ``orders``, on the ``equator`` states where the branch is equator-symmetric and the mode in reflection class
    0 (as the sphere's surface branches keep a mode's symmetry), else (or ``whole``) on the whole discretisation (a mode
    odd in z breaks it)."""
    m = bp.m
    degree = located_degree(branch, bp)
    perturbation, mode = critical_mode(branch, bp, degree)
    even = perturbation.classes[0]
    equator = not whole and branch.disc.symmetric and np.abs(np.delete(mode, even)).max() <= 1e-10 * np.abs(mode).max()
    disc = replace(branch.disc, symmetric=equator)
    basis = kind(disc, scene.geometry, degree, orders or (0, m, 2 * m), n_phi, equator)
    mode = basis.carried(m, perturbation, mode)[basis.kept(m)]
    mode = basis.with_mode(np.zeros(basis.size), m, mode / np.sqrt(mode @ basis.gram(m) @ mode))
    return basis, basis.axisymmetric(branch.disc.transfer(bp.X[:-1], disc)), mode


def switched_point(scene, branch, bp, amplitude: float, orders: tuple | None = None, n_phi: int = 0,
                   tol: float = 1e-12, max_iter: int = 30, whole: bool = False,
                   kind: type = CapsuleSurfaceBasis) -> SwitchedPoint:
    """The point of amplitude ε = ``amplitude`` (≠ 0) on the branch born at the located m ≥ 1 point ``bp`` of the
    axisymmetric ``branch`` (``start``, ``kind`` its basis), solved by switching.point_at_amplitude
    (φᵀ G c_m = ε, the m = 1 zero modes gauged)."""
    return _switched(scene, branch, bp, start(scene, branch, bp, orders, n_phi, whole, kind), amplitude, tol,
                     max_iter)


def _switched(scene, branch, bp, started: tuple, amplitude: float, tol: float, max_iter: int) -> SwitchedPoint:
    """``switched_point`` from the ``start`` (basis, zero, mode)."""
    if amplitude == 0:
        raise ValueError("amplitude: 0 is the axisymmetric state itself (allowed: ε ≠ 0)")
    basis, zero, mode = started
    m = bp.m
    return point_at_amplitude(scene, basis, zero + amplitude * mode, bp.X[-1], mode_row(basis, m, mode[basis.block(m)]),
                              amplitude, m, branch.params_at(bp.X), tol, max_iter)


def traced_branch(scene, branch, bp, direction: float = 1.0, max_points: int | None = None,
                  orders: tuple | None = None, parent: tuple | None = None, progress=None,
                  kind: type = CapsuleSurfaceBasis):
    """The branch born at the located m ≥ 1 point ``bp`` of the capsule's (``kind``: its CapsuleSurfaceBasis) or
    the sphere's (sphere.SphereSurfaceBasis) ``branch``, traced in P from its switched
    point at ε = START_AMPLITUDE (trace.trace_from: refined by capsule_resolution, its mirror sector's
    stability read at every point; ``progress`` told of every traced point); SurfaceBranchStartError where the
    switched point does not converge."""
    solver = scene.solver
    started = start(scene, branch, bp, orders, kind=kind)
    first = _switched(scene, branch, bp, started, direction * START_AMPLITUDE, solver.tol, solver.max_newton)
    _, zero, mode = started
    return trace_from(scene, first, mode, zero, bp.X[-1], branch.params_at(bp.X), capsule_resolution, direction,
                      max_points, parent, progress)
