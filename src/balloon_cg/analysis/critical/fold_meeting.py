"""Meetings of a fold and a pitchfork: points of a curve of pear pitchforks where the symmetric branch has a fold.

At a point X = (u, P, φ, q) of a curve of pear pitchforks (``codim2``) the equator-symmetric branch through the
branch point, at that q, has the tangent τ = (v, μ): F_x τ = 0 with F_x = [J_u  R_P] on the symmetric layout (of
rank n there: the pear mode is not in that layout). Its fold test under the control c (``control``: P, V, n = P V)
is the rate of c along τ,

    g_c(X) = ∇c·τ,  τ normalised by τ_ref·τ = 1       μ (LP), ∇V·v (LV), P ∇V·v + V μ (LN); ∇_u V = −2π R_P

(τ_ref a unit tangent of the symmetric branch at a neighbouring curve point: the sign of g_c is then that of
dc/ds along one orientation of the branch). Where g_c changes sign between two curve points the pitchfork
crosses the fold curve of c in (q, P): a codim-2 point, the meeting of a fold (LP, LV or LN) and a pitchfork
(``MEETING_KIND``). It is located by Brent's method in the arclength of the pitchfork curve between the two
points (``continuation.locate_root``, 1e-13 in s), each evaluation a curve point corrected on the hyperplane
normal to the curve's tangent at the first point: LOCATED, or APPROXIMATE with the bracket's half-width when the
root search fell back. Pitchfork and fold are then both at that (q, P) (tests/test_fold_meeting.py: the fold
and the pitchfork located on a primary branch traced at that q). Not covered: a point where F_x itself loses rank
(an even-block branch point of the symmetric branch on the curve: codim 2 for an n × (n + 1) matrix, so met along
a curve only through a symmetry, as on the sphere); τ would turn over there and every g_c change sign. Such a point
is found from the fold curve's side instead (``fold_crossing``).
"""
from dataclasses import dataclass

import numpy as np

from ...numerics import continuation
from ...scene import Control
from ..branches.control import FOLD_KIND, control_gradient_at
from ..results import Kind, SpecialPoint, located_or_bracketed

MEETING_KIND = {Control.PRESSURE: Kind.LP_BP, Control.VOLUME: Kind.LV_BP, Control.GAS: Kind.LN_BP}


def tangent_matrix(system, X) -> np.ndarray:
    """F_x = [J_u  R_P] of the symmetric branch at the point X = (u, P, φ, q) of the extended pitchfork
    ``system``."""
    u, P, _, q = system.split(X)
    return system.eq.bordered_jacobian(u, system.set_q(q).with_value("P", P), "P")


def symmetric_tangent(F, reference=None) -> np.ndarray:
    """τ with F τ = 0: the unit null vector of F (its smallest right singular vector) without ``reference``, else
    normalised by reference·τ = 1."""
    if reference is None:
        return np.linalg.svd(F)[2][-1]
    return np.linalg.solve(np.vstack([F, reference]), np.append(np.zeros(F.shape[0]), 1.0))


def oriented_tangents(system, X) -> np.ndarray:
    """Unit tangents τ of the symmetric branch at the curve points X, each oriented along the previous one."""
    out = []
    for x in X:
        tau = symmetric_tangent(tangent_matrix(system, x), out[-1] if out else None)
        out.append(tau / np.linalg.norm(tau))
    return np.array(out)


@dataclass(frozen=True)
class FoldTest:
    """g_c of the module docstring on an extended pitchfork system (``codim2.ExtendedSystem``)."""

    system: object
    control: Control

    def __call__(self, X, tau) -> float:
        """g_c = ∇c·τ at the curve point X."""
        u, P, _, q = self.system.split(X)
        return float(control_gradient_at(self.system.eq, u, self.system.set_q(q).with_value("P", P), self.control)
                     @ tau)


def fold_meetings(system, points: list, disc, settings: continuation.Settings, block) -> list[SpecialPoint]:
    """The meetings of a fold (LP, LV, LN) and the pitchfork along the traced curve ``points``
    (continuation.Point: X and the curve's tangent) of the extended ``system``, each located between the two
    curve points where its g_c changes sign (module docstring); SpecialPoints of kind ``MEETING_KIND`` with X
    on the curve's layout (u, P, φ, q), in order along the curve."""
    X = np.array([p.X for p in points])
    tangents = oriented_tangents(system, X)
    found = []
    for control in MEETING_KIND:
        test = FoldTest(system, control)
        g = np.array([test(x, tau) for x, tau in zip(X, tangents)])
        for i in np.flatnonzero(g[:-1] * g[1:] < 0):
            found.append(_locate(test, i, points[i], points[i + 1], tangents[i], disc, settings, block))
    return sorted(found, key=lambda s: (s.index, s.X[-1]))


def _locate(test: FoldTest, index: int, start, end, reference, disc, settings, block) -> SpecialPoint:
    """The meeting between the curve points ``start`` and ``end``, points ``index`` and ``index`` + 1 (Brent in
    the arclength, module docstring)."""
    sigma = float(start.tangent @ (end.X - start.X))

    def value(X):
        return test(X, symmetric_tangent(tangent_matrix(test.system, X), reference))

    def value_at(s):
        result = continuation.correct(test.system, start.X + s * start.tangent, start.tangent, settings)
        if not result.converged:
            raise ArithmeticError(result.message)
        return value(result.x), result.x

    known = {s: (value(x), x) for s, x in ((0.0, start.X), (sigma, end.X))}
    root = continuation.locate_root(value_at, sigma, known=known)
    n = test.system.n
    before, after = (np.append(x[:n], x[n]) for x in (start.X, end.X))
    fold = FOLD_KIND[test.control].value
    status = located_or_bracketed(root.status, disc, before, after, f"meeting of the {fold} and the pitchfork")
    return SpecialPoint(MEETING_KIND[test.control], index, root.payload, block=block, **status,
                        note=f"the symmetric branch through the pitchfork has its {fold} here: the {fold} curve "
                             f"meets the pitchfork curve")
