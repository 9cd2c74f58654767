"""The branch born at a branch point of a tube's primary branch (tube/primary.py): the bulge.

At a branch point of the odd block (interval.Mirror) the mirror-symmetric branch is crossed by a pitchfork whose states
break the symmetry (u_odd → −u_odd maps it onto its other half, the mirror image): the bulge at one end of a tube with
sliding ends (plugged ends are refused: ``PLUGGED_WHY``, docs/tubes.md). At a branch point of the even block of a
uniform primary branch (sliding ends, no field: the modes cos(nπS/L), n even) the branch stays mirror-symmetric and
breaks the uniformity (a pitchfork too: on the tube of length L it is the odd bulge branch of the tube of length
L/n, repeated). The branch leaves the branch point X* = (u*, P*) along the block's null vector φ with dP = 0: the first
point is the Keller corrector from X* + σ(φ, 0)/|φ| on the hyperplane normal to (φ, 0) (which the primary branch never
meets: its states have no component along φ), oriented so that ``Side`` is positive (the bulge at S = 0 on sliding
ends), and the trace starts there: at X* itself dP/ds and dV/ds vanish by the symmetry (P and V are even in the
arclength along a pitchfork), so the fold monitors start from the first point. It is traced by pseudo-arclength
continuation in X = (u, P), at an odd branch point on every unknown, at an even one on the even block (a held λ̄ stays
fixed), its folds in P (LP), in the enclosed volume (LV: V/(2π) = −∂E/∂P, whose gradient is −∂R/∂P) and under gas
control in n = P V (LN: tube/control.py) located by the tracer's fold monitors, until it rejoins the primary branch's
kind of states (``Side`` changes sign: the bulge has filled the tube and the branch meets the primary branch again at
another branch point of the block, the other end of the pitchfork's loop, where P and V are again even in the arclength:
the monitors' sign changes in that last step are that symmetry, not folds, and are not kept), its V reaches
``continuation.stop_volume`` (or the argument ``stop_volume``, the same V/R0³; the end landed there exactly:
tube/control.VolumeStop), its largest hoop stretch ``stop_stretch``, in a coil field where its states turn compressed
(IntervalStop.COMPRESSED: tube/stability.CompressionStop), where a point's Legendre tail passes ``max_error`` when one
is given (IntervalStop.UNRESOLVED: that point is not stored, nor a fold located in the step to it; tube/resolution.py
retraces at a higher degree), after ``continuation.max_points``, or at the next point after SIGINT/SIGTERM
(StopCode.INTERRUPTED). Every point carries its tail and first-integral spread (tube/accuracy.py). The branch point
X* is the branch's first point; the stability of every point is ``unstable_counts``' (at X* itself one eigenvalue is
zero, its sign rounding). The scene's [[events]]: UZ points (tube/events.py).
"""
from dataclasses import replace

import numpy as np

from .accuracy import accuracy
from .control import VolumeStop, control_monitors, gradient
from .events import with_events
from .primary import TubeSystem, held, in_field, stressed, volume_ratio
from .results import IntervalBranch, IntervalSpecial
from .stability import CompressionStop, smallest_stress, unstable_counts
from ..analysis.branches.problem import ParameterSystem, continuation_settings
from ..analysis.results import IntervalStop, Kind, StopCode, signalled
from ..galerkin.equilibrium import Equilibrium
from ..galerkin.interval import Mirror
from ..galerkin.interval_elements import ElementInterval, collocated
from ..numerics import continuation
from ..numerics.continuation import Stop
from ..numerics.threads import limited_blas
from ..scene.loading import Control
from ..scene.tables import Ends


PLUGGED_WHY = ("closed plugged ends have no odd bifurcation (the lowest odd eigenvalue, the middle bulge's shift "
               "towards a plug, stays positive wherever it is resolved in the degree: the odd branch points reported "
               "there are under-resolution), and the branch born at the odd branch point of plugged ends held apart "
               "is compressed beside the plugs from its first steps, where a membrane wrinkles and no relaxed energy "
               "is built (docs/tubes.md)")
# On spectral elements (``on``) a corrector step of 4 iterations is easy: one SuperLU factorisation and its chord
# (numerics/newton.py: REFRESH_RATIO_LARGE), which from a step of the plateau needs 4 corrections to reach the
# tolerance; at the default 3 the step never grew there (the L = 30 branch: 478 points, 284 at 4, docs/tubes.md)
EASY_NEWTON_ELEMENTS = 4


class UnswitchableBranchPoint(ValueError):
    """A branch point ``bulge_branch`` does not switch at (one line saying which and why)."""


class BranchStartError(ArithmeticError):
    """The first step off the branch point did not converge (one line)."""


@limited_blas
def bulge_branch(scene, primary: IntervalBranch, point: IntervalSpecial, stop_volume: float | None = None,
                 step: float | None = None, stop_stretch: float | None = None,
                 max_error: float | None = None, on=None, refine=None) -> IntervalBranch:
    """The branch switched at ``point``, a branch point of ``primary`` (module docstring); ``stop_volume``: the
    enclosed volume V/R0³ where it ends, as the scene key (None: the scene's continuation.stop_volume, if any; V/V0 = v
    is v·πL on a tube of length L); ``step``: the first arclength step (None:
    continuation.step); ``stop_stretch``: also stop where the largest hoop stretch at the nodes passes it;
    ``max_error``: stop where a point's Legendre tail passes it (None: no check); ``on``: the discretisation the
    branch is traced on (None: the primary's; else at an odd branch point a spectral-element layout of the same
    tube, galerkin/interval_elements.py: ``_switched_onto``); ``refine``: with ``on`` and ``max_error``, (layout,
    u) ↦ the finer layout (holding the layout's space) where a point u's tail passes max_error: the trace is continued
    there from its last point (``_continued_on``; None from ``refine``: stopped UNRESOLVED as without), tube/front.py.
    A branch traced on several layouts stores its states on the last (``collocated``: exact), its folds located on the last (``_relocated``), each
    point's tail, spread, stability counts and smallest stress those of the layout it was traced on (``_assembled``).
    UnswitchableBranchPoint for a point that is no branch point, or an even one of a primary branch that is not
    uniform."""
    if point.kind != Kind.BP or point.block is None:
        raise UnswitchableBranchPoint(f"a branch is switched at a branch point of a mirror block, not at "
                                      f"{point.kind.value}")
    disc = primary.disc
    if disc.ends != Ends.SLIDING:
        raise UnswitchableBranchPoint(f"a branch is switched on sliding ends, not {disc.ends.value}: {PLUGGED_WHY}")
    if point.block == Mirror.EVEN and in_field(scene):
        raise UnswitchableBranchPoint("an even branch point is switched on a uniform primary branch (no field), not "
                                      "in a coil field")
    if on is not None and point.block != Mirror.ODD:
        raise UnswitchableBranchPoint("a branch is traced on its own discretisation from an odd branch point, not "
                                      f"from an {point.block.value} one")
    u, phi, disc = _switched(scene, primary, point) if on is None else _switched_onto(scene, primary, point, on)
    params = primary.params.with_value("P", point.pressure)
    if Side(disc, point.block)(phi) < 0:
        phi = -phi
    unknowns = disc.free if point.block == Mirror.ODD else disc.block(Mirror.EVEN)
    system = _tube_system(scene, disc, params, unknowns)
    settings = continuation_settings(scene)
    settings.step = settings.step if step is None else step
    settings.easy_newton = settings.easy_newton if on is None else EASY_NEWTON_ELEMENTS
    X = np.append(u, point.pressure)[system.columns]
    direction = np.append(phi, 0.0)[system.columns] / np.linalg.norm(phi)
    first = continuation.correct(system, X + settings.step * direction, direction, settings)
    if not first.converged:
        raise BranchStartError(f"the first step of the bulge branch did not converge: {first.message}")
    start = continuation.Point(first.x, continuation.tangent(system, first.x, direction), first.iterations,
                               first.residual)
    compressed = CompressionStop(system.system.eq, in_field(scene))
    compressed(u)
    target = scene.continuation.stop_volume if stop_volume is None else stop_volume
    branch_point, legs, stored = system.full(X), [], 0
    while True:
        volume_stop = VolumeStop(target, system)
        stop = _stop_rule(system, point.block, volume_stop, stop_stretch, max_error, compressed)
        monitors = _monitors(system, scene)
        leg = replace(settings, max_points=settings.max_points - stored + (1 if legs else 0))
        path = continuation.trace(system, start, leg, stop, monitors)
        legs.append((system, path, volume_stop))
        stored += len(path.points) - (1 if len(legs) > 1 else 0)
        if refine is None or path.stop.code != IntervalStop.UNRESOLVED:
            break
        finer = refine(system.system.eq.disc, system.full(path.overshoot.X)[:-1])
        continued = None if finer is None else _continued_on(scene, params, system, path, finer, settings)
        if continued is None:
            if finer is not None:
                legs[-1] = (system, replace(path, stop=Stop(path.stop.code, f"{path.stop.message}; its last point did "
                                                            f"not converge on the refined layout ({finer.count} "
                                                            "elements)")), volume_stop)
            break
        system, start, step = continued
        settings, compressed = replace(settings, step=step), compressed.on(system.system.eq)
    if len(legs) > 1 and path.stop.code == continuation.TraceStop.MAX_POINTS:  # the branch's, not the last leg's
        legs[-1] = (system, replace(path, stop=Stop(path.stop.code, f"maximum number of points "
                                                                    f"({settings.max_points}) reached")), volume_stop)
    return _assembled(scene, primary.params, branch_point, legs, settings, max_error)


def _monitors(system, scene) -> dict:
    """The fold monitors of a trace on ``system``: P (LP), V (LV) and the control's (tube/control.py)."""
    monitors = {Kind.LP: np.eye(system.columns.size)[-1], Kind.LV: gradient(system, Control.VOLUME)}
    return monitors | control_monitors(system, scene.loading.control)


def _tube_system(scene, disc, params, unknowns) -> TubeSystem:
    """R(u; P) of ``scene`` on ``disc`` in X = (u[unknowns], P), a held λ̄ fixed."""
    return TubeSystem(ParameterSystem(Equilibrium(scene, disc), params, "P"), unknowns, held(disc))


def _stop_rule(system, block: Mirror, volume_stop, stop_stretch, max_error, compressed):
    """The stop of a trace on ``system`` (``bulge_branch``; module docstring)."""
    disc = system.system.eq.disc
    side = Side(disc, block)

    def stop(p):
        if (interrupted := signalled()) is not None:
            return interrupted
        Y = system.full(p.X)
        if side(Y[:-1]) < 0:
            return Stop(IntervalStop.REJOINED, f"the branch rejoined the {side.rejoins} states")
        if (reached := volume_stop(p.X)) is not None:
            return reached
        hoop = disc.node_state(Y[:-1])[0].max()
        if stop_stretch is not None and hoop > stop_stretch:
            return Stop(IntervalStop.HOOP_STRETCH, f"the largest hoop stretch {hoop:.6g} passed stop_stretch "
                                                   f"{stop_stretch:g}")
        if max_error is not None and (tail := disc.tail(Y[:-1])) > max_error:
            return Stop(IntervalStop.UNRESOLVED, f"the Legendre tail {tail:.3g} passed solver.max_error "
                                                 f"{max_error:g} at degree {disc.degree}")
        return compressed(Y[:-1])

    return stop


def _continued_on(scene, params, system, path, finer, settings) -> tuple | None:
    """(system, start, step) of a trace continued on the layout ``finer`` (``bulge_branch``'s ``refine``): the last
    stored point of ``path`` and its tangent collocated onto it (exact: it holds the layout's space), the point
    re-solved there by the Keller corrector on the hyperplane through it normal to the tangent, its tangent
    recomputed, the step the one that reached the unresolved point (``path.overshoot``); None where the corrector
    does not converge."""
    last = path.points[-1]
    onto = _tube_system(scene, finer, params, finer.free)
    X, direction = _moved(system, last.X, last.tangent, onto)
    solved = continuation.correct(onto, X, direction, settings)
    if not solved.converged:
        return None
    start = continuation.Point(solved.x, continuation.tangent(onto, solved.x, direction, solved.factors),
                               solved.iterations, solved.residual)
    return onto, start, float(last.tangent @ (path.overshoot.X - last.X))


def _assembled(scene, params, branch_point: np.ndarray, legs: list, settings, max_error) -> IntervalBranch:
    """The IntervalBranch of the traces ``legs`` ((system, path, VolumeStop) per layout, each after the first
    starting at the one before's last stored point re-solved: that start not stored again) from ``branch_point``
    Y* = (u*, P): the end landed on the last leg's stop_volume, the folds of each leg but those in the step that
    ended it where it rejoined or was unresolved (the next leg traces that step again) or beyond the landed end, an earlier leg's located again on the last layout (``_relocated``); each point's counts,
    stress, volume, tail and spread on its own layout, the states on the last (``collocated``)."""
    last_system, last_path, volume_stop = legs[-1]
    disc = last_system.system.eq.disc
    end, stopped = volume_stop.end(last_path, settings)
    if end is not None and max_error is not None and (tail := disc.tail(end[:-1])) > max_error:
        end, stopped = None, Stop(IntervalStop.UNRESOLVED, f"the Legendre tail {tail:.3g} of the landed end passed "
                                                           f"solver.max_error {max_error:g} at degree {disc.degree}")
    states, pressure, volume, special, stress, tail, spread = [], [], [], [], [], [], []
    unstable = {control: [] for control in Control}
    base = 1  # the index of a leg's first path point among the branch's points
    for k, (system, path, _) in enumerate(legs):
        eq, last = system.system.eq, len(path.points) - 1
        folds = [f for f in path.folds
                 if not (path.stop.code in (IntervalStop.REJOINED, IntervalStop.UNRESOLVED) and f.index == last)]
        if k == len(legs) - 1 and path.stop.code == StopCode.STOP_VOLUME:
            folds = [f for f in folds if f.index < last or volume_stop.kept(path, end, f.point.X)]
        points = ([branch_point] if k == 0 else []) + [system.full(p.X) for p in path.points[(1 if k else 0):]]
        points += [end] if k == len(legs) - 1 and end is not None else []
        if system is not last_system:  # located again on the layout the branch is stored on
            folds = [_relocated(scene, f, system, path, last_system, settings) for f in folds]
        leg_special = stressed(last_system.system.eq, tuple(
            IntervalSpecial(Kind(f.label), last_system.full(f.point.X)[:-1], float(f.point.X[-1]), f.index + base,
                            f.status) for f in sorted(folds, key=lambda f: f.index)))
        moved = (lambda rows: rows) if eq.disc == disc else (lambda rows: collocated(eq.disc, rows, disc))
        Y = np.array(points)
        states.append(moved(Y[:, :-1]))
        pressure.append(Y[:, -1])
        volume.append([volume_ratio(eq, y) for y in Y])
        special += leg_special
        stress.append([smallest_stress(eq, y[:-1]) for y in Y])
        for control, counts in unstable_counts(eq, Y, params).items():
            unstable[control].append(counts)
        accurate = accuracy(eq, Y[:, :-1])
        tail.append(accurate[0])
        spread.append(accurate[1])
        base += last
    return with_events(scene, last_system, IntervalBranch(
        disc, np.concatenate(states), np.concatenate(pressure), np.concatenate(volume), {},
        {control: np.concatenate(counts) for control, counts in unstable.items()}, tuple(special), stopped,
        np.concatenate(stress), params, np.concatenate(tail), np.concatenate(spread)), settings)


def _relocated(scene, fold, system, path, onto, settings):
    """``fold`` of the trace ``path`` on ``system`` located again on the finer layout of ``onto`` (the one the branch
    is stored on: a state solved on one layout is not stored with readings on another): points[index] and its
    tangent moved onto it (``_moved``: exact) and re-solved there by the Keller corrector, and the monitor's zero
    located in the step to the point after it, moved likewise, as the tracer locates it
    (numerics/continuation.locate_fold). Where that fails: the fold's own state moved, status NEAREST."""
    after = path.points[fold.index + 1]  # an earlier leg's folds lie before its last point (bulge_branch)
    X, t = _moved(system, path.points[fold.index].X, path.points[fold.index].tangent, onto)
    solved = continuation.correct(onto, X, t, settings)
    root = None
    if solved.converged:
        start = continuation.Point(solved.x, continuation.tangent(onto, solved.x, t, solved.factors),
                                   solved.iterations, solved.residual)
        end, _ = _moved(system, after.X, after.tangent, onto)
        root = continuation.locate_fold(onto, start, float(start.tangent @ (end - start.X)),
                                        _monitors(onto, scene)[Kind(fold.label)], settings)
    if root is None or root.status != continuation.RootStatus.LOCATED:
        X, t = _moved(system, fold.point.X, fold.point.tangent, onto)
        return replace(fold, point=continuation.Point(X, t, 0, np.nan), status=continuation.RootStatus.NEAREST,
                       bracket=None)
    return replace(fold, point=root.payload, status=root.status, bracket=None)


def _moved(system, X, t, onto) -> tuple:
    """(X, unit tangent) of ``system``'s point X and tangent t collocated onto the finer layout of ``onto``
    (galerkin/interval_elements.collocated: exact where it holds the coarser one's space)."""
    disc, finer = system.system.eq.disc, onto.system.eq.disc
    Y, direction = system.full(X), np.zeros(disc.size + 1)
    direction[system.columns] = t
    X = np.append(collocated(disc, Y[:-1], finer), Y[-1])[onto.columns]
    direction = np.append(collocated(disc, direction[:-1], finer), direction[-1])[onto.columns]
    return X, direction / np.linalg.norm(direction)


def _switched(scene, primary: IntervalBranch, point: IntervalSpecial) -> tuple:
    """(u*, φ, disc) on the primary's discretisation: the branch point's state and its block's null vector."""
    disc = primary.disc
    block = disc.block(point.block)
    params = primary.params.with_value("P", point.pressure)
    values, vectors = np.linalg.eigh(Equilibrium(scene, disc).jacobian(point.u, params)[np.ix_(block, block)])
    phi = np.zeros(disc.size)
    phi[block] = vectors[:, np.argmin(np.abs(values))]
    return point.u, phi, disc


def _switched_onto(scene, primary: IntervalBranch, point: IntervalSpecial, disc) -> tuple:
    """(u*, φ, disc) on another discretisation ``disc`` of the tube: the branch point's state collocated there
    (galerkin/interval_elements.collocated: exact for the uniform tube) and φ the eigenvector of ∂R/∂u on the free
    unknowns whose eigenvalue is nearest zero (the bulge mode: the odd block's zero of the primary's basis, within
    the discretisations' difference)."""
    u = collocated(primary.disc, point.u, disc)
    params = primary.params.with_value("P", point.pressure)
    free = disc.free
    values, vectors = np.linalg.eigh(Equilibrium(scene, disc).jacobian(u, params)[np.ix_(free, free)])
    phi = np.zeros(disc.size)
    phi[free] = vectors[:, np.argmin(np.abs(values))]
    return u, phi, disc


class Side:
    """Which side of the primary branch a state of the switched branch lies on: a linear functional of u that
    vanishes on the primary branch's states (module docstring). Odd block: ρ(0) − ρ(L) = −2 Σ_{k odd} a_k, zero on
    every mirror-symmetric state (the bulge at S = 0 where positive). Even block (the uniform primary branch of
    sliding ends): ρ(0) − ρ̄ = Σ_{k ≥ 1 even} a_k, zero on every uniform state (ρ̄ = a_0, the Legendre series' mean;
    P_k(−1) = (−1)^k). On spectral elements (the odd block's branch: tube/front.py) ρ(0) − ρ(L) from the basis's
    values at the ends."""

    def __init__(self, disc, block: Mirror):
        self.disc, self.odd = disc, block == Mirror.ODD
        self.hoops = np.arange(1 if self.odd else 2, disc.degree + 1, 2)
        self.weight = -2.0 if self.odd else 1.0
        self.rejoins = "mirror-symmetric" if self.odd else "uniform"
        if isinstance(disc, ElementInterval):  # ρ(0) − ρ(L) from the basis's values at the ends
            ends = disc.functions(np.array([-1.0, 1.0]))[0]
            self.ends = ends[0] - ends[1]

    def __call__(self, u: np.ndarray) -> float:
        if isinstance(self.disc, ElementInterval):
            return float(self.ends @ u[: self.ends.size])
        return self.weight * float(u[self.hoops].sum())
