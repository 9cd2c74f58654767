"""The m = 1 block by brute force: a second method for the held m = 1 spectrum of ``azimuthal``, sharing neither
its kinematics, its generated kernel, its shear coefficient nor its basis (docs/paper.md, the m = 1 claim).

The energy of a general mid-surface x(θ, φ) (MODEL.md §2 without the axisymmetric reduction), per 2π:

    E = (1/2π) ∫∫ [Φ(Λ1, Λ2) − ½ χ M H²(x)] sin θ dθ dφ − P V/(2π),   V = (1/3) ∫∫ x·(x_θ × x_φ) dθ dφ,

Λ1², Λ2² the eigenvalues ½(c11 + c22) ± √(¼(c11 − c22)² + c12²) of C = G⁻¹g in the orthonormal reference
frame, c11 = |x_θ|², c22 = |q|², c12 = x_θ·q with q = x_φ / sin θ; H² = h_ρ² + h_z² from
``model.field.field_components``
at the 3D point. With Gauss nodes in cos θ (dθ sin θ = −d cos θ) and the trapezoid in φ, E = Σ_n w_n g(y_n), where
the density g = Φ − ½χMH²(x) − (P/3) x·(x_θ × q) at node n depends on the nine numbers y = (x, x_θ, q) there only.
So the Hessian of E in the coefficients c of x = x0 + Σ c_i δx_i is

    H = Σ_n w_n J_nᵀ (∂²g/∂y²)(y0_n) J_n,   J_n = ∂y_n/∂c (the basis functions' x, x_θ, q at node n),

∂²g/∂y² by central differences of g (step h and h/2, Richardson: O(h⁴)), one 9 × 9 matrix per node.

Basis of the m = 1 (cos φ) family: δx = R cos φ e_ρ + T sin φ e_φ + Z cos φ e_z with D = R − T = p(cos θ),
U = R + T = sin²θ p(cos θ), Z = sin θ p(cos θ), p plain Legendre polynomials of degree ≤ N, N − 2, N − 1: the
smooth fields (a smooth Cartesian δx), spanning the same space as ``azimuthal``'s P̄_k^j of degree N by another
construction. Cartesian components are built at every φ node; x_φ by FFT in φ.

Gram matrix: ‖δx‖² = (1/2π) ∫∫ |δx|² dA. Held: (1/2π) ∫∫ δx·e_x dA = 0 (the material centroid stays put). The
relabelling zero mode (the reference sphere rotated about e_y: δx = d/dε x0(Q_ε X), by central differences of the
state at rotated labels) is removed by G-orthogonality; it costs nothing at an equilibrium, so removing it
changes no negative eigenvalue. Every direction c satisfying the constraints with cᵀHc < 0 proves the state
unstable, whatever N: a negative lowest eigenvalue at any N is a certificate (Rayleigh–Ritz: it bounds the true
one from above).
"""
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre
from scipy import linalg, special

from ...galerkin.equilibrium import Parameters
from ...model.field import coaxial_table, field_components
from ...numerics.threads import limited_blas

STEP = 1e-3  # central-difference step in y (Richardson with STEP/2)
RELABEL_STEP = 1e-5  # rotation angle of the reference sphere, central difference


@dataclass(frozen=True)
class Grid:
    """Gauss–Legendre nodes in cos θ (``n_theta``) × ``n_phi`` equispaced φ; ``weights`` (n_theta·n_phi) carry
    the 1/2π of E per 2π (Σ weights = 2, the reference area / 2π)."""

    n_theta: int
    n_phi: int

    def __post_init__(self):
        x, w = special.roots_legendre(self.n_theta)
        phi = 2 * np.pi * np.arange(self.n_phi) / self.n_phi
        put = object.__setattr__
        put(self, "x", x)
        put(self, "theta", np.arccos(x))
        put(self, "phi", phi)
        put(self, "weights", np.repeat(w / self.n_phi, self.n_phi))


def _cartesian(radial, azimuthal, axial, phi):
    """(3, n_theta, n_phi) Cartesian vectors radial·e_ρ(φ) + azimuthal·e_φ(φ) + axial·e_z, components (n_theta,
    n_phi) each."""
    c, s = np.cos(phi), np.sin(phi)
    return np.array([radial * c - azimuthal * s, radial * s + azimuthal * c, axial])


def _d_phi(field, n_phi):
    """∂/∂φ of a field sampled at the φ nodes (last axis), spectrally (FFT)."""
    k = np.fft.fftfreq(n_phi, 1.0 / n_phi)
    return np.real(np.fft.ifft(1j * k * np.fft.fft(field, axis=-1), axis=-1))


def state_vectors(disc, u, grid: Grid) -> np.ndarray:
    """y0 = (x0, x0_θ, x0_φ / sin θ) of the axisymmetric state u (unknowns of ``disc``) at the grid nodes, (9, n)."""
    lam2, dlam2, eta, deta = disc.evaluate(np.asarray(u, dtype=float), grid.theta)
    s, c = np.sin(grid.theta), grid.x
    ones = np.ones(grid.n_phi)
    rho, drho = lam2 * s, dlam2 * s + lam2 * c
    x = _cartesian(np.outer(rho, ones), 0.0, np.outer(eta, ones), grid.phi)
    xt = _cartesian(np.outer(drho, ones), 0.0, np.outer(deta, ones), grid.phi)
    q = _d_phi(x, grid.n_phi) / s[:, None]
    return np.concatenate([x, xt, q]).reshape(9, -1)


def basis_vectors(grid: Grid, degree: int) -> np.ndarray:
    """J: (9, n, size) the (δx, δx_θ, δx_φ / sin θ) of each basis function (module docstring), ordered (D, U, Z)."""
    x, s = grid.x, np.sin(grid.theta)
    columns = []
    for name, power, top in (("D", 0, degree), ("U", 2, degree - 2), ("Z", 1, degree - 1)):
        for k in range(top + 1):
            e = np.eye(top + 1)[k]
            p, dp = legendre.legval(x, e), legendre.legval(x, legendre.legder(e))
            f = s**power * p  # sin^j θ p(cos θ) and its θ-derivative
            df = (power * s ** max(power - 1, 0) * x * p if power else 0.0) - s ** (power + 1) * dp
            columns.append((name, f, df))
    cm, sm = np.cos(grid.phi), np.sin(grid.phi)
    out = np.empty((9, grid.weights.size, len(columns)))
    for i, (name, f, df) in enumerate(columns):
        zero = np.zeros_like(f)
        if name == "Z":
            R, T, Z, dR, dT, dZ = zero, zero, f, zero, zero, df
        else:  # R = (U + D)/2, T = (U − D)/2
            sign = 1.0 if name == "U" else -1.0
            R, T, Z, dR, dT, dZ = f / 2, sign * f / 2, zero, df / 2, sign * df / 2, zero
        dx = _cartesian(np.outer(R, cm), np.outer(T, sm), np.outer(Z, cm), grid.phi)
        dxt = _cartesian(np.outer(dR, cm), np.outer(dT, sm), np.outer(dZ, cm), grid.phi)
        dq = _d_phi(dx, grid.n_phi) / s[:, None]
        out[:, :, i] = np.concatenate([dx, dxt, dq]).reshape(9, -1)
    return out


def density(y: np.ndarray, material, coils: np.ndarray, params: Parameters, field=None) -> np.ndarray:
    """g(y) at every node (module docstring), y (9, n) = (x, x_θ, x_φ / sin θ); ``field``: −½χMH²(x) at these x
    when known (``field_energy``)."""
    x, xt, q = y[0:3], y[3:6], y[6:9]
    c11, c22, c12 = (xt * xt).sum(0), (q * q).sum(0), (xt * q).sum(0)
    mean, radius = 0.5 * (c11 + c22), np.hypot(0.5 * (c11 - c22), c12)
    l1, l2 = np.sqrt(mean + radius), np.sqrt(mean - radius)
    g = sum(m / a * (l1**a + l2**a + (l1 * l2) ** (-a) - 3) for m, a in zip(material.mu, material.alpha))
    field = field_energy(x, coils, params) if field is None else field
    return g + field - params.P / 3 * (x * np.cross(xt, q, axis=0)).sum(0)


def field_energy(x: np.ndarray, coils: np.ndarray, params: Parameters):
    """−½ χ M H²(x) at the points x (3, n), H² = h_ρ² + h_z² (0 without field)."""
    if not (params.M and coils.shape[0]):
        return 0.0
    h_rho, h_z = field_components(np.hypot(x[0], x[1]), x[2], coils)
    return -0.5 * params.chi * params.M * (h_rho**2 + h_z**2)


def density_hessians(y0, material, coils, params, step: float = STEP) -> np.ndarray:
    """∂²g/∂y² at every node, (n, 9, 9): central differences at ``step`` and ``step``/2, Richardson."""

    field0 = field_energy(y0[0:3], coils, params)

    def second(h):
        def g(*shifts):  # the field at x0 unless a shift moves x (rows 0–2)
            moved = any(row < 3 for row, _ in shifts)
            return density(_shifted(y0, shifts), material, coils, params, None if moved else field0)

        out = np.empty((y0.shape[1], 9, 9))
        g0 = g()
        for a in range(9):
            out[:, a, a] = (g((a, h)) + g((a, -h)) - 2 * g0) / h**2
            for b in range(a):
                out[:, a, b] = out[:, b, a] = (g((a, h), (b, h)) - g((a, h), (b, -h)) - g((a, -h), (b, h))
                                               + g((a, -h), (b, -h))) / (4 * h * h)
        return out

    return (4 * second(step / 2) - second(step)) / 3


def _shifted(y, shifts):
    out = y.copy()
    for row, h in shifts:
        out[row] += h
    return out


def relabelling(disc, u, grid: Grid, step: float = RELABEL_STEP) -> np.ndarray:
    """δx = d/dε x0(Q_ε X) at the grid nodes, (3, n): the state at labels X on the unit sphere rotated by ε about
    e_y (central difference)."""
    X = np.array([np.outer(np.sin(grid.theta), np.cos(grid.phi)), np.outer(np.sin(grid.theta), np.sin(grid.phi)),
                  np.outer(grid.x, np.ones(grid.n_phi))]).reshape(3, -1)

    def position(angle):
        c, s = np.cos(angle), np.sin(angle)
        Y = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]) @ X
        theta, phi = np.arccos(np.clip(Y[2], -1, 1)), np.arctan2(Y[1], Y[0])
        lam2, _, eta, _ = disc.evaluate(np.asarray(u, dtype=float), theta)
        return np.array([lam2 * np.sin(theta) * np.cos(phi), lam2 * np.sin(theta) * np.sin(phi), eta])

    return (position(step) - position(-step)) / (2 * step)


@dataclass(frozen=True)
class BruteForceBlock:
    """The m = 1 block of one state: Hessian ``H`` and Gram ``G`` (size 3N), constraint rows G-products of the
    basis with the translation e_x (``translation``) and the relabelling mode (``relabelling``), and the rigid
    rotation e_y × x0 as the right-hand side of its L2 projection (``rotation``)."""

    H: np.ndarray
    G: np.ndarray
    translation: np.ndarray
    relabelling: np.ndarray
    rotation: np.ndarray

    def lowest(self, count: int = 3, held: bool = True, vectors: bool = False):
        """The ``count`` lowest μ of H c = μ G c with the relabelling mode removed and, ``held``, the
        translation constrained (free: only the relabelling)."""
        rows = np.vstack([self.relabelling, self.translation] if held else [self.relabelling])
        null = linalg.null_space(rows)
        values, vecs = linalg.eigh(null.T @ self.H @ null, null.T @ self.G @ null, subset_by_index=(0, count - 1))
        return (values, null @ vecs) if vectors else values

    def rotation_share(self, c: np.ndarray) -> float:
        """|⟨δx_c, e_y × x0⟩| / (‖δx_c‖ ‖P(e_y × x0)‖), P the projection on the basis: how much of the mode c
        is the rigid tilt."""
        projected = linalg.solve(self.G, self.rotation, assume_a="pos")
        return abs(c @ self.rotation) / np.sqrt((c @ self.G @ c) * (projected @ self.rotation))


def coil_rows(scene) -> np.ndarray:
    """The scene's coils as rows (radius, height, current)."""
    return coaxial_table(scene.field.coils)


@limited_blas
def m1_block(disc, scene, u, params: Parameters, degree: int, grid: Grid, step: float = STEP) -> BruteForceBlock:
    """``BruteForceBlock`` of the axisymmetric state u (unknowns of ``disc``) of ``scene`` at ``params``."""
    coils = coil_rows(scene)
    y0 = state_vectors(disc, u, grid)
    J = basis_vectors(grid, degree)
    D = density_hessians(y0, scene.material, coils, params, step) * grid.weights[:, None, None]
    weighted = np.matmul(D, J.transpose(1, 0, 2))  # (∂²g/∂y²) J at every node, (n, 9, size)
    H = J.transpose(1, 0, 2).reshape(-1, J.shape[2]).T @ weighted.reshape(-1, J.shape[2])
    w = grid.weights
    dx = J[0:3]
    G = (dx * w[:, None]).reshape(-1, J.shape[2]).T @ dx.reshape(-1, J.shape[2])
    x0 = y0[0:3]
    rotation = np.array([x0[2], 0 * x0[0], -x0[0]])  # e_y × x0
    project = lambda field: (dx * w[:, None]).reshape(-1, J.shape[2]).T @ field.reshape(-1)  # noqa: E731
    return BruteForceBlock(0.5 * (H + H.T), 0.5 * (G + G.T), dx[0].T @ w, project(relabelling(disc, u, grid)),
                           project(rotation))


def energy(disc, scene, u, params: Parameters, grid: Grid, dy=None) -> float:
    """E/(2π) of the surface with node values y0 + ``dy`` ((9, n): a perturbation's (δx, δx_θ, δx_φ / sin θ),
    e.g. ε·J c from ``basis_vectors``) integrated on ``grid``: the global check of ``m1_block``'s H."""
    y = state_vectors(disc, u, grid)
    return float(grid.weights @ density(y if dy is None else y + dy, scene.material, coil_rows(scene), params))
