"""Lowest eigenvalues of a banded symmetric pencil (H, G), G > 0, on hyperplanes Nᵀc = 0 and with a positive
rank-one term ρ g gᵀ: shift-invert Lanczos on a banded Cholesky factor (LAPACK dpbtrf, dtbtrs and dsbmv through
scipy), O(n b²) to factor and O(n b) a solve for half-bandwidth b, where the dense blocks cost O(n³).

Matrices are kept in LAPACK's lower band storage ``band[i − j, j] = A[i, j]`` (i ≥ j, shape (b + 1, n)).

A shift σ is proved below the spectrum by the Cholesky factorisation K − σG = R Rᵀ (it exists iff every
eigenvalue of the pencil exceeds σ: Sylvester's law of inertia). With z = Rᵀc the Rayleigh quotient

    ν = cᵀGc / cᵀ(K − σG)c = zᵀWz / zᵀz,      W = R⁻¹ G R⁻ᵀ,

so the largest ν of W are 1/(μ − σ) of the lowest μ (``eigen.largest_by_lanczos``, to rounding). A gas term:
K + ρggᵀ − σG = R (I + ρĝĝᵀ) Rᵀ with ĝ = R⁻¹g (ρ > 0 keeps σ a lower bound), and z = M z' with
M = (I + ρĝĝᵀ)^(−1/2) = I + α ĝĝᵀ/|ĝ|², α = (1 + ρ|ĝ|²)^(−1/2) − 1, makes the operator M W M. A constraint
nᵀc = 0 reads (R⁻¹n)ᵀ z = 0, i.e. (M R⁻¹ n)ᵀ z' = 0: the operator P M W M P, P the orthogonal projector onto the
complement of those rows, whose largest eigenvalues are the constrained pencil's 1/(μ − σ) (Courant–Fischer), its
spectrum still above σ (a restriction interlaces).
"""
import numpy as np
from scipy.linalg.blas import dsbmv
from scipy.linalg.lapack import dpbtrf, dtbtrs

from .eigen import RCOND, orthonormal_rows, largest_by_lanczos

SHIFT_TRIES = 12  # shifts tried (each 4× farther below the guess) before giving up
# Lanczos steps between stopping tests (``largest_by_lanczos``): a step on a banded factor costs tens of µs, the
# tridiagonal eigensolve of the test ~0.5 ms
CHECK_EVERY = 8


def band_matvec(band: np.ndarray, v: np.ndarray) -> np.ndarray:
    """A v for the symmetric A in lower band storage."""
    return dsbmv(band.shape[0] - 1, 1.0, band, v, lower=1)


class BandedShiftInvert:
    """The banded Cholesky factor R of K − σG for a σ proved below the pencil (K, G)'s spectrum (module docstring),
    and the lowest eigenvalues of the pencil and of its relatives (constraints, a positive rank-one term)."""

    def __init__(self, factor: np.ndarray, gram: np.ndarray, sigma: float):
        self.factor, self.gram, self.sigma, self.size = factor, gram, sigma, factor.shape[1]

    @classmethod
    def below(cls, hessian: np.ndarray, gram: np.ndarray, guess: float, scale: float = 1.0):
        """σ = guess − δ, δ = max(|guess|, 1e-2 scale), tried by Cholesky of K − σG (δ × 4 per failure, SHIFT_TRIES
        times); None when none is a lower bound. ``hessian`` and ``gram`` in lower band storage, the same shape."""
        delta = max(abs(guess), 1e-2 * scale)
        for _ in range(SHIFT_TRIES):
            sigma = guess - delta
            factor, info = dpbtrf(hessian - sigma * gram, lower=1)
            if info == 0:
                return cls(factor, gram, sigma)
            delta *= 4.0
        return None

    def _solve(self, v: np.ndarray, transpose: bool) -> np.ndarray:
        """R⁻¹v, or R⁻ᵀv with ``transpose``."""
        out, info = dtbtrs(self.factor, v[:, None], uplo="L", trans="T" if transpose else "N")
        if info != 0:
            raise np.linalg.LinAlgError(f"dtbtrs failed (info = {info})")
        return out[:, 0]

    def lowest(self, count: int, constraints=None, update=None, rcond: float = RCOND) -> np.ndarray:
        """The ``count`` lowest eigenvalues (ascending) of the pencil (K + ρ g gᵀ, G) on Nᵀc = 0 (module docstring);
        ``update`` (g, ρ) with ρ ≥ 0 or None, ``constraints`` the rows of N (k × n; dependent ones dropped) or
        None."""
        n = self.size
        gram = self.gram
        scaled = None
        if update is not None and update[1] > 0.0:
            g_hat = self._solve(np.asarray(update[0], dtype=float), False)
            norm2 = float(g_hat @ g_hat)
            alpha = (1.0 + float(update[1]) * norm2) ** -0.5 - 1.0
            scaled = (g_hat, alpha / norm2)
        elif update is not None and update[1] < 0.0:
            raise ValueError(f"BandedShiftInvert.lowest: the rank-one weight ρ = {update[1]} must be ≥ 0")

        def half(z):
            """M z (M symmetric: M = Mᵀ)."""
            return z if scaled is None else z + scaled[1] * (scaled[0] @ z) * scaled[0]

        directions = np.zeros((0, n))
        if constraints is not None and len(constraints):
            rows = np.array([half(self._solve(np.asarray(row, dtype=float), False))
                             for row in np.atleast_2d(constraints)])
            directions = orthonormal_rows(np.ascontiguousarray(rows), rcond)

        def project(z):
            return z - directions.T @ (directions @ z) if directions.shape[0] else z

        def operator(z):
            z = half(project(z))
            w = self._solve(band_matvec(gram, self._solve(z, True)), False)
            return project(half(w))

        # the projected-out directions are ν = 0, below every wanted one (each ν = 1/(μ − σ) > 0)
        nu = largest_by_lanczos(operator, n, min(count, n - directions.shape[0]), CHECK_EVERY)
        return np.sort(self.sigma + 1.0 / nu)
