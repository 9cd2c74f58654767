"""Newton with Jacobian reuse (simplified Newton): converges to the root within the tolerance, factors the
Jacobian only when the corrections stop contracting fast, reports failures instead of returning garbage, and ends
at the rounding floor (AT_ROUNDING, with the accuracy attained) only where the caller accepts that accuracy."""
import mpmath
import numpy as np
import pytest
from scipy.linalg.lapack import dgetrf, dgetrs

from balloon_cg.numerics.newton import EPSILON, SMALL_SOLVE, Convergence, _correction, newton, rounding_floor


def circle_and_line():
    """x² + y² = 4 with the bordering row x − y = 0: root (√2, √2)."""
    calls = {"jacobian": 0}

    def residual(z):
        return np.array([z[0] ** 2 + z[1] ** 2 - 4.0])

    def jacobian(z):
        calls["jacobian"] += 1
        return np.array([[2 * z[0], 2 * z[1]]])

    return residual, jacobian, np.array([[1.0, -1.0]]), calls


@pytest.mark.parametrize("start", [(1.5, 1.5), (1.0, 1.0), (3.0, 3.0)])
def test_converges_to_root_within_tolerance(start):
    residual, jacobian, rows, calls = circle_and_line()
    result = newton(residual, jacobian, start, rows, 0.0, 1e-12, 50)
    assert result.converged and result.message == "converged"
    assert np.abs(result.x - np.sqrt(2.0)).max() < 1e-12
    assert result.residual < 1e-12
    assert result.jacobians == calls["jacobian"] <= result.iterations


def test_good_start_factors_once():
    """From 1e-3 of the root one Jacobian serves every correction (chord contraction ~1e-3 < REFRESH_RATIO)."""
    residual, jacobian, rows, _ = circle_and_line()
    result = newton(residual, jacobian, (np.sqrt(2.0) + 1e-3,) * 2, rows, 0.0, 1e-13, 50)
    assert result.converged and result.jacobians == 1 and result.iterations >= 3


def test_poor_start_refreshes_the_jacobian():
    """From far away the chord steps contract slower than REFRESH_RATIO: the Jacobian is refreshed."""
    residual, jacobian, rows, _ = circle_and_line()
    result = newton(residual, jacobian, (10.0, 10.0), rows, 0.0, 1e-13, 50)
    assert result.converged and result.jacobians >= 3


def test_a_neighbour_s_factors_start_the_chord():
    """Given the factors of a solve at a neighbouring point with the same rows, a solve nearby needs no Jacobian of
    its own and lands on the same root as with a fresh one; factors from far away (a poor chord) are refreshed."""
    residual, jacobian, _, calls = circle_and_line()
    rows = np.array([[1.0, 0.0]])  # x = target: the root (target, √(4 − target²))
    neighbour = newton(residual, jacobian, (1.0, 1.732), rows, 1.0, 1e-13, 50)  # factored at ~its root
    assert neighbour.converged and neighbour.factors is not None
    fresh = newton(residual, jacobian, (1.001, 1.7), rows, 1.001, 1e-13, 50)
    calls["jacobian"] = 0
    chord = newton(residual, jacobian, (1.001, 1.7), rows, 1.001, 1e-13, 50, neighbour.factors)
    assert chord.converged and chord.jacobians == calls["jacobian"] == 0
    assert abs(chord.x[1] - np.sqrt(4.0 - 1.001**2)) < 1e-13 and np.abs(chord.x - fresh.x).max() < 1e-13
    far = newton(residual, jacobian, (1.9, 1.7), rows, 1.9, 1e-13, 50, neighbour.factors)
    assert far.converged and far.jacobians >= 1 and abs(far.x[1] - np.sqrt(4.0 - 1.9**2)) < 1e-13


def test_double_root_converges_linearly_and_error_estimate_holds():
    """x² = 0: Newton halves the error each step (ρ = 1/2); the stop must account for ρ/(1 − ρ)|dx| = |dx|."""
    result = newton(lambda z: np.array([z[0] ** 2]), lambda z: np.array([[2 * z[0], 0.0]]), (1.0, 0.0),
                    np.array([[0.0, 1.0]]), 0.0, 1e-6, 200)
    assert result.converged
    assert abs(result.x[0]) <= 2e-6  # the true error, not only the last correction, is near the tolerance


def test_iteration_bound_reports_failure():
    result = newton(lambda z: np.array([z[0] ** 2 + 1.0]), lambda z: np.array([[2 * z[0], 0.0]]), (1.0, 0.0),
                    np.array([[0.0, 1.0]]), 0.0, 1e-12, 30)
    assert not result.converged and result.iterations <= 30 and result.message


def test_singular_matrix_and_domain_errors_are_reported():
    singular = newton(lambda z: np.array([z[0] - 1.0]), lambda z: np.array([[0.0, 0.0]]), (0.0, 0.0),
                      np.array([[0.0, 1.0]]), 0.0, 1e-12, 10)
    assert not singular.converged and "singular" in singular.message

    def leaves(z):
        raise ArithmeticError("stretch ≤ 0")

    left = newton(leaves, lambda z: np.eye(1, 2), (0.0, 0.0), np.array([[0.0, 1.0]]), 0.0, 1e-12, 10)
    assert not left.converged and "left the domain" in left.message


def test_non_finite_residual_at_the_end_is_not_convergence():
    calls = {"n": 0}

    def residual(z):
        calls["n"] += 1
        return np.array([z[0] - 1.0]) if calls["n"] < 3 else np.array([np.nan])

    result = newton(residual, lambda z: np.array([[1.0, 0.0]]), (0.0, 0.0), np.array([[0.0, 1.0]]), 0.0, 1e-12, 10)
    assert not result.converged and "non-finite" in result.message


@pytest.mark.parametrize("size", [2, 9, 30, SMALL_SOLVE - 1])
def test_jitted_correction_is_the_lapack_solve(size):
    """Below SMALL_SOLVE unknowns the correction comes from _correction's substitutions on dgetrf's factors: against
    scipy's dgetrs on the same factors (a matrix whose rows need interchanging) and the scaled size."""
    rng = np.random.default_rng(size)
    A = rng.normal(size=(size, size)) + np.diag(np.full(size, 0.1))
    A = A[rng.permutation(size)]
    k = 1  # one bordering row
    r, rows, targets, x = rng.normal(size=size - k), A[size - k:], rng.normal(size=k), rng.normal(size=size)
    lu, pivots, info = dgetrf(np.asfortranarray(A))
    assert info == 0 and (pivots != np.arange(size)).any()
    expected, _ = dgetrs(lu, pivots, np.concatenate([-r, targets - rows @ x]))
    dx = np.empty(size)
    step = _correction(lu, pivots, r, rows, targets, x, dx)
    assert np.abs(dx - expected).max() <= 1e-12 * np.abs(expected).max()
    assert step == pytest.approx(np.max(np.abs(dx) / (1.0 + np.abs(x))), rel=1e-15)


def ill_conditioned(condition: float, size: int = 12):
    """A linear system R(x) = A[:-1] x − b[:-1], bordering row A[-1]·x = b[-1], A = U diag(σ) Vᵀ with σ from 1 to
    1/condition, and x of mixed sizes (10⁻² … 10³: the scaled norm matters); its exact solution from the stored
    floats by mpmath at 40 digits."""
    rng = np.random.default_rng(7)
    U, _ = np.linalg.qr(rng.normal(size=(size, size)))
    V, _ = np.linalg.qr(rng.normal(size=(size, size)))
    A = U @ np.diag(np.logspace(0, -np.log10(condition), size)) @ V.T
    x_true = rng.choice([-1.0, 1.0], size) * 10.0 ** rng.uniform(-2, 3, size)
    b = A @ x_true
    with mpmath.workdps(40):
        exact = np.array(mpmath.lu_solve(mpmath.matrix(A.tolist()), mpmath.matrix(b.tolist())).tolist(),
                         dtype=float).ravel()
    return (lambda x: A[:-1] @ x - b[:-1]), (lambda x: A[:-1]), A, b, exact


def test_ill_conditioned_system_ends_at_the_rounding_floor():
    """κ∞(A D) ~ 1e10 with tol 1e-14 far below ε·κ: the corrections stagnate at the rounding level. With a limit
    above it the solve ends AT_ROUNDING, its attained accuracy (``step``) above tol and below ε·κ∞(A D), and the
    true scaled error against the 40-digit solution below ε·κ∞(A D) too; without a limit the same solve fails (as
    before the rule: never a silent success)."""
    residual, jacobian, A, b, exact = ill_conditioned(1e8)
    start = exact * (1 + 1e-3)
    result = newton(residual, jacobian, start, A[-1:], b[-1:], 1e-14, 60, rounding_limit=1e-3)
    assert result.outcome == Convergence.AT_ROUNDING and result.converged
    assert "rounding floor" in result.message
    floor = rounding_floor(dgetrf(np.asfortranarray(A))[0], result.x)
    assert 1e-14 < result.step <= floor
    error = np.abs(result.x - exact) / (1 + np.abs(exact))
    assert error.max() <= floor
    failed = newton(residual, jacobian, start, A[-1:], b[-1:], 1e-14, 60)
    assert failed.outcome == Convergence.FAILED and not failed.converged


def test_rounding_limit_below_the_attained_accuracy_is_ill_conditioned():
    """The caller's limit decides: a stagnation above ``rounding_limit`` is ILL_CONDITIONED, not a solution."""
    residual, jacobian, A, b, exact = ill_conditioned(1e8)
    accepted = newton(residual, jacobian, exact * (1 + 1e-3), A[-1:], b[-1:], 1e-14, 60, rounding_limit=1e-3)
    limited = newton(residual, jacobian, exact * (1 + 1e-3), A[-1:], b[-1:], 1e-14, 60,
                     rounding_limit=accepted.step / 10)
    assert limited.outcome == Convergence.ILL_CONDITIONED and not limited.converged
    assert limited.step > accepted.step / 10 and "rounding floor" in limited.message


def test_rounding_floor_is_epsilon_times_the_scaled_condition():
    """``rounding_floor`` (dgecon's estimate on the column-scaled factors) against ε·κ∞(A D) from the explicit
    inverse: dgecon's estimate of ‖(A D)⁻¹‖ is a lower bound, in practice within a factor 3."""
    _, _, A, _, exact = ill_conditioned(1e6)
    AD = A * (1 + np.abs(exact))
    direct = EPSILON * np.linalg.cond(AD, np.inf)
    assert direct / 3 <= rounding_floor(dgetrf(np.asfortranarray(A))[0], exact) <= direct * (1 + 1e-10)


def test_well_conditioned_and_linear_convergence_are_unchanged_by_a_limit():
    """Where Newton reaches tol (a regular root; the double root's linear convergence, ρ = 1/2 < 1) a rounding
    limit changes nothing: the same iterates, CONVERGED."""
    residual, jacobian, rows, _ = circle_and_line()
    plain = newton(residual, jacobian, (3.0, 3.0), rows, 0.0, 1e-13, 50)
    limited = newton(residual, jacobian, (3.0, 3.0), rows, 0.0, 1e-13, 50, rounding_limit=1e-3)
    assert limited.outcome == plain.outcome == Convergence.CONVERGED and np.array_equal(limited.x, plain.x)
    double = newton(lambda z: np.array([z[0] ** 2]), lambda z: np.array([[2 * z[0], 0.0]]), (1.0, 0.0),
                    np.array([[0.0, 1.0]]), 0.0, 1e-6, 200, rounding_limit=1e-3)
    assert double.outcome == Convergence.CONVERGED and abs(double.x[0]) <= 2e-6
