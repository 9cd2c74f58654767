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
import math
from dataclasses import dataclass

import numpy as np

from ..azimuthal import basis_values
from ...galerkin.interval import IntervalDiscretisation
from ...scene.tables import Ends

NODE_VARIABLES = ("x", "y", "z", "xt", "yt", "zt", "xp", "yp", "zp")  # the surface kernels' names (frame components)


@dataclass(frozen=True)
class TubeSurfaceBasis:
    """The interval discretisation ``disc`` per azimuthal order in ``orders`` (ascending, 0 first, distinct) on
    ``n_phi`` uniform nodes in φ (0: the default of the module docstring)."""

    disc: IntervalDiscretisation
    orders: tuple = (0, 1)
    n_phi: int = 0

    def __post_init__(self):
        orders = tuple(int(m) for m in self.orders)
        if not orders or orders[0] != 0 or any(b <= a for a, b in zip(orders, orders[1:])):
            raise ValueError(f"orders: {self.orders} must start at 0 and ascend (allowed: distinct m ≥ 0)")
        object.__setattr__(self, "orders", orders)
        least = 2 * orders[-1] + 1
        if self.n_phi == 0:
            period = 2 * math.gcd(*orders[1:]) if len(orders) > 1 else 2
            object.__setattr__(self, "n_phi", -(-2 * least // period) * period)
        elif self.n_phi < least:
            raise ValueError(f"n_phi: {self.n_phi} nodes in φ cannot hold the products of order {orders[-1]} "
                             f"(allowed: n_phi ≥ {least})")

    @property
    def mode_size(self) -> int:
        """The unknowns of one m ≥ 1 order: (R, T, Z) of tube/azimuthal.basis_values."""
        return 2 * self.disc.hoops + self.disc.degree - 1

    @property
    def size(self) -> int:
        return self.disc.size + (len(self.orders) - 1) * self.mode_size

    def block(self, m: int) -> slice:
        """The slice of c holding order m (m = 0: the interval's u)."""
        i = self.orders.index(m)
        if i == 0:
            return slice(0, self.disc.size)
        start = self.disc.size + (i - 1) * self.mode_size
        return slice(start, start + self.mode_size)

    @property
    def free(self) -> np.ndarray:
        """The indices of the unknowns: all but λ̄ where the ends are held (galerkin/interval.py ``free``)."""
        return np.flatnonzero(np.arange(self.size) != (self.disc.axial_index if self.disc.held else -1))

    @property
    def phi(self) -> np.ndarray:
        return 2 * np.pi * np.arange(self.n_phi) / self.n_phi

    @property
    def weights(self) -> np.ndarray:
        """(n_q · n_phi,): W_q / n_phi per node, node order q n_phi + k."""
        return np.repeat(self.disc.weights, self.n_phi) / self.n_phi

    @property
    def factors(self) -> tuple:
        """Per order, (F (9, n_q, unknowns of the order), g (9, n_phi)): node variable a (NODE_VARIABLES) is
        Σ_m (F_a c_m)(S_q) g_a(φ_k), g_a = cos mφ or sin mφ (module docstring)."""
        return _tables(self)[0]

    def node_state(self, c: np.ndarray) -> np.ndarray:
        """(9, n_q · n_phi): x, a_S, a_φ in the frame at every node, node order q n_phi + k (module docstring)."""
        out = _tables(self)[1].copy()
        for m, (F, g) in zip(self.orders, self.factors):
            out += (F @ c[self.block(m)])[:, :, None] * g[:, None, :]
        return out.reshape(9, -1)

    def project(self, pointwise: np.ndarray) -> np.ndarray:
        """Σ_a T_aᵀ p_a of node rows p (9, n_q · n_phi), T_a the map of node variable a: Σ_q F_aᵀ Σ_k g_a p_a per
        order (a residual from W ∂π/∂q)."""
        p = pointwise.reshape(9, self.disc.x.size, self.n_phi)
        out = np.empty(self.size)
        for m, (F, g) in zip(self.orders, self.factors):
            out[self.block(m)] = np.einsum("aq,aqj->j", np.einsum("aqk,ak->aq", p, g), F)
        return out

    def hessian(self, pointwise: np.ndarray) -> np.ndarray:
        """Σ_ab T_aᵀ diag(h_ab) T_b of node rows h (9, 9, n_q · n_phi), sum-factorised over φ: the block of orders
        (m, m') is Σ_ab F_aᵀ diag(Θ_ab) F'_b with Θ_ab(S_q) = Σ_k g_a(φ_k) h_ab(S_q, φ_k) g'_b(φ_k) (9 n_q n² flops
        over all blocks instead of the n_phi times more of the dense node maps)."""
        h = pointwise.reshape(9, 9, self.disc.x.size, self.n_phi)
        out = np.empty((self.size, self.size))
        factors = list(zip(self.orders, self.factors))
        for i, (m, (F, g)) in enumerate(factors):
            for m_, (F_, g_) in factors[i:]:
                theta = np.einsum("abqk,ak,bk->abq", h, g, g_)
                scaled = np.einsum("abq,bqj->aqj", theta, F_)
                block = F.reshape(-1, F.shape[2]).T @ scaled.reshape(-1, F_.shape[2])
                out[self.block(m), self.block(m_)] = block
                out[self.block(m_), self.block(m)] = block.T
        return out

    def axisymmetric(self, u: np.ndarray) -> np.ndarray:
        """c of the interval discretisation's state u (every m ≥ 1 amplitude 0)."""
        c = np.zeros(self.size)
        c[self.block(0)] = u
        return c

    def with_mode(self, c: np.ndarray, m: int, amplitudes: np.ndarray) -> np.ndarray:
        """c with order m ≥ 1 set to ``amplitudes`` (coefficients of tube/azimuthal.basis_values, e.g. a critical
        mode)."""
        if m == 0:
            raise ValueError(f"m: 0 is the axisymmetric state, set by ``axisymmetric`` (allowed: {self.orders[1:]})")
        out = np.array(c, dtype=float)
        out[self.block(m)] = amplitudes
        return out

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
    """(the ``factors`` per order, offset (9, n_q, n_phi): a plugged end's 1 in r and a_φ2), read-only."""
    disc, phi = basis.disc, basis.phi
    n_q = disc.x.size
    axis = disc.maps  # (λ2, v, η, w) of u
    F = np.zeros((9, n_q, disc.size))
    for row, source in ((0, 0), (7, 0), (2, 2), (3, 1), (5, 3)):  # r, a_φ2 = r, z, r_S, z_S
        F[row] = axis[source]
    factors = [(F, np.ones((9, basis.n_phi)))]
    R, dR, Z, dZ, T, dT = basis_values(disc, disc.x)  # (n_q, mode_size) each
    for m in basis.orders[1:]:
        rows = (R, T, Z, dR, dT, dZ, -(m * R + T), m * T + R, -m * Z)  # r, t, z, a_S, a_φ (module docstring)
        cos, sin = np.cos(m * phi), np.sin(m * phi)
        factors.append((np.array(rows), np.array([cos, sin, cos, cos, sin, cos, sin, cos, sin])))
    offset = np.zeros((9, n_q, basis.n_phi))
    if disc.ends == Ends.PLUGGED:  # λ2 = 1 + bubbles: r and a_φ2 = r carry the 1
        offset[0] = offset[7] = 1.0
    for table in (offset, *(a for pair in factors for a in pair)):
        table.flags.writeable = False
    return tuple(factors), offset
