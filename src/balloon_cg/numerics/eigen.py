"""Lowest eigenvalues of a symmetric pencil (H, G), G = L Lᵀ > 0, on the hyperplanes nᵢᵀc = 0.

With y = Lᵀc the pencil becomes the standard problem A y = μ y, A = L⁻¹ H L⁻ᵀ, and a constraint nᵀc = 0 becomes
(L⁻¹n)ᵀ y = 0. The constraint directions are orthonormalised by Gram–Schmidt with pivoting (a direction whose
remainder is below rcond times the largest is dropped: linearly dependent normals are fine) and each is removed
by a Householder reflection Q (Q d ∥ e₁, then the first row and column dropped): a rank-two update, no
null-space basis. The spectrum of the result is that of the Rayleigh quotient cᵀHc / cᵀGc on {c : Nᵀc = 0}.
The reduction L⁻¹ H L⁻ᵀ is BLAS or LAPACK (``LARGE_BLOCK``), the gathering and the reflections plain jitted loops
(quick to compile);
the eigenvalues come from LAPACK's dsyevr for the lowest ``count`` only (tridiagonalisation and bisection).
"""
import numpy as np
from numba import njit
from scipy.linalg.lapack import dpotrf, dsyevr, dsygst

RCOND = 1e-9  # constraint directions below RCOND times the largest are dependent ones (dropped)
NO_CONSTRAINT = np.zeros((0, 1))
# from this size on L⁻¹ H L⁻ᵀ is LAPACK's dsygst (n³ flops; n = 960: 43 ms) instead of two products with a stored
# L⁻¹ (4n³ flops, but BLAS-3: faster on small blocks; n = 960: 119 ms, n = 60: 19 µs against 38 µs)
LARGE_BLOCK = 200


class GramFactor:
    """G = L Lᵀ of a Gram matrix (or block) that serves many pencils: L (column order, for dsygst) and L⁻¹."""

    def __init__(self, G):
        lower = np.linalg.cholesky(G)
        self.lower = np.asfortranarray(lower)
        self.inverse = np.linalg.inv(lower)

    def directions(self, normals) -> np.ndarray:
        """The rows L⁻¹nᵢ of the constraint rows nᵢ (k × n)."""
        return normals @ self.inverse.T


def restricted(H, factor: GramFactor, normals=NO_CONSTRAINT, index=None, rcond: float = RCOND) -> np.ndarray:
    """The standard symmetric matrix A of the pencil (H, G) on the block ``index`` of H (None: all of it) with
    Nᵀc = 0 (module docstring); ``factor`` is the GramFactor of the block of G, ``normals`` the rows nᵢ on the
    block (k × n). Its eigenvalues are the pencil's on the constrained block, its inertia the block's."""
    block = H if index is None else _gather(np.ascontiguousarray(H, dtype=float), np.asarray(index, dtype=np.int64))
    if block.shape[0] >= LARGE_BLOCK:
        A, info = dsygst(block, factor.lower, itype=1, lower=1)  # the lower triangle of L⁻¹ H L⁻ᵀ
        if info != 0:
            raise np.linalg.LinAlgError(f"dsygst failed (info = {info})")
        A = np.ascontiguousarray(A)
    else:
        A = factor.inverse @ block @ factor.inverse.T
    normals = np.atleast_2d(normals)
    directions = factor.directions(normals) if normals.shape[0] else np.zeros((0, A.shape[0]))
    return _reflect_out(A, directions, rcond)


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


def lowest(H, factor: GramFactor, count: int, normals=NO_CONSTRAINT, index=None, rcond: float = RCOND) -> np.ndarray:
    """The ``count`` lowest μ (ascending) of H c = μ G c on the block ``index`` with Nᵀc = 0 (``restricted``)."""
    return lowest_of(restricted(H, factor, normals, index, rcond), count)


@njit(cache=True)
def _gather(H, index):
    """H[index][:, index]."""
    n = index.size
    block = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            block[i, j] = H[index[i], index[j]]
    return block


@njit(cache=True)
def _orthonormal_rows(D, rcond):
    """Orthonormal rows spanning the rows of D (k × n): Gram–Schmidt with pivoting on the largest remaining norm
    and a second pass; a row whose remainder is below rcond times the largest norm is dependent and dropped."""
    k, n = D.shape
    Q = D.copy()
    norms = np.empty(k)
    for i in range(k):
        norms[i] = np.sqrt(_dot(Q[i], Q[i]))
    largest = norms.max() if k else 0.0
    done = np.zeros(k, dtype=np.bool_)
    out = np.empty((k, n))
    count = 0
    for _ in range(k):
        pick, best = -1, rcond * largest
        for i in range(k):
            if not done[i] and norms[i] > best:
                pick, best = i, norms[i]
        if pick < 0:
            break
        done[pick] = True
        for j in range(n):
            out[count, j] = Q[pick, j]
        for r in range(count):  # second pass against the accepted rows
            _subtract_projection(out, count, r)
        scale = 1.0 / np.sqrt(_dot(out[count], out[count]))
        for j in range(n):
            out[count, j] *= scale
        for i in range(k):
            if not done[i]:
                projection = _dot(Q[i], out[count])
                for j in range(n):
                    Q[i, j] -= projection * out[count, j]
                norms[i] = np.sqrt(_dot(Q[i], Q[i]))
        count += 1
    return out[:count].copy()


@njit(cache=True)
def _subtract_projection(rows, i, r):
    """rows[i] −= (rows[i]·rows[r]) rows[r]."""
    projection = _dot(rows[i], rows[r])
    for j in range(rows.shape[1]):
        rows[i, j] -= projection * rows[r, j]


@njit(cache=True)
def _reflect_out(A, directions, rcond):
    """The symmetric matrix of A's lower triangle on the orthogonal complement of the rows of ``directions``: each
    orthonormal direction d removed by the Householder reflection Q = I − w v vᵀ with Q d = ∓e₁ (a rank-two
    update), then the first row and column dropped (and the first coordinate of the remaining directions)."""
    n = A.shape[0]
    B = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            B[i, j] = A[i, j] if i >= j else A[j, i]
    D = _orthonormal_rows(directions, rcond)
    for r in range(D.shape[0]):
        v = D[r].copy()
        v[0] += 1.0 if v[0] >= 0.0 else -1.0
        w = 2.0 / _dot(v, v)
        Bv = np.zeros(n)
        for i in range(n):
            for j in range(n):
                Bv[i] += B[i, j] * v[j]
        c = w * w * _dot(v, Bv)
        C = np.empty((n - 1, n - 1))
        for i in range(1, n):
            for j in range(1, n):
                C[i - 1, j - 1] = B[i, j] - w * (v[i] * Bv[j] + Bv[i] * v[j]) + c * v[i] * v[j]
        rest = np.empty((D.shape[0], n - 1))
        for s in range(r + 1, D.shape[0]):
            projected = _dot(D[s], v)
            for i in range(1, n):
                rest[s, i - 1] = D[s, i] - w * v[i] * projected
        B, D, n = C, rest, n - 1
    return B


@njit(cache=True)
def _dot(a, b):
    total = 0.0
    for i in range(a.size):
        total += a[i] * b[i]
    return total
