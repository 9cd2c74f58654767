"""The tube's deformed surface in Legendre(S) × Fourier(φ), the mirror sector y → −y (MODEL.md §8, §10).

In the cylindrical frame (e_ρ(φ), e_φ(φ), e_z) of the reference tube (R = 1, Z = −S: codegen/meridian.py) the deformed
point is

    x(S, φ) = r e_ρ + t e_φ + z e_z,   r = Σ_m r_m(S) cos mφ,   t = Σ_{m≥1} t_m(S) sin mφ,   z = Σ_m z_m(S) cos mφ,

over the orders m of ``orders`` (0 first). The order 0 is the interval discretisation's state u (galerkin/interval.py:
r_0 = λ2, z_0 = η; λ̄ the ends' distance over L), each m ≥ 1 the amplitudes (R, T, Z) = (r_m, t_m, z_m) on the basis of
tube/azimuthal.py (sliding ends: R, T on P_k, Z on the bubbles P_{k+2} − P_k; plugged: all three on the bubbles), so
c = (u, c_1, c_2, …) and an m ≥ 1 block of the Hessian is in the coefficients of tube/azimuthal.hessian. The ends stay
in the planes z = ±λ̄L/2 (Z vanishes there) and a plug's rim is held (R = T = Z = 0).

At a node the 9 variables of the surface kernels (codegen/surface.py), in the frame (the membrane energy is isotropic
and has no field here, so it sees only frame-invariant I, J):

    x = (r, t, z),   a_S = ∂x/∂S = (r_S, t_S, z_S),   a_φ = ∂x/∂φ = (r_φ − t, t_φ + r, z_φ)      (R = 1)

(∂e_ρ/∂φ = e_φ, ∂e_φ/∂φ = −e_ρ). Each is Σ_m F_m(S) g(mφ) with g = cos or sin, linear in c (plugged ends: r and a_φ's
second entry carry λ2's 1). Gauss–Legendre in S (the interval's rule, weights per dS) and ``n_phi`` uniform nodes in
φ, weight 1/n_phi: E/(2π) = (1/2π) ∫∫ π dS dφ ≈ Σ_q W_q Σ_k π(S_q, φ_k)/n_phi, exact for products of orders m, m'
when n_phi > m + m'. The default n_phi is the least multiple of 2g above 2(2 m_max + 1), g the greatest common divisor
of the orders: the rotation by π/g (c_m → (−1)^(m/g) c_m, the symmetry of a branch's pitchfork on the orders 0, g,
2g, …) maps the nodes to nodes, so the discrete energy keeps it exactly, not to the quadrature's aliasing.
"""
import functools
from dataclasses import dataclass

import numpy as np

from .meridian import NODE_VARIABLES, MeridianSurfaceBasis, default_phi_nodes, meridian_tables
from ..azimuthal import basis_values, operators, translation
from ...galerkin.interval import IntervalDiscretisation
from ...scene.tables import Ends, Shape


@dataclass(frozen=True)
class TubeSurfaceBasis(MeridianSurfaceBasis):
    """The interval discretisation ``disc`` per azimuthal order in ``orders`` (ascending, 0 first, distinct) on
    ``n_phi`` uniform nodes in φ (0: the default of tube/surface/meridian.py): the engine's case R = 1, S' = 1."""

    disc: IntervalDiscretisation
    orders: tuple = (0, 1)
    n_phi: int = 0
    shape = Shape.TUBE

    def __post_init__(self):
        orders, n_phi = default_phi_nodes(self.orders, self.n_phi)
        object.__setattr__(self, "orders", orders)
        object.__setattr__(self, "n_phi", n_phi)

    def rule(self) -> tuple:
        ones = np.ones(self.disc.x.size)
        return self.disc.weights, ones, np.zeros_like(ones), ones

    def axis(self) -> tuple:
        """(λ2, v, η, w) of u (ρ = λ2 with R = 1), a plugged end's 1 in λ2."""
        offset = np.zeros((4, self.disc.x.size))
        if self.disc.ends == Ends.PLUGGED:  # λ2 = 1 + bubbles
            offset[0] = 1.0
        return self.disc.maps, offset

    def mode(self, m: int) -> np.ndarray:
        return _modes(self.disc)

    def tables(self) -> tuple:
        return _tables(self)

    def check_scene(self, scene) -> None:
        """ValueError where the scene's ends are not the basis'."""
        if self.disc.ends != scene.geometry.ends:
            raise ValueError(f"basis ends: {self.disc.ends.value!r} (allowed: the scene's, "
                             f"{scene.geometry.ends.value!r})")

    @property
    def axis_size(self) -> int:
        return self.disc.size

    def volume_ratio(self, volume: float) -> float:
        """V/V0 of V/(2π) = ``volume`` (V0 = πL)."""
        return 2 * volume / self.disc.length

    def gram(self, m: int) -> np.ndarray:
        """The order's Gram matrix G of ‖δx‖² (tube/azimuthal.py)."""
        return operators(self.disc)[1]

    def gauge_rows(self, field: bool = False) -> np.ndarray:
        """(rows, size): G t of the sideways translation t in order 1 on sliding ends (tube/surface/system.py), no
        row where nothing is gauged (plugged ends, no order 1, or in a coil's ``field``)."""
        if 1 not in self.orders or self.disc.ends != Ends.SLIDING or field:
            return np.zeros((0, self.size))
        row = np.zeros((1, self.size))
        row[0, self.block(1)] = self.gram(1) @ translation(self.disc)
        return row

    @property
    def mode_size(self) -> int:
        """The unknowns of one m ≥ 1 order: (R, T, Z) of tube/azimuthal.basis_values."""
        return 2 * self.disc.hoops + self.disc.degree - 1

    @property
    def free(self) -> np.ndarray:
        """The indices of the unknowns: all but λ̄ where the ends are held (galerkin/interval.py ``free``)."""
        return np.flatnonzero(np.arange(self.size) != (self.disc.axial_index if self.disc.held else -1))

    def fields(self, m: int) -> tuple:
        """The sizes of order m's fields in c, in order: (λ2, λ̄, η) at m = 0, (R, T, Z) at m ≥ 1; a field's k-th
        coefficient is the same function (P_k or P_{k+2} − P_k) at every degree."""
        hoops, bubbles = self.disc.hoops, self.disc.degree - 1
        return (hoops, 1, bubbles) if m == 0 else (hoops, hoops, bubbles)

    def raised(self, c: np.ndarray, to: "TubeSurfaceBasis") -> np.ndarray:
        """c as coefficients of ``to`` (the same ends and length, a degree and orders at least this one's): each
        field's coefficients zero-padded, the orders ``to`` adds zero: the same surface."""
        if not (to.disc.degree >= self.disc.degree and set(self.orders) <= set(to.orders)
                and (to.disc.ends, to.disc.length) == (self.disc.ends, self.disc.length)):
            raise ValueError(f"to: degree {to.disc.degree}, orders {to.orders} (allowed: the same ends and length, "
                             f"degree ≥ {self.disc.degree}, orders holding {self.orders})")
        out = np.zeros(to.size)
        for m in self.orders:
            source, target = c[self.block(m)], out[to.block(m)]
            i = j = 0
            for size, wider in zip(self.fields(m), to.fields(m)):
                target[j:j + size] = source[i:i + size]
                i, j = i + size, j + wider
        return out

    def profile(self, c: np.ndarray, S: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """(3, S.size, phi.size): the Cartesian deformed point at reference arclengths S and azimuths φ."""
        S, phi = np.asarray(S, dtype=float), np.asarray(phi, dtype=float)
        rho, eta = self.disc.profile(c[self.block(0)], S)
        r, t, z = rho[:, None] * np.ones(phi.size), np.zeros((S.size, phi.size)), eta[:, None] * np.ones(phi.size)
        for m in self.orders[1:]:
            y = basis_values(self.disc, 2 * S / self.disc.length - 1) @ c[self.block(m)]
            r += y[0][:, None] * np.cos(m * phi)
            t += y[4][:, None] * np.sin(m * phi)
            z += y[2][:, None] * np.cos(m * phi)
        return np.array([r * np.cos(phi) - t * np.sin(phi), r * np.sin(phi) + t * np.cos(phi), z])


@functools.lru_cache(maxsize=8)
def _tables(basis: TubeSurfaceBasis) -> tuple:
    return meridian_tables(basis)


@functools.lru_cache(maxsize=8)
def _modes(disc: IntervalDiscretisation) -> np.ndarray:
    """(6, n_q, mode_size): tube/azimuthal.basis_values at the nodes, the same for every order."""
    modes = basis_values(disc, disc.x)
    modes.flags.writeable = False
    return modes
