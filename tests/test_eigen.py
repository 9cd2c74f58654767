"""Constrained lowest eigenvalues (balloon_cg.numerics.eigen) and the stability flags from the inertia alone.

Independent checks: the restricted pencil against an explicit null-space basis (scipy.linalg.null_space) and
scipy's generalized eigensolver; positive definiteness against the sign of the lowest eigenvalue; and, on
branches with and without a field, the flags of ``SecondVariation.flags`` (Cholesky) against those of
``SecondVariation.assess`` (eigenvalues) at every point and both degrees the check uses.
"""
from pathlib import Path

import numpy as np
import pytest
from scipy import linalg

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.stability.axisymmetric import SecondVariation
from balloon_cg.numerics import eigen
from balloon_cg.scene import load_scene, parse_scene

ROOT = Path(__file__).resolve().parent.parent


def pencil(n, seed):
    rng = np.random.default_rng(seed)
    B = rng.normal(size=(n, n))
    G = B @ B.T + n * np.eye(n)
    H = rng.normal(size=(n, n))
    return 0.5 * (H + H.T), G, rng


@pytest.mark.parametrize("n, k", [(12, 0), (30, 1), (41, 3), (60, 3), (eigen.LARGE_BLOCK + 40, 3)])
def test_restricted_lowest_matches_an_explicit_null_space(n, k):
    H, G, rng = pencil(n, n + k)
    normals = rng.normal(size=(k, n))
    if k == 3:
        normals[2] = 2.0 * normals[0] - normals[1]  # linearly dependent: one direction fewer
    values = eigen.lowest(H, eigen.GramFactor(G), 4, normals)
    null = linalg.null_space(normals) if k else np.eye(n)
    assert null.shape[1] == n - min(k, 2)
    expected = linalg.eigh(null.T @ H @ null, null.T @ G @ null, eigvals_only=True)[:4]
    assert np.abs(values - expected).max() < 1e-12 * np.abs(expected).max()


def test_restricted_block_of_a_larger_matrix():
    H, G, rng = pencil(20, 3)
    index = np.array([1, 4, 5, 9, 12, 17])
    g = rng.normal(size=20)
    values = eigen.lowest(H, eigen.GramFactor(G[np.ix_(index, index)]), 3, g[index], index)
    null = linalg.null_space(g[index][None])
    Hb, Gb = H[np.ix_(index, index)], G[np.ix_(index, index)]
    expected = linalg.eigh(null.T @ Hb @ null, null.T @ Gb @ null, eigvals_only=True)[:3]
    assert np.abs(values - expected).max() < 1e-12 * np.abs(expected).max()


def test_a_block_diagonal_gram_factor_is_the_dense_one():
    """G block-diagonal (blocks of 7, 1, 12 and 20 unknowns, the entries outside zero): the factor of its blocks
    (``GramFactor(blocks=)``, triangular solves block by block) gives the pencil's lowest eigenvalues on
    constraints as an explicit null space does (1e-12 relative), the same constraint directions L⁻¹n and L as the
    dense factor (1e-14), and G wᵢ for ``weighed``."""
    H, _, rng = pencil(40, 7)
    slices = (slice(0, 7), slice(7, 8), slice(8, 20), slice(20, 40))
    G = np.zeros((40, 40))
    for s in slices:
        B = rng.normal(size=(s.stop - s.start,) * 2)
        G[s, s] = B @ B.T + (s.stop - s.start) * np.eye(s.stop - s.start)
    normals = rng.normal(size=(2, 40))
    blocks, dense = eigen.GramFactor(G, blocks=slices), eigen.GramFactor(G)
    values = eigen.lowest(H, blocks, 4, normals)
    null = linalg.null_space(normals)
    expected = linalg.eigh(null.T @ H @ null, null.T @ G @ null, eigvals_only=True)[:4]
    assert np.abs(values - expected).max() < 1e-12 * np.abs(expected).max()
    assert np.abs(blocks.directions(normals) - dense.directions(normals)).max() < 1e-14 * np.abs(normals).max()
    assert np.abs(blocks.lower - dense.lower).max() < 1e-14 * np.abs(dense.lower).max()
    np.testing.assert_array_equal(blocks.weighed(normals), normals @ G)


def spring_chain(n, seed) -> tuple:
    """(H, G, slices): a free chain of n masses, H = Dᵀ diag(k) D with integer springs k ∈ [1, 1000] (exact in
    floating point: H 1 = 0 exactly, so the pencil's lowest μ is exactly 0 with c = 1), G the masses' Gram
    matrix, block-diagonal on ``slices``, its masses down to 1e-3 (the pencil's largest μ ~ 1e6, as a refined
    element layout's)."""
    rng = np.random.default_rng(seed)
    springs = rng.integers(1, 1001, n - 1).astype(float)
    D = np.diff(np.eye(n), axis=0)
    H = D.T @ (springs[:, None] * D)
    slices = (slice(0, n // 3), slice(n // 3, n // 3 + 1), slice(n // 3 + 1, n))
    G = np.zeros((n, n))
    for s in slices:
        size = s.stop - s.start
        B = 0.1 * rng.normal(size=(size, size)) / np.sqrt(size)
        G[s, s] = B @ B.T + np.diag(10.0 ** rng.uniform(-3, 0, size))
    return H, G, slices


@pytest.mark.parametrize("kind", ["dense", "blocks", "orthogonal"])
@pytest.mark.parametrize("n, constrained", [(40, False), (eigen.LARGE_BLOCK + 40, True)])
def test_ritz_values_read_a_zero_eigenvalue_to_rounding_where_the_dense_solve_cannot(kind, n, constrained):
    """The spring chain's pencil (exact zero μ, largest μ ~ 1e6), on the constraints (e₀ − e₁)ᵀc = 0 and
    (e₂ − 2e₃ + e₄)ᵀc = 0 (both hold for c = 1: the zero stays) or none: ``lowest_ritz`` reads the zero to 1e-13
    (measured ≤ 4.4e-14) where ``lowest`` is off by up to ε‖A‖, ‖A‖ the largest μ (measured up to 1.1e-10), and the other lowest μ agree
    with ``lowest``'s to ε‖A‖ and with an explicit null space's scipy.linalg.eigh to ε‖A‖ (each dense); with G
    dense, block-diagonal (``blocks``) or its diagonal (``orthogonal``)."""
    H, G, slices = spring_chain(n, n)
    if kind == "orthogonal":
        G = np.diag(np.diag(G))
    factor = {"dense": lambda: eigen.GramFactor(G), "blocks": lambda: eigen.GramFactor(G, blocks=slices),
              "orthogonal": lambda: eigen.GramFactor(np.diag(G), orthogonal=True)}[kind]()
    normals = np.zeros((2, n))
    normals[0, :2] = (1.0, -1.0)
    normals[1, 2:5] = (1.0, -2.0, 1.0)
    normals = normals if constrained else eigen.NO_CONSTRAINT
    ritz = eigen.lowest_ritz(H, factor, 4, normals)
    dense = eigen.lowest(H, factor, 4, normals)
    null = linalg.null_space(normals) if constrained else np.eye(n)
    expected = linalg.eigh(null.T @ H @ null, null.T @ G @ null, eigvals_only=True)
    rounding = eigen.EPS * expected[-1]
    assert abs(ritz[0]) <= 1e-13 and expected[-1] > 1e5
    assert np.abs(ritz - dense).max() <= 10 * rounding and np.abs(ritz - expected[:4]).max() <= 10 * rounding


def test_ritz_values_on_a_block_of_a_larger_matrix():
    """``lowest_ritz`` on the unknowns ``index`` of a larger H (the spring chain's, a zero μ on them: the chain of
    the masses 5 to 24) is the Ritz problem of that block alone."""
    H, G, _ = spring_chain(30, 5)
    index = np.arange(5, 25)
    H[np.ix_(index, index)] = spring_chain(20, 6)[0]
    factor = eigen.GramFactor(G[np.ix_(index, index)])
    alone = eigen.lowest_ritz(H[np.ix_(index, index)], factor, 3)
    assert abs(alone[0]) <= 1e-13
    np.testing.assert_array_equal(eigen.lowest_ritz(H, factor, 3, index=index), alone)


def test_positive_definite_is_the_sign_of_the_lowest_eigenvalue():
    H, G, _ = pencil(25, 11)
    factor = eigen.GramFactor(G)
    lowest = eigen.lowest(H, factor, 1)[0]
    for shift in (lowest - 1e-3, lowest + 1e-3):
        A = eigen.restricted(H - shift * G, factor)
        assert eigen.positive_definite(A) == (lowest - shift > 0)


def stiff_matrix(n, lowest, seed):
    """A symmetric matrix with the eigenvalues ``lowest`` and then n − len(lowest) spread over 1..1e6 (a membrane
    Hessian's range), and its spectrum."""
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.normal(size=(n, n)))
    spectrum = np.concatenate([lowest, np.geomspace(1.0, 1e6, n - len(lowest))])
    A = (Q * spectrum) @ Q.T
    return 0.5 * (A + A.T), np.sort(spectrum)


@pytest.mark.parametrize("guess", [-3.0, -20.0, 0.5, 1e-9])
def test_lowest_following_matches_the_dense_spectrum(guess):
    """Lanczos on (A − σI)⁻¹ below the spectrum returns the lowest eigenvalues to 1e-10 whatever the guess (one far
    above the lowest needs several shifts), near-zero and clustered ones included."""
    A, spectrum = stiff_matrix(eigen.FOLLOWING_SIZE + 50, [-3.9, -1e-12, 0.3, 0.3 + 1e-7, 0.5], 5)
    kept = A.copy()
    values = eigen.lowest_following(A, 4, guess)
    assert np.array_equal(A, kept)
    assert np.abs(values - spectrum[:4]).max() < 1e-10


def test_lanczos_goes_on_past_an_invariant_krylov_space():
    """The start vector an eigenvector (of 2.0) of an operator of rank 4 in 60 dimensions: its Krylov space closes at
    once (breakdown) and the other wanted eigenvalues come only from the new directions; all four to rounding."""
    start = np.random.default_rng(eigen.LANCZOS_START).standard_normal(60)
    Q, _ = np.linalg.qr(np.column_stack([start, np.random.default_rng(4).normal(size=(60, 59))]))
    spectrum = np.concatenate([[2.0, 3.0, 3.5, 7.0], np.zeros(56)])
    S = (Q * spectrum) @ Q.T
    calls = []
    values = eigen.largest_by_lanczos(lambda v: calls.append(1) or S @ v, 60, 4)
    assert np.abs(values - [2.0, 3.0, 3.5, 7.0]).max() < 1e-13
    assert len(calls) > 4  # the breakdown happened and was passed (4 products would have sufficed otherwise)


@pytest.mark.parametrize("controls", ["pressure", "volume", "gas"])
def test_one_shifted_factorisation_serves_the_constrained_and_updated_readings(controls):
    """ShiftInvert of the matrix with fewer constraints (the free balloon under pressure) gives the lowest
    eigenvalues of its relatives, more constraints (held: restricted_rows of the extra normals), a volume
    constraint, a positive rank-one term (gas), to 1e-10 of each relative's own restricted matrix solved dense."""
    n = eigen.FOLLOWING_SIZE + 40
    A, _ = stiff_matrix(n, [-3.9, -0.2, 0.3, 0.3 + 1e-7, 0.5], 7)
    rng = np.random.default_rng(8)
    G = np.full(n, 2.0)
    factor = eigen.GramFactor(G, orthogonal=True)
    H = A * G  # the pencil (H, 2I): its standard matrix is A
    base = rng.normal(size=(2, n))
    held = np.vstack([base, rng.normal(size=(2, n)), 3.0 * base[0] - base[1]])  # one dependent row
    g = rng.normal(size=n)
    if controls == "volume":
        normals, extra, update = np.vstack([held, g]), np.vstack([held, g]), None
    else:
        normals, extra = held, held
        update = (eigen.restricted_rows(factor, base, g[None, :])[0], 0.7) if controls == "gas" else None
    explicit = eigen.restricted(H + (0.7 * np.outer(g, g) if controls == "gas" else 0.0), factor, normals)
    shifted = eigen.ShiftInvert.below(eigen.restricted(H, factor, base), -3.0)
    values = shifted.lowest(4, eigen.restricted_rows(factor, base, extra), update)
    assert eigen.rank_of(factor.directions(extra)) == n - explicit.shape[0]
    assert np.abs(values - eigen.lowest_of(explicit, 4)).max() < 1e-10
    if update is not None:  # a negative term may take the spectrum below σ: refused
        assert shifted.lowest(4, update=(update[0], -0.7)) is None


def test_relatives_in_lockstep_are_each_alone_to_the_solve_s_rounding():
    """The Lanczos runs of several relatives sharing each solve (one right-hand side of several columns) give every
    relative the numbers it gets alone to the shifted solve's rounding (ε‖A‖/dist(σ, spectrum), ‖A‖ = 1e6, the gap
    0.9: a column solved among others may differ in its last bits from one solved alone, as the BLAS build blocks
    them), a refused one (a negative update) None among them; the same call twice gives the same bits."""
    n = eigen.FOLLOWING_SIZE + 40
    A, _ = stiff_matrix(n, [-3.9, -0.2, 0.3, 0.3 + 1e-7, 0.5], 7)
    rng = np.random.default_rng(9)
    factor = eigen.GramFactor(np.full(n, 2.0), orthogonal=True)
    base, extra, g = rng.normal(size=(2, n)), rng.normal(size=(3, n)), rng.normal(size=n)
    shifted = eigen.ShiftInvert.below(eigen.restricted(A * 2.0, factor, base), -3.0)
    held = eigen.restricted_rows(factor, base, extra)
    u = eigen.restricted_rows(factor, base, g[None, :])[0]
    relatives = [(4, None, None), (4, held, None), (3, np.vstack([held, u]), None), (4, held, (u, 0.7)),
                 (4, None, (u, -0.7)), (5, None, (u, 0.2))]
    together = shifted.lowest_of_relatives(relatives)
    assert together[4] is None
    rounding = np.finfo(float).eps * 1e6 / 0.9
    for relative, found, again in zip(relatives, together, shifted.lowest_of_relatives(relatives)):
        alone = shifted.lowest(*relative)
        assert (found is None and alone is None) or np.abs(found - alone).max() <= rounding
        assert (found is None and again is None) or np.array_equal(found, again)


@pytest.mark.parametrize("n", [60, 140])
def test_relatives_read_below_the_base_matrix_s_lowest_eigenvalue(n, monkeypatch):
    """``lowest_with_relatives``: the base matrix's own lowest eigenvalues are the dense ones, each relative's (a
    volume constraint, a positive rank-one term, both) within 10 ε‖A‖ (‖A‖ = 1e6: the dense solve's own rounding
    level) of its own matrix solved dense (through one
    factorisation from RELATIVES_SIZE rows, here 100, the dense solve itself below it), a refused one (a negative
    term) dense."""
    monkeypatch.setattr(eigen, "RELATIVES_SIZE", 100)
    A, _ = stiff_matrix(n, [-3.9, -0.2, 0.3, 0.3 + 1e-7, 0.5], 7)
    rng = np.random.default_rng(10)
    row, u = rng.normal(size=(1, n)), rng.normal(size=n)
    unit = eigen.GramFactor(np.ones(n), orthogonal=True)
    matrices = [lambda: eigen.restricted(A, unit, row), lambda: A + 0.7 * np.outer(u, u),
                lambda: eigen.restricted(A + 0.7 * np.outer(u, u), unit, row), lambda: A - 0.7 * np.outer(u, u)]
    relatives = [(row, None, matrices[0]), (None, (u, 0.7), matrices[1]), (row, (u, 0.7), matrices[2]),
                 (None, (u, -0.7), matrices[3])]
    own, values = eigen.lowest_with_relatives(A, 3, relatives)
    assert np.array_equal(own, eigen.lowest_of(np.array(A), 3))
    for found, matrix in zip(values, matrices):
        assert np.abs(found - eigen.lowest_of(matrix(), 3)).max() < 10 * eigen.EPS * 1e6
    assert np.array_equal(values[3], eigen.lowest_of(matrices[3](), 3))


def test_assessment_reads_the_relatives_to_the_dense_rounding(monkeypatch):
    """A point of the paper coil at perturbation degree 60 in the general layout with RELATIVES_SIZE 50 (m = 0 blocks
    of 121 rows, the m = 1 block's two reflection classes of ~90: the volume, gas and held blocks read through one
    factorisation each, ``lowest_with_relatives``): every block's lowest eigenvalues within 100 ε‖A‖ of its matrices'
    by a second dense method (LAPACK's divide and conquer, dsyevd), the rounding level of dense eigenvalues of A
    (at the default size: tests/test_stability_reference.py, the paper coil and the off-equator scene)."""
    monkeypatch.setattr(eigen, "RELATIVES_SIZE", 50)
    branch = trace_primary(load_scene(ROOT / "scenes" / "spom1_paper_coil.toml"), stop_stretch=2.5, down=False)
    variation, X = SecondVariation(equilibrium_of(branch), 60), branch.X[-1]
    params = branch.params_at(X)
    found = variation.assess(X[:-1], params, False, 1).blocks
    for name, parts, _ in variation.blocks(X[:-1], params, False, 1):
        scale = 100 * np.finfo(float).eps * max(np.linalg.norm(A, 2) for A in parts)
        dense = np.sort(np.concatenate([linalg.eigh(A, eigvals_only=True, driver="evd")[:3] for A in parts]))[:3]
        assert min(A.shape[0] for A in parts) >= eigen.RELATIVES_SIZE
        assert np.abs(found[name] - dense).max() < scale, name


def test_negative_count_is_the_inertia():
    """The Bunch–Kaufman inertia counts the negative eigenvalues, with 2×2 pivots (zero diagonal blocks force them)."""
    for negatives in (0, 1, 3, 7):
        A, spectrum = stiff_matrix(120, -np.geomspace(1e-6, 5.0, negatives), negatives)
        assert eigen.negative_count(A) == negatives == int((spectrum < 0).sum())
    swap = np.array([[0.0, 1.0], [1.0, 0.0]])  # eigenvalues ±1: a 2×2 pivot
    assert eigen.negative_count(np.kron(np.eye(3), swap)) == 3
    assert eigen.negative_count(-np.kron(np.eye(3), swap) - 2 * np.eye(6)) == 6


def flag_pairs(branch, symmetric, m_max, degrees):
    eq = equilibrium_of(branch)
    for degree in degrees:
        variation = SecondVariation(eq, degree)
        for X in branch.X:
            params = branch.params.with_value("P", X[-1])
            yield (tuple(variation.assess(X[:-1], params, symmetric, m_max).flags().values()),
                   variation.flags(X[:-1], params, symmetric, m_max))


@pytest.mark.parametrize("scene, stop", [("spom1", 4.0), ("spom1_two_coils_M0.002", 1.8)])
def test_inertia_flags_agree_with_the_eigenvalue_flags(scene, stop):
    """Both symmetry readings (the equator-symmetric blocks and the general ones), m = 0 and 1, held and free in
    a field; the flags must change along the branch for the comparison to mean something."""
    branch = trace_primary(load_scene(ROOT / "scenes" / f"{scene}.toml"), stop_stretch=stop, down=False)
    for symmetric in (True, False):
        pairs = list(flag_pairs(branch, symmetric, 1, (20, 40)))
        assert all(eigenvalues == inertia for eigenvalues, inertia in pairs)
        assert len({eigenvalues for eigenvalues, _ in pairs}) > 1


def test_inertia_flags_without_m1_blocks():
    branch = trace_primary(parse_scene('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 3.0\n',
                                       name="spom1"), down=False)
    pairs = list(flag_pairs(branch, True, 0, (20,)))
    assert all(eigenvalues == inertia for eigenvalues, inertia in pairs)
    assert len({eigenvalues for eigenvalues, _ in pairs}) > 1
