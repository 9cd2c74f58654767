"""Crossings of a fold curve and a branch point: points of a fold curve where the branch itself branches.

At a point X = (u, P, w, q) of a fold curve (``fold_curve``) the branch tangent w spans the null space of
F_x = [J_u  R_P]. Where F_x loses rank a second null vector joins it: the branch has a branch point at its fold (on
the sphere the LN fold meets the n = 4 bifurcation), a codim-2 point met along a curve only through a symmetry (an
n × (n + 1) matrix loses rank in codim 2: ``fold_meeting``'s "not covered" case, here found from the fold curve).
The bordered matrix M = [F_x; ŵᵀ] (ŵ = w/|w|) is singular exactly there (a z ≠ 0 with F_x z = 0, ŵ·z = 0 is that
second null vector), so the test

    g(X) = sign(det M) · σ_min(M)            (σ_min: the smallest singular value)

is continuous along the curve (w is, normalised by ℓ·w = 1) and changes sign where the curve passes a branch point.

Location. The fold system is singular at the crossing (its Jacobian's smallest singular value falls like the
square of the distance), so its corrector reaches tol only some way off it: within it Newton stagnates above
solver.max_error (ILL_CONDITIONED) and the trace steps across (``pitchfork_curve.curve_settings``). The crossing
is bracketed by bisection in the arclength between the two curve points where g changes sign, each evaluation a
curve point corrected on the hyperplane normal to the curve's tangent at the first point; where the midpoint's
corrector fails the quarter points are tried, and the bisection ends when all three fail. LOCATED when the bracket
reaches 1e-13 in s; else APPROXIMATE with the bracket's half-width (in P and λ2(0)), the end with the smaller |g|
stored. Stored as the meeting of that fold and a branch point (``MEETING_KIND``: LP-BP, LV-BP, LN-BP; block
``even`` on the equator-symmetric layout).
"""
import numpy as np

from ...numerics import continuation
from ..branches.control import FOLD_KIND
from ..results import Block, SpecialPoint, Status, approximate
from .fold_meeting import MEETING_KIND

XTOL = 1e-13  # the bracket's width in the arclength, relative to max(1, σ), that makes a crossing LOCATED


def crossing_test(system, X) -> float:
    """g(X) = sign(det M) σ_min(M), M = [F_x; ŵᵀ], at the fold-curve point X of ``system`` (module docstring)."""
    u, P, w, q = system.split(X)
    M = np.vstack([system.tangent_matrix(u, system.at(P, q)), w / np.linalg.norm(w)])
    return float(np.linalg.slogdet(M)[0] * np.linalg.svd(M, compute_uv=False)[-1])


def fold_crossings(system, points: list, disc, settings: continuation.Settings) -> list[SpecialPoint]:
    """The branch points the traced fold curve ``points`` (continuation.Point) of the fold ``system`` passes, each
    bracketed between the two curve points where ``crossing_test`` changes sign (module docstring): SpecialPoints
    of kind ``MEETING_KIND[system.control]`` with X on the curve's layout (u, P, w, q), in order along the
    curve."""
    g = [crossing_test(system, p.X) for p in points]
    fold, n = FOLD_KIND[system.control].value, system.n
    found = []
    for i in np.flatnonzero(np.array(g[:-1]) * np.array(g[1:]) < 0):
        low, high, narrowed = _bracket(system, points[i], (0.0, g[i], points[i].X),
                                       (float(points[i].tangent @ (points[i + 1].X - points[i].X)), g[i + 1],
                                        points[i + 1].X), settings)
        X = min(low, high, key=lambda end: abs(end[1]))[2]
        before, after = (np.append(end[2][:n], end[2][n]) for end in (low, high))
        status = {"status": Status.LOCATED} if narrowed else approximate(
            disc, before, after, f"crossing of the {fold} and a branch point: the fold system's corrector fails "
                                 "nearer to it; the bracket's end with the smaller test value is stored")
        found.append(SpecialPoint(MEETING_KIND[system.control], int(i), X, **status,
                                  block=Block.EVEN if disc.symmetric else Block.NONE,
                                  note=f"the branch has a branch point at its {fold} here: F_x = [J_u  R_P] loses "
                                       f"rank, the {fold} curve crosses a curve of branch points"))
    return found


def _bracket(system, start, low: tuple, high: tuple, settings: continuation.Settings) -> tuple:
    """(low, high, narrowed): the ends (s, g, X) of the narrowest sign change of g found by bisection in the
    arclength s along ``start``'s tangent from (``low``, ``high``), skipping failed correctors (module
    docstring); ``narrowed``: the bracket reached XTOL."""
    def value_at(s):
        result = continuation.correct(system, start.X + s * start.tangent, start.tangent, settings)
        if not result.converged:
            return None
        try:
            return s, crossing_test(system, result.x), result.x
        except ArithmeticError:  # a state whose test is not finite (NonFiniteState): skipped as a failed corrector
            return None

    xtol = XTOL * max(1.0, high[0])
    while high[0] - low[0] > xtol:
        width = high[0] - low[0]
        middle = next(filter(None, (value_at(low[0] + fraction * width) for fraction in (0.5, 0.25, 0.75))), None)
        if middle is None:
            return low, high, False
        if middle[1] * low[1] > 0:
            low = middle
        else:
            high = middle
    return low, high, True
