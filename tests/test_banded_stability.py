"""The banded sibling of the m = 0 second variation (issue 37): C⁰ piecewise polynomials on the wire map
(galerkin/piecewise.py), banded shift-invert Lanczos (numerics/banded.py), the blocks of analysis/stability/banded.py.

- the eigensolver against a dense generalized eigensolve of the same pencil, with constraints and a gas term;
- the basis: the constant function, ∫1 dx = 2 on the whole interval and on the half one;
- the scene key stability.banded_from, and the assessment of a whole branch with it (SPOM1 M = 0: flags unchanged);
- near a wire (the two-coil primary branch's last point, gap 0.1, stored at mapped degree 90): every block's three
  lowest eigenvalues (m = 0; m = 1 held and free), equator-symmetric blocks and the general ones, against the
  Legendre blocks (an independent discretisation) to within the two discretisations' own error estimates;
- the flags from the banded blocks' inertia (numerics/banded.py ``BandedSigns``) against the dense eigenvalues'
  signs of random pencils and their relatives, and against the Legendre blocks' flags near that wire.
"""
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy import linalg

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.stability.axisymmetric import SecondVariation, assess_branch, point_degrees
from balloon_cg.analysis.stability.banded import BandedVariation
from balloon_cg.analysis.stability.banded_azimuthal import BandedAzimuthal
from balloon_cg.galerkin.piecewise import PiecewiseBasis
from balloon_cg.numerics.band_ldlt import BandLDLT
from balloon_cg.numerics.banded import BandedShiftInvert, BandedSigns, InsideShift
from balloon_cg.scene import SceneError, load_scene, parse_scene

SCENES = Path(__file__).resolve().parent.parent / "scenes"
TWO_COILS, SPOM1 = SCENES / "spom1_two_coils_M0.002.toml", SCENES / "spom1.toml"


def _band(A: np.ndarray, bandwidth: int) -> np.ndarray:
    n = A.shape[0]
    return np.array([np.concatenate([np.diag(A, -d), np.zeros(d)]) for d in range(bandwidth + 1)])


def _banded_matrix(rng, n: int, bandwidth: int) -> np.ndarray:
    A = np.zeros((n, n))
    for d in range(bandwidth + 1):
        values = rng.standard_normal(n - d)
        A += np.diag(values, -d) + (np.diag(values, d) if d else 0.0)
    return A


def _relatives(H, G, N, g, rho) -> list:
    """(constraints, update, the dense pencil) of (H, G), on Nᵀc = 0, with ρggᵀ, and both."""
    Z = linalg.null_space(N)
    return [(None, None, (H, G)), (N, None, (Z.T @ H @ Z, Z.T @ G @ Z)),
            (None, (g, rho), (H + rho * np.outer(g, g), G)),
            (N, (g, rho), (Z.T @ (H + rho * np.outer(g, g)) @ Z, Z.T @ G @ Z))]


def test_banded_shift_invert_against_a_dense_generalized_eigensolve():
    rng = np.random.default_rng(3)
    n, b = 120, 5
    H = _banded_matrix(rng, n, b)
    G = _banded_matrix(rng, n, b) * 0.05 + np.eye(n) * 2.0  # positive definite
    assert np.linalg.eigvalsh(G).min() > 0.5
    N = rng.standard_normal((2, n))
    g, rho = rng.standard_normal(n), 0.7
    shifted = BandedShiftInvert.below(_band(H, b), _band(G, b), guess=0.0)
    assert shifted is not None and shifted.sigma < linalg.eigh(H, G, eigvals_only=True)[0]
    for constraints, update, (K, M) in _relatives(H, G, N, g, rho):
        dense = linalg.eigh(K, M, eigvals_only=True, subset_by_index=(0, 2))
        found = shifted.lowest(3, constraints, update)
        np.testing.assert_allclose(found, dense, rtol=0, atol=1e-10 * max(1.0, np.abs(dense).max()))


def test_band_ldlt_counts_the_negative_eigenvalues_and_solves():
    rng = np.random.default_rng(5)
    n, b = 90, 4
    A = _banded_matrix(rng, n, b)
    for shift in (-3.0, 0.0, 2.5):
        shifted = A - shift * np.eye(n)
        ldlt = BandLDLT.factor(_band(shifted, b))
        assert ldlt is not None and ldlt.negatives == int((np.linalg.eigvalsh(shifted) < 0).sum())
        r = rng.standard_normal(n)
        np.testing.assert_allclose(shifted @ ldlt.solve(r), r, atol=1e-9 * np.abs(r).max())
    # a tiny pivot (growth 1e16 against max |A_ii| = 1) and a zero one: no inertia is claimed
    assert BandLDLT.factor(_band(np.array([[1e-16, 1.0], [1.0, 1.0]]), 1)) is None
    assert BandLDLT.factor(_band(np.array([[0.0, 1.0], [1.0, 1.0]]), 1)) is None


def test_inside_shift_reads_an_isolated_lowest_eigenvalue_against_a_dense_eigensolve():
    """A pencil as the paper coil's blocks near a wire: μ₁ far below a cluster μ₂, μ₃ (a deep local well in a
    discrete Laplacian); the inside shift is found and every relative's three lowest are the dense ones."""
    rng = np.random.default_rng(1)
    n, b = 400, 6
    x = np.linspace(0.0, 1.0, n)
    H = (n * n / 50.0) * (2.0 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    H -= np.diag(300.0 * np.exp(-((x - 0.3) / 0.01) ** 2))
    G = np.eye(n) + 0.02 * (_banded_matrix(rng, n, b) - np.diag(np.diag(_banded_matrix(rng, n, b))))
    G = 0.5 * (G + G.T)
    H_band, G_band = _band(H, b), _band(G, b)
    dense = linalg.eigh(H, G, eigvals_only=True, subset_by_index=(0, 2))
    assert dense[0] < -100.0 and dense[2] - dense[1] < 2.0  # the case the inside shift is for
    shifted = BandedShiftInvert.below(H_band, G_band, float(np.min(np.diag(H) / np.diag(G))))
    estimates = shifted._below(1, None, None, 1e-9, also=2)
    inside = InsideShift.between(shifted, estimates, None, None)
    assert inside is not None and dense[0] < inside.sigma < dense[1]
    N, g, rho = rng.standard_normal((2, n)), rng.standard_normal(n), 0.7
    for constraints, update, (K, M) in _relatives(H, G, N, g, rho):
        expected = linalg.eigh(K, M, eigvals_only=True, subset_by_index=(0, 2))
        np.testing.assert_allclose(shifted.lowest(3, constraints, update), expected, rtol=0,
                                   atol=1e-10 * np.abs(expected).max())


def test_piecewise_basis_integrates_the_constant():
    for half in (False, True):
        basis = PiecewiseBasis(6, 5, 13, half=half)
        assert basis.weights.sum() == pytest.approx(2.0, abs=1e-14)
        dofs = basis.dofs((1,) if half else ())
        vertex = dofs[:, 0::2][:, [0, -1]]  # the δλ2 hats: the constant is all ones there, no bubble
        constant = basis.phi[:, :, 0] + basis.phi[:, :, -1]
        assert np.all(vertex >= 0)
        np.testing.assert_allclose(constant, 1.0, atol=1e-15)


@pytest.fixture(scope="module")
def near_wire():
    """The two-coil primary branch (M = 0.002, to wire gap 0.1) and its last point."""
    branch = trace_primary(load_scene(TWO_COILS), down=False)
    return branch, len(branch.X) - 1


@pytest.mark.parametrize("symmetric", [True, False])
def test_banded_blocks_agree_with_the_legendre_blocks_near_a_wire(near_wire, symmetric):
    """Both discretisations of every block (m = 0: the equator-symmetric ones on the half interval, or the general
    ones with the held row ∫δη dx = 0 and the volume row on the whole interval; m = 1: its reflection classes or the
    whole block, the special modes' rows removed per reading): the three lowest eigenvalues agree
    to within the Legendre blocks' own estimate |μ(N) − μ(N/1.5)| plus the elements' |μ(E, p) − μ(E, p − 2)|, and a
    rounding floor of 1e-10·max(1, |μ|)."""
    branch, n = near_wire
    eq, X = equilibrium_of(branch), branch.X[n]
    u, params = X[:-1], branch.params_at(X)
    degree = int(point_degrees(branch, branch.scene.stability.degree)[n])
    legendre = SecondVariation(eq, degree).assess(u, params, symmetric, 1).blocks
    coarse = SecondVariation(eq, int(degree / 1.5)).assess(u, params, symmetric, 1).blocks
    elements = 8 if symmetric else 16  # the half interval or the whole one: the same elements per unit of s

    def blocks(order):
        variation = BandedVariation(eq, elements, order, symmetric=symmetric)
        readings = BandedAzimuthal(variation, 1).lowest_readings(u, params, 3)
        return variation.lowest_blocks(u, params) | {"m1_held": readings[True], "m1_free": readings[False]}

    banded, lower = blocks(8), blocks(6)
    assert banded.keys() == legendre.keys()
    for name, values in legendre.items():
        tolerance = (np.abs(values - coarse[name]) + np.abs(banded[name] - lower[name])
                     + 1e-10 * np.maximum(1.0, np.abs(values)))
        assert np.all(np.abs(banded[name] - values) <= tolerance), (name, banded[name] - values, tolerance)
    assert min(v[0] for v in banded.values()) < 0.0  # a point with negative blocks: the signs are read too


@pytest.mark.parametrize("key, default", [("banded_from", 225), ("banded_flags_from", 60)])
def test_banded_keys_default_and_refusal(key, default):
    assert getattr(parse_scene('[material]\npreset = "SPOM1"\n').stability, key) == default
    assert getattr(parse_scene(f'[material]\npreset = "SPOM1"\n[stability]\n{key} = 0\n').stability, key) == 0
    with pytest.raises(SceneError) as error:
        parse_scene(f'[material]\npreset = "SPOM1"\n[stability]\n{key} = 10\n', name="s")
    message = str(error.value)
    assert "\n" not in message and f"stability.{key} = 10" in message and "[20, 400]" in message


def test_assessment_with_banded_from_reads_the_banded_blocks_and_keeps_the_flags():
    """The SPOM1 M = 0 primary branch assessed with stability.banded_from = 20 (every point's blocks, m = 0 and
    m = 1, on elements, unmapped: in x) against the default Legendre blocks: the same flags at every point, every
    eigenvalue within the Legendre blocks' estimate |μ(20) − μ(13)| plus 1e-9·max(1, |μ|)."""
    scene = load_scene(SPOM1)
    branch = trace_primary(scene, down=False)
    banded_scene = scene.with_overrides({"stability.banded_from": 20}, name=scene.name)
    banded_branch = replace(branch, scene=banded_scene)
    legendre, _ = assess_branch(branch, 20, m_max=1)
    coarse, _ = assess_branch(branch, 13, m_max=1)
    banded, _ = assess_branch(banded_branch, 20, m_max=1)
    for a, c, b in zip(legendre, coarse, banded):
        assert b.flags() == a.flags()
        assert b.blocks.keys() == a.blocks.keys()
        for name, values in a.blocks.items():
            tolerance = np.abs(values - c.blocks[name]) + 1e-9 * np.maximum(1.0, np.abs(values))
            assert np.all(np.abs(b.blocks[name] - values) <= tolerance), (name, b.blocks[name] - values, tolerance)


def test_banded_signs_against_a_dense_generalized_eigensolve():
    """``BandedSigns``: whether each relative (constraints, a positive rank-one term, both) of a banded pencil is
    positive definite, against the sign of the dense pencil's lowest eigenvalue: K positive definite (its Cholesky
    settles every relative), K with one negative eigenvalue (the inertia; the constraint Nᵀc = 0 with N = Gv₁ and
    the term ρ(Gv₁)(Gv₁)ᵀ each make it positive), K with three, and a K whose LDLᵀ meets a zero pivot (K₀₀ = 0: the
    lowest eigenvalue's sign decides)."""
    rng = np.random.default_rng(11)
    n, b = 80, 4
    H = _banded_matrix(rng, n, b)
    G = _banded_matrix(rng, n, b) * 0.05 + np.eye(n) * 2.0
    mu, vectors = linalg.eigh(H, G)
    seen = set()
    for below in (None, 1, 3):  # the number of eigenvalues shifted below zero (None: all above)
        shift = mu[0] - 1.0 if below is None else 0.5 * (mu[below - 1] + mu[below])
        K = H - shift * G
        dual = G @ vectors[:, 0]  # Gv₁: its constraint or rank-one term lifts μ₁
        noise = 0.01 * rng.standard_normal(n)
        for N, update in ((None, None), (dual[None, :], None), (None, (dual, 50.0)), ((dual + noise)[None, :], None),
                          (rng.standard_normal((2, n)), (rng.standard_normal(n), 0.3))):
            Z = np.eye(n) if N is None else linalg.null_space(N)
            M = K + (0.0 if update is None else update[1] * np.outer(update[0], update[0]))
            expected = linalg.eigh(Z.T @ M @ Z, Z.T @ G @ Z, eigvals_only=True)[0] > 0.0
            assert BandedSigns(_band(K, b), _band(G, b)).positive(N, update) == expected, (below, N, update)
            seen.add(expected)
    assert seen == {True, False}
    K = H - (0.5 * (mu[1] + mu[2])) * G
    K[0, 0] = 0.0  # a zero pivot: the LDLᵀ is refused
    assert BandLDLT.factor(_band(K, b)) is None
    assert BandedSigns(_band(K, b), _band(G, b)).positive() == (linalg.eigh(K, G, eigvals_only=True)[0] > 0.0)


@pytest.mark.parametrize("symmetric", [True, False])
def test_banded_flags_agree_with_the_legendre_flags_near_a_wire(near_wire, symmetric):
    """``SecondVariation.flags`` on the banded sibling (stability.banded_flags_from = 20: the blocks' inertia)
    against the Legendre blocks' Cholesky factorisations (banded_flags_from = 0) and against the signs of the
    banded eigenvalues (``assess``, banded_from = 20), every block m = 0 and m = 1, held and free, at the branch's
    first point and at its near-wire last point, where some flag fails."""
    branch, last = near_wire
    degree = int(point_degrees(branch, branch.scene.stability.degree)[last])
    variations = {}
    for start in (0, 20):
        scene = branch.scene.with_overrides({"stability.banded_from": start, "stability.banded_flags_from": start},
                                            name=branch.scene.name)
        variations[start] = SecondVariation(equilibrium_of(replace(branch, scene=scene)), degree)
    for n in (0, last):
        X = branch.X[n]
        u, params = X[:-1], branch.params_at(X)
        banded = variations[20].flags(u, params, symmetric, 1)
        assert banded == variations[0].flags(u, params, symmetric, 1)
        assert banded == tuple(variations[20].assess(u, params, symmetric, 1).flags().values())
    assert not all(banded)  # the last point: some flag fails there, its sign read by the inertia
