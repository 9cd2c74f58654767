"""Branch switching at a pear branch point: the bifurcating branch and its mirror image.

From u* + δφ (φ the critical mode, ±), corrected on the hyperplane normal to φ, then pseudo-arclength in the
general (non-symmetric) space of the branch point's reading (``bifurcation.general_tracer``: the balloon held, or
free at an odd_free point, where the translation b_0 is an unknown and the net axial force vanishes), until it rejoins the primary
branch (the amplitude φ·(u − u*) changes sign: a closed loop, the isola, when that happens at another branch
point) or a stop rule applies (those of the primary branch, and the south pole stretch reaching stop_stretch); it ends
exactly on stop_stretch (north or south), or on continuation.stop_volume or loading.stop_amount, when it stops there.

The rejoin is an extremum of P, not a fold: near a pitchfork P = P* + c A² + O(A⁴) on the pear branch (P is
even in the pear amplitude A), so dP/ds vanishes where the branch crosses the primary branch and the fold
search sees a sign change there, which it cannot locate as a regular fold (the corrector is singular at the
branch point). A fold candidate of a branch that rejoined at a branch point is that branch point
(``rejoin_fold``) when the amplitude A = λ2(0) − λ2(π) changes sign (or vanishes) across its bracket and the
branch point lies within the bracket's width of it; ``mark_rejoin`` stores the branch point there in its place.
"""
import enum
import time
from dataclasses import replace

import numpy as np

from ...numerics import continuation
from ...numerics.continuation import Stop
from ...numerics.newton import newton
from ..branches.assembly import assemble
from ..points.branch_points import general_tracer, mode_direction, plain_degree, to_general
from ..branches.control import landing
from ..branches.events import with_events
from ..branches.primary import stop_rule
from ..results import Branch, Kind, SpecialPoint, StopCode
from ..branches.tracer import TOP_TURNING
from ...numerics.threads import limited_blas


class Turn(enum.StrEnum):
    """A fold label of a pear trace that is no ``Kind``: the turning point of the south pole stretch, located when
    ``trace_pear`` is asked for ``bottom_turns`` (the mirror image's TP: ``mirror``); never stored as such."""

    BOTTOM = "TP_bottom"


@limited_blas
def trace_pear(branch: Branch, bp: SpecialPoint, sign: float, name: str, progress=None,
               delta: float = 1e-3, bottom_turns: bool = False) -> Branch | None:
    """The bifurcating branch leaving ``bp`` along sign·φ until it rejoins or stops; None if the first
    correction fails. ``bottom_turns``: its special points include the turning points of the south pole stretch
    too, labelled ``Turn.BOTTOM`` (located as TP is for the north pole)."""
    t0 = time.perf_counter()
    traced = pear_leg(branch, bp, sign, progress, delta, bottom_turns)
    if traced is None:
        return None
    tracer, leg = traced
    return with_events(assemble(tracer, branch.params, name, leg, t0=t0, land_on=pear_landing(branch.scene)))


def pear_leg(branch: Branch, bp: SpecialPoint, sign: float, progress=None, delta: float = 1e-3,
             bottom_turns: bool = False, until=None):
    """(tracer, LegTrace) of the pear branch leaving ``bp`` along sign·φ (``trace_pear`` before its assembly), None
    if the first correction fails. ``until(disc, point)``: a stop rule asked after the pear branch's own."""
    scene = branch.scene
    tracer = general_tracer(scene, bp.block)
    degree = plain_degree(branch, bp.X)
    params = branch.params
    system = tracer.system(degree, params)
    X_star = np.append(to_general(branch, tracer, degree, bp.X[:-1]), bp.X[-1])
    phi = sign * mode_direction(bp, system.eq.disc)
    guess = X_star + delta * phi
    result = newton(system.residual, system.jacobian, guess, phi, phi @ guess, scene.solver.tol,
                    scene.solver.max_newton)
    if not result.converged:
        return None
    start = continuation.Point(result.x, continuation.tangent(system, result.x, phi), result.iterations,
                               result.residual)
    base = pear_stop_rule(scene)
    anchors = {}

    def stop(disc, point):
        if disc not in anchors:
            coarse = system.eq.disc
            anchors[disc] = (coarse.transfer(phi, disc), coarse.transfer(X_star, disc))
        direction, star = anchors[disc]
        if direction @ (point.X - star) < 0:
            return Stop(StopCode.REJOINED, "rejoined the primary branch")
        return base(disc, point) or (until(disc, point) if until is not None else None)

    turning = TOP_TURNING | ({Turn.BOTTOM: "lam2_bottom"} if bottom_turns else {})
    return tracer, tracer.leg(start, params, stop, progress, degree=degree, turning=turning)


def bottom_stop_stretch(upper: float) -> Stop:
    """The stop of a pear branch whose south pole stretch reached ``upper`` (continuation.stop_stretch)."""
    return Stop(StopCode.BOTTOM_STOP_STRETCH, f"south pole stretch reached stop_stretch {upper:g}")


def pear_stop_rule(scene):
    """stop(disc, point) -> Stop or None of a pear branch (no equator symmetry, either pole may grow): its south
    pole stretch reaches continuation.stop_stretch (``bottom_stop_stretch``), or the primary branch's rule
    (``primary.stop_rule``: the north pole's range, the wires, the control's stops)."""
    stretch = scene.continuation.stop_stretch
    base = stop_rule(scene, stretch)

    def stop(disc, point):
        south = float(disc.pole_rows()["lam2_bottom"] @ point.X[:-1])
        return bottom_stop_stretch(stretch) if south >= stretch else base(disc, point)

    return stop


def pear_landing(scene) -> dict:
    """``assembly.assemble``'s land_on of a pear branch: either pole stretch at stop_stretch, the north pole at
    min_stretch, and the control stop (``control.landing``)."""
    stretch = scene.continuation.stop_stretch
    return {StopCode.STOP_STRETCH: ("lam2_top", stretch), StopCode.BOTTOM_STOP_STRETCH: ("lam2_bottom", stretch),
            StopCode.MIN_STRETCH: ("lam2_top", scene.continuation.min_stretch)} | landing(scene)


def rejoin_fold(branch: Branch, fold: SpecialPoint, bp_X) -> bool:
    """Whether the fold candidate ``fold`` of ``branch`` is its rejoin at the branch point X = ``bp_X`` (on
    ``branch.disc``): the pear amplitude λ2(0) − λ2(π) changes sign or vanishes between the bracketing points,
    and the branch point is within the bracket's max-norm width in (P, λ2(0), λ2(π)) of the nearer of them
    (module docstring)."""
    i = fold.index
    if fold.kind != Kind.LP or i + 1 >= len(branch.X):
        return False
    poles = branch.pole_values(branch.X[i:i + 2])
    amplitude = poles["lam2_top"] - poles["lam2_bottom"]
    if amplitude[0] * amplitude[1] > 0:
        return False
    at = branch.pole_values(bp_X)
    point = np.array([bp_X[-1], at["lam2_top"][0], at["lam2_bottom"][0]])
    ends = np.stack([branch.X[i:i + 2, -1], poles["lam2_top"], poles["lam2_bottom"]], axis=1)
    return float(np.abs(ends - point).max(axis=1).min()) <= float(np.abs(ends[1] - ends[0]).max())


def mark_rejoin(branch: Branch, primary: Branch, bp: SpecialPoint) -> None:
    """Replace each fold candidate of ``branch`` that is its rejoin at the primary branch's branch point ``bp``
    (``rejoin_fold``) by that branch point on the branch's basis (its location status,
    classification and mode; ``index`` the fold's interval)."""
    X = primary.disc.transfer(bp.X, branch.disc)
    branch.special = [replace(bp, index=s.index, X=X, note="the rejoin on the primary branch (P is even in the pear "
                                                           "amplitude there)")
                      if rejoin_fold(branch, s, X) else s for s in branch.special]
