"""One Branch from the legs of a trace: the storage basis, the points moved onto it, exact end points.

Points are stored on the finest discretisation used (the last one of the most refined leg: its map is the
latest), its degree raised by the resolution policy while the projection would lose more than the policy's
loss limit of any point and raising it helps. A point's stored error estimate adds its measured projection
loss. A leg that stopped on passing a pole stretch given in ``land_on`` (STOP_STRETCH, MIN_STRETCH,
BOTTOM_STOP_STRETCH) gets its exact end point there (Newton on the pole row r·X = target from the linear
interpolant; on the leg's own last basis, then moved, where the storage basis does not resolve it); one that stopped on a value of the control parameter q (STOP_VOLUME, STOP_AMOUNT: q = V or n,
nonlinear in X) lands by Newton on the linearised constraint ∇q(X_k)·(X − X_k) = target − q(X_k), repeated
until |q − target| ≤ LANDING_RTOL·max(1, |target|); a fold found between the last point and the overshoot is
kept only if it lies before that end. One that stopped on a value of a continuation parameter that has a
range (STOP_FIELD, ZERO_FIELD: M in [0, stop_field]) lands on its row X[-1] = target (``PARAMETER``).
"""
import time

import numpy as np

from ...numerics import continuation
from ...numerics.continuation import Stop
from ...numerics.newton import newton
from ...scene import Control
from .control import control_gradient, control_value
from .graded import covering_basis
from .resolution import transfer_error
from ..results import Branch, Kind, Leg, SpecialPoint, StopCode, located_or_bracketed
from .tracer import ContinuationError, LegTrace


def _moved(legs: list[LegTrace], target) -> dict:
    """Per path with points (by id): its points transferred to ``target`` and their projection losses."""
    out = {}
    for leg in legs:
        for coarse, path in leg.segments:
            if path.points:
                own = np.array([p.X for p in path.points])
                moved = coarse.transfer(own, target)
                out[id(path)] = moved, transfer_error(coarse, own, target, moved)
    return out


def _worst(moves: dict) -> float:
    return max(loss.max() for _, loss in moves.values())


def storage_basis(tracer, params, legs: list[LegTrace]):
    """(discretisation, moves) for storing ``legs``: the finest one used, raised while that lowers the worst
    projection loss below the policy's limit (a narrow final map may not hold the early points); on graded bases
    the one covering them all (``graded.covering_basis``: no loss)."""
    policy = tracer.resolution
    used = [d for leg in legs for d, _ in leg.segments]
    if any(d.element_degrees for d in used):  # graded: the basis holding them all, each point moved exactly
        disc = covering_basis(used)
        return disc, _moved(legs, disc)
    disc = [d for d in used if d.degree == max(u.degree for u in used)][-1]
    moves = _moved(legs, disc)
    while _worst(moves) > policy.loss_limit and disc.degree < policy.max_degree:
        finer = tracer.system(policy.grow(disc.degree), params, disc.mapping).eq.disc
        finer_moves = _moved(legs, finer)
        if _worst(finer_moves) >= _worst(moves):
            break
        disc, moves = finer, finer_moves
    return disc, moves


def _collect(leg: LegTrace, disc, moves):
    """Points (X on disc, continuation point, solved degree, error estimate + loss) and folds (kind, index, X,
    status fields) of one leg, in order."""
    points, folds = [], []
    for coarse, path in leg.segments:
        if not path.points:
            continue
        base = len(points)
        moved, loss = moves[id(path)]
        for p, X, lost in zip(path.points, moved, loss):
            points.append((X, p, coarse.degree, coarse.tail(p.X[:-1]) + lost))
        for f in path.folds:
            found = located_or_bracketed(f.status, coarse, *path.bracket(f), f"fold {f.label.value}")
            folds.append((f.label, base + f.index, coarse.transfer(f.point.X, disc), found))
    return points, folds


LANDING_RTOL = 1e-12
LANDING_ROUNDS = 8


PARAMETER = "parameter"  # a landing target: the continuation parameter itself, X[-1]


def quantity_of(system, name):
    """(q, ∇q) of a landing target: the pole row ``name`` (linear), the control parameter of a Control, or the
    continuation parameter (``PARAMETER``)."""
    if isinstance(name, Control):
        return ((lambda X: control_value(system.eq.disc, X, name, system.eq.scene.geometry)),
                (lambda X: control_gradient(system, X, name)))
    if name == PARAMETER:
        row = np.zeros(system.eq.disc.size + 1)
        row[-1] = 1.0
        return (lambda X: float(X[-1])), (lambda X: row)
    row = np.append(system.eq.disc.pole_rows()[name], 0.0)
    return (lambda X: float(row @ X)), (lambda X: row)


def land(system, before, after, quantity, target, settings):
    """The point with q(X) = target between two branch points (Newton from the linear interpolant, on the
    linearised constraint while q is not met: module docstring)."""
    q, gradient = quantity
    f0, f1 = q(before), q(after)
    X = before + (target - f0) / (f1 - f0) * (after - before)
    for _ in range(LANDING_ROUNDS):
        row = gradient(X)
        result = newton(system.residual, system.jacobian, X, row, row @ X + target - q(X), settings.tol,
                        settings.max_newton)
        if not result.converged:
            return None
        X = result.x
        if abs(q(X) - target) <= LANDING_RTOL * max(1.0, abs(target)):
            return continuation.Point(X, np.zeros_like(X), result.iterations, result.residual)
    return None


def _landed(tracer, final, leg: LegTrace, points: list, folds: list, land_on: dict):
    """(points, folds, stop) of a leg: with its exact end point when it stopped on passing a ``land_on`` pole
    stretch; folds found past the last stored point (between it and the overshoot) are kept only if they lie
    before that end point, i.e. on the stored branch."""
    beyond = [f for f in folds if f[1] >= len(points) - 1]
    kept = [f for f in folds if f[1] < len(points) - 1]
    target_of_stop = land_on.get(leg.stop.code)
    if target_of_stop is None or not points:
        return points, kept, leg.stop
    pole, target = target_of_stop
    disc = final.eq.disc
    last_disc, last_path = leg.segments[-1]
    overshoot = last_disc.transfer(last_path.overshoot.X, disc)
    quantity = quantity_of(final, pole)
    end = land(final, points[-1][0], overshoot, quantity, target, tracer.settings)
    if end is None:
        return points, kept, Stop(StopCode.LANDING_FAILED, f"could not land on {pole} = {target:g} (Newton "
                                                           "failed); stopped before it")
    q, last = quantity[0], quantity[0](points[-1][0])
    kept += [f for f in beyond if (q(f[2]) - last) * (target - q(f[2])) >= 0]
    return points + [_resolved_end(tracer, final, leg, pole, target, end)], kept, leg.stop


def _resolved_end(tracer, final, leg: LegTrace, pole, target, end: continuation.Point) -> tuple:
    """(X, point, solved degree, error estimate) of a leg's end landed on the storage basis (``final``); where it
    is not resolved there (its tail above max_error: a storage map made for another leg's states) and the leg
    ended on another basis, the end landed on that one instead and moved to storage like the leg's other points,
    its estimate the tail there plus the projection loss, if that is smaller."""
    disc = final.eq.disc
    estimate = disc.tail(end.X[:-1])
    own_disc, path = leg.segments[-1]
    if estimate <= tracer.resolution.max_error or own_disc is disc or not path.points:
        return end.X, end, disc.degree, estimate
    own = tracer.system_on(own_disc, final.params)
    own_end = land(own, path.points[-1].X, path.overshoot.X, quantity_of(own, pole), target, tracer.settings)
    if own_end is None:
        return end.X, end, disc.degree, estimate
    moved = own_disc.transfer(own_end.X, disc)
    own_estimate = own_disc.tail(own_end.X[:-1]) + transfer_error(own_disc, own_end.X, disc, moved)[0]
    if own_estimate >= estimate:
        return end.X, end, disc.degree, estimate
    return moved, continuation.Point(moved, own_end.tangent, own_end.iterations, own_end.residual), \
        own_disc.degree, own_estimate


def assemble(tracer, params, name: str, forward: LegTrace, backward: LegTrace | None = None, t0: float = 0.0,
             land_on: dict | None = None, labels=("forward", "backward")) -> Branch:
    """One Branch (module docstring): reversed ``backward`` (without its first point), then ``forward``.
    ``land_on``: StopCode -> (pole row name or Control, target) to land exactly on for legs stopped with that
    code (a pole stretch, or the control parameter V or n)."""
    legs = [leg for leg in (backward, forward) if leg is not None]
    disc, moves = storage_basis(tracer, params, legs)
    final = tracer.system_on(disc, params)
    land_on = land_on or {}
    forward_points, forward_folds = _collect(forward, disc, moves)
    forward_points, forward_folds, forward_stop = _landed(tracer, final, forward, forward_points, forward_folds,
                                                          land_on)
    backward_points, backward_folds = [], []
    if backward:
        backward_points, backward_folds = _collect(backward, disc, moves)
        backward_points, backward_folds, backward_stop = _landed(tracer, final, backward, backward_points,
                                                                 backward_folds, land_on)
    points = backward_points[:0:-1] + forward_points
    if not points:
        raise ContinuationError(f"{name}: no converged point ({forward.stop.message})")
    offset = max(len(backward_points) - 1, 0)
    special = [SpecialPoint(kind, offset - index - 1, X, **found) for kind, index, X, found in backward_folds[::-1]]
    special += [SpecialPoint(kind, offset + index, X, **found) for kind, index, X, found in forward_folds]
    special.append(SpecialPoint(Kind.EP, len(points) - 1, points[-1][0], stop=forward_stop))
    traced = (Leg(labels[0], forward_stop),)
    if backward:
        traced += (Leg(labels[1], backward_stop),)
        if backward_points:
            special.insert(0, SpecialPoint(Kind.EP, 0, points[0][0], stop=backward_stop))
    loss_limit = tracer.resolution.loss_limit
    lossy = tuple(float(lost) for _, loss in moves.values() for lost in loss if lost > loss_limit)
    kernels = final.eq.kernels
    return Branch(
        name=name,
        scene=tracer.scene,
        disc=disc,
        kernel_class=kernels.name,
        kernel_signature=kernels.signature,
        params=params,
        X=np.array([p[0] for p in points]),
        iterations=np.array([p[1].iterations for p in points]),
        residual=np.array([p[1].residual for p in points]),
        error_estimate=np.array([p[3] for p in points]),
        degree=np.array([p[2] for p in points]),
        special=special,
        legs=traced,
        lossy=lossy,
        wall_time=time.perf_counter() - t0,
        parameter=tracer.parameter,
    )
