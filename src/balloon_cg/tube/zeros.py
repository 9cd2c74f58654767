"""Where an eigenvalue of a tube's block vanishes between two points of a trace, and whether that zero is a fold.

Brent in the arclength s ∈ (0, length] along a direction d from a point X₀ of the trace, each value the eigenvalue
at the Keller corrector of the predictor X₀ + s d (``corrected_zero``: tube/primary's branch points in P,
tube/voltage's in Φ̄, tube/azimuthal_crossings' m ≥ 1 zeros). A zero of the branch's own block is the fold in the
continuation parameter q, not a branch point, where its null vector φ is not orthogonal to ∂R/∂q
(|φ·∂R/∂q| > ORTHOGONAL·|φ||∂R/∂q|: ``is_fold``).
"""
from dataclasses import replace

import numpy as np
from scipy import linalg

from ..numerics import continuation
from ..numerics.newton import Convergence, newton

ORTHOGONAL = 1e-6  # |φ·∂R/∂q| relative to |φ||∂R/∂q| below which a block's zero is a branch point, not the fold
BRENT_XTOL = 1e-13  # Brent's tolerance in the arclength, relative to the step


def corrected_zero(system, settings, origin: np.ndarray, direction: np.ndarray, length: float, eigenvalue,
                   known: dict | None = None, fallback=None):
    """``continuation.locate_root`` of eigenvalue(Y) (Y = system.full(X)) at the Keller correctors of
    origin + s·direction, s ∈ (0, length] (``known``: s -> (value, Y) already evaluated); ``fallback(predictor)``
    a second corrector tried where Keller's fails; a corrector that fails ends the search (``locate_root``)."""
    def value_at(s):
        predictor = origin + s * direction
        result = continuation.correct(system, predictor, direction, settings)
        if not result.converged and fallback is not None:
            result = fallback(predictor)
        if not result.converged:
            raise ArithmeticError(result.message)
        Y = system.full(result.x)
        return eigenvalue(Y), Y

    return continuation.locate_root(value_at, length, BRENT_XTOL, known=known)


def is_fold(eq, u: np.ndarray, params, dq: np.ndarray, index: np.ndarray, order: int) -> bool:
    """Whether the zero eigenvalue number ``order`` of the block ``index`` at the state u (``params`` at it) is the
    fold in the continuation parameter q, ``dq`` = ∂R/∂q there (module docstring)."""
    phi = np.linalg.eigh(eq.jacobian(u, params)[np.ix_(index, index)])[1][:, order]
    return abs(phi @ dq[index]) > ORTHOGONAL * np.linalg.norm(dq)


def off_mode_corrector(system, predictor: np.ndarray, tangent: np.ndarray, mode: np.ndarray, settings):
    """Keller's corrector with the direction ``mode`` (X-coordinates; the crossing eigenvalue's vector of the branch's
    own block) held at the predictor's component: near a branch point that breaks a symmetry the branch keeps (the
    uniform tube's modes cos(nπS/L), n even, in the even block) the branch's states have no component along it, and
    Keller's system, singular at the branch point, lets rounding grow along it. Solved: Qᵀ R(X) = 0 (Q an orthonormal
    basis of the residual rows orthogonal to the mode: its own row, zero on the branch by the symmetry, dropped),
    tangent·X and mode·X at the predictor's; not converged where the dropped row is not zero there (the branch does
    move along the mode: no symmetry)."""
    Q = linalg.null_space(mode[None, :-1])
    result = newton(lambda X: Q.T @ system.residual(X), lambda X: Q.T @ system.jacobian(X), predictor,
                    np.vstack([tangent, mode]), [tangent @ predictor, mode @ predictor], settings.tol,
                    settings.max_newton)
    dropped = abs(mode[:-1] @ system.residual(result.x)) if result.converged else np.inf
    if dropped > settings.tol:
        return replace(result, outcome=Convergence.FAILED,
                       message=f"{result.message}; off the mode: the residual along it is {dropped:.3g}")
    return result
