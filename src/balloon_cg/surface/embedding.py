"""Axisymmetric states and azimuthal modes as coefficients of the whole-sphere basis (MODEL.md §8).

An axisymmetric state (λ2, η)(θ) is the surface x = (λ2 sin θ cos φ, λ2 sin θ sin φ, η); an azimuthal mode of
order m (analysis/stability/azimuthal.py) the displacement δx = R cos mφ e_ρ + T sin mφ e_φ + Z cos mφ e_z. Both are
projected on the spherical harmonics by the basis' quadrature: exact for a Legendre state of degree N when
L ≥ N + 1 (x, y are λ2 sin θ times cos φ, sin φ; z is η), and for a mode of degree ≤ L; a wire-mapped state is
approximated to the truncation error of degree L.
"""
import numpy as np

from .basis import SphericalBasis


def displacement_coefficients(basis: SphericalBasis, displacement: np.ndarray) -> np.ndarray:
    """The coefficients of the vector field given at the basis' nodes (3 rows x, y, z)."""
    return 2.0 * np.pi * basis.project(displacement)


def node_angles(basis: SphericalBasis) -> tuple:
    """(θ, φ) at every node, node order j N_φ + k."""
    theta = np.arccos(basis.nodes["cos_theta"])
    return np.repeat(theta, basis.n_phi), np.tile(basis.nodes["phi"], basis.n_theta)


def axisymmetric_coefficients(basis: SphericalBasis, disc, u: np.ndarray) -> np.ndarray:
    """c of the axisymmetric state u of the Discretisation ``disc`` (u = x − X)."""
    theta, phi = node_angles(basis)
    rings = np.arccos(basis.nodes["cos_theta"])
    lam2, _, eta, _ = disc.evaluate(u, rings)
    rho = np.repeat(lam2 * np.sin(rings), basis.n_phi)
    x = np.array([rho * np.cos(phi), rho * np.sin(phi), np.repeat(eta, basis.n_phi)])
    return displacement_coefficients(basis, x - basis.nodes["reference"][:3])


def mode_coefficients(basis: SphericalBasis, azimuthal_basis, vector: np.ndarray) -> np.ndarray:
    """c of an azimuthal mode (its coefficients ``vector`` in ``azimuthal_basis``, analysis.stability.azimuthal)."""
    theta, phi = node_angles(basis)
    return displacement_coefficients(basis, azimuthal_basis.cartesian(vector, theta, phi))


def transfer(source: SphericalBasis, c: np.ndarray, target: SphericalBasis) -> np.ndarray:
    """The state c of ``source`` on ``target`` (a finer degree or order, or another map): its displacement at the
    target's nodes, projected (exact when the target's space holds the source's, up to the quadrature of
    non-polynomial mapped functions)."""
    x = source.grid_values(c, target.nodes["cos_theta"], target.nodes["phi"]).reshape(3, -1)
    return displacement_coefficients(target, x - target.nodes["reference"][:3])


def embedded(source: SphericalBasis, c: np.ndarray, target: SphericalBasis) -> np.ndarray:
    """The coefficients c of ``source`` in ``target``, a basis of the same degree, order and unmapped harmonics whose
    space holds the source's (fewer reflections, or another sector's characters): placed by (component, m, type,
    degree), exact (``transfer`` projects through the nodes: rounding of the quadrature)."""
    if source.mapping is not None or target.mapping is not None or (source.degree, source.order) != (
            target.degree, target.order):
        raise ValueError("embedded: the bases must share their degree and order and have no polar map")
    blocks = {(b.component, b.m, b.t): b for b in target.blocks}
    out = np.zeros(target.size)
    for b in source.blocks:
        into = blocks[b.component, b.m, b.t]
        out[into.offset + np.searchsorted(into.degrees, b.degrees)] = c[b.slice]
    return out
