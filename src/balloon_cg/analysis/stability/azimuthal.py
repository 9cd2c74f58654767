"""Second variation for non-axisymmetric perturbations (azimuthal number m ≥ 1, MODEL.md §5).

The perturbed mid-surface is x0 + ε δx with (derivation: codegen/second_variation.py, docs/second_variation.md)

    δx = R(θ) cos mφ e_ρ + T(θ) sin mφ e_φ + Z(θ) cos mφ e_z,

R = a sin θ the radial displacement (a: the λ2 perturbation), T = ρ0 B the azimuthal one (B: the angle β − φ),
Z the axial one. The generated kernel ``azimuthal_hessian`` gives at each node the 6×6 matrix h with
d²E/dε² = ∫ yᵀ h y d(cos θ), y = (R, R', Z, Z', T, T') (E per 2π, as the axisymmetric Hessian).

Basis (regular at the poles for every m ≥ 1). In complex notation the horizontal displacement is
δx_x + i δx_y = ½ (R + T) e^{i(m+1)φ} + ½ (R − T) e^{−i(m−1)φ}, and f(θ) e^{ijφ} is smooth on the sphere iff
f = sin^|j| θ · (smooth function of cos θ). So the regular perturbations are exactly

    U = R + T ∈ sin^{m+1}θ · C^∞,   D = R − T ∈ sin^{m−1}θ · C^∞,   Z ∈ sin^m θ · C^∞,

expanded in orthonormal associated Legendre functions P̄_k^j(cos θ) (∫ P̄_k^j P̄_l^j dx = δ_kl, Condon–Shortley):

    Z = Σ_{k=m}^{N} z_k P̄_k^m,   U = Σ_{k=m+1}^{N} u_k P̄_k^{m+1},   D = Σ_{k=m−1}^{N} d_k P̄_k^{m−1},

i.e. every vector field whose Cartesian components are spherical harmonics of degree ≤ N (restricted to the
cos mφ family), 3(N − m + 1) unknowns, ordered (z, u, d). For m = 1, D = R − T does not vanish at the poles:
the rigid translation ⊥ the axis (R = 1, T = −1: D = 2) and the rotation about a horizontal axis
(R = η0, T = −η0, Z = −ρ0) need it, and both have a = R/sin θ, B = T/ρ0 unbounded there, which is why the
unknowns are displacements and not (a, B). A basis a = Σ c_k P_k^m (R ∈ sin^{m+1}) would miss them.

G is the Gram matrix of the displacement's L2 norm on the reference sphere, per 2π like E:
‖δx‖² = (1/2π) ∫∫ |δx|² dA = ½ ∫ (R² + T² + Z²) d(cos θ), so the eigenvalues of H c = μ G c are basis
independent (the Rayleigh quotient of d²E/dε² over ‖δx‖²), and comparable with the axisymmetric Hessian
normalised by ∫ (sin²θ δλ2² + δη²) d(cos θ) (the same norm for m = 0).

Zero modes of the m = 1 block (``special_modes``): at every equilibrium the relabelling of material points by a
rotation of the (isotropic) reference sphere; at M = 0 also the rigid translation and rotation. ``spectrum``
removes them and gives the free or the held (centre fixed) reading.
"""
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import linalg

from numba import njit

from ...galerkin.coordinate_map import WireMap
from ...galerkin.discretisation import even_half, symmetric_rows
from ...galerkin.equilibrium import Equilibrium, Parameters
from ...galerkin.legendre import assoc_legendre, gauss_rule, legendre_values
from ...generated import AZIMUTHAL_PAIRS
from ...model.meridian import hoop, mass_density, metric
from ...numerics import eigen
from ...scene.tables import Geometry, Shape
from .capsule_basis import capsule_basis


@dataclass(frozen=True)
class AzimuthalBasis:
    """Basis of the cos mφ perturbations (module docstring) at Gauss–Legendre nodes in x = cos θ; with a ``mapping``
    (coordinate_map.WireMap, s = h(x)) the functions P̄_k^j(s(x)) at Gauss nodes in s, weights w_q/h'(x_q)
    (``_nodes_and_functions``); ``geometry`` the reference surface of its mass matrix (model/meridian.py)."""

    m: int
    degree: int
    quadrature: int
    mapping: WireMap | None = None
    geometry: Geometry = Geometry()

    def __post_init__(self):
        m, n = self.m, self.degree
        if m < 1:
            raise ValueError(f"m = {m}: the azimuthal second variation needs m ≥ 1 (m = 0 is Equilibrium.jacobian)")
        if n < m:
            raise ValueError(f"degree = {n}: must be ≥ m = {m}")
        nodes, weights = gauss_rule(self.quadrature)
        # owned, writable arrays either way: numba compiles its loops again for a read-only argument
        x = nodes.copy() if self.mapping is None else self.mapping.x(nodes)
        weights = weights.copy() if self.mapping is None else weights / self.mapping.ds_dx(x)  # dx = ds/h'
        put = object.__setattr__
        put(self, "x", x)
        put(self, "weights", weights)
        put(self, "sin_theta", np.sqrt(1.0 - x * x))
        put(self, "theta", np.arccos(x))
        blocks, ops = _point_ops(m, n, nodes, x, self.mapping)
        offset = ops.shape[2]
        put(self, "blocks", blocks)
        put(self, "size", offset)
        put(self, "ops", ops)
        # R, R', T, T' involve only the U and D coefficients, Z, Z' only the Z ones: the assembly works on these
        # column groups (about half the work of the full products)
        z = blocks["Z"][0]
        put(self, "ops_z", np.ascontiguousarray(ops[2:4, :, z]))
        put(self, "ops_ud", np.ascontiguousarray(ops[[0, 1, 4, 5], :, z.stop:]))
        # the kinetic energy's mass matrix (generated/inertia.py: t = ¼(Ṙ² + Ṫ² + Ż²) S' per d(cos θ))
        mass = mass_density(self.geometry, "azimuthal", x, self.sin_theta)
        put(self, "gram", _assemble(mass, weights, _pair_rows(AZIMUTHAL_PAIRS), self.ops_ud, self.ops_z))
        # orthonormal P̄ in x: G = diag(½ | ¼, ¼) on the sphere; in s, ∫ P̄_k^j(s) P̄_l^j(s) dx is not diagonal, nor
        # ∫ P̄_k^j P̄_l^j S' dx on a spheroid
        orthogonal = self.mapping is None and self.geometry.shape == Shape.SPHERE
        put(self, "factor", eigen.GramFactor(self.gram, orthogonal=orthogonal))
        # G c for the L2 (‖δx‖ over the reference surface) projection c of node values (R, T, Z):
        # ½ Σ_q w_q S'_q (R ∂R/∂c + T ∂T/∂c + Z ∂Z/∂c)
        moments = 0.5 * ops[[0, 4, 2]] * (weights * metric(self.geometry, x, self.sin_theta))[None, :, None]
        put(self, "moments", np.ascontiguousarray(moments.reshape(-1, offset)))
        # reflection classes z → −z of an equator-symmetric state (P̄_k^j(−x) = (−1)^{k+j} P̄_k^j(x); on the odd map of
        # an equator-symmetric state, s(−x) = −s(x), the same): k + m odd is
        # (R, T even in x, Z odd), k + m even the opposite; H and G have no entries between them
        parity = np.concatenate([(k + m) % 2 for _, k in blocks.values()])
        classes = tuple(np.flatnonzero(parity == p) for p in (1, 0))
        put(self, "classes", classes)
        # within a class every integrand is even in x: its blocks need only the nodes x ≥ 0 (``even_half``), and
        # only the class's own columns (Z ones first, as in the class's index order)
        keep, even_weights = even_half(nodes, weights)  # nodes mirror-symmetric in s (x = g(s) only to rounding)
        nz = z.stop
        put(self, "even", (keep, even_weights, tuple(
            (np.ascontiguousarray(self.ops_ud[:, keep][:, :, c[c >= nz] - nz]),
             np.ascontiguousarray(self.ops_z[:, keep][:, :, c[c < nz]])) for c in classes)))
        put(self, "class_factors", tuple(eigen.GramFactor(self.gram[np.ix_(c, c)], orthogonal=orthogonal)
                                         for c in classes))

    def values(self, c: np.ndarray) -> np.ndarray:
        """(R, R', Z, Z', T, T') at the nodes for coefficients c, shape (6, n_q)."""
        return self.ops @ c

    def displacement(self, c: np.ndarray, theta: np.ndarray) -> np.ndarray:
        """(R, Z, T) on any θ grid (poles included) for coefficients c (one vector or rows): the amplitudes of
        δρ = R cos mφ, δz = Z cos mφ, δφ = T sin mφ, shape (3, n_θ) or (rows, 3, n_θ)."""
        x = np.cos(theta)
        with np.errstate(divide="ignore", invalid="ignore"):  # the θ-derivatives (not used) divide by sin σ at a pole
            _, ops = _point_ops(self.m, self.degree, x if self.mapping is None else self.mapping.s(x), x,
                                self.mapping)
        c = np.asarray(c, dtype=float)
        return ops[[0, 2, 4]] @ c if c.ndim == 1 else np.moveaxis(ops[[0, 2, 4]] @ c.T, -1, 0)

    def cartesian(self, c: np.ndarray, theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """Cartesian displacement δx (3, len(theta)) at points (θ, φ), θ anywhere in [0, π] (poles included)."""
        theta = np.asarray(theta, dtype=float)
        x = np.cos(theta)
        fields = {}
        for name, order in (("Z", self.m), ("U", self.m + 1), ("D", self.m - 1)):
            sl, k = self.blocks[name]
            p = legendre_values(x if self.mapping is None else np.clip(self.mapping.s(x), -1.0, 1.0), self.degree, order)
            fields[name] = p[:, k] @ c[sl]
        R, T, Z = (fields["U"] + fields["D"]) / 2, (fields["U"] - fields["D"]) / 2, fields["Z"]
        cm, sm = np.cos(self.m * phi), np.sin(self.m * phi)
        horizontal_r, horizontal_p = R * cm, T * sm
        return np.array([horizontal_r * np.cos(phi) - horizontal_p * np.sin(phi),
                         horizontal_r * np.sin(phi) + horizontal_p * np.cos(phi), Z * cm])


def _point_ops(m: int, degree: int, nodes, x, mapping) -> tuple:
    """({"Z", "U", "D": (columns, k)}, the values of (R, R', Z, Z', T, T') at the points x (s = ``nodes`` on a map)
    per coefficient, shape (6, points, size)): Z on P̄_k^m, U on P̄_k^(m+1), D on P̄_k^(m−1), R = (U + D)/2,
    T = (U − D)/2 (docs/second_variation.md)."""
    blocks, columns, offset = {}, [], 0
    for name, order in (("Z", m), ("U", m + 1), ("D", m - 1)):
        p, dp = _functions(nodes, x, degree, order, mapping)
        k = np.arange(order, degree + 1)
        blocks[name] = (slice(offset, offset + k.size), k)
        columns.append((name, p[:, k], dp[:, k]))
        offset += k.size
    ops = np.zeros((6, np.size(x), offset))
    for name, p, dp in columns:
        sl = blocks[name][0]
        if name == "Z":
            ops[2, :, sl], ops[3, :, sl] = p, dp
        else:  # R = (U + D)/2, T = (U − D)/2
            sign = 1.0 if name == "U" else -1.0
            ops[0, :, sl], ops[1, :, sl] = p / 2, dp / 2
            ops[4, :, sl], ops[5, :, sl] = sign * p / 2, sign * dp / 2
    return blocks, ops


def _functions(nodes, x, degree: int, order: int, mapping):
    """(P̄_k^order, dP̄_k^order/dθ) at the nodes, k = 0..degree: of x = cos θ without a map; with one of s = h(x)
    (``nodes``), dP̄/dθ = dP̄/dσ · h'(x) sin θ / sin σ (s = cos σ: ds/dθ = −h' sin θ, ds/dσ = −sin σ). P̄_k^j(s) =
    (1 − s²)^{j/2} q(s) and (1 − s²)/(1 − x²) is smooth and positive on [−1, 1] (h fixes ±1, h' > 0), so
    P̄_k^j(s(x)) = sin^j θ · (a smooth function of x): the pole regularity of the unmapped basis."""
    if mapping is None:
        return assoc_legendre(x, degree, order)
    p, dp = assoc_legendre(nodes, degree, order)
    return p, dp * (mapping.ds_dx(x) * np.sqrt(1.0 - x * x) / np.sqrt(1.0 - nodes * nodes))[:, None]


def perturbation_map(equilibrium: Equilibrium, basis: str | None = None) -> WireMap | None:
    """The map of the perturbation bases at ``equilibrium``: its own wire map for the stability basis "mapped"
    (``basis``; None: the scene's stability.basis), else None (Legendre in x)."""
    kind = equilibrium.scene.stability.basis if basis is None else basis
    return equilibrium.disc.mapping if kind == "mapped" else None


def default_quadrature(degree: int, equilibrium_degree: int) -> int:
    """Gauss nodes: the integrand is a product of two basis functions (degree ≤ N each) and coefficients that are
    smooth functions of the equilibrium (degree N_eq), so N + N_eq + 16 nodes integrate it to rounding."""
    return degree + equilibrium_degree + 16


@lru_cache(maxsize=32)
def basis(m: int, degree: int, quadrature: int, mapping: WireMap | None = None,
          geometry: Geometry = Geometry()) -> AzimuthalBasis:
    return AzimuthalBasis(m, degree, quadrature, mapping, geometry)


@dataclass(frozen=True)
class StateMaps:
    """The linear map of the unknowns u of a discretisation onto the nodes of an azimuthal basis: ``state``
    (size, 4 n_q), u @ state = (λ2, λ2', η, η') at the nodes; and ``translation`` (size_b), the translation's row
    G c (``_mode_moments``), which does not depend on u."""

    state: np.ndarray
    translation: np.ndarray


@lru_cache(maxsize=32)
def state_maps(disc, b: AzimuthalBasis) -> StateMaps:
    """``StateMaps`` of ``disc`` (a galerkin Discretisation) on the nodes of ``b``: columns of unit unknowns."""
    unit = tuple(np.atleast_2d(v) for v in disc.evaluate(np.eye(disc.size), b.theta))  # each (size, n_q)
    zero = _mode_moments(b, tuple(np.zeros((1, b.x.size)) for _ in range(4)))[0, 0]
    return StateMaps(np.ascontiguousarray(np.concatenate(unit, axis=1)), zero)


@lru_cache(maxsize=32)
def kernel_state_map(disc, b: AzimuthalBasis, even: bool) -> np.ndarray:
    """u @ map: the kernels' node state (λ2, v = λ2' sin θ, η, w = η') of the unknowns u of ``disc`` at the nodes
    of ``b`` (only those x ≥ 0 if ``even``: AzimuthalBasis.even), its four rows one after the other."""
    state = state_maps(disc, b).state.reshape(disc.size, 4, -1).copy()
    state[:, 1] *= b.sin_theta
    if even:
        state = state[:, :, b.even[0]]
    return np.ascontiguousarray(state.reshape(disc.size, -1))


def _node_hessian(equilibrium: Equilibrium, u, params: Parameters, m: int, b: AzimuthalBasis, even: bool):
    """The kernel's 21 entries of h (the AZIMUTHAL_PAIRS of y = PERTURBATION) at the nodes of ``b`` (x ≥ 0 only if
    ``even``) for the axisymmetric state u, on the equilibrium's kernels held at those nodes."""
    x, s = (b.x[b.even[0]], b.sin_theta[b.even[0]]) if even else (b.x, b.sin_theta)
    nodes = equilibrium.at_nodes(("azimuthal", b, even), (x, s))
    np.dot(np.asarray(u, dtype=float), kernel_state_map(equilibrium.disc, b, even), out=nodes.state.reshape(-1))
    nodes.hold(params)
    return nodes("azimuthal_hessian", params, m=float(m))


def _hessian(equilibrium: Equilibrium, u, params: Parameters, m: int, b: AzimuthalBasis):
    """H for the axisymmetric state u: the kernel's h at every node (``_node_hessian``), assembled by
    ``_assemble``."""
    h = _node_hessian(equilibrium, u, params, m, b, even=False)
    return _assemble(h, b.weights, _pair_rows(equilibrium.kernels.module.AZIMUTHAL_PAIRS), b.ops_ud, b.ops_z)


def _class_hessians(equilibrium: Equilibrium, u, params: Parameters, m: int, b: AzimuthalBasis) -> tuple:
    """The blocks H[c, c] of the reflection classes c (AzimuthalBasis.classes) of an equator-symmetric state u: H
    has no entries between them, and within one every integrand is even in x, so each is assembled on the nodes
    x ≥ 0 and on its own columns (AzimuthalBasis.even)."""
    _, weights, columns = b.even
    h = _node_hessian(equilibrium, u, params, m, b, even=True)
    row = _pair_rows(equilibrium.kernels.module.AZIMUTHAL_PAIRS)
    return tuple(_assemble(h, weights, row, ops_ud, ops_z) for ops_ud, ops_z in columns)


@lru_cache(maxsize=4)
def _pair_rows(pairs: tuple) -> np.ndarray:
    return symmetric_rows(pairs)


_UD_ROWS = np.array([0, 1, 4, 5])  # R, R', T, T'
_Z_ROWS = np.array([2, 3])  # Z, Z'


def _assemble(h, weights, row, ops_ud, ops_z):
    """H = Σ_q w_q Σ_kl h_kl(q) ∂y_k/∂c ∂y_l/∂c, h_kl in row ``row[k, l]`` of h, on the column groups (Z | U, D):
    (R, R', T, T') depend on the U, D coefficients only (``ops_ud``, (4, n_q, n_ud)), (Z, Z') on the Z ones only
    (``ops_z``, (2, n_q, n_z)); each group pair is one BLAS product of the stacked ops of one group with the
    node-wise weighted combinations of the other's (``_weighted``); symmetrised (``_symmetrise``). The products
    stay in numpy: numba's np.dot would cost seconds of compilation at a cold start."""
    nz, nud = ops_z.shape[2], ops_ud.shape[2]
    stacked_ud, stacked_z = ops_ud.reshape(-1, nud), ops_z.reshape(-1, nz)
    H = np.empty((nz + nud, nz + nud))
    H[nz:, nz:] = stacked_ud.T @ _weighted(h, weights, row, _UD_ROWS, _UD_ROWS, ops_ud).reshape(-1, nud)
    H[:nz, :nz] = stacked_z.T @ _weighted(h, weights, row, _Z_ROWS, _Z_ROWS, ops_z).reshape(-1, nz)
    H[:nz, nz:] = stacked_z.T @ _weighted(h, weights, row, _Z_ROWS, _UD_ROWS, ops_ud).reshape(-1, nud)
    _symmetrise(H, nz)
    return H


@njit(cache=True)
def _symmetrise(H, nz):
    """H ← (H + Hᵀ)/2 on the diagonal group blocks; the lower (U, D)–Z block the transpose of the upper one."""
    n = H.shape[0]
    for i in range(n):
        for j in range(i):
            if j < nz <= i:
                H[i, j] = H[j, i]
            else:
                H[i, j] = H[j, i] = 0.5 * (H[i, j] + H[j, i])


@njit(cache=True)
def _weighted(h, weights, row, rows_i, rows_j, ops_j):
    """Σ_{l ∈ rows_j} w_q h_kl(q) ops_j[l] at every node q for each k ∈ rows_i, shape (len(rows_i), n_q, n_j)."""
    ni, nq, nj = rows_i.size, weights.size, ops_j.shape[2]
    scaled = np.zeros((ni, nq, nj))
    for a in range(ni):
        for b in range(rows_j.size):
            r = row[rows_i[a], rows_j[b]]
            for q in range(nq):
                c = weights[q] * h[r, q]
                for j in range(nj):
                    scaled[a, q, j] += c * ops_j[b, q, j]
    return scaled


def azimuthal_hessian(equilibrium: Equilibrium, u, params: Parameters, m: int, degree: int, quadrature: int = 0):
    """(H, G): the Galerkin matrix of d²E/dε² and the Gram matrix of ‖δx‖² for cos mφ perturbations of the
    axisymmetric state u (unknowns of ``equilibrium.disc``) at parameters ``params``, basis of ``degree`` N
    (module docstring; see ``perturbation_basis`` for the layout). Both are symmetric, of size 3(N − m + 1)."""
    b = perturbation_basis(equilibrium, m, degree, quadrature)
    return _hessian(equilibrium, u, params, m, b), b.gram


def perturbation_basis(equilibrium: Equilibrium, m: int, degree: int, quadrature: int = 0,
                       kind: str | None = None) -> AzimuthalBasis:
    """The basis ``azimuthal_hessian`` uses for this equilibrium's discretisation (cached): in x, or in s on its
    wire map (``perturbation_map``; ``kind`` None: the scene's stability.basis). Quadrature: ``default_quadrature``
    (on a map both degrees are in s). A capsule's: capsule_basis.CapsuleBasis (its own elements and rule)."""
    geometry = equilibrium.scene.geometry
    if geometry.shape == Shape.CAPSULE:  # spectral elements joined at the joins (capsule_basis.py)
        return capsule_basis(m, degree, geometry)
    return basis(int(m), int(degree), int(quadrature or default_quadrature(degree, equilibrium.disc.degree)),
                 perturbation_map(equilibrium, kind), geometry)


MODES = ("translation", "rotation", "relabelling")
MODE_CLASS = (0, 1, 1)  # the reflection class (AzimuthalBasis.classes) of each mode: R, T even / odd in x


def _mode_moments(b: AzimuthalBasis, state: tuple) -> np.ndarray:
    """G c for the special modes (``special_modes``, in the order MODES) from node states (λ2, λ2', η, η'), each
    (k, n_q) for k states: the L2 projection's right-hand sides ½ ∫ (R δR + T δT + Z δZ) dx, shape (3, k, size);
    the translation's is the same for every state."""
    lam2, dlam2, eta, deta = state
    s, c = b.sin_theta, b.x
    one = np.ones_like(eta)
    radius = hoop(b.geometry, c, s)  # R: sin θ but on a capsule
    values = np.array([[one, -one, 0.0 * one], [eta, -eta, -lam2 * radius], [lam2 * c + dlam2 * s, -lam2 * c, deta]])
    k = values.shape[2]  # Σ_j Σ_q values[m, j, k, q] moments[j, q, i]: one BLAS product per mode
    return np.matmul(values.transpose(0, 2, 1, 3).reshape(3, k, -1), b.moments.reshape(-1, b.size))


def mode_moments(equilibrium: Equilibrium, u, b: AzimuthalBasis) -> np.ndarray:
    """G c of the special modes (rows in the order MODES) of the state u, from its node state (``state_maps``):
    O(n_q size_b) a point (a map of every unit state's moments cost O(size n_q size_b) once per basis)."""
    state = np.asarray(u, dtype=float) @ state_maps(equilibrium.disc, b).state
    return _mode_moments(b, tuple(state.reshape(4, 1, -1)))[:, 0]


def special_modes(equilibrium: Equilibrium, u, degree: int, quadrature: int = 0) -> dict:
    """Coefficient vectors of the m = 1 perturbations that cost no energy by symmetry, for the state u:

    - ``translation`` along e_x: R = 1, T = −1, Z = 0 (a zero mode at M = 0, any state);
    - ``rotation`` about e_y, δx = e_y × x0: R = η0, T = −η0, Z = −ρ0 (a zero mode at M = 0 equilibria);
    - ``relabelling``: the rotation of the *reference* sphere about e_y, δx = ∂x0/∂X·(e_y × X):
      R = ρ0', T = −ρ0 cot θ, Z = η0'. The reference sphere and the material are isotropic, so E[x ∘ Q] = E[x]
      for every rotation Q of the material labels: a zero mode of every equilibrium, with or without field
      (material slides along the deformed surface, the shape does not change), where the reference is a sphere
      (``excluded_modes``). On a sphere state it is the rotation.

    All are regular (D = R − T ≠ 0 at the poles) and exact in the basis when degree ≥ the equilibrium's Legendre
    degree + 1 (the translation for any degree)."""
    b = perturbation_basis(equilibrium, 1, degree, quadrature)
    moments = mode_moments(equilibrium, u, b)
    coefficients = b.factor.inverse.T @ (b.factor.inverse @ moments.T)  # G⁻¹ (G c)
    return dict(zip(MODES, coefficients.T))


def lowest_eigenvalues(H, G, count: int = 6, exclude=None, vectors: bool = False):
    """The ``count`` lowest μ of H c = μ G c. ``exclude`` (rows: coefficient vectors, e.g. from ``special_modes``)
    restricts the problem to {c : E G c = 0}, the G-orthogonal complement of their span (linearly dependent rows
    are fine): an exact null vector is then removed from the spectrum and nothing else changes, and excluding
    the translation is the constraint that the material centroid stays put (∫ δx dA = 0). Returned vectors are
    in the full basis. Eigenvalues only: ``numerics.eigen.lowest`` (the constraint rows are E G)."""
    excluding = exclude is not None and len(exclude)
    count = min(count, H.shape[0])
    if not vectors:
        normals = np.atleast_2d(exclude) @ G if excluding else eigen.NO_CONSTRAINT
        return eigen.lowest(H, eigen.GramFactor(G), count, normals)
    null = None
    if excluding:
        null = linalg.null_space(np.atleast_2d(exclude) @ G, rcond=eigen.RCOND)
        H, G = null.T @ H @ null, null.T @ G @ null
    values, vecs = linalg.eigh(H, G, subset_by_index=(0, count - 1))
    if null is not None:
        vecs = null @ vecs
    return values, vecs


def spectrum(equilibrium: Equilibrium, u, params: Parameters, m: int, degree: int, count: int = 6,
             held: bool = False, quadrature: int = 0) -> np.ndarray:
    """Lowest ``count`` eigenvalues of the m-th block with the symmetry zero modes removed: for m = 1 always the
    relabelling mode, and at M = 0 (or without coils) also the translation and the rotation. ``held=True`` is the
    balloon held at its centre (MODEL.md §5): the translation ⊥ the axis is constrained (∫ δx dA = 0) also with a
    field; ``held=False`` is the free balloon, for which a paramagnetic balloon at a field minimum can slide
    sideways (a negative eigenvalue). At M = 0 both readings coincide. Negative values: unstable under pressure
    control (P fixed); the m ≥ 1 modes leave the enclosed volume unchanged to first order, so volume control
    gives the same m ≥ 1 spectrum."""
    return spectra(equilibrium, u, params, m, degree, count, (held,), quadrature)[held]


def spectra(equilibrium: Equilibrium, u, params: Parameters, m: int, degree: int, count: int = 6,
            readings=(True, False), quadrature: int = 0) -> dict:
    """``spectrum`` for several readings (held: True, free: False) from one assembly of the m-th block."""
    matrices = restricted_blocks(equilibrium, u, params, m, degree, readings, quadrature)
    return {held: merged_lowest(parts, count) for held, parts in matrices.items()}


def merged_lowest(parts, count: int) -> np.ndarray:
    """The ``count`` lowest eigenvalues of a block given as the standard matrices of its uncoupled parts."""
    return merged_parts([eigen.lowest_of(A, count) for A in parts], count)


def merged_parts(found: list, count: int) -> np.ndarray:
    """The ``count`` lowest of the uncoupled parts' lowest eigenvalues ``found`` (ascending each)."""
    return found[0] if len(found) == 1 else np.sort(np.concatenate(found))[:count]


def restricted_blocks(equilibrium: Equilibrium, u, params: Parameters, m: int, degree: int, readings=(True, False),
                      quadrature: int = 0, kind: str | None = None) -> dict:
    """The m-th block for each reading (held: True, free: False) as standard symmetric matrices with the special
    modes removed (``numerics.eigen.restricted``): their eigenvalues together are ``spectrum``'s, and the block is
    positive when each is. On an equator-symmetric discretisation the state is symmetric and the block splits
    into its two reflection classes (``AzimuthalBasis.classes``, each mode in its own: MODE_CLASS), two matrices
    of half the size; else one. One assembly and, for m = 1, one evaluation of the modes' constraint rows G c
    serve every reading. ``kind``: the perturbation basis (``perturbation_basis``)."""
    b = perturbation_basis(equilibrium, m, degree, quadrature, kind)
    moments, parts = _parts(equilibrium, u, params, m, b)
    out = {}
    for held in readings:
        modes = list(excluded_modes(equilibrium, params, held)) if m == 1 else []
        out[held] = tuple(eigen.restricted(H, factor, _class_rows(moments, modes, cls, index))
                          for H, index, factor, cls in parts)
    return out


def lowest_readings(equilibrium: Equilibrium, u, params: Parameters, m: int, degree: int, count: int,
                    readings=(True, False), kind: str | None = None) -> dict:
    """The ``count`` lowest eigenvalues of each reading of ``restricted_blocks`` (held: True, free: False). Where
    both are asked for at m = 1, the held matrix of each part is the free one on the translation's rows also
    (``eigen.restricted_rows``: in the free matrix's coordinates), a relative of it (``eigen.lowest_with_relatives``:
    large ones through one shifted factorisation below the free reading's lowest eigenvalue, no second reduction
    nor dense eigensolve); a part without the translation's rows (its other reflection class) has one matrix for
    both."""
    if m != 1 or tuple(readings) != (True, False):
        return {held: merged_lowest(parts, count) for held, parts in
                restricted_blocks(equilibrium, u, params, m, degree, readings, kind=kind).items()}
    b = perturbation_basis(equilibrium, m, degree, 0, kind)
    moments, parts = _parts(equilibrium, u, params, m, b)
    free_modes, held_modes = list(excluded_modes(equilibrium, params, False)), list(excluded_modes(equilibrium, params, True))
    extra = [k for k in held_modes if k not in free_modes]
    held, free = [], []
    for H, index, factor, cls in parts:
        free_rows, held_rows = _class_rows(moments, free_modes, cls, index), _class_rows(moments, held_modes, cls, index)
        A = eigen.restricted(H, factor, free_rows)
        if len(held_rows) == len(free_rows):  # the translation is not in this part: one matrix
            values = eigen.lowest_of(A, count)
            free.append(values)
            held.append(values)
            continue
        own, (values,) = eigen.lowest_with_relatives(
            A, count, [(eigen.restricted_rows(factor, free_rows, _class_rows(moments, extra, cls, index)), None,
                        lambda: eigen.restricted(H, factor, held_rows))])
        free.append(own)
        held.append(values)
    return {True: merged_parts(held, count), False: merged_parts(free, count)}


def _parts(equilibrium: Equilibrium, u, params: Parameters, m: int, b: AzimuthalBasis) -> tuple:
    """(the special modes' constraint rows G c, ((H, index, Gram factor, class) of each uncoupled part)): the two
    reflection classes of an equator-symmetric state, else the whole block (index and class None)."""
    moments = mode_moments(equilibrium, u, b) if m == 1 else np.zeros((0, b.size))
    if equilibrium.disc.symmetric and b.classes:
        return moments, tuple(zip(_class_hessians(equilibrium, u, params, m, b), b.classes, b.class_factors, (0, 1)))
    return moments, ((_hessian(equilibrium, u, params, m, b), None, b.factor, None),)


def block_pencils(equilibrium: Equilibrium, u, params: Parameters, m: int, degree: int, held: bool,
                  kind: str | None = None) -> tuple:
    """The m-th block of one reading (``restricted_blocks``) as the pencils of its uncoupled parts on the
    coefficients of its basis: (basis, ((K, G, N, index), ...)), K q = ν G q on N q = 0 (N the removed special
    modes' rows) for q supported on ``index``; for the eigenvectors (dynamics.modes)."""
    b = perturbation_basis(equilibrium, m, degree, 0, kind)
    moments, parts = _parts(equilibrium, u, params, m, b)
    modes = list(excluded_modes(equilibrium, params, held)) if m == 1 else []
    every = np.arange(b.size)
    return b, tuple((H, b.gram[np.ix_(index, index)] if cls is not None else b.gram, _class_rows(moments, modes, cls, index),
                     index if cls is not None else every) for H, index, _, cls in parts)


def _class_rows(moments, modes: list, cls, index):
    """The constraint rows of ``modes`` on the part ``index`` (all of them for the whole block, cls None; else
    those of the modes in reflection class cls)."""
    if cls is None:
        return moments[modes]
    kept = [k for k in modes if MODE_CLASS[k] == cls]
    return moments[kept][:, index] if kept else eigen.NO_CONSTRAINT


def excluded_modes(equilibrium: Equilibrium, params: Parameters, held: bool) -> tuple:
    """Indices into MODES of the m = 1 modes ``spectrum`` removes: always the relabelling; at M = 0 (or without
    coils) also the translation and the rotation; with a field the translation for a held balloon. The relabelling
    only where the reference is a sphere: a capsule of length L > 0 and a spheroid of aspect ≠ 1 have none (a
    rotation of the reference about a horizontal axis is no symmetry of it: no zero mode, and removing it would
    drop a mode of the block; surface.basis.SphericalBasis.relabellings)."""
    if params.M == 0 or not equilibrium.coils.shape[0]:
        modes = 0, 1, 2
    else:
        modes = (0, 2) if held else (2,)
    geometry = equilibrium.scene.geometry
    relabelled = geometry.aspect == 1.0 and not geometry.length  # the sphere, also as a spheroid or a capsule
    return modes if relabelled else tuple(k for k in modes if k != 2)
