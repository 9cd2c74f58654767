"""Lowest eigenvalues of a symmetric pencil (H, G), G = L Lᵀ > 0, on the hyperplanes nᵢᵀc = 0.

With y = Lᵀc the pencil becomes the standard problem A y = μ y, A = L⁻¹ H L⁻ᵀ, and a constraint nᵀc = 0 becomes
(L⁻¹n)ᵀ y = 0. The constraint directions are orthonormalised by an SVD (directions below rcond times the largest
singular value are dropped: linearly dependent normals are fine) and each is removed by a Householder
reflection Q (Q d ∥ e₁, then the first row and column dropped): a rank-two update, no null-space basis. The
spectrum of the result is that of the Rayleigh quotient cᵀHc / cᵀGc on {c : Nᵀc = 0}. The reduction is one
jitted call (``restricted_matrix``); the eigenvalues come from LAPACK's dsyevr for the lowest ``count`` only
(tridiagonalisation and bisection, no full spectrum).
"""
import numpy as np
from numba import njit
from scipy.linalg.lapack import dpotrf, dsyevr

RCOND = 1e-9  # constraint directions below RCOND times the largest are dependent ones (dropped)
NO_CONSTRAINT = np.zeros((0, 1))


def restricted(H, inverse_factor, normals=NO_CONSTRAINT, index=None, rcond: float = RCOND) -> np.ndarray:
    """The standard symmetric matrix A of the pencil (H, G) on the block ``index`` of H (None: all of it) with
    Nᵀc = 0 (module docstring); ``inverse_factor`` is L⁻¹ of the block of G (G = LLᵀ), ``normals`` the rows nᵢ on
    the block (k × n). Its eigenvalues are the pencil's on the constrained block, its inertia the block's."""
    index = np.arange(H.shape[0]) if index is None else np.asarray(index, dtype=np.int64)
    normals = np.ascontiguousarray(np.atleast_2d(normals), dtype=float)
    return restricted_matrix(np.ascontiguousarray(H, dtype=float), index, inverse_factor, normals, rcond)


def lowest_of(A, count: int) -> np.ndarray:
    """The ``count`` lowest eigenvalues (ascending) of the symmetric A (LAPACK dsyevr, range 'I'; A is passed as
    its F-ordered transpose, no copy, and overwritten)."""
    values, _, found, _, info = dsyevr(A.T, compute_v=0, range="I", il=1, iu=min(count, A.shape[0]), overwrite_a=1)
    if info != 0:
        raise np.linalg.LinAlgError(f"dsyevr failed (info = {info})")
    return values[:found]


def positive_definite(A) -> bool:
    """Whether the symmetric A has no eigenvalue ≤ 0 (its Cholesky factorisation exists: LAPACK dpotrf, the
    inertia at the cost of a factorisation; A is overwritten)."""
    return dpotrf(A.T, lower=1, clean=0, overwrite_a=1)[1] == 0


def lowest(H, inverse_factor, count: int, normals=NO_CONSTRAINT, index=None, rcond: float = RCOND) -> np.ndarray:
    """The ``count`` lowest μ (ascending) of H c = μ G c on the block ``index`` with Nᵀc = 0 (``restricted``)."""
    return lowest_of(restricted(H, inverse_factor, normals, index, rcond), count)


@njit(cache=True)
def restricted_matrix(H, index, inverse_factor, normals, rcond):
    """L⁻¹ H[index, index] L⁻ᵀ on the orthogonal complement of the directions L⁻¹nᵢ (module docstring)."""
    n = index.size
    block = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            block[i, j] = H[index[i], index[j]]
    A = inverse_factor @ block @ inverse_factor.T
    A = 0.5 * (A + A.T)
    if normals.shape[0]:
        directions = normals @ inverse_factor.T  # rows L⁻¹nᵢ
        _, s, vt = np.linalg.svd(directions, full_matrices=False)
        kept = 0
        while kept < s.size and s[kept] > rcond * s[0]:
            kept += 1
        D = np.ascontiguousarray(vt[:kept].T)  # orthonormal columns
        while D.shape[1]:
            A, D = _reflect_out(A, D)
    return A


@njit(cache=True)
def _reflect_out(A, D):
    """(Q A Q, Q D) without their first rows (and A's first column), Q = I − w v vᵀ the Householder reflection
    that maps the first column d of D (unit length) to ∓e₁."""
    n = A.shape[0]
    v = D[:, 0].copy()
    v[0] += 1.0 if v[0] >= 0.0 else -1.0
    w = 2.0 / (v @ v)
    Av = A @ v
    c = w * w * (v @ Av)
    B = np.empty((n - 1, n - 1))
    for i in range(1, n):
        for j in range(1, n):
            B[i - 1, j - 1] = A[i, j] - w * (v[i] * Av[j] + Av[i] * v[j]) + c * v[i] * v[j]
    E = np.empty((n - 1, D.shape[1] - 1))
    for j in range(1, D.shape[1]):
        projected = 0.0
        for i in range(n):
            projected += v[i] * D[i, j]
        for i in range(1, n):
            E[i - 1, j - 1] = D[i, j] - w * v[i] * projected
    return B, E
