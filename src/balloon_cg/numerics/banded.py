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
spectrum still above σ (a restriction interlaces). That reads μ₁; μ₂, μ₃, … come from a shift between μ₁ and μ₂
proved by inertia (``InsideShift``), where the ν of clustered μ₂, μ₃ far above a very negative μ₁ no longer differ
by only (μ₃ − μ₂)/(μ₂ − σ).
"""
import numpy as np
from scipy.linalg.blas import dsbmv
from scipy.linalg.lapack import dpbtrf, dtbtrs

from .band_ldlt import BandLDLT, lower_times
from .eigen import RCOND, orthonormal_rows, largest_by_lanczos

SHIFT_TRIES = 12  # shifts tried (each 4× farther below the guess) before giving up
TIGHTEN = 6  # bisections of a proved shift towards μ₁ (``BandedShiftInvert.below``)
INSIDE_TRIES = 4  # inside shifts tried (each halfway down to μ₁) before reading everything on the proved one
# Lanczos steps between stopping tests (``largest_by_lanczos``): a step on a banded factor costs tens of µs, the
# tridiagonal eigensolve of the test ~0.5 ms; 4 rather than 8 since a block takes two runs of ~15–40 steps (the
# paper coil's pear_free_2 points: 272–280 products for all blocks at 4 against 296–320 at 8, ~10 % less CPU)
CHECK_EVERY = 4


def band_matvec(band: np.ndarray, v: np.ndarray) -> np.ndarray:
    """A v for the symmetric A in lower band storage."""
    return dsbmv(band.shape[0] - 1, 1.0, band, v, lower=1)


class BandedShiftInvert:
    """The banded Cholesky factor R of K − σG for a σ proved below the pencil (K, G)'s spectrum (module docstring),
    and the lowest eigenvalues of the pencil and of its relatives (constraints, a positive rank-one term)."""

    def __init__(self, factor: np.ndarray, hessian: np.ndarray, gram: np.ndarray, sigma: float):
        self.factor, self.hessian, self.gram, self.sigma, self.size = factor, hessian, gram, sigma, factor.shape[1]

    @classmethod
    def below(cls, hessian: np.ndarray, gram: np.ndarray, guess: float, scale: float = 1.0):
        """σ = guess − δ, δ = max(|guess|, 1e-2 scale), tried by Cholesky of K − σG (δ × 4 per failure, SHIFT_TRIES
        times), then moved up by TIGHTEN bisections between it and the last failure (or ``guess``, an upper bound of
        μ₁ as a Rayleigh quotient: the smallest H_ii/G_ii), each kept when its Cholesky exists: the Lanczos run for
        μ₁ takes steps as (μ₁ − σ)/(μ₂ − μ₁) grows. None when no shift is a lower bound. ``hessian`` and ``gram``
        in lower band storage, the same shape."""
        delta, upper = max(abs(guess), 1e-2 * scale), guess
        for _ in range(SHIFT_TRIES):
            sigma = guess - delta
            factor, info = dpbtrf(hessian - sigma * gram, lower=1)
            if info == 0:
                break
            upper, delta = sigma, 4.0 * delta
        else:
            return None
        for _ in range(TIGHTEN):
            middle = 0.5 * (sigma + upper)
            tighter, info = dpbtrf(hessian - middle * gram, lower=1)
            if info == 0:
                sigma, factor = middle, tighter
            else:
                upper = middle
        return cls(factor, hessian, gram, sigma)

    @classmethod
    def under(cls, hessian: np.ndarray, gram: np.ndarray, name: str = "") -> "BandedShiftInvert":
        """``below`` from the smallest diagonal ratio H_ii/G_ii (an upper bound of μ₁ as a Rayleigh quotient);
        LinAlgError naming the pencil ``name`` where no shift is found."""
        guess = float(np.min(hessian[0] / gram[0]))
        shifted = cls.below(hessian, gram, guess, scale=max(1.0, abs(guess)))
        if shifted is None:
            raise np.linalg.LinAlgError(f"no shift below the spectrum of block {name} from {guess:.4g}")
        return shifted

    def _solve(self, v: np.ndarray, transpose: bool) -> np.ndarray:
        """R⁻¹v, or R⁻ᵀv with ``transpose``."""
        out, info = dtbtrs(self.factor, v[:, None], uplo="L", trans="T" if transpose else "N")
        if info != 0:
            raise np.linalg.LinAlgError(f"dtbtrs failed (info = {info})")
        return out[:, 0]

    def lowest(self, count: int, constraints=None, update=None, rcond: float = RCOND) -> np.ndarray:
        """The ``count`` lowest eigenvalues (ascending) of the pencil (K + ρ g gᵀ, G) on Nᵀc = 0 (module docstring);
        ``update`` (g, ρ) with ρ ≥ 0 or None, ``constraints`` the rows of N (k × n; dependent ones dropped) or
        None. From count 2 on: μ₁ on the proved shift, the others on an inside shift (``InsideShift``) when one
        is found, else all on the proved shift."""
        if update is not None and update[1] < 0.0:
            raise ValueError(f"BandedShiftInvert.lowest: the rank-one weight ρ = {update[1]} must be ≥ 0")
        if count < 2:
            return self._below(count, constraints, update, rcond)
        estimates = self._below(1, constraints, update, rcond, also=2)
        inside = InsideShift.between(self, estimates, constraints, update, rcond) if len(estimates) == 3 else None
        if inside is None:
            return self._below(count, constraints, update, rcond)
        return np.concatenate([estimates[:1], inside.lowest_above(count - 1)])

    def _below(self, count: int, constraints, update, rcond: float, also: int = 0) -> np.ndarray:
        """The ``count`` lowest eigenvalues (ascending) on the proved shift, and ``also`` upper bounds of the next
        ones (Ritz values, unconverged)."""
        n = self.size
        gram = self.gram
        scaled = None
        if update is not None and update[1] > 0.0:
            g_hat = self._solve(np.asarray(update[0], dtype=float), False)
            norm2 = float(g_hat @ g_hat)
            alpha = (1.0 + float(update[1]) * norm2) ** -0.5 - 1.0
            scaled = (g_hat, alpha / norm2)

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
        nu = largest_by_lanczos(operator, n, min(count, n - directions.shape[0]), CHECK_EVERY, also)
        return np.sort(self.sigma + 1.0 / nu)


class InsideShift:
    """Shift-invert at σ₁ between μ₁ and μ₂ of the pencil (K + ρggᵀ, G) on Nᵀc = 0, proved there by inertia: the
    banded LDLᵀ of A = K − σ₁G (numerics/band_ldlt.py) counts A's negative eigenvalues, the gas term removes one
    when 1 + ρ gᵀA⁻¹g < 0 and the constraints as many as C = NᵀA'⁻¹N has negative ones (Haynsworth's inertia
    additivity on the bordered matrices), A' = A + ρggᵀ. With exactly one below σ₁, the largest ν of

        T y = Lᵀ (x − A'⁻¹N C⁻¹ Nᵀx),   x = A'⁻¹ L y   (G = L Lᵀ, A'⁻¹ by Sherman–Morrison)

    (symmetric, zero on L⁻¹N, ν = 1/(μ − σ₁) on the constraint space) are μ₂, μ₃, … . Placed at μ̃₂ − (μ̃₃ − μ̃₂)
    from the proved shift's Ritz estimates (upper bounds), the wanted ν are separated by O(1) ratios, where on a
    shift below a very negative μ₁ they differ by (μ₃ − μ₂)/(μ₂ − σ): the Lanczos run's length."""

    def __init__(self, sigma: float, gram_factor: np.ndarray, solve, constraints: np.ndarray, solved: np.ndarray,
                 schur: np.ndarray):
        self.sigma, self.gram_factor, self._solve = sigma, gram_factor, solve
        self.constraints, self.solved, self.schur = constraints, solved, schur

    @classmethod
    def between(cls, below: BandedShiftInvert, estimates: np.ndarray, constraints, update, rcond: float = RCOND):
        """The inside shift from ``estimates`` (μ₁ converged, upper bounds of μ₂ and μ₃), moved halfway down to μ₁
        while more than one eigenvalue lies below it (INSIDE_TRIES times); None when none is found."""
        lowest, second, third = estimates
        if not (np.isfinite(second) and np.isfinite(third) and second > lowest):
            return None
        gram_factor, info = dpbtrf(below.gram, lower=1)
        if info != 0:
            return None
        rows = np.zeros((0, below.size))
        if constraints is not None and len(constraints):
            rows = orthonormal_rows(np.ascontiguousarray(np.atleast_2d(constraints), dtype=float), rcond)
        sigma = max(second - (third - second), 0.5 * (lowest + second))
        for _ in range(INSIDE_TRIES):
            negatives, shift = cls._at(sigma, below, gram_factor, rows, update)
            if negatives is None or negatives < 2:
                return shift
            sigma = 0.5 * (lowest + sigma)
        return None

    @classmethod
    def _at(cls, sigma: float, below: BandedShiftInvert, gram_factor, rows, update):
        """(the number of eigenvalues below σ, None if not trusted (``BandedInertia``); the shift at σ if that number
        is one, else None)."""
        inertia = BandedInertia.at(below.hessian, below.gram, sigma)
        negatives, solve, solved, schur = (None, None, None, None) if inertia is None else inertia.of(rows, update)
        if negatives is None:
            return None, None
        return negatives, cls(sigma, gram_factor, solve, rows, solved, schur) if negatives == 1 else None

    def lowest_above(self, count: int) -> np.ndarray:
        """The ``count`` lowest eigenvalues above σ₁ (ascending)."""
        n, k = self.gram_factor.shape[1], self.constraints.shape[0]

        def operator(y):
            x = self._solve(lower_times(self.gram_factor, y, False))
            if k:
                x = x - self.solved.T @ np.linalg.solve(self.schur, self.constraints @ x)
            return lower_times(self.gram_factor, x, True)

        nu = largest_by_lanczos(operator, n, min(count, n - k - 1), CHECK_EVERY)
        return np.sort(self.sigma + 1.0 / nu)


class BandedInertia:
    """The number of eigenvalues of the pencil (K + ρggᵀ, G) on Nᵀc = 0 below σ, from the banded LDLᵀ of A = K − σG
    (numerics/band_ldlt.py): A's negative pivots, one fewer when 1 + ρ gᵀA⁻¹g < 0 (ρ > 0) and as many fewer as
    C = NᵀA'⁻¹N (N orthonormal rows, A' = A + ρggᵀ by Sherman–Morrison) has negative eigenvalues (Haynsworth's
    inertia additivity on the bordered matrices). One factorisation serves every relative (``of``)."""

    def __init__(self, ldlt: BandLDLT):
        self.ldlt = ldlt

    @classmethod
    def at(cls, hessian: np.ndarray, gram: np.ndarray, sigma: float) -> "BandedInertia | None":
        """The LDLᵀ of K − σG (lower band storage), or None where it is refused (``BandLDLT.factor``)."""
        ldlt = BandLDLT.factor(hessian - sigma * gram)
        return None if ldlt is None else cls(ldlt)

    def of(self, rows: np.ndarray, update) -> tuple:
        """(the number of eigenvalues below σ on rowsᵀc = 0 (orthonormal rows, k × n) with the rank-one term
        ``update`` (g, ρ ≥ 0) or None, None if not trusted (a singular term 1 + ρ gᵀA⁻¹g); x ↦ A'⁻¹x; A'⁻¹ of the
        rows; C)."""
        ldlt = self.ldlt
        negatives, solve = ldlt.negatives, ldlt.solve
        if update is not None and update[1] > 0.0:
            g, rho = np.asarray(update[0], dtype=float), float(update[1])
            a_g = ldlt.solve(g)
            denominator = 1.0 + rho * float(g @ a_g)
            if denominator == 0.0:
                return None, None, None, None
            negatives -= int(denominator < 0.0)

            def solve(w):
                x = ldlt.solve(w)
                return x - (rho * float(g @ x) / denominator) * a_g
        solved = np.array([solve(row) for row in rows]).reshape(rows.shape)
        schur = rows @ solved.T
        if rows.shape[0]:
            negatives -= int(np.count_nonzero(np.linalg.eigvalsh(0.5 * (schur + schur.T)) < 0.0))
        return negatives, solve, solved, schur


class BandedSigns:
    """Whether the relatives of a banded pencil (K, G), G > 0, are positive definite (the stability flags at a
    check degree, where only signs are asked): (K + ρggᵀ, G) with ρ ≥ 0 on Nᵀc = 0 has no eigenvalue ≤ 0 iff its
    inertia at σ = 0 counts no negative one and A = K is not singular there. K's banded Cholesky (dpbtrf) settles
    every relative when it exists (K > 0: so is every restriction and K + ρggᵀ); otherwise one LDLᵀ of K serves
    them all (``BandedInertia``); where that is refused (a zero pivot or growth, a singular term) the sign of the
    relative's lowest eigenvalue decides (``BandedShiftInvert``), the same answer at the cost of a Lanczos run."""

    def __init__(self, hessian: np.ndarray, gram: np.ndarray):
        self.hessian, self.gram = hessian, gram
        self.definite = dpbtrf(hessian, lower=1)[1] == 0
        self._inertia = None

    def positive(self, constraints=None, update=None, rcond: float = RCOND) -> bool:
        """Whether every eigenvalue of the relative (``update`` (g, ρ) with ρ ≥ 0 or None, ``constraints`` the
        rows of N or None) is positive."""
        if update is not None and update[1] < 0.0:
            raise ValueError(f"BandedSigns.positive: the rank-one weight ρ = {update[1]} must be ≥ 0")
        if self.definite:
            return True
        rows = np.zeros((0, self.hessian.shape[1]))
        if constraints is not None and len(constraints):
            rows = orthonormal_rows(np.ascontiguousarray(np.atleast_2d(constraints), dtype=float), rcond)
        if self._inertia is None:
            self._inertia = BandedInertia.at(self.hessian, self.gram, 0.0) or False
        negatives = self._inertia.of(rows, update)[0] if self._inertia else None
        if negatives is not None:
            return negatives == 0
        return bool(BandedShiftInvert.under(self.hessian, self.gram).lowest(1, constraints, update, rcond)[0] > 0.0)
