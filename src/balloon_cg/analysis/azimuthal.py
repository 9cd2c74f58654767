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
from numpy.polynomial import legendre
from scipy import linalg

from ..galerkin.equilibrium import Equilibrium, Parameters

# blocks of at least this size use LAPACK's subset driver (n = 960: 0.06 s against 0.19 s for the Cholesky
# reduction and a full syevd, which wins on small blocks)
LARGE_BLOCK = 200


def legendre_values(x: np.ndarray, degree: int, order: int) -> np.ndarray:
    """P̄_k^order(x) for k = 0..degree (zero for k < order), shape (len(x), degree + 1); orthonormal on [−1, 1]
    (∫ P̄_k^j P̄_l^j dx = δ_kl), Condon–Shortley phase, stable three-term recurrence; valid at x = ±1."""
    x = np.asarray(x, dtype=float)
    s = np.sqrt(np.clip(1.0 - x * x, 0.0, None))
    p = np.zeros((x.size, degree + 1))
    j = order
    if j > degree:
        return p
    pjj = np.full(x.size, np.sqrt(0.5))
    for i in range(1, j + 1):
        pjj = -np.sqrt((2 * i + 1) / (2 * i)) * s * pjj
    p[:, j] = pjj
    if j + 1 <= degree:
        p[:, j + 1] = np.sqrt(2 * j + 3) * x * pjj
    for k in range(j + 2, degree + 1):
        a = np.sqrt((4 * k * k - 1) / (k * k - j * j))
        b = np.sqrt(((k - 1) ** 2 - j * j) / (4 * (k - 1) ** 2 - 1))
        p[:, k] = a * (x * p[:, k - 1] - b * p[:, k - 2])
    return p


def assoc_legendre(x: np.ndarray, degree: int, order: int):
    """(P̄_k^order(x), dP̄_k^order/dθ) for k = 0..degree at interior points x = cos θ ∈ (−1, 1), using
    dP_k^j/dθ = (k x P_k^j − (k + j) P_{k−1}^j)/sin θ (normalised)."""
    x = np.asarray(x, dtype=float)
    p = legendre_values(x, degree, order)
    dp = np.zeros_like(p)
    s = np.sqrt(1.0 - x * x)
    for k in range(order, degree + 1):
        c = np.sqrt((k * k - order * order) * (2 * k + 1) / (2 * k - 1)) if k > order else 0.0
        previous = p[:, k - 1] if k > order else 0.0
        dp[:, k] = (k * x * p[:, k] - c * previous) / s
    return p, dp


@dataclass(frozen=True)
class AzimuthalBasis:
    """Basis of the cos mφ perturbations (module docstring) at Gauss–Legendre nodes in x = cos θ."""

    m: int
    degree: int
    quadrature: int

    def __post_init__(self):
        m, n = self.m, self.degree
        if m < 1:
            raise ValueError(f"m = {m}: the azimuthal second variation needs m ≥ 1 (m = 0 is Equilibrium.jacobian)")
        if n < m:
            raise ValueError(f"degree = {n}: must be ≥ m = {m}")
        x, weights = legendre.leggauss(self.quadrature)
        put = object.__setattr__
        put(self, "x", x)
        put(self, "weights", weights)
        put(self, "sin_theta", np.sqrt(1.0 - x * x))
        put(self, "theta", np.arccos(x))
        blocks = {}
        offset = 0
        columns = []
        for name, order in (("Z", m), ("U", m + 1), ("D", m - 1)):
            p, dp = assoc_legendre(x, n, order)
            k = np.arange(order, n + 1)
            blocks[name] = (slice(offset, offset + k.size), k)
            columns.append((name, p[:, k], dp[:, k]))
            offset += k.size
        put(self, "blocks", blocks)
        put(self, "size", offset)
        ops = np.zeros((6, x.size, offset))  # node values of (R, R', Z, Z', T, T') per unknown
        for name, p, dp in columns:
            sl = blocks[name][0]
            if name == "Z":
                ops[2, :, sl], ops[3, :, sl] = p, dp
            else:  # R = (U + D)/2, T = (U − D)/2
                sign = 1.0 if name == "U" else -1.0
                ops[0, :, sl], ops[1, :, sl] = p / 2, dp / 2
                ops[4, :, sl], ops[5, :, sl] = sign * p / 2, sign * dp / 2
        put(self, "ops", ops)
        # R, R', T, T' involve only the U and D coefficients, Z, Z' only the Z ones: the assembly works on these
        # column groups (about half the work of the full products)
        z = blocks["Z"][0]
        ud = slice(z.stop, offset)
        put(self, "groups", tuple((rows, cols, np.ascontiguousarray(ops[np.ix_(rows, np.arange(x.size),
                                                                                np.arange(offset)[cols])]))
                                  for rows, cols in (((0, 1, 4, 5), ud), ((2, 3), z))))
        w = weights[:, None]
        gram = 0.5 * sum(ops[k].T @ (w * ops[k]) for k in (0, 2, 4))
        put(self, "gram", 0.5 * (gram + gram.T))

    def values(self, c: np.ndarray) -> np.ndarray:
        """(R, R', Z, Z', T, T') at the nodes for coefficients c, shape (6, n_q)."""
        return self.ops @ c

    def project(self, R: np.ndarray, T: np.ndarray, Z: np.ndarray) -> np.ndarray:
        """L2 (‖δx‖) projection of node values of (R, T, Z) onto the basis: the coefficients c."""
        w = self.weights
        rhs = 0.5 * (self.ops[0].T @ (w * R) + self.ops[4].T @ (w * T) + self.ops[2].T @ (w * Z))
        return linalg.solve(self.gram, rhs, assume_a="pos")

    def cartesian(self, c: np.ndarray, theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """Cartesian displacement δx (3, len(theta)) at points (θ, φ), θ anywhere in [0, π] (poles included)."""
        theta = np.asarray(theta, dtype=float)
        x = np.cos(theta)
        fields = {}
        for name, order in (("Z", self.m), ("U", self.m + 1), ("D", self.m - 1)):
            sl, k = self.blocks[name]
            p = legendre_values(x, self.degree, order)
            fields[name] = p[:, k] @ c[sl]
        R, T, Z = (fields["U"] + fields["D"]) / 2, (fields["U"] - fields["D"]) / 2, fields["Z"]
        cm, sm = np.cos(self.m * phi), np.sin(self.m * phi)
        horizontal_r, horizontal_p = R * cm, T * sm
        return np.array([horizontal_r * np.cos(phi) - horizontal_p * np.sin(phi),
                         horizontal_r * np.sin(phi) + horizontal_p * np.cos(phi), Z * cm])


def default_quadrature(degree: int, equilibrium_degree: int) -> int:
    """Gauss nodes: the integrand is a product of two basis functions (degree ≤ N each) and coefficients that are
    smooth functions of the equilibrium (degree N_eq), so N + N_eq + 16 nodes integrate it to rounding."""
    return degree + equilibrium_degree + 16


@lru_cache(maxsize=32)
def basis(m: int, degree: int, quadrature: int) -> AzimuthalBasis:
    return AzimuthalBasis(m, degree, quadrature)


def _node_matrix(equilibrium: Equilibrium, u, params: Parameters, m: int, b: AzimuthalBasis) -> np.ndarray:
    """The kernel's entries of h at every node (the AZIMUTHAL_PAIRS of y = PERTURBATION), shape (21, n_q)."""
    lam2, dlam2, eta, deta = equilibrium.disc.evaluate(np.asarray(u, dtype=float), b.theta)
    state = (lam2, dlam2 * b.sin_theta, eta, deta)
    return equilibrium.pointwise("azimuthal_hessian", (b.x, b.sin_theta), state, params, m=float(m))


def azimuthal_hessian(equilibrium: Equilibrium, u, params: Parameters, m: int, degree: int, quadrature: int = 0):
    """(H, G): the Galerkin matrix of d²E/dε² and the Gram matrix of ‖δx‖² for cos mφ perturbations of the
    axisymmetric state u (unknowns of ``equilibrium.disc``) at parameters ``params``, basis of ``degree`` N
    (module docstring; see ``perturbation_basis`` for the layout). Both are symmetric, of size 3(N − m + 1)."""
    b = perturbation_basis(equilibrium, m, degree, quadrature)
    h = _node_matrix(equilibrium, u, params, m, b) * b.weights
    blocks = np.empty((6, 6, b.x.size))
    for row, (k, l) in enumerate(equilibrium.kernels.module.AZIMUTHAL_PAIRS):
        blocks[k, l] = blocks[l, k] = h[row]
    H = np.empty((b.size, b.size))
    for i, (rows_i, cols_i, ops_i) in enumerate(b.groups):
        for rows_j, cols_j, ops_j in b.groups[i:]:
            scaled = np.einsum("kln,lni->kni", blocks[np.ix_(rows_i, rows_j)], ops_j)
            H[cols_i, cols_j] = ops_i.reshape(-1, ops_i.shape[2]).T @ scaled.reshape(-1, ops_j.shape[2])
            H[cols_j, cols_i] = H[cols_i, cols_j].T
    return 0.5 * (H + H.T), b.gram


def perturbation_basis(equilibrium: Equilibrium, m: int, degree: int, quadrature: int = 0) -> AzimuthalBasis:
    """The basis ``azimuthal_hessian`` uses for this equilibrium's discretisation (cached)."""
    return basis(int(m), int(degree), int(quadrature or default_quadrature(degree, equilibrium.disc.degree)))


def special_modes(equilibrium: Equilibrium, u, degree: int, quadrature: int = 0) -> dict:
    """Coefficient vectors of the m = 1 perturbations that cost no energy by symmetry, for the state u:

    - ``translation`` along e_x: R = 1, T = −1, Z = 0 (a zero mode at M = 0, any state);
    - ``rotation`` about e_y, δx = e_y × x0: R = η0, T = −η0, Z = −ρ0 (a zero mode at M = 0 equilibria);
    - ``relabelling``: the rotation of the *reference* sphere about e_y, δx = ∂x0/∂X·(e_y × X):
      R = ρ0', T = −ρ0 cot θ, Z = η0'. The reference sphere and the material are isotropic, so E[x ∘ Q] = E[x]
      for every rotation Q of the material labels: a zero mode of every equilibrium, with or without field
      (material slides along the deformed surface, the shape does not change). On a sphere it is the rotation.

    All are regular (D = R − T ≠ 0 at the poles) and exact in the basis when degree ≥ the equilibrium's Legendre
    degree + 1 (the translation for any degree)."""
    b = perturbation_basis(equilibrium, 1, degree, quadrature)
    lam2, dlam2, eta, deta = equilibrium.disc.evaluate(np.asarray(u, dtype=float), b.theta)
    s, c = b.sin_theta, b.x
    one = np.ones_like(eta)
    return {
        "translation": b.project(one, -one, 0 * one),
        "rotation": b.project(eta, -eta, -lam2 * s),
        "relabelling": b.project(lam2 * c + dlam2 * s, -lam2 * c, deta),
    }


def restrict(H, G, normals, rcond: float = 1e-9):
    """(H, G) on the hyperplanes n·c = 0 of the columns n of ``normals`` (linearly dependent columns are fine:
    directions below rcond times the largest singular value are dropped): one Householder reflection Q per
    direction (Qn ∥ e_1, then the first coordinate dropped), each a rank-two update of H and G (O(n²), no
    null-space basis); the result is the restriction in an orthonormal basis of the intersection."""
    U, s, _ = np.linalg.svd(np.reshape(normals, (len(H), -1)), full_matrices=False)
    U = U[:, s > rcond * s[0]]
    while U.shape[1]:
        v = U[:, 0].copy()
        v[0] += np.copysign(1.0, v[0])
        w = 2.0 / (v @ v)
        H, G = _reflect(H, v, w)[1:, 1:], _reflect(G, v, w)[1:, 1:]
        U = (U[:, 1:] - w * np.outer(v, v @ U[:, 1:]))[1:]
    return H, G


def _reflect(A, v, w):
    """Q A Q for symmetric A and Q = I − w v vᵀ (w = 2/(vᵀv))."""
    Av = A @ v
    return A - w * (np.outer(v, Av) + np.outer(Av, v)) + w * w * (v @ Av) * np.outer(v, v)


def lowest_eigenvalues(H, G, count: int = 6, exclude=None, vectors: bool = False):
    """The ``count`` lowest μ of H c = μ G c. ``exclude`` (rows: coefficient vectors, e.g. from ``special_modes``)
    restricts the problem to {c : E G c = 0}, the G-orthogonal complement of their span (linearly dependent rows
    are fine): an exact null vector is then removed from the spectrum and nothing else changes, and excluding
    the translation is the constraint that the material centroid stays put (∫ δx dA = 0). Returned vectors are
    in the full basis. Blocks of size ≥ LARGE_BLOCK (eigenvalues only) go through ``restrict`` and the subset driver."""
    excluding = exclude is not None and len(exclude)
    if not vectors and H.shape[0] >= LARGE_BLOCK:
        if excluding:
            H, G = restrict(H, G, (np.atleast_2d(exclude) @ G).T)
        return linalg.eigh(H, G, eigvals_only=True, subset_by_index=(0, min(count, H.shape[0]) - 1))
    null = None
    if excluding:
        null = linalg.null_space(np.atleast_2d(exclude) @ G, rcond=1e-9)
        H, G = null.T @ H @ null, null.T @ G @ null
    count = min(count, H.shape[0])
    if not vectors:  # Cholesky reduction + LAPACK syevd: several times faster than the subset driver on small blocks
        inverse = np.linalg.inv(np.linalg.cholesky(G))
        return np.linalg.eigvalsh(inverse @ H @ inverse.T)[:count]
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
    H, G = azimuthal_hessian(equilibrium, u, params, m, degree, quadrature)
    modes = special_modes(equilibrium, u, degree, quadrature) if m == 1 else None
    out = {}
    for held in readings:
        exclude = []
        if m == 1:
            exclude.append(modes["relabelling"])
            if params.M == 0 or not equilibrium.coils.shape[0]:
                exclude += [modes["translation"], modes["rotation"]]
            elif held:
                exclude.append(modes["translation"])
        out[held] = lowest_eigenvalues(H, G, count, exclude)
    return out
