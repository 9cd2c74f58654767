"""A surface of revolution's deformed surface in (t, φ): the engine of tube/surface/ over any reference meridian
R(t), Z(t) (a tube's, a capsule's with its poles), the mirror sector y → −y (MODEL.md §8, §10).

In the cylindrical frame (e_ρ(φ), e_φ(φ), e_z) the deformed point is

    x(t, φ) = r e_ρ + t e_φ + z e_z,   r = Σ_m r_m(t) cos mφ,   t = Σ_{m≥1} t_m(t) sin mφ,   z = Σ_m z_m(t) cos mφ,

over the orders m of ``orders`` (0 first): order 0 an axisymmetric state (ρ, η)(t), linear in its unknowns u (an
interval's or a capsule's discretisation), each m ≥ 1 a perturbation basis' amplitudes (R, T, Z) = (r_m, t_m, z_m)
(tube/azimuthal.py, analysis/stability/capsule_basis.py). The reference frame is orthonormal in (S, φ/R): with
S' = dS/dt the node variables of the surface kernels (codegen/surface.py) are

    x = (r, t, z),   a_S = ∂x/∂t / S',   a_φ = ∂x/∂φ / R = (r_φ − t, t_φ + r, z_φ)/R,

(∂e_ρ/∂φ = e_φ, ∂e_φ/∂φ = −e_ρ), as the sphere's in (θ, φ/sin θ). At a pole R → 0 and a_φ stays finite by the
per-order basis' regularity: ρ = λ2 R, and for m ≥ 1 (mR + T, mT + R, mZ) = ((m+1)U ± (m−1)D, 2mZ)/2 with
U ∈ R^(m+1), D ∈ R^(m−1), Z ∈ R^m (U = R + T, D = R − T; the (m − 1) D vanishes for m = 1): the rows are divided by
R at the quadrature's nodes, never at a pole. Each node variable is Σ_m F_m(t) g(mφ), g = cos or sin, linear in c
(+ an ``offset``, a plugged tube's 1). Gauss in t (the meridian's rule, weights per dt) times the reference area
R S' and ``n_phi`` uniform nodes in φ, weight 1/n_phi: E/(2π) = (1/2π) ∫∫ π R S' dt dφ ≈ Σ_q W_q R_q S'_q Σ_k
π(t_q, φ_k)/n_phi, exact in φ for products of orders m, m' when n_phi > m + m'. The default n_phi is the least
multiple of 2g above 2(2 m_max + 1), g the greatest common divisor of the orders: the rotation by π/g (c_m →
(−1)^(m/g) c_m) maps the nodes to nodes, so the discrete energy keeps the pitchfork's symmetry exactly.

A shape is a subclass giving its ``rule`` (nodes' W, R, R', S'), its ``axis`` (the rows of ρ, ρ', η, η' in u and
their offset) and its per-order ``mode`` rows (R, R', Z, Z', T, T'), primes d/dt: tube/surface/basis.py (R = 1,
S' = 1: every division exact) and tube/surface/capsule.py.
"""
import math

import numpy as np

NODE_VARIABLES = ("x", "y", "z", "xt", "yt", "zt", "xp", "yp", "zp")  # the surface kernels' names (frame components)


def default_phi_nodes(orders: tuple, n_phi: int) -> tuple:
    """(the orders as ints, n_phi or its default: module docstring); ValueError where they are not 0 first and
    ascending, or n_phi cannot hold the products of the highest order."""
    orders = tuple(int(m) for m in orders)
    if not orders or orders[0] != 0 or any(b <= a for a, b in zip(orders, orders[1:])):
        raise ValueError(f"orders: {orders} must start at 0 and ascend (allowed: distinct m ≥ 0)")
    least = 2 * orders[-1] + 1
    if n_phi == 0:
        period = 2 * math.gcd(*orders[1:]) if len(orders) > 1 else 2
        return orders, -(-2 * least // period) * period
    if n_phi < least:
        raise ValueError(f"n_phi: {n_phi} nodes in φ cannot hold the products of order {orders[-1]} "
                         f"(allowed: n_phi ≥ {least})")
    return orders, n_phi


class MeridianSurfaceBasis:
    """The engine (module docstring). A subclass is a frozen dataclass with ``orders`` and ``n_phi`` (set through
    ``default_phi_nodes``), ``axis_size`` (the unknowns of order 0) and ``mode_size`` (of each m ≥ 1 order), and
    the hooks ``rule``, ``axis``, ``mode``; its node tables are built once (``tables``, cached by the subclass)."""

    def rule(self) -> tuple:
        """(W per dt, R, dR/dt, S' = dS/dt) at the n_q nodes in t."""
        raise NotImplementedError

    def axis(self) -> tuple:
        """(rows (4, n_q, axis_size) of (ρ, dρ/dt, η, dη/dt) in u, offset (4, n_q))."""
        raise NotImplementedError

    def mode(self, m: int) -> np.ndarray:
        """(6, n_q, mode_size): the rows of (R, R', Z, Z', T, T') of order m ≥ 1 (primes d/dt)."""
        raise NotImplementedError

    @property
    def size(self) -> int:
        return self.axis_size + (len(self.orders) - 1) * self.mode_size

    def block(self, m: int) -> slice:
        """The slice of c holding order m (m = 0: the axisymmetric unknowns u)."""
        i = self.orders.index(m)
        if i == 0:
            return slice(0, self.axis_size)
        start = self.axis_size + (i - 1) * self.mode_size
        return slice(start, start + self.mode_size)

    @property
    def phi(self) -> np.ndarray:
        return 2 * np.pi * np.arange(self.n_phi) / self.n_phi

    @property
    def weights(self) -> np.ndarray:
        """(n_q · n_phi,): W_q R_q S'_q / n_phi per node, node order q n_phi + k."""
        W, R, _, rate = self.rule()
        return np.repeat(W * R * rate, self.n_phi) / self.n_phi

    @property
    def factors(self) -> tuple:
        """Per order, (F (9, n_q, unknowns of the order), g (9, n_phi)): node variable a (NODE_VARIABLES) is
        Σ_m (F_a c_m)(t_q) g_a(φ_k), g_a = cos mφ or sin mφ (module docstring)."""
        return self.tables()[0]

    def reference_normal(self) -> np.ndarray:
        """(2, n_q): the (e_ρ, e_z) components of the reference's outward normal, (−Z', R')/S' with
        Z' = −sqrt(S'² − R'²) (the meridian runs downwards from its top, as the sphere's from its north pole)."""
        _, _, dR, rate = self.rule()
        return np.array([np.sqrt(np.maximum(rate**2 - dR**2, 0.0)), dR]) / rate

    def tables(self) -> tuple:
        """(the ``factors`` per order, offset (9, n_q, n_phi)), read-only; built by ``meridian_tables``."""
        raise NotImplementedError

    def node_state(self, c: np.ndarray) -> np.ndarray:
        """(9, n_q · n_phi): x, a_S, a_φ in the frame at every node, node order q n_phi + k (module docstring)."""
        factors, offset = self.tables()
        out = offset.copy()
        for m, (F, g) in zip(self.orders, factors):
            out += (F @ c[self.block(m)])[:, :, None] * g[:, None, :]
        return out.reshape(9, -1)

    def project(self, pointwise: np.ndarray) -> np.ndarray:
        """Σ_a T_aᵀ p_a of node rows p (9, n_q · n_phi), T_a the map of node variable a: Σ_q F_aᵀ Σ_k g_a p_a per
        order (a residual from W ∂π/∂q)."""
        p = pointwise.reshape(9, -1, self.n_phi)
        out = np.empty(self.size)
        for m, (F, g) in zip(self.orders, self.factors):
            out[self.block(m)] = np.einsum("aq,aqj->j", np.einsum("aqk,ak->aq", p, g), F)
        return out

    def hessian(self, pointwise: np.ndarray) -> np.ndarray:
        """Σ_ab T_aᵀ diag(h_ab) T_b of node rows h (9, 9, n_q · n_phi), sum-factorised over φ: the block of orders
        (m, m') is Σ_ab F_aᵀ diag(Θ_ab) F'_b with Θ_ab(t_q) = Σ_k g_a(φ_k) h_ab(t_q, φ_k) g'_b(φ_k) (9 n_q n² flops
        over all blocks instead of the n_phi times more of the dense node maps)."""
        h = pointwise.reshape(9, 9, -1, self.n_phi)
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
        """c of the axisymmetric state u (every m ≥ 1 amplitude 0)."""
        c = np.zeros(self.size)
        c[self.block(0)] = u
        return c

    def with_mode(self, c: np.ndarray, m: int, amplitudes: np.ndarray) -> np.ndarray:
        """c with order m ≥ 1 set to ``amplitudes`` (the order's perturbation coefficients, e.g. a critical mode)."""
        if m == 0:
            raise ValueError(f"m: 0 is the axisymmetric state, set by ``axisymmetric`` (allowed: {self.orders[1:]})")
        out = np.array(c, dtype=float)
        out[self.block(m)] = amplitudes
        return out


def meridian_tables(basis: MeridianSurfaceBasis) -> tuple:
    """``MeridianSurfaceBasis.tables`` from the hooks (module docstring), read-only."""
    _, R, _, rate = basis.rule()
    rows, axis_offset = basis.axis()  # ρ, ρ', η, η'
    n_q, phi = R.size, basis.phi
    F = np.zeros((9, n_q, basis.axis_size))
    F[0], F[2], F[3], F[5], F[7] = rows[0], rows[2], rows[1] / rate[:, None], rows[3] / rate[:, None], \
        rows[0] / R[:, None]  # r, z, a_S = (ρ', 0, η')/S', a_φ2 = ρ/R
    factors = [(F, np.ones((9, basis.n_phi)))]
    for m in basis.orders[1:]:
        dR, dZ, dT = (basis.mode(m)[k] / rate[:, None] for k in (1, 3, 5))
        Rm, Zm, Tm = (basis.mode(m)[k] for k in (0, 2, 4))
        over = 1.0 / R[:, None]
        rows_m = (Rm, Tm, Zm, dR, dT, dZ, -(m * Rm + Tm) * over, (m * Tm + Rm) * over, -m * Zm * over)
        cos, sin = np.cos(m * phi), np.sin(m * phi)
        factors.append((np.array(rows_m), np.array([cos, sin, cos, cos, sin, cos, sin, cos, sin])))
    offset = np.zeros((9, n_q, basis.n_phi))
    for row, value in ((0, axis_offset[0]), (2, axis_offset[2]), (3, axis_offset[1] / rate),
                       (5, axis_offset[3] / rate), (7, axis_offset[0] / R)):
        offset[row] = value[:, None]
    for table in (offset, *(a for pair in factors for a in pair)):
        table.flags.writeable = False
    return tuple(factors), offset
