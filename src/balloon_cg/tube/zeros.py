"""Where an eigenvalue of a tube's block vanishes between two points of a trace, and whether that zero is a fold.

Brent in the arclength s ∈ (0, length] along a direction d from a point X₀ of the trace, each value the eigenvalue
at the Keller corrector of the predictor X₀ + s d (``corrected_zero``: tube/primary's branch points in P,
tube/voltage's in Φ̄, tube/azimuthal_crossings' m ≥ 1 zeros). A zero of the branch's own block is the fold in the
continuation parameter q, not a branch point, where its null vector φ is not orthogonal to ∂R/∂q
(|φ·∂R/∂q| > ORTHOGONAL·|φ||∂R/∂q|: ``is_fold``).
"""
import numpy as np

from ..numerics import continuation

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
