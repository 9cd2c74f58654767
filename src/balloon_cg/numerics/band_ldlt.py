"""LDLᵀ of a symmetric banded matrix without pivoting, and its inertia: the number of eigenvalues of a banded pencil
below a shift σ inside its spectrum (numerics/banded.py), which LAPACK's banded routines (Cholesky, LU with row
pivoting) do not give and scipy has no banded or sparse LDLᵀ for.

A = L D Lᵀ, L unit lower triangular with A's half-bandwidth b (no pivoting: no fill), O(n b²) to factor and O(n b)
a solve. By Sylvester's law of inertia A has as many negative eigenvalues as D has negative entries. Without pivoting
the factorisation is backward stable when its growth is small: the computed factors are exact for A + E,
|E| ≤ γ |L||D||Lᵀ| entrywise (γ ≈ (b + 2)ε), and the entries of |L||D||Lᵀ| are bounded by its largest diagonal
one, ``growth`` = maxᵢ Σⱼ L_ij² |d_j|. ``BandLDLT.factor`` refuses a factor whose growth exceeds MAX_GROWTH times
maxᵢ |A_ii| or with a zero pivot, so the inertia counted is that of a matrix within ~1e-11 ‖A‖ of A.

Storage: LAPACK's lower band ``band[i − j, j] = A[i, j]``; the factor keeps D in row 0 and L below it. The loops
run on its transpose (n, b + 1), each column of the band one contiguous row: in Fortran order (as LAPACK keeps its
band factors) that transpose is the array's own memory, no copy.
"""
import numpy as np
from numba import njit

MAX_GROWTH = 1e4


class BandLDLT:
    """A = L D Lᵀ of a symmetric banded A without pivoting (module docstring)."""

    def __init__(self, factor: np.ndarray):
        self.factor = factor

    @classmethod
    def factor(cls, band: np.ndarray) -> "BandLDLT | None":
        """The factorisation of ``band`` (lower band storage), or None at a zero pivot or a growth beyond
        MAX_GROWTH maxᵢ |A_ii| (its inertia then not trusted)."""
        factor, growth = _ldlt(np.ascontiguousarray(np.asarray(band, dtype=float).T))
        if not np.isfinite(growth) or growth > MAX_GROWTH * np.abs(band[0]).max():
            return None
        return cls(factor.T)

    @property
    def negatives(self) -> int:
        """The number of negative eigenvalues of A (Sylvester: D's negative entries)."""
        return int(np.count_nonzero(self.factor[0] < 0.0))

    def solve(self, r: np.ndarray) -> np.ndarray:
        """A⁻¹ r for a vector r."""
        return _ldlt_solve(self.factor.T, np.ascontiguousarray(r, dtype=float))


def lower_times(factor: np.ndarray, y: np.ndarray, transpose: bool) -> np.ndarray:
    """L y, or Lᵀ y with ``transpose``, for the lower triangular L in lower band storage (a Cholesky factor)."""
    return _lower_times(np.ascontiguousarray(factor.T), np.ascontiguousarray(y, dtype=float), transpose)


@njit(cache=True)
def _ldlt(columns):
    """(the factor: D in column 0, L's columns in the rows (f[j, i] = L[j + i, j]), the growth
    maxᵢ Σⱼ L_ij² |d_j|; inf at a zero pivot) of the band's transpose ``columns`` (n, b + 1)."""
    f = columns.copy()
    n, width = f.shape
    diagonal = np.zeros(n)
    for j in range(n):
        d = f[j, 0]
        if d == 0.0:
            return f, np.inf
        last = min(width - 1, n - 1 - j)
        for k in range(1, last + 1):
            t = f[j, k] / d
            for i in range(k, last + 1):
                f[j + k, i - k] -= f[j, i] * t
        diagonal[j] += abs(d)
        for i in range(1, last + 1):
            f[j, i] /= d
            diagonal[j + i] += f[j, i] * f[j, i] * abs(d)
    return f, diagonal.max()


@njit(cache=True)
def _ldlt_solve(f, r):
    """A⁻¹ r from the factor's transpose ``f`` (``_ldlt``)."""
    n, width = f.shape
    x = r.copy()
    for j in range(n):
        for i in range(1, min(width - 1, n - 1 - j) + 1):
            x[j + i] -= f[j, i] * x[j]
    for j in range(n):
        x[j] /= f[j, 0]
    for j in range(n - 1, -1, -1):
        for i in range(1, min(width - 1, n - 1 - j) + 1):
            x[j] -= f[j, i] * x[j + i]
    return x


@njit(cache=True)
def _lower_times(f, y, transpose):
    """L y or Lᵀ y from the factor's transpose ``f`` (n, b + 1)."""
    n, width = f.shape
    out = np.zeros(n)
    for j in range(n):
        for i in range(min(width - 1, n - 1 - j) + 1):
            if transpose:
                out[j] += f[j, i] * y[j + i]
            else:
                out[j + i] += f[j, i] * y[j]
    return out


class ArrowLDLT:
    """The inertia and solves of a symmetric A = [[B, C], [Cᵀ, F]] whose leading block B is banded and whose border
    (C, F: a few dense rows and columns) is not, by B's ``BandLDLT`` and the Schur complement S = F − Cᵀ B⁻¹ C:
    In(A) = In(B) + In(S) (Haynsworth), and A⁻¹r by block elimination. The same ``negatives`` and ``solve`` as
    BandLDLT (numerics/banded.BandedInertia reads either)."""

    def __init__(self, ldlt: BandLDLT, border: np.ndarray, corner: np.ndarray):
        self.ldlt, self.border = ldlt, border
        self.solved = np.array([ldlt.solve(c) for c in border.T]).T.reshape(border.shape)  # B⁻¹ C
        self.schur = corner - border.T @ self.solved

    @classmethod
    def factor(cls, band: np.ndarray, border: np.ndarray, corner: np.ndarray) -> "ArrowLDLT | None":
        """B in lower band storage, C (n_B, k), F (k, k); None where B's LDLᵀ is refused (``BandLDLT.factor``) or S
        is singular."""
        ldlt = BandLDLT.factor(band)
        if ldlt is None:
            return None
        arrow = cls(ldlt, border, corner)
        values = np.linalg.eigvalsh(arrow.schur) if arrow.schur.size else np.zeros(0)
        if np.any(values == 0.0):
            return None
        arrow.schur_negatives = int(np.count_nonzero(values < 0.0))
        return arrow

    @property
    def negatives(self) -> int:
        """The number of negative eigenvalues of A: B's and S's."""
        return self.ldlt.negatives + self.schur_negatives

    def solve(self, r: np.ndarray) -> np.ndarray:
        """A⁻¹ r: y = B⁻¹ r_B, x_F = S⁻¹(r_F − Cᵀ y), x_B = y − B⁻¹C x_F."""
        n = self.border.shape[0]
        y = self.ldlt.solve(r[:n])
        if not self.schur.size:
            return y
        x_border = np.linalg.solve(self.schur, r[n:] - self.border.T @ y)
        return np.concatenate([y - self.solved @ x_border, x_border])
