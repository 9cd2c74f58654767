"""Mode shapes: the eigenvectors of the lowest natural frequencies of a block at one equilibrium (docs/dynamics.md).

A block's pencil K q = ν M q on its constraints N q = 0 (``SecondVariation.block_pencil`` for m = 0,
``azimuthal.block_pencils`` for m ≥ 1: the matrices ``frequencies.frequencies`` reduces to standard form) is
solved on an orthonormal basis Z of the null space of N: Zᵀ K Z w = ν Zᵀ M Z w (LAPACK's generalized symmetric
solver through scipy.linalg.eigh), q = Z w, a second solve of the pencil whose ν match the stored Ω² = ν/2. Each
mode is mass-normalised, qᵀMq = 1, and drawn as a displacement of the reference meridian on a θ grid:

    m = 0:  δρ = R δλ2,  δz = δη,  δφ = 0      (δλ2 = Σ a_k P_k, δη = Σ b_k P_k less its held mean on a map)
    m ≥ 1:  δρ = R cos mφ,  δz = Z cos mφ,  δφ = T sin mφ, stored as the amplitudes (R, Z, T)

in lengths over R0 for a unit modal mass qᵀMq = (1/2π)∫∫|δx|² dA = 1 over the reference surface (T = ½ q̇ᵀMq̇ the
kinetic energy per 2π of generated/inertia.py): ∫(δρ² + δz²) S' dx = 1 for m = 0, ½∫(R² + Z² + T²) S' dx = 1 for
m ≥ 1 (x = cos θ, S' = 1 on the sphere: model/meridian.py); on the sphere a rigid translation along the axis is
δz = 1/√2. The sign: the component of largest magnitude is
positive.
"""
import numpy as np
from scipy import linalg

from ..analysis.stability.azimuthal import block_pencils
from ..analysis.results import Block
from ..analysis.stability.axisymmetric import held_means
from ..model.meridian import hoop
from ..numerics.eigen import RCOND
from .pencil import PER_EIGENVALUE

COMPONENTS = ("d_rho", "d_z", "d_phi")  # the stored displacement components (m ≥ 1: amplitudes of cos mφ, sin mφ)


def lowest_modes(K, M, normals, count: int) -> tuple:
    """(ν, q): the ``count`` lowest eigenvalues (ascending) of K q = ν M q on N q = 0 (``normals`` N, k × n;
    dependent rows dropped at numerics.eigen.RCOND) and their M-orthonormal eigenvectors (rows)."""
    Z = linalg.null_space(normals, rcond=RCOND) if normals.shape[0] else np.eye(K.shape[0])
    k = min(count, Z.shape[1])
    values, w = linalg.eigh(Z.T @ K @ Z, Z.T @ M @ Z, subset_by_index=[0, k - 1])
    return values, (Z @ w).T


def block_modes(variation, u, params, symmetric: bool, name: str, count: int, theta) -> tuple:
    """(Ω², shapes) of the block ``name`` at the equilibrium u: its ``count`` lowest Ω² (ascending) and their mode
    shapes (count × 3 components (COMPONENTS) × θ), module docstring; ``variation`` the pencil's second variation
    (frequencies' ``mass_variation``)."""
    m = Block.order_of(name)
    if not m:
        K, M, normals, index = variation.block_pencil(u, params, symmetric, name)
        values, q = lowest_modes(K, M, normals, count)
        c = np.zeros((values.size, variation.basis.size))
        c[:, index] = q
        shapes = _axisymmetric_shapes(variation.basis, c, theta, variation.eq.scene.geometry)
    else:
        basis, parts = block_pencils(variation.eq, u, params, m, variation.basis.degree, Block(name).held,
                                     variation.basis_kind)
        found = [lowest_modes(K, M, normals, count) + (index,) for K, M, normals, index in parts]
        values = np.concatenate([v for v, _, _ in found])
        c = np.zeros((values.size, basis.size))
        row = 0
        for v, q, index in found:
            c[row:row + v.size, index] = q
            row += v.size
        order = np.argsort(values)[:count]
        values, c = values[order], c[order]
        shapes = basis.displacement(c, theta)
    largest = np.abs(shapes).reshape(len(shapes), -1).argmax(axis=1)
    signs = np.sign(shapes.reshape(len(shapes), -1)[np.arange(len(shapes)), largest])
    return PER_EIGENVALUE * values, shapes * signs[:, None, None]


def _axisymmetric_shapes(basis, c, theta, geometry) -> np.ndarray:
    """(δρ, δz, 0) on θ (rows × 3 × θ) of the m = 0 perturbation coefficients c (rows: a_0..a_N, b_0..b_N) on
    ``basis`` (its held η functions P_k − m_k on a map or a spheroid: ``stability.held_means``), δρ = R δλ2 with R the reference
    meridian's (model/meridian.hoop: sin θ on the sphere)."""
    lam2, _, eta, _ = basis.evaluate(c, theta)
    eta = eta - (c[:, basis.a_index.size + 1:] @ held_means(basis, geometry))[:, None]
    return np.stack([hoop(geometry, np.cos(theta), np.sin(theta)) * lam2, eta, np.zeros_like(eta)], axis=1)
