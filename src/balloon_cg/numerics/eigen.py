"""Lowest eigenvalues of a symmetric pencil (H, G), G = L Lᵀ > 0, on the hyperplanes nᵢᵀc = 0.

With y = Lᵀc the pencil becomes the standard problem A y = μ y, A = L⁻¹ H L⁻ᵀ, and a constraint nᵀc = 0 becomes
(L⁻¹n)ᵀ y = 0. The constraint directions are orthonormalised by Gram–Schmidt with pivoting (a direction whose
remainder is below rcond times the largest is dropped: linearly dependent normals are fine) and each is removed
by a Householder reflection Q (Q d ∥ e₁, then the first row and column dropped): a rank-two update, no
null-space basis. The spectrum of the result is that of the Rayleigh quotient cᵀHc / cᵀGc on {c : Nᵀc = 0}.
The reduction L⁻¹ H L⁻ᵀ is BLAS or LAPACK (``LARGE_BLOCK``), the gathering and the reflections plain jitted loops
(quick to compile);
the eigenvalues come from LAPACK's dsyevr for the lowest ``count`` only (tridiagonalisation and bisection).

Large matrices along a branch (``lowest_following``, ``ShiftInvert``): Lanczos (``largest_by_lanczos``) on
(A − σI)⁻¹ with σ below the spectrum,
proved so by a Cholesky factorisation of A − σI (n³/3 flops against dsyevr's 4n³/3 for the tridiagonal form): the
eigenvalues of the inverse closest to its top are the lowest of A. The inertia of an indefinite matrix
(``negative_count``) is the Bunch–Kaufman LDLᵀ's (Sylvester's law), again a factorisation, no eigensolve.
"""
import math
from functools import cached_property

import numpy as np
from numba import njit
from scipy import linalg
from scipy.linalg.lapack import dpotrf, dpotrs, dsyevr, dsygst, dsytrf, dsytrs

EPS = np.finfo(float).eps

RCOND = 1e-9  # constraint directions below RCOND times the largest are dependent ones (dropped)
NO_CONSTRAINT = np.zeros((0, 1))
# from this size on L⁻¹ H L⁻ᵀ is LAPACK's dsygst (n³ flops; n = 960: 43 ms) instead of two products with a stored
# L⁻¹ (4n³ flops, but BLAS-3: faster on small blocks; n = 960: 119 ms, n = 60: 19 µs against 38 µs)
LARGE_BLOCK = 200
# below this size the lowest eigenvalues come from jitted loops (LAPACK's dsyevr, three eigenvalues: ~17, 31, 55 and
# 92 µs at n = 20, 30, 41 and 57, mostly in its O(n) calls of level-2 BLAS and in the tridiagonal solver; the loops
# ~8, 14, 27 and 56 µs, even at n = 80: benchmarks/eigen_small.py)
SMALL_EIGEN = 64


class GramFactor:
    """G = L Lᵀ of a Gram matrix (or block) that serves many pencils: L (column order, for dsygst) and L⁻¹.

    ``orthogonal``: the basis is orthogonal, G diagonal in exact arithmetic (its off-diagonal entries are
    quadrature rounding; G may be given as its diagonal): L = diag(√G_ii), and L⁻¹ H L⁻ᵀ is the scaling
    H_ij/√(G_ii G_jj) (``scale`` = 1/√G_ii; None for a general G). ``blocks``: slices partitioning the unknowns
    along which G is block-diagonal (the entries outside are not read): L the blocks' Cholesky factors (``parts``),
    and L⁻¹ H L⁻ᵀ triangular solves block by block (``standard``: Σ_b n_b² n flops each side, not dsygst's n³).
    L and L⁻¹ are made when asked for."""

    def __init__(self, G, orthogonal: bool = False, blocks: tuple | None = None):
        G = np.asarray(G, dtype=float)
        self.gram, self.scale, self.parts, self._lower = G, None, None, None
        if orthogonal:
            self.scale = 1.0 / np.sqrt(G if G.ndim == 1 else np.diag(G))
        elif blocks is not None:
            self.parts = tuple((s, np.linalg.cholesky(G[s, s])) for s in blocks)
        else:
            self._lower = np.asfortranarray(np.linalg.cholesky(G))

    @cached_property
    def lower(self) -> np.ndarray:
        if self.scale is not None:
            return np.asfortranarray(np.diag(1.0 / self.scale))
        if self.parts is not None:
            L = np.zeros(self.gram.shape, order="F")
            for s, part in self.parts:
                L[s, s] = part
            return L
        return self._lower

    @cached_property
    def inverse(self) -> np.ndarray:
        return np.diag(self.scale) if self.scale is not None else np.linalg.inv(self.lower)

    @property
    def nbytes(self) -> int:
        """The bytes it holds: G, its factors, and L and L⁻¹ once made."""
        arrays = [v for v in vars(self).values() if isinstance(v, np.ndarray)]
        return sum(a.nbytes for a in arrays) + sum(part.nbytes for _, part in self.parts or ())

    def weighed(self, rows) -> np.ndarray:
        """The rows G wᵢ of the vectors wᵢ (k × n): the normals of the constraints (G wᵢ)ᵀc = 0, c G-orthogonal to
        the wᵢ (a diagonal G as the products wᵢ G_ii)."""
        if self.scale is None:
            return rows @ self.gram
        return rows * (self.gram if self.gram.ndim == 1 else np.diag(self.gram))

    def directions(self, normals) -> np.ndarray:
        """The rows L⁻¹nᵢ of the constraint rows nᵢ (k × n), C-ordered whatever the normals' layout (the jitted
        reflections then compile for one layout only)."""
        if self.parts is not None:
            normals = np.asarray(normals, dtype=float)
            out = np.empty(normals.shape)
            for s, part in self.parts:
                out[:, s] = linalg.solve_triangular(part, normals[:, s].T, lower=True).T
            return out
        return np.ascontiguousarray(normals * self.scale if self.scale is not None else normals @ self.inverse.T)

    def back(self, Y) -> np.ndarray:
        """The columns L⁻ᵀy of the columns y of Y (n × m): the vectors c of the coordinates y = Lᵀc."""
        if self.scale is not None:
            return Y * self.scale[:, None]
        if self.parts is not None:
            out = np.empty(Y.shape)
            for s, part in self.parts:
                out[s] = linalg.solve_triangular(part, Y[s], lower=True, trans="T")
            return out
        return linalg.solve_triangular(self.lower, Y, lower=True, trans="T")

    def standard(self, B) -> np.ndarray:
        """L⁻¹ B L⁻ᵀ of a block-diagonal factor (``blocks``), B overwritten: the rows of each block solved, then its
        columns."""
        if B.shape != (len(self.gram),) * 2:  # the blocks' slices are the factor's own unknowns
            raise ValueError(f"a {B.shape} block against a block-diagonal factor of {len(self.gram)} unknowns")
        for s, part in self.parts:
            B[s, :] = linalg.solve_triangular(part, B[s, :], lower=True)
        for s, part in self.parts:
            B[:, s] = linalg.solve_triangular(part, B[:, s].T, lower=True).T
        return B


def restricted(H, factor: GramFactor, normals=NO_CONSTRAINT, index=None, rcond: float = RCOND) -> np.ndarray:
    """The standard symmetric matrix A of the pencil (H, G) on the block ``index`` of H (None: all of it) with
    Nᵀc = 0 (module docstring); ``factor`` is the GramFactor of the block of G, ``normals`` the rows nᵢ on the
    block (k × n). Its eigenvalues are the pencil's on the constrained block, its inertia the block's."""
    H = np.ascontiguousarray(H, dtype=float)
    index = np.arange(H.shape[0]) if index is None else np.asarray(index, dtype=np.int64)
    normals = np.atleast_2d(normals)
    if factor.scale is not None:  # orthogonal basis: L⁻¹ H L⁻ᵀ is a scaling, gathered with the reflections
        directions = factor.directions(normals) if normals.shape[0] else np.zeros((0, index.size))
        return _scaled_block(H, index, factor.scale, directions, rcond)
    if factor.parts is not None:
        A = factor.standard(_gather(H, index))
    elif index.size >= LARGE_BLOCK:
        A, info = dsygst(_gather(H, index), factor.lower, itype=1, lower=1)  # lower triangle
        if info != 0:
            raise np.linalg.LinAlgError(f"dsygst failed (info = {info})")
        A = np.ascontiguousarray(A)
    else:
        A = factor.inverse @ _gather(H, index) @ factor.inverse.T
    directions = factor.directions(normals) if normals.shape[0] else np.zeros((0, A.shape[0]))
    return _reflect_out(A, directions, rcond)


def restricted_rows(factor: GramFactor, normals, rows, rcond: float = RCOND) -> np.ndarray:
    """The rows L⁻¹wᵢ of the vectors wᵢ (``rows``, k × n) in the coordinates of ``restricted``'s matrix for
    ``normals``: each reflection Q of ``_reflect`` applied, its first coordinate dropped ((Q w)[1:]: a constraint
    wᵀy = 0 or a rank-one term w wᵀ reads so there). A row whose remainder is below rcond times its own norm lies
    in the normals' span and is dropped."""
    rows = factor.directions(np.atleast_2d(rows))
    normals = np.atleast_2d(normals)
    directions = factor.directions(normals) if normals.shape[0] else np.zeros((0, rows.shape[1]))
    mapped = _reflect_rows(directions, rcond, rows)
    keep = np.linalg.norm(mapped, axis=1) > rcond * np.linalg.norm(rows, axis=1)
    return mapped[keep]


def rank_of(rows, rcond: float = RCOND) -> int:
    """The number of independent rows (k × n) as ``restricted`` counts them (pivoted Gram–Schmidt, rcond)."""
    rows = np.ascontiguousarray(np.atleast_2d(rows), dtype=float)
    return orthonormal_rows(rows, rcond).shape[0] if rows.size else 0


@njit(cache=True)
def _householder_vectors(directions, rcond):
    """The Householder vectors v_r of the reflections ``_reflect`` makes of ``directions`` (orthonormalised): v_0
    maps the first direction to ∓e₁, v_r the r-th one, reflected by the r earlier ones and its first r coordinates
    dropped (each v_r of length n − r)."""
    D = orthonormal_rows(directions, rcond)
    vectors = []
    for r in range(D.shape[0]):
        n = D.shape[1]
        v = _householder(D[r])
        vectors.append(v)
        w = 2.0 / _dot(v, v)
        rest = np.empty((D.shape[0], n - 1))
        for s in range(r + 1, D.shape[0]):
            projected = _dot(D[s], v)
            for i in range(1, n):
                rest[s, i - 1] = D[s, i] - w * v[i] * projected
        D = rest
    return vectors


@njit(cache=True)
def _reflect_rows(directions, rcond, rows):
    """The rows w of ``rows`` through the reflections ``_reflect`` makes of ``directions``: (Q w)[1:] each time."""
    W = rows.copy()
    for v in _householder_vectors(directions, rcond):
        n = v.size
        w = 2.0 / _dot(v, v)
        moved = np.empty((W.shape[0], n - 1))
        for s in range(W.shape[0]):
            projected = _dot(W[s], v)
            for i in range(1, n):
                moved[s, i - 1] = W[s, i] - w * v[i] * projected
        W = moved
    return W


def lowest_of(A, count: int) -> np.ndarray:
    """The ``count`` lowest eigenvalues (ascending) of the symmetric A, overwritten: below SMALL_EIGEN rows by
    the jitted Householder tridiagonalisation and bisection (``_lowest_small``), else LAPACK dsyevr, range 'I' (A
    passed as its F-ordered transpose, no copy). Both are backward stable: eigenvalues to O(ε‖A‖)."""
    if A.shape[0] < SMALL_EIGEN:
        return _lowest_small(A, min(count, A.shape[0]))
    values, _, found, _, info = dsyevr(A.T, compute_v=0, range="I", il=1, iu=min(count, A.shape[0]), overwrite_a=1)
    if info != 0:
        raise np.linalg.LinAlgError(f"dsyevr failed (info = {info})")
    return values[:found]


# from this size on the relatives of a matrix (``lowest_with_relatives``) are read through one shifted factorisation
# below its lowest eigenvalue (n³/3 flops and a Lanczos run each) instead of a dense eigensolve each (4n³/3)
RELATIVES_SIZE = 400


def lowest_with_relatives(A, count: int, relatives) -> tuple:
    """The ``count`` lowest eigenvalues (ascending) of the symmetric A (both triangles; kept) and of each of its
    relatives A + ρ u uᵀ on Uᵀy = 0 (``relatives``: (constraints U, update (u, ρ) or None, matrix) each, ``matrix()``
    the relative's own dense matrix), ((A's, [each relative's]): A's by ``lowest_of`` (dense), the relatives' spectra
    lie above A's lowest μ₁ (a restriction interlaces, a positive rank-one term raises), so from RELATIVES_SIZE rows
    they come through one ``ShiftInvert`` below μ₁ (``ShiftInvert.below``: a Cholesky factorisation instead of a
    dense eigensolve each, their Lanczos runs in lockstep), to rounding the dense values. A relative the shift does
    not serve (ρ ≤ 0, or no shift proves a lower bound), and every relative below RELATIVES_SIZE rows, is solved
    dense on ``matrix()``."""
    n = A.shape[0]
    own = lowest_of(np.array(A), count)
    found = [None] * len(relatives)
    if n >= RELATIVES_SIZE and relatives and count < n - 1:
        shifted = ShiftInvert.below(A, own[0])
        if shifted is not None:
            found = shifted.lowest_of_relatives([(count, constraints, update)
                                                 for constraints, update, _ in relatives])
    return own, [lowest_of(matrix(), count) if values is None else values
                 for values, (_, _, matrix) in zip(found, relatives)]


FOLLOWING_SIZE = 600  # from this size on ``lowest_following`` factors and iterates; below it dsyevr is as quick
LANCZOS_START = 0  # the seed of the Lanczos start vector (a fixed one: the same numbers every run)
SHIFT_TRIES = 4  # shifts tried (each 4× farther below the guess) before the dense eigensolve


def lowest_following(A, count: int, guess: float | None) -> np.ndarray:
    """The ``count`` lowest eigenvalues (ascending) of the symmetric A (both triangles; kept), where ``guess``
    estimates the lowest (the previous point's along a branch; None: unknown): Lanczos on (A − σI)⁻¹ with σ below
    the spectrum (``ShiftInvert``). Falls back to ``lowest_of`` (dsyevr) below FOLLOWING_SIZE, without a guess, or
    when no shift is a lower bound."""
    n = A.shape[0]
    shifted = None if guess is None or n < FOLLOWING_SIZE or count >= n - 1 else ShiftInvert.below(A, guess)
    return lowest_of(np.array(A), count) if shifted is None else shifted.lowest(count)


class ShiftInvert:
    """The Cholesky factor of A − σI for a σ proved below A's spectrum (the factorisation exists), and the lowest
    eigenvalues of A and of its relatives through it: ν = 1/(μ − σ), the largest eigenvalues of (A − σI)⁻¹, by
    Lanczos to machine precision (``largest_by_lanczos``).

    A relative of A (``lowest``) is A + ρ u uᵀ (ρ > 0, a gas under pressure) restricted to Uᵀy = 0 (constraints):
    its spectrum is still above σ (a positive update raises it, a restriction interlaces), and with S = (A − σI)⁻¹
    S' = (A + ρuuᵀ − σI)⁻¹ = S − ρ (Su)(Su)ᵀ/(1 + ρ uᵀSu) (Sherman–Morrison) and
    T = S' − S'U (UᵀS'U)⁻¹ UᵀS' is the inverse of the restricted shifted matrix on {Uᵀy = 0} and zero on U's span
    (T (A + ρuuᵀ − σI) y = y for Uᵀy = 0, T U = 0): its largest eigenvalues are the relative's ν. One factorisation
    serves every reading of a matrix that differs by constraints and positive rank-one terms."""

    def __init__(self, factor: np.ndarray, sigma: float):
        self.factor, self.sigma, self.size = factor, sigma, factor.shape[0]

    @classmethod
    def below(cls, A, guess: float):
        """σ = guess − δ, δ = max(|guess|, 1e-2), tried as a lower bound by Cholesky of A − σI (δ × 4 per failure,
        SHIFT_TRIES times); None when none is. A symmetric, both triangles (as ``restricted`` makes it, to rounding:
        its reflections' c vᵢvⱼ): its column-major copy is that of Aᵀ, a plain memory copy of a C-ordered A instead
        of a transposing one (the upper triangle read, which differs from the lower by rounding)."""
        n = A.shape[0]
        delta = max(abs(guess), 1e-2)
        for _ in range(SHIFT_TRIES):
            sigma = guess - delta
            shifted = np.array(A.T if A.flags.c_contiguous else A, order="F")
            shifted[np.diag_indices(n)] -= sigma
            factor, info = dpotrf(shifted, lower=1, clean=0, overwrite_a=1)
            if info == 0:
                return cls(factor, sigma)
            delta *= 4.0
        return None

    def solve(self, v) -> np.ndarray:
        """(A − σI)⁻¹ v (v a vector or the columns of a matrix)."""
        return dpotrs(self.factor, np.asarray(v, dtype=float), lower=1)[0]

    def lowest(self, count: int, constraints=None, update=None, rcond: float = RCOND) -> np.ndarray | None:
        """The ``count`` lowest eigenvalues (ascending) of A + ρ u uᵀ on Uᵀy = 0 (class docstring); ``update``:
        (u, ρ) or None, ``constraints``: the rows of U (k × n; dependent ones dropped as in ``restricted``) or None.
        None when ρ ≤ 0 or the update does not keep A + ρuuᵀ − σI positive (then σ is no lower bound)."""
        return self.lowest_of_relatives([(count, constraints, update)], rcond)[0]

    def lowest_of_relatives(self, relatives, rcond: float = RCOND) -> list:
        """``lowest(count, constraints, update)`` of every (count, constraints, update) in ``relatives``, their
        Lanczos runs in lockstep: each step solves with the factor once for all of them (the columns of one
        right-hand side: the factor, memory-bound to read, is read once instead of once per relative), the rest of
        each run as alone. A column solved among others may differ from one solved alone in its last bits (whether
        dpotrs blocks the columns is the BLAS build's choice), so the values agree with ``lowest``'s to the solve's
        rounding, not always bit for bit; a run's own numbers are the same on every call."""
        operators = [self._relative(constraints, update, rcond) for _, constraints, update in relatives]
        runs = {k: _lanczos(self.size, count) for k, (count, _, _) in enumerate(relatives)
                if operators[k] is not None}
        wanted = {k: next(run) for k, run in runs.items()}
        out = [None] * len(relatives)
        while wanted:
            keys = list(wanted)
            solved = self.solve(np.column_stack([wanted[k] for k in keys]))
            for i, k in enumerate(keys):
                try:
                    wanted[k] = runs[k].send(operators[k](wanted[k], solved[:, i]))
                except StopIteration as done:
                    out[k] = np.sort(self.sigma + 1.0 / done.value)
                    del wanted[k]
        return out

    def _relative(self, constraints, update, rcond: float):
        """(v, (A − σI)⁻¹v) ↦ T v of one relative (class docstring), or None when its update is no positive one
        that keeps σ a lower bound (``lowest``)."""

        def base(v, solved):
            return solved

        if update is not None:
            u, rho = np.asarray(update[0], dtype=float), float(update[1])
            Su = self.solve(u)
            denominator = 1.0 + rho * (u @ Su)
            if rho <= 0.0 or not denominator > 0.0:
                return None
            weight = rho / denominator

            def base(v, solved):
                return solved - (weight * (Su @ v)) * Su
        operator = base
        if constraints is not None and len(constraints):
            U = orthonormal_rows(np.ascontiguousarray(np.atleast_2d(constraints), dtype=float), rcond).T
            if U.shape[1]:
                SU = np.column_stack([base(U[:, k], self.solve(U[:, k])) for k in range(U.shape[1])])
                K = np.linalg.cholesky(U.T @ SU)
                correction = linalg.solve_triangular(K, SU.T, lower=True).T  # S'U K⁻ᵀ: T = S' − C Cᵀ

                def operator(v, solved):
                    return base(v, solved) - correction @ (correction.T @ v)
        return operator


def largest_by_lanczos(operator, n: int, count: int, check_every: int = 1, also: int = 0) -> np.ndarray:
    """The ``count`` largest eigenvalues (ascending) of the symmetric positive semidefinite operator (x ↦ Sx on
    vectors of size n) by Lanczos with full reorthogonalisation (two Gram–Schmidt passes a step, no restarts: ~2/3
    of the products ARPACK's implicitly restarted Lanczos needs here), stopped when every wanted Ritz pair's
    residual |β_j y_j| is below 4ε times the largest Ritz value (ARPACK's tol = 0 is ε: the Ritz values are then
    exact to rounding, their error ≤ residual²/gap). A breakdown (an invariant Krylov space) continues from a new
    vector orthogonal to it; at n steps the space is everything and the Ritz values are the eigenvalues. As any
    single-vector Krylov method (ARPACK's too) it sees an exactly multiple eigenvalue once: its callers read
    states off any symmetry that forces one (an axisymmetric point 0 of a surface branch is solved dense).
    ``check_every``: the Ritz values (the stopping test) are computed every that many steps only, for runs of
    ~100 steps on an operator cheaper than the tridiagonal eigensolve (banded pencils: numerics/banded.py).
    ``also``: that many next Ritz values are returned below the wanted ones, unconverged (lower bounds of the
    eigenvalues they approach: Cauchy interlacing), as estimates."""
    run = _lanczos(n, count, check_every, also)
    v = next(run)
    while True:
        try:
            v = run.send(operator(v))
        except StopIteration as done:
            return done.value


def _lanczos(n: int, count: int, check_every: int = 1, also: int = 0):
    """``largest_by_lanczos`` as a generator: yields each vector the operator is to be applied to, is sent its
    product, and returns the Ritz values (StopIteration.value); several runs can share their products' cost."""
    rng = np.random.default_rng(LANCZOS_START)
    V = np.empty((min(n, 4 * count + 40), n))
    alpha, beta = np.empty(n), np.empty(n)
    v = rng.standard_normal(n)
    V[0] = v / np.linalg.norm(v)
    for j in range(n):
        w = yield V[j]
        alpha[j] = V[j] @ w
        basis = V[:j + 1]
        for _ in range(2):
            w -= basis.T @ (basis @ w)
        beta[j] = np.linalg.norm(w)
        if j + 1 >= count and ((j + 1 - count) % check_every == 0 or j + 1 == n):
            theta, Y = _ritz(alpha[:j + 1], beta[:j], max(0, j + 1 - count - also), j)
            if j + 1 == n or np.all(np.abs(beta[j] * Y[-1, -count:]) <= 4.0 * EPS * theta.max()):
                return theta
        if j + 1 == V.shape[0]:
            V = np.vstack([V, np.empty((min(V.shape[0], n - V.shape[0]), n))])
        if beta[j] <= EPS * max(abs(alpha[j]), 1.0):  # invariant: go on from a new direction (β_j = 0)
            w = rng.standard_normal(n)
            for _ in range(2):
                w -= basis.T @ (basis @ w)
            beta[j] = 0.0
            V[j + 1] = w / np.linalg.norm(w)
        else:
            V[j + 1] = w / beta[j]
    raise AssertionError("unreachable: at n steps the Krylov space is complete")


_STEBZ, _STEIN = linalg.get_lapack_funcs(("stebz", "stein"), (np.empty(1),))


def _ritz(alpha: np.ndarray, beta: np.ndarray, first: int, last: int) -> tuple:
    """The eigenvalues first..last (ascending, from 0) of the symmetric tridiagonal matrix (diagonal ``alpha``,
    off-diagonal ``beta``) and their eigenvectors: ``linalg.eigh_tridiagonal(alpha, beta, select="i",
    select_range=(first, last))``'s LAPACK calls (dstebz, then dstein) without its checks, which cost ~10× the
    solve of a Lanczos run's tridiagonal of tens of rows."""
    if alpha.size == 1:
        return alpha.copy(), np.ones((1, 1))
    m, w, block, split, info = _STEBZ(alpha, beta, 2, 0.0, 1.0, first + 1, last + 1, 0.0, "B")
    if info != 0:
        raise np.linalg.LinAlgError(f"dstebz failed (info = {info})")
    w = w[:m]
    vectors, info = _STEIN(alpha, beta, w, block, split)
    if info != 0:
        raise np.linalg.LinAlgError(f"dstein failed (info = {info})")
    order = np.argsort(w)
    return w[order], vectors[:, order]


def negative_count(A) -> int:
    """The number of negative eigenvalues of the symmetric A (lower triangle read; kept): the inertia of its
    Bunch–Kaufman factorisation P A Pᵀ = L D Lᵀ (LAPACK dsytrf), D of 1×1 and 2×2 blocks: ``DenseLDLT``'s."""
    return DenseLDLT(A).negatives


class DenseLDLT:
    """The Bunch–Kaufman P A Pᵀ = L D Lᵀ of a dense symmetric A (LAPACK dsytrf): its inertia and A⁻¹r (dsytrs), the
    dense sibling of band_ldlt.BandLDLT (the same ``negatives`` and ``solve``: numerics/banded.BandedInertia reads
    either, every relative of A from the one factorisation)."""

    def __init__(self, A):
        self.ldu, self.pivots, info = dsytrf(np.array(A, order="F"), lower=1)
        if info < 0:
            raise np.linalg.LinAlgError(f"dsytrf failed (info = {info})")
        self.singular = info > 0

    @property
    def negatives(self) -> int:
        """The number of negative eigenvalues of A (Sylvester: D's)."""
        return _block_negatives(np.ascontiguousarray(np.diag(self.ldu)), np.ascontiguousarray(np.diag(self.ldu, -1)),
                                self.pivots)

    def solve(self, r: np.ndarray) -> np.ndarray:
        """A⁻¹ r for a vector r (A not singular)."""
        return dsytrs(self.ldu, self.pivots, r, lower=1)[0]


@njit(cache=True)
def _block_negatives(diagonal, sub, pivots):
    """Negative eigenvalues of D: a 1×1 block where pivots[k] > 0, a 2×2 block [d_k, s_k; s_k, d_k+1] where
    pivots[k] = pivots[k + 1] < 0 (lower storage)."""
    count, k, n = 0, 0, diagonal.size
    while k < n:
        if pivots[k] > 0 or k == n - 1:
            count += diagonal[k] < 0.0
            k += 1
        else:
            det = diagonal[k] * diagonal[k + 1] - sub[k] * sub[k]
            trace = diagonal[k] + diagonal[k + 1]
            count += 1 if det < 0.0 else (2 if trace < 0.0 and det > 0.0 else 0)
            k += 2
    return count


def positive_definite(A) -> bool:
    """Whether the symmetric A has no eigenvalue ≤ 0 (its Cholesky factorisation exists: LAPACK dpotrf, the
    inertia at the cost of a factorisation; A is overwritten)."""
    return dpotrf(A.T, lower=1, clean=0, overwrite_a=1)[1] == 0


def lowest(H, factor: GramFactor, count: int, normals=NO_CONSTRAINT, index=None, rcond: float = RCOND) -> np.ndarray:
    """The ``count`` lowest μ (ascending) of H c = μ G c on the block ``index`` with Nᵀc = 0 (``restricted``)."""
    return lowest_of(restricted(H, factor, normals, index, rcond), count)


def lowest_ritz(H, factor: GramFactor, count: int, normals=NO_CONSTRAINT, index=None,
                rcond: float = RCOND) -> np.ndarray:
    """``lowest``'s μ each to the rounding of its own Rayleigh quotient: the Ritz values of the pencil (H, G) on the
    block on the span of its ``count`` lowest eigenvectors, c_i = L⁻ᵀ Qᵀ(0, y_i) (y_i of ``restricted``'s A, moved
    back through the reflections and the factor), eig(VᵀHV, VᵀGV).

    A dense eigensolver's eigenvalues of A are exact for a matrix within ε‖A‖ of it, and ‖A‖ is the pencil's largest
    μ in every basis (a refined element layout's highest mode: 7.2e5 on tube_spom1_L10's bulge), so its μ near zero
    carry errors up to ε‖A‖ (1.6e-10 there). A Ritz value on y_i's span is off by Σ_j (μ_j − μ_i) δ_ij² ≈ n (ε‖A‖)²/gap
    (δ_ij ≈ ε‖A‖/|μ_j − μ_i| the computed vector's part along the other eigenvectors) plus the rounding of VᵀHV,
    ε‖H‖‖c‖²/cᵀGc: ~1e-15 near zero where ``lowest``'s read ±3e-11."""
    A = restricted(H, factor, normals, index, rcond)
    found = min(count, A.shape[0])
    _, vectors, _, _, info = dsyevr(A.T, compute_v=1, range="I", il=1, iu=found)
    if info != 0:
        raise np.linalg.LinAlgError(f"dsyevr failed (info = {info})")
    H = np.asarray(H, dtype=float)
    block = H if index is None else _gather(np.ascontiguousarray(H), np.asarray(index, dtype=np.int64))
    normals = np.atleast_2d(normals)
    directions = factor.directions(normals) if normals.shape[0] else np.zeros((0, block.shape[0]))
    V = factor.back(_reflect_back(np.ascontiguousarray(directions), rcond,
                                  np.ascontiguousarray(vectors[:, :found].T)).T)
    G = factor.gram
    return linalg.eigvalsh(V.T @ block @ V, V.T @ (G[:, None] * V if G.ndim == 1 else G @ V))


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
def orthonormal_rows(D, rcond):
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
def _scaled_block(H, index, scale, directions, rcond):
    """``_reflect_out`` of the block H[index][:, index] scaled, scale_i H_ij scale_j (its lower triangle read)."""
    n = index.size
    B = np.empty((n, n))
    for i in range(n):
        for j in range(i + 1):
            B[i, j] = B[j, i] = scale[i] * H[index[i], index[j]] * scale[j]
    return _reflect(B, directions, rcond)


@njit(cache=True)
def _reflect_out(A, directions, rcond):
    """The symmetric matrix of A's lower triangle on the orthogonal complement of the rows of ``directions``
    (``_reflect``)."""
    n = A.shape[0]
    B = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            B[i, j] = A[i, j] if i >= j else A[j, i]
    return _reflect(B, directions, rcond)


@njit(cache=True)
def _reflect(B, directions, rcond):
    """The symmetric B (owned, overwritten) on the orthogonal complement of the rows of ``directions``: each
    orthonormal direction d removed by the Householder reflection Q = I − w v vᵀ with Q d = ∓e₁ (a rank-two update
    B ← B − w(v (Bv)ᵀ + (Bv) vᵀ) + w²(vᵀBv) v vᵀ), then the first row and column dropped (and the first coordinate
    of the remaining directions). In place: the k-th reduced matrix is B[k:, k:], updated in one pass that also
    forms the next B v (each entry and sum as a fresh matrix per direction would give them)."""
    n = B.shape[0]
    D = orthonormal_rows(directions, rcond)
    k = D.shape[0]
    if k == 0:
        return B
    v = _householder(D[0])
    Bv = np.zeros(n)
    for i in range(n):
        for j in range(n):
            Bv[i] += B[i, j] * v[j]
    for r in range(k):
        o, size = r, n - r  # the current matrix is B[o:, o:]
        w = 2.0 / _dot(v, v)
        c = w * w * _dot(v, Bv)
        rest = np.empty((D.shape[0], size - 1))
        for s in range(r + 1, D.shape[0]):
            projected = _dot(D[s], v)
            for i in range(1, size):
                rest[s, i - 1] = D[s, i] - w * v[i] * projected
        following = r + 1 < k
        v_next = _householder(rest[r + 1]) if following else np.zeros(0)
        Bv_next = np.zeros(size - 1)
        for i in range(1, size):
            for j in range(1, size):
                value = B[o + i, o + j] - w * (v[i] * Bv[j] + Bv[i] * v[j]) + c * v[i] * v[j]
                B[o + i, o + j] = value
                if following:
                    Bv_next[i - 1] += value * v_next[j - 1]
        D, v, Bv = rest, v_next, Bv_next
    return np.ascontiguousarray(B[k:, k:])


@njit(cache=True)
def _reflect_back(directions, rcond, Y):
    """The rows y of Y (m × (n − k)) in the coordinates of ``_reflect``'s result moved back to the n of its input:
    y ← Q (0, y) for each of its k reflections Q, the last first (orthogonal to the ``directions``)."""
    reflections = _householder_vectors(directions, rcond)
    out = Y.copy()
    for r in range(len(reflections) - 1, -1, -1):
        v = reflections[r]
        w = 2.0 / _dot(v, v)
        moved = np.zeros((out.shape[0], out.shape[1] + 1))
        moved[:, 1:] = out
        for s in range(moved.shape[0]):
            projected = _dot(moved[s], v)
            for i in range(moved.shape[1]):
                moved[s, i] -= w * v[i] * projected
        out = moved
    return out


@njit(cache=True)
def _householder(d):
    """v = d ± e₁ (the sign of d₀): Q = I − 2 v vᵀ/vᵀv maps the unit d to ∓e₁."""
    v = d.copy()
    v[0] += 1.0 if v[0] >= 0.0 else -1.0
    return v


@njit(cache=True)
def _dot(a, b):
    total = 0.0
    for i in range(a.size):
        total += a[i] * b[i]
    return total


@njit(cache=True)
def _lowest_small(A, count):
    """The ``count`` ≤ n lowest eigenvalues of the symmetric A (its lower triangle; overwritten), ascending."""
    d, e = _tridiagonal(A)
    return _lowest_tridiagonal(d, e, count)


@njit(cache=True)
def _tridiagonal(A):
    """(d, e), the diagonal and subdiagonal of Qᵀ A Q = T for the symmetric A (lower triangle read and overwritten):
    Householder reflections H = I − τ v vᵀ from both sides, A₂₂ ← A₂₂ − v wᵀ − w vᵀ with p = τ A₂₂ v,
    w = p − ½ τ (pᵀv) v (Golub & Van Loan, Matrix Computations, §8.3.1)."""
    n = A.shape[0]
    d = np.empty(n)
    e = np.zeros(max(n - 1, 0))
    v = np.empty(n)
    p = np.empty(n)
    for k in range(n - 2):
        alpha = A[k + 1, k]
        sigma = 0.0
        for i in range(k + 2, n):
            sigma += A[i, k] * A[i, k]
        d[k] = A[k, k]
        if sigma == 0.0:  # already tridiagonal in this column
            e[k] = alpha
            continue
        norm = math.sqrt(alpha * alpha + sigma)
        beta = -norm if alpha >= 0.0 else norm
        tau = (beta - alpha) / beta
        scale = 1.0 / (alpha - beta)
        e[k] = beta
        v[k + 1] = 1.0
        for i in range(k + 2, n):
            v[i] = A[i, k] * scale
        for i in range(k + 1, n):
            p[i] = 0.0
        for i in range(k + 1, n):  # p = A₂₂ v from the lower triangle, row by row
            vi = v[i]
            even, odd = A[i, i] * vi, 0.0  # two partial sums: half the latency of the dot product
            j = k + 1
            while j + 1 < i:
                a0, a1 = A[i, j], A[i, j + 1]
                even += a0 * v[j]
                odd += a1 * v[j + 1]
                p[j] += a0 * vi
                p[j + 1] += a1 * vi
                j += 2
            if j < i:
                even += A[i, j] * v[j]
                p[j] += A[i, j] * vi
            p[i] += even + odd
        pv = 0.0
        for i in range(k + 1, n):
            p[i] *= tau
            pv += p[i] * v[i]
        half = 0.5 * tau * pv
        for i in range(k + 1, n):
            p[i] -= half * v[i]
        for i in range(k + 1, n):
            vi, wi = v[i], p[i]
            for j in range(k + 1, i + 1):
                A[i, j] -= vi * p[j] + wi * v[j]
    if n >= 2:
        d[n - 2] = A[n - 2, n - 2]
        e[n - 2] = A[n - 1, n - 2]
    d[n - 1] = A[n - 1, n - 1]
    return d, e


@njit(cache=True)
def _sturm_newton(d, e2, x, pivot, counts, slopes):
    """At each of the three points x[j]: the number of eigenvalues below x[j] of the tridiagonal (d, e² shifted:
    e2[i] = e[i−1]²), from the signs of the LDLᵀ pivots q_i = d_i − x − e²_i/q_{i−1} (a pivot below ``pivot``
    in magnitude taken as −pivot, as LAPACK's dstebz), into counts[j]; and Σ_i q_i'/q_i = d ln|det(T − x)|/dx,
    q_i' = −1 + e²_i q_{i−1}'/q_{i−1}², into slopes[j] (the Newton step on det(T − x) is −1/slope). One
    reciprocal per pivot; the three recurrences interleaved (independent divisions overlap)."""
    x0, x1, x2 = x[0], x[1], x[2]
    r0 = r1 = r2 = 1.0  # 1/q_{i−1}
    p0 = p1 = p2 = 0.0  # q_{i−1}'
    s0 = s1 = s2 = 0.0
    c0 = c1 = c2 = 0
    for i in range(d.shape[0]):
        f = e2[i]
        p0 = -1.0 + f * p0 * r0 * r0
        p1 = -1.0 + f * p1 * r1 * r1
        p2 = -1.0 + f * p2 * r2 * r2
        q0 = d[i] - x0 - f * r0
        q1 = d[i] - x1 - f * r1
        q2 = d[i] - x2 - f * r2
        if abs(q0) < pivot:
            q0 = -pivot
        if abs(q1) < pivot:
            q1 = -pivot
        if abs(q2) < pivot:
            q2 = -pivot
        c0 += q0 < 0.0
        c1 += q1 < 0.0
        c2 += q2 < 0.0
        r0, r1, r2 = 1.0 / q0, 1.0 / q1, 1.0 / q2
        s0 += p0 * r0
        s1 += p1 * r1
        s2 += p2 * r2
    counts[0], counts[1], counts[2] = c0, c1, c2
    slopes[0], slopes[1], slopes[2] = s0, s1, s2


@njit(cache=True)
def _lowest_tridiagonal(d, e, count):
    """The ``count`` lowest eigenvalues (ascending) of the symmetric tridiagonal (d, e), each to an interval of
    width 4 ε ‖T‖ (the accuracy of any backward-stable method) on whose ends the Sturm counts differ: three
    eigenvalues at a time, every count narrowing every interval, from Gershgorin's interval. The next point of an
    eigenvalue is its interval's midpoint (bisection) until the interval holds it alone; then the Newton step on
    det(T − x) from the last point (``_sturm_newton``) while it lands inside the interval and at least halves
    the previous step, and once the step is below half the width, the point half a width beyond the Newton
    estimate, which closes the interval from the other side."""
    n = d.shape[0]
    e2 = np.zeros(n)
    low, high = math.inf, -math.inf
    for i in range(n):
        radius = (abs(e[i - 1]) if i > 0 else 0.0) + (abs(e[i]) if i < n - 1 else 0.0)
        low, high = min(low, d[i] - radius), max(high, d[i] + radius)
        if i > 0:
            e2[i] = e[i - 1] * e[i - 1]
    pivot = 2.2250738585072014e-308 * max(1.0, e2.max())
    width = 4.0 * 2.220446049250313e-16 * max(abs(low), abs(high)) + 2.0 * pivot
    lower = np.full(count, low - width)
    upper = np.full(count, high + width)
    below_lower = np.zeros(count, dtype=np.int64)  # the Sturm counts at the interval ends
    below_upper = np.full(count, n, dtype=np.int64)
    x = np.empty(3)
    counts = np.zeros(3, dtype=np.int64)
    slopes = np.zeros(3)
    step = np.full(3, math.inf)  # the lanes' last Newton steps
    out = np.empty(count)
    for start in range(0, count, 3):
        for j in range(3):
            k = min(start + j, count - 1)
            x[j] = 0.5 * (lower[k] + upper[k])
            step[j] = math.inf
        while True:
            settled = True
            for j in range(3):
                k = min(start + j, count - 1)
                settled = settled and upper[k] - lower[k] <= width
            if settled:
                break
            _sturm_newton(d, e2, x, pivot, counts, slopes)
            for j in range(3):
                for k in range(count):
                    if counts[j] > k:
                        if x[j] < upper[k]:
                            upper[k], below_upper[k] = x[j], counts[j]
                    elif x[j] > lower[k]:
                        lower[k], below_lower[k] = x[j], counts[j]
            for j in range(3):
                k = min(start + j, count - 1)
                mid = 0.5 * (lower[k] + upper[k])
                alone = below_lower[k] == k and below_upper[k] == k + 1 and slopes[j] != 0.0
                delta = -1.0 / slopes[j] if alone else math.inf
                if not (alone and abs(delta) <= 0.5 * step[j]):  # not isolated, no slope, or no contraction
                    x[j], step[j] = mid, math.inf
                    continue
                guess = x[j] + delta
                if abs(delta) <= 0.5 * width:
                    guess += 0.5 * width if delta > 0.0 else -0.5 * width
                if lower[k] < guess < upper[k]:
                    x[j], step[j] = guess, abs(delta)
                else:
                    x[j], step[j] = mid, math.inf
        for j in range(min(3, count - start)):
            k = start + j
            out[k] = 0.5 * (lower[k] + upper[k])
    return out
