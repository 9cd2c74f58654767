"""Benchmark: the order-block structure of the two-coil m = 1 branch's sector Hessians as a preconditioner (issue 37).

About an axisymmetric state the second variation commutes with the rotations about the coil axis, so in the
azimuthal families of a sector (``families``: z of order k, and the pairs (x, y) of order k ± 1 combined as
x cos ± y sin, the cos kφ family of surface.stability.azimuthal_family and its sin twin) it is block-diagonal: D,
M + 2 blocks of up to ~3L/2 rows. The m = 1 branch's states leave the axisymmetric one, and H = D + E with E the
coupling between families. The branch of scenes/spom1_two_coils_M0.002.toml is traced (its stability not read), and
at the points ``POINTS`` (early, middle, last: the last 0.114 from the wires) each symmetry sector is studied:

(a) the spectrum of (D − σI)⁻¹(H − σI) on the constraint space, σ the shift today's reading factors at (below the
    lowest μ by δ): its condition against that of H − σI alone, and ‖E‖/‖H − σI‖; the coupling's decay with the
    distance between families (``coupling``: the band of families that would prove σ, or keep the values within
    1e-10, and what that band's Cholesky would cost);
(b) the ``COUNT`` lowest μ of every reading (the zero modes and gᵀc = 0 as constraints, the gas term a rank-one
    term) with (D − σI)⁻¹ as preconditioner, started from D's lowest eigenvectors, on dense products with H, by
    scipy's LOBPCG and by block Davidson (``davidson``): the largest deviation from today's values
    (``sector_spectra`` following the previous point's, as the assessment reads) relative to max(1, |μ|), the
    iterations, and the CPU against today's read of the sector by parts (``Phases``);
(c) the CPU of assembling H (``SurfaceEquilibrium.hessian`` on the sector) against assembling only D (each family's
    blocks as their own basis on the same nodes: the same contraction restricted to D's block pairs), and of one
    matrix-free product ``SurfaceEquilibrium.hessian_product`` against a dense one.

The certificate a preconditioned method needs (issue 37's verification: that the values found are the LOWEST) is an
inertia count of H − σI below them, i.e. one dense factorisation of the assembled sector: today's reading already is
that factorisation plus Lanczos through it. CPU seconds of this process, one BLAS thread (as the assessment reads),
one run; the load average is printed.

    BALLOON_CG_WORKERS=1 python benchmarks/surface_precond.py [POINT ...] > benchmarks/results/surface_precond.txt
"""
import os
import sys
import time
import warnings
from dataclasses import replace

import numpy as np
from scipy import linalg, sparse
from scipy.sparse.linalg import LinearOperator, lobpcg

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from surface_subbasis import SCENE, traced_branch  # noqa: E402

from balloon_cg.numerics import eigen  # noqa: E402
from balloon_cg.numerics.threads import blas_threads  # noqa: E402
from balloon_cg.scene import load_scene  # noqa: E402
from balloon_cg.scene.loading import Control  # noqa: E402
from balloon_cg.surface import stability  # noqa: E402
from balloon_cg.surface.basis import COS, SIN  # noqa: E402
from balloon_cg.surface.equilibrium import SurfaceEquilibrium  # noqa: E402

POINTS = (2, 8, 13)
COUNT = 4
TOL = 1e-10  # the agreement asked of (b), relative to max(1, |μ|)
LOBPCG_TOL = 1e-8  # LOBPCG's residual tolerance (μ to ~|r|²/gap)
EXTRA = 2  # start vectors beyond COUNT
MAXITER = 300
DAVIDSON_TOL = 1e-8  # the residual asked of block Davidson, relative to max(1, |θ|)
SPECTRUM = True  # (a) computed (a dense generalized eigensolve per sector)


def families(sector) -> tuple:
    """(Q, [index arrays]): the orthogonal Q (sparse, columns the family coordinates in the sector's) and, per
    azimuthal family k = 0, 1, …, the columns of Q in it. z of order m: family m; x, y of order 0: family 1; the
    pair (x cos mφ, y sin mφ) combined as (x ± y)/√2: + to family m − 1, − to m + 1 (x cos + y sin = Re[(e_x − ie_y)
    e^{imφ}], e_x − ie_y = (e_ρ − ie_φ)e^{−iφ}); the pair (x sin mφ, y cos mφ): − to m − 1, + to m + 1."""
    find = {(b.component, b.m, b.t): b for b in sector.blocks}
    rows, cols, vals, family = [], [], [], []

    def column(entries, k):
        for row, value in entries:
            rows.append(row)
            cols.append(len(family))
            vals.append(value)
        family.append(k)

    h = np.sqrt(0.5)
    for b in sector.blocks:
        if b.component == 2:
            for i in range(len(b.degrees)):
                column([(b.offset + i, 1.0)], b.m)
        elif b.component == 0 or (b.component == 1 and (0, b.m, COS if b.t == SIN else SIN) not in find):
            other = find.get((1 - b.component, b.m, COS if b.t == SIN else SIN)) if b.m else None
            if other is None:
                if b.m:
                    raise ValueError(f"unpaired block {b}")
                for i in range(len(b.degrees)):
                    column([(b.offset + i, 1.0)], 1)
                continue
            x, y = (b, other) if b.component == 0 else (other, b)
            if x.degrees != y.degrees:
                raise ValueError(f"pair {x}, {y} with different degrees")
            down = 1.0 if x.t == COS else -1.0  # the sign of y in the combination of family m − 1
            for i in range(len(x.degrees)):
                column([(x.offset + i, h), (y.offset + i, down * h)], x.m - 1)
                column([(x.offset + i, h), (y.offset + i, -down * h)], x.m + 1)
    Q = sparse.csc_matrix((vals, (rows, cols)), shape=(sector.size, sector.size))
    family = np.array(family)
    return Q, [np.flatnonzero(family == k) for k in range(family.max() + 1) if (family == k).any()]


def block_diagonal(A: np.ndarray, index: list) -> np.ndarray:
    """D: A's diagonal blocks ``index`` (family coordinates), zero elsewhere."""
    D = np.zeros_like(A)
    for ix in index:
        D[np.ix_(ix, ix)] = A[np.ix_(ix, ix)]
    return D


class BlockInverse:
    """(D − σI)⁻¹ by the Cholesky factors of its blocks (the preconditioner; SPD where σ is below D's spectrum)."""

    def __init__(self, A: np.ndarray, index: list, sigma: float):
        self.index = index
        self.factors = [linalg.cho_factor(A[np.ix_(ix, ix)] - sigma * np.eye(ix.size), lower=True) for ix in index]

    def __call__(self, X):
        X = np.asarray(X)
        out = np.empty_like(X)
        for ix, f in zip(self.index, self.factors):
            out[ix] = linalg.cho_solve(f, X[ix])
        return out


def lowest_block(A: np.ndarray, index: list, count: int) -> tuple:
    """(the ``count`` lowest eigenvalues of D, a start block: D's lowest eigenvectors, ``count`` + 2 of them)."""
    found = []
    for ix in index:
        w, v = linalg.eigh(A[np.ix_(ix, ix)], subset_by_index=[0, min(count + EXTRA - 1, ix.size - 1)])
        for k in range(w.size):
            found.append((w[k], ix, v[:, k]))
    found.sort(key=lambda t: t[0])
    X = np.zeros((A.shape[0], count + EXTRA))
    for j, (_, ix, v) in enumerate(found[:count + EXTRA]):
        X[ix, j] = v
    return np.array([f[0] for f in found[:count]]), X


def reading_problem(H, gram, rows, control, g, weight, Q):
    """(A, constraints Y) of one reading in family coordinates: A = Qᵀ(H [+ (P/Ṽ)ggᵀ])Q/gram, Y the zero-mode rows
    (and g under volume control) as columns."""
    A = (Q.T @ (Q.T @ H).T).T / gram
    extra = [rows]
    if control == Control.VOLUME:
        extra.append(g[None, :])
    if control == Control.GAS:
        q = Q.T @ g
        A = A + (weight / gram) * np.outer(q, q)
    Y = (Q.T @ np.vstack(extra).T) if sum(e.shape[0] for e in extra) else None
    return A, Y


def cpu(f, *args):
    start = time.process_time()
    out = f(*args)
    return out, time.process_time() - start


class Phases:
    """CPU seconds of today's read by part: the sector's assembly (``SurfaceEquilibrium.hessian``), the shifted
    Cholesky (``eigen.ShiftInvert.below``), the Lanczos runs through it (``lowest_of_relatives``), the dense
    readings (``eigen.lowest_of``); the rest (zero-mode reflections, g, the readings' rows) is the remainder."""

    PARTS = (("assembly", SurfaceEquilibrium, "hessian"), ("cholesky", eigen.ShiftInvert, "below"),
             ("lanczos", eigen.ShiftInvert, "lowest_of_relatives"), ("dense", eigen, "lowest_of"))

    def __init__(self):
        self.seconds = {name: 0.0 for name, _, _ in self.PARTS}

    def __enter__(self):
        self.saved = []
        for name, owner, attribute in self.PARTS:
            raw = owner.__dict__[attribute]
            self.saved.append((owner, attribute, raw))
            function = raw.__func__ if isinstance(raw, classmethod) else raw

            def timed(*args, _f=function, _name=name, **kwargs):
                start = time.process_time()
                try:
                    return _f(*args, **kwargs)
                finally:
                    self.seconds[_name] += time.process_time() - start
            setattr(owner, attribute, classmethod(timed) if isinstance(raw, classmethod) else timed)
        return self

    def __exit__(self, *exc):
        for owner, attribute, raw in self.saved:
            setattr(owner, attribute, raw)


def coupling(A: np.ndarray, index: list, delta: float) -> tuple:
    """(‖E_{|Δk|>j}‖_F/δ for j = 1, 2, 4, 8; then for ε = δ/2 and ε = TOL: j_ε, the fewest neighbouring families
    whose band leaves ‖E_{|Δk|>j}‖_F ≤ ε, and that band's Cholesky flops over the dense one's, 3(w/n)², w its
    half-width in rows). ε = δ/2: a Cholesky of the band shifted to σ + δ/2 proves σ below A's spectrum (Weyl);
    ε = TOL: the band's eigenvalues are A's within TOL (Weyl: a bound, not an estimate). ``δ``: the gap below the
    lowest μ that today's shift leaves."""
    k = len(index)
    F = np.array([[np.linalg.norm(A[np.ix_(a, b)]) for b in index] for a in index])
    distance = np.abs(np.subtract.outer(np.arange(k), np.arange(k)))
    tail = [float(np.sqrt((F[distance > j] ** 2).sum())) for j in range(k)]
    sizes, n = np.array([ix.size for ix in index]), A.shape[0]
    out = [[tail[j] / delta if j < k else 0.0 for j in (1, 2, 4, 8)]]
    for eps in (0.5 * delta, TOL):
        star = next((j for j in range(k) if tail[j] <= eps), k - 1)
        width = max(int(sizes[a:a + star + 1].sum()) for a in range(k))
        out += [star, 3.0 * (min(width, n) / n) ** 2]
    return out


def study(eq, c, params, sector, guesses, out):
    """Prints one sector's rows of (a), (b), (c); returns today's spectra of it."""
    key, gram = sector.characters, sector.gram()
    with blas_threads():
        eq.hessian(c, params, sector)  # the state's node rows and Fourier table (shared by every sector) made once
        H, t_full = cpu(eq.hessian, c, params, sector)
        with Phases() as phases:
            today, t_today = cpu(stability.sector_spectra, eq, c, params, COUNT, stability.READINGS, guesses, (key,))
    Q, index = families(sector)
    t_d = _block_assembly(eq, sector, Q, index)
    w = np.random.default_rng(0).standard_normal(sector.size)
    sub_eq = SurfaceEquilibrium(eq.scene, sector, eq.kernels)
    sub_eq._held, sub_eq._named, sub_eq._outputs = eq._held, eq._named, eq._outputs
    with blas_threads():
        _, t_free = cpu(sub_eq.hessian_product, c, params, w)
        _, t_dense = cpu(lambda: H @ w)
    *_, groups, weight = next(stability._sectors(eq, c, params, stability.READINGS, (key,)))
    g = -eq.parameter_derivative(c, params, "P", sector) if stability._own(sector, eq.basis) else None
    worst, iters, converged, t_lobpcg = 0.0, [], 0, 0.0
    worst_d, steps_d, count_d, t_davidson = 0.0, [], 0, 0.0
    cond = band = None
    for (_, control), (rows, shared) in groups.items():
        control = control if g is not None else Control.PRESSURE
        A, Y = reading_problem(H, gram, rows, control, g, weight, Q)
        reference = today[shared[0]][key]
        with blas_threads():
            lowest_d, X = lowest_block(A, index, COUNT)
            delta = max(abs(float(reference[0])), 1e-2)
            sigma = min(float(reference[0]), float(lowest_d[0])) - delta
            inverse = BlockInverse(A, index, sigma)
            (values, iterations, ok), t = cpu(_lobpcg, A, Y, X, inverse)
            (found, steps, products), t2 = cpu(davidson, A, Y, X, inverse)
        t_lobpcg += t
        t_davidson += t2
        worst = max(worst, float(np.max(np.abs(values - reference) / np.maximum(1.0, np.abs(reference)))))
        worst_d = max(worst_d, float(np.max(np.abs(found - reference) / np.maximum(1.0, np.abs(reference)))))
        steps_d.append(steps)
        count_d += products
        iters.append(iterations)
        converged += ok
        if shared[0] == stability.Reading(True):
            with blas_threads():
                cond = _condition(A, Y, index, sigma) if SPECTRUM else (np.nan,) * 5
                band = coupling(A - sigma * np.eye(A.shape[0]), index, delta)
    p = phases.seconds
    print(f"  {str(key):>9} {sector.size:>5} {len(index):>3} |{t_today:6.2f} {p['assembly']:5.2f} {p['cholesky']:5.2f} "
          f"{p['lanczos']:5.2f} {p['dense']:5.2f} | {cond[2]:8.3g} {cond[3]:8.3g} {cond[4]:7.2g} | "
          + " ".join(f"{v:7.1e}" for v in band[0]) + f" {band[1]:>3} {band[2]:5.2f} {band[3]:>3} {band[4]:5.2f} | {worst:7.1e} "
          f"{converged}/{len(iters)} {max(iters):>4} {t_lobpcg:6.2f} | {worst_d:7.1e} {max(steps_d):>3} {count_d:>5} "
          f"{t_davidson:6.2f} | {t_full:5.2f} {t_d:5.2f} {1e3 * t_free:6.1f} "
          f"{1e3 * t_dense:5.1f}", flush=True)
    for k, v in (("lobpcg", t_lobpcg), ("davidson", t_davidson), ("today", t_today), ("H", t_full), ("D", t_d), *p.items()):
        out[k] = out.get(k, 0.0) + v
    out["dev"] = max(out.get("dev", 0.0), worst)
    out["dev_davidson"] = max(out.get("dev_davidson", 0.0), worst_d)
    return today


def _block_assembly(eq, sector, Q, index) -> float:
    """CPU s of assembling D alone: each family's blocks as their own basis on the sector's nodes (their tables
    built first, untimed, as a sector's are once per basis), contracted with the state's Fourier table."""
    fourier = next(v for k, v in eq._outputs.items() if k[0] == "fourier of surface_hessian")
    rows_of = Q.tocsr()
    total = 0.0
    for ix in index:
        touched = np.unique(rows_of[:, ix].nonzero()[0])
        used = [b for b in sector.blocks if np.any((touched >= b.offset) & (touched < b.slice.stop))]
        part = replace(sector)
        object.__setattr__(part, "blocks", _renumbered(used))
        part.tables, part._products  # noqa: B018
        with blas_threads():
            _, t = cpu(part.hessian, fourier, eq._pairs)
        total += t
    return total


def _renumbered(blocks):
    offset, out = 0, []
    for b in blocks:
        out.append(replace(b, offset=offset))
        offset += len(b.degrees)
    return tuple(out)


def _lobpcg(A, Y, X, precondition):
    """(the COUNT lowest, iterations, whether it reached LOBPCG_TOL) by LOBPCG from the start block X."""
    n = A.shape[0]
    operator = LinearOperator((n, n), matvec=lambda v: A @ v, matmat=lambda V: A @ V, dtype=float)
    M = LinearOperator((n, n), matvec=precondition, matmat=precondition, dtype=float)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        values, _, history = lobpcg(operator, X, M=M, Y=Y, tol=LOBPCG_TOL, maxiter=MAXITER, largest=False,
                                    retLambdaHistory=True)
    return np.sort(values)[:COUNT], len(history) - 1, not any("not reaching" in str(w.message) for w in caught)


def davidson(A, Y, X, precondition, tol: float = DAVIDSON_TOL, most: int = 200) -> tuple:
    """(the COUNT lowest μ, iterations, products with A) of A on the complement of Y's columns by block Davidson:
    Rayleigh–Ritz on a basis V (orthonormal, ⊥ Y), the residuals R = AX − XΘ of the block's Ritz pairs expanded by
    the preconditioner (V ← [V, orth(P T R)], P the projector off Y, T = (D − σI)⁻¹), restarted from the Ritz block
    when V reaches 8 blocks; stopped when the COUNT lowest residuals are ≤ tol · max(1, |θ|) (then each θ is within
    |r|²/gap of its eigenvalue, Rayleigh–Ritz)."""
    Yo = linalg.orth(Y) if Y is not None else np.zeros((A.shape[0], 0))

    def off(V):
        return V - Yo @ (Yo.T @ V)

    b = X.shape[1]
    V = linalg.orth(off(X))
    AV = A @ V
    products = V.shape[1]
    for iteration in range(most):
        theta, S = linalg.eigh(0.5 * (V.T @ AV + (V.T @ AV).T))
        Xr, AX = V @ S[:, :b], AV @ S[:, :b]
        R = off(AX - Xr * theta[:b])
        norms = np.linalg.norm(R, axis=0)
        open_ = norms > tol * np.maximum(1.0, np.abs(theta[:b]))
        if not open_[:COUNT].any():
            return theta[:COUNT], iteration, products
        W = off(precondition(R[:, open_]))
        if V.shape[1] + W.shape[1] > 8 * b:
            V, AV = Xr, AX
        for _ in range(2):
            W -= V @ (V.T @ W)
        W, r = linalg.qr(W, mode="economic")
        W = W[:, np.abs(np.diag(r)) > 1e-12 * np.abs(r).max()]
        V, AV = np.hstack([V, W]), np.hstack([AV, A @ W])
        products += W.shape[1]
    raise ArithmeticError(f"davidson: not converged in {most} iterations")


def _condition(A, Y, index, sigma) -> tuple:
    """(λ_min, λ_max, κ of (D − σI)⁻¹(A − σI), κ of A − σI, ‖E‖₂/‖A‖₂) on the complement of Y's columns."""
    N = linalg.null_space(Y.T) if Y is not None else np.eye(A.shape[0])
    S = A - sigma * np.eye(A.shape[0])
    D = block_diagonal(S, index)
    a, d = N.T @ S @ N, N.T @ D @ N
    generalized = linalg.eigh(a, d, eigvals_only=True)
    plain = linalg.eigvalsh(a)
    E = S - D
    return (generalized[0], generalized[-1], generalized[-1] / generalized[0], plain[-1] / plain[0],
            np.linalg.norm(E, 2) / np.linalg.norm(S, 2))


HEADER = ("  sector     n  NF | today: read assembly Cholesky Lanczos dense | (a) κ((D−σ)⁻¹(A−σ)) κ(A−σ) ‖E‖/‖A−σ‖ | "
          "‖E_{|Δk|>j}‖_F/δ j = 1 2 4 8, j and band Cholesky/dense for ε = δ/2, for ε = 1e-10 | (b) LOBPCG: max dev, converged groups, most "
          "iterations, CPU | block Davidson: max dev, most iterations, products, CPU | (c) assembly H, D s, product matrix-free, dense ms")


def main(points=POINTS):
    scene = load_scene(SCENE)
    traced, values, params0 = traced_branch(scene)
    print(f"# {SCENE.name}: m = 1 branch, {len(traced)} points; load average before the study "
          f"{os.getloadavg()[0]:.1f}")
    totals = {}
    guesses = None
    for i in range(max(points) + 1):
        trace, c = traced[i]
        eq, params = trace.eq, params0.with_value("P", values[i])
        if i not in points:
            with blas_threads():
                guesses = stability.sector_spectra(eq, c, params, COUNT, stability.READINGS, guesses)
            continue
        print(f"# point {i}: P = {values[i]:.10f}, degree {trace.basis.degree}, order {trace.basis.order}", flush=True)
        print(HEADER, flush=True)
        spectra = {r: {} for r in stability.READINGS}
        for sector in trace.basis.sectors():
            if sector.size:
                today = study(eq, c, params, sector, guesses, totals)
                for r in stability.READINGS:
                    spectra[r][sector.characters] = today[r][sector.characters]
        guesses = spectra
    t = totals
    print(f"# totals over these points (CPU s): today's reads {t['today']:.1f} (assembly {t['assembly']:.1f}, Cholesky "
          f"{t['cholesky']:.1f}, Lanczos {t['lanczos']:.1f}, dense {t['dense']:.1f}); LOBPCG alone {t['lobpcg']:.1f}, its "
          f"largest deviation {t['dev']:.1e}; block Davidson alone {t['davidson']:.1f}, {t['dev_davidson']:.1e}; assembly of H {t['H']:.1f}, of D {t['D']:.1f}; load average after "
          f"{os.getloadavg()[0]:.1f}")

if __name__ == "__main__":
    main(tuple(int(a) for a in sys.argv[1:]) or POINTS)
