"""What a non-axisymmetric state is measured by: the stretch at the material poles, the enclosed volume, the
centroid of the enclosed body (offset from the held centre) and the tilt of its axis, and the spectral tail.

Volume integrals become surface integrals over the reference sphere with n dS = (a_θ × a_φ) dA (divergence theorem):
V = ⅓ ∫ x·n dS, ∫_V x_i dV = ½ ∫ x_i² n_i dS, ∫_V x_i x_j dV = ⅕ ∫ x_i x_j (x·n) dS. Every value is per 2π like E
(the centroid and the tilt are ratios, free of it).
"""
import numpy as np

from .basis import SphericalBasis

MEASURES = ("lam_top", "lam_bottom", "volume", "centroid", "tilt")  # centroid: (n, 3); tilt: degrees


def pole_stretch(basis: SphericalBasis, c: np.ndarray, theta: float) -> float:
    """√J = √(λ1 λ2) at the material point θ ∈ {0, π}: the tangent plane there is spanned by the θ-derivatives
    along φ = 0 and φ = π/2 (the two orthogonal directions away from the pole), and J = |a(0) × a(π/2)|."""
    _, a = basis.point_values(c, np.full(2, theta), np.array([0.0, np.pi / 2]))
    return float(np.sqrt(np.linalg.norm(np.cross(a[:, 0], a[:, 1]))))


def body_moments(basis: SphericalBasis, state: np.ndarray) -> tuple:
    """(V, ∫_V x dV, ∫_V x xᵀ dV), per 2π, from the node state (9 rows)."""
    x, normal = state[:3], np.cross(state[3:6], state[6:9], axis=0)
    weights = np.repeat(basis.nodes["weights"], basis.n_phi)
    flux = np.einsum("in,in->n", x, normal)
    volume = weights @ flux / 3.0
    first = (x * x * normal) @ weights / 2.0
    second = np.einsum("in,jn,n->ij", x, x, flux * weights) / 5.0
    return float(volume), first, second


def measures(basis: SphericalBasis, c: np.ndarray) -> dict:
    """The MEASURES of the state c: the pole stretches, V/(2π), the centroid x_c and the tilt: the angle (degrees,
    0..90) between e_z and the body's axis (``body_axis``)."""
    volume, first, second = body_moments(basis, basis.node_state(c))
    centroid = first / volume
    central = second / volume - np.outer(centroid, centroid)
    tilt = np.degrees(np.arccos(min(1.0, abs(float(body_axis(central)[2])))))
    return {"lam_top": pole_stretch(basis, c, 0.0), "lam_bottom": pole_stretch(basis, c, np.pi),
            "volume": volume, "centroid": centroid, "tilt": tilt}


def body_axis(central: np.ndarray) -> np.ndarray:
    """The axis of a body from its central second moments m0 ≤ m1 ≤ m2: the principal axis whose moment stands
    apart, that of m2 when m2 − m1 ≥ m1 − m0 (a body longest along it), else that of m0 (a body shortest along it).
    For a body of revolution it is the axis of revolution either way: a balloon that turns from elongated to
    flattened along one axis keeps it, where the axis of the largest moment would jump to any normal direction."""
    moments, axes = np.linalg.eigh(central)
    return axes[:, 2] if moments[2] - moments[1] >= moments[1] - moments[0] else axes[:, 0]


def tails(basis: SphericalBasis, c: np.ndarray) -> tuple:
    """(θ-tail, φ-tail): the largest coefficient of degree L − 1 or L, and of order M − 1 or M when the basis stops
    at an order M < L (0 otherwise: the degree tail holds it). On a resolved state the coefficients decay
    geometrically in both, and these bound what the truncation cuts off."""
    theta = max((np.abs(c[b.slice][np.array(b.degrees) >= basis.degree - 1]).max(initial=0.0) for b in basis.blocks),
                default=0.0)
    phi = 0.0
    if basis.order < basis.degree:
        phi = max((np.abs(c[b.slice]).max(initial=0.0) for b in basis.blocks if b.m >= basis.order - 1), default=0.0)
    return float(theta), float(phi)


def tail(basis: SphericalBasis, c: np.ndarray) -> float:
    """The spectral error estimate of the state: the larger of its ``tails``."""
    return max(tails(basis, c))


def axial_stretch_row(basis: SphericalBasis) -> tuple:
    """(r, r0) with e_x · a_θ(θ = 0, φ = 0) = r0 + r · c: the north pole stretch λ2(0) of an axisymmetric state (there
    a_θ = λ2(0) e_x at φ = 0), a linear function of c: a bordering row that prescribes it (as the axisymmetric
    solver's point_solve does)."""
    r0 = float(basis.point_values(np.zeros(basis.size), 0.0, 0.0)[1][0, 0])
    row = np.zeros(basis.size)
    for b in basis.blocks:
        if b.component == 0 and b.m == 1:
            for k in range(b.offset, b.offset + len(b.degrees)):
                row[k] = basis.point_values(np.eye(basis.size)[k], 0.0, 0.0)[1][0, 0] - r0
    return row, r0
