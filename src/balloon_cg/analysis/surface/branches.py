"""Non-axisymmetric branches born at the m ≥ 1 branch points of an axisymmetric branch, traced on the whole sphere
(``surface``; MODEL.md §8).

At a located BP of block m<m>_held the critical mode is the eigenvector of the held m-block whose eigenvalue is
zero there (``azimuthal``, its zero modes removed; not always the lowest: at a later crossing of the block the
lowest is already negative), δx = R cos mφ e_ρ + T sin mφ e_φ + Z cos mφ e_z. The branch it starts keeps the
symmetry of that mode: the mirror y → −y always, the rotation by π about the axis for an even m, and on an
equator-symmetric state the reflection z → −z (a mode even in z) or, for an odd m, the inversion x → −x (a mode
odd in z, which rotation by π about the axis maps to −itself); it is solved in that invariant subspace of degree L
(``surface.degree``), with the balloon's centre held and the relabelling modes removed (``surface.gauge``).

Point 0 is the BP state solved on the whole sphere at P* within its axisymmetric family (``axisymmetric_solve``:
regular there, where the subspace's Jacobian is singular). Switching: from (c*, P*) the predictor c* + δφ (φ the
embedded mode, unit) is corrected on the hyperplane normal to φ, then the branch is followed by pseudo-arclength
continuation until it rejoins the axisymmetric branch (the amplitude φ·(c − c*) changes sign), a pole stretch
reaches stop_stretch, the membrane comes within wire_gap of a coil, or max_points; a point whose spectral tail
exceeds solver.max_error refines the basis (``surface.resolution``: the wire map re-centred on the state, the
degree and order extended; past MAX_DEGREE or MAX_ORDER the branch stops, flagged) and is solved again there as the
branch's next point (``follow``). The sign −φ is the image of the
+φ branch under the rotation by π about the axis (``rotated``). Folds in P are located (LP).

Every point carries its measures (pole stretches, volume, centroid offset, tilt) and the lowest eigenvalues of
its second variation over every symmetry sector, held and free, under pressure, volume and gas control, and the
secondary branch points are located (``surface.assessment``).

Classification of the parent point: the reduced energy E(Λ) − E* along φ at P* (the other coefficients relax on
φ·(c − c*) = Λ, as ``bifurcation.classify`` for the pear points), fitted by E2 Λ² + E3 Λ³ + E4 Λ⁴ (+ E6 Λ⁶:
``classify``).
"""
import time
from dataclasses import replace

import numpy as np
from scipy import linalg

from ...galerkin.equilibrium import Parameters
from ...model.loop import loop_distance
from ...numerics import continuation, interrupt
from ...numerics.continuation import Stop
from ...numerics.newton import Convergence, newton
from ...numerics.threads import limited_blas
from ...surface import stability as surface_stability
from ...surface.basis import EQUATOR, HALF_TURN, INVERSION, MIRROR_Y, SphericalBasis
from ...surface.embedding import axisymmetric_coefficients, mode_coefficients, transfer
from ...surface.equilibrium import SurfaceEquilibrium
from ...surface.gauge import Gauge
from ...surface.measures import MEASURES, measures, tail, tails
from ...surface.system import SurfaceSystem
from ..stability import azimuthal
from ..branches.primary import start_parameters
from ..branches.problem import continuation_settings, equilibrium_of
from ..results import (Branch, Classification, Kind, Leg, Origin, SpecialPoint, Status, StopCode,
                      SurfaceBranch, TraceStop)
from ..stability.axisymmetric import assessed_degrees
from .assessment import assess, fed, readers
from .resolution import MAX_DEGREE, MAX_ORDER, refined, remapped
from ...scene import Shape

SWITCH_STEP = 2e-2  # the first step off the axisymmetric branch, along the unit mode in coefficient space
CRITICAL_SEARCH = 4  # the eigenvalues of the BP's block among which the critical (nearest zero) one is taken
SWITCH_REACH, SWITCH_TRIES = 4.0, 3  # how far from the branch point (in steps) the first point may land; tries
CLASSIFY_TRIES = 3  # halvings of the classification's amplitude δ before it gives up


class SurfaceStartError(ArithmeticError):
    """A branch could not be started: its start needs a degree above MAX_DEGREE, or the first correction off the
    axisymmetric branch did not converge."""


def located_degree(branch: Branch, bp: SpecialPoint) -> int:
    """The perturbation degree a branch point was located at: the larger of its bracketing points' assessments
    (``azimuthal_points.find``; near a wire it reaches hundreds); on a branch not assessed (read back from a run
    file by ``continue``) the larger of their ``stability.point_degrees`` at stability.degree, which the
    assessment starts from (stability.degree itself does not resolve the mode near a wire)."""
    degrees = assessed_degrees(branch)
    last = len(degrees) - 1
    return max(degrees[min(bp.index, last)], degrees[min(bp.index + 1, last)])


def critical_mode(branch: Branch, bp: SpecialPoint, degree: int, count: int = CRITICAL_SEARCH):
    """(the azimuthal basis, the eigenvector of block m at the BP (of its reading: held or free) whose eigenvalue is
    nearest zero, among the ``count`` lowest) at perturbation degree ``degree`` (``located_degree``: a lower one may not resolve the mode):
    at a later crossing of the block the lowest eigenvalue is already negative and the one that crosses is above it
    (module docstring). Its sign (which direction is +φ, which branch the rotated image) is fixed by its largest
    entry, positive, not left to the eigensolver."""
    eq = equilibrium_of(branch)
    u, params = bp.X[:-1], branch.params_at(bp.X)
    b = azimuthal.perturbation_basis(eq, bp.m, degree)
    H, G = azimuthal.azimuthal_hessian(eq, u, params, bp.m, degree)
    exclude = None
    if bp.m == 1:
        modes = azimuthal.special_modes(eq, u, degree)
        exclude = np.array([modes[azimuthal.MODES[k]] for k in azimuthal.excluded_modes(eq, params, bp.block.held)])
    values, vectors = azimuthal.lowest_eigenvalues(H, G, count, exclude, vectors=True)
    vector = vectors[:, int(np.argmin(np.abs(values)))]
    return b, vector * np.sign(vector[np.argmax(np.abs(vector))])  # its largest entry positive: +φ is reproducible


def mode_symmetry(branch: Branch, az_basis, vector, degree: int) -> tuple:
    """The reflections the branch born along the mode keeps (module docstring): MIRROR_Y; HALF_TURN when the mode is
    invariant under the rotation by π about the axis (even m: cos m(φ + π) = cos mφ); on an equator-symmetric branch
    EQUATOR or INVERSION when the mode is even or odd in z. Each is tested on the embedded mode (its part in the
    smaller subspace is all of it); the tuple is independent (with HALF_TURN and EQUATOR, INVERSION is their product
    and not listed). An even-m mode odd in z keeps neither EQUATOR nor INVERSION (only EQUATOR composed with the
    rotation by π/m, which is not diagonal)."""
    candidates = (HALF_TURN, EQUATOR, INVERSION) if branch.disc.symmetric else (HALF_TURN,)
    whole = np.linalg.norm(mode_coefficients(SphericalBasis(degree, (MIRROR_Y,)), az_basis, vector))
    symmetry = (MIRROR_Y,)
    for reflection in candidates:
        if INVERSION in symmetry or (reflection == INVERSION and EQUATOR in symmetry):
            break
        part = np.linalg.norm(mode_coefficients(SphericalBasis(degree, (*symmetry, reflection)), az_basis, vector))
        if abs(part - whole) <= 1e-8 * whole:
            symmetry += (reflection,)
    return symmetry


class SurfaceTrace:
    """The problem of one surface branch on one basis: the equilibrium, gauge and continuation system at the
    branch's parameters; ``held``: the balloon held at its centre (the net force a reaction) or free (its
    translation an unknown, the net force zero)."""

    def __init__(self, scene, basis: SphericalBasis, params: Parameters, held: bool = True):
        self.scene, self.basis, self.held = scene, basis, held
        self.eq = SurfaceEquilibrium(scene, basis)
        self.gauge = Gauge(basis, held=held, field_symmetry=surface_stability.field_symmetry(self.eq, params))
        self.system = SurfaceSystem(self.eq, self.gauge, params, "P")

    def on(self, basis: SphericalBasis) -> "SurfaceTrace":
        return SurfaceTrace(self.scene, basis, self.system.params, self.held)

    def move(self, X: np.ndarray, to: "SurfaceTrace") -> np.ndarray:
        """A point X = (a, p) of this trace's system on ``to``'s (its coefficients transferred)."""
        return to.system.point(transfer(self.basis, self.system.coefficients(X), to.basis), X[-1])

    def move_direction(self, t: np.ndarray, to: "SurfaceTrace") -> np.ndarray:
        """A direction (δa, δp) on ``to``'s system (linear: the transfer of δc without the reference sphere)."""
        zero = transfer(self.basis, np.zeros(self.basis.size), to.basis)
        moved = transfer(self.basis, self.system.gauge.expand(t[:-1]), to.basis) - zero
        return np.append(to.gauge.reduce(moved), t[-1])


def compile_kernels(scene) -> None:
    """Compile into numba's on-disk cache the kernels the surface branches of a sphere ``scene`` call (its class's
    whole-sphere kernels, the coil field, the Hessian's assembly, the gauge's reduction) by one residual, Jacobian,
    energy and reduced Hessian of a trace at the reference sphere (c = 0) in a degree-2 basis: the kernels'
    argument types, and so the signatures compiled, are those of any degree, symmetry or wire map (the default
    run's child does this for the scene it runs beside: app/default_run.py)."""
    params = start_parameters(scene, "P").with_value("M", scene.field.M)
    trace = SurfaceTrace(scene, SphericalBasis(2, (MIRROR_Y,), aspect=scene.geometry.aspect), params)
    c = np.zeros(trace.basis.size)
    X = trace.system.point(c, params.P)
    trace.system.residual(X)
    trace.system.jacobian(X)
    trace.eq.energy(c, params)
    trace.gauge.reduce_matrix(trace.eq.hessian(c, params))


def initial_basis(scene, disc, u, symmetry: tuple) -> SphericalBasis:
    """The basis of a branch's start: degree surface.degree on the axisymmetric state's wire map (isotropic without
    one, order min(degree, 6) with one: a field's fine features are in θ) and the scene's reference (a spheroid's
    aspect), refined until the embedded state's tails are below solver.max_error / 10 (``refined``);
    SurfaceStartError past MAX_DEGREE."""
    degree = scene.surface.degree
    order = degree if disc.mapping is None else min(degree, 6)
    basis = SphericalBasis(degree, symmetry, order=order, mapping=disc.mapping, aspect=scene.geometry.aspect)
    while True:
        finer = refined(basis, axisymmetric_coefficients(basis, disc, u), scene.solver.max_error / 10)
        if finer is None:
            raise SurfaceStartError(f"the branch point's state needs a whole-sphere degree above {MAX_DEGREE} "
                                    f"(tails {tails(basis, axisymmetric_coefficients(basis, disc, u))})")
        if finer is basis:
            return basis
        basis = finer


def axisymmetric_solve(trace: SurfaceTrace, c: np.ndarray, P: float) -> np.ndarray | None:
    """The axisymmetric state near c at the pressure P solved on the whole sphere within its axisymmetric family
    (c + E a, E spanning the part of ``surface.stability.azimuthal_family`` the gauge's constraints keep: a held
    balloon's axial translation is not an unknown, its net axial force a reaction): the Jacobian Eᵀ H E is regular
    at an m ≥ 1 branch point, where the whole subspace's is singular; None when Newton does not converge."""
    E = surface_stability.azimuthal_family(trace.basis, 0)
    held = trace.gauge.constraints @ E
    if held.size and np.abs(held).max() > 1e-14:  # an axial translation in the family (no z-reflection kept)
        E = E @ linalg.null_space(held)
    params, solver = trace.system.params, trace.scene.solver

    def residual(X):
        return E.T @ trace.eq.residual(c + E @ X[:-1], params.with_value("P", X[-1]))

    def jacobian(X):
        state, at = c + E @ X[:-1], params.with_value("P", X[-1])
        return np.hstack([E.T @ trace.eq.hessian(state, at) @ E,
                          (E.T @ trace.eq.parameter_derivative(state, at, "P"))[:, None]])

    start = np.append(np.zeros(E.shape[1]), P)
    result = newton(residual, jacobian, start, np.eye(start.size)[-1], P, solver.tol, solver.max_newton)
    return c + E @ result.x[:-1] if result.converged else None


POLE_STOPS = {StopCode.STOP_STRETCH: StopCode.BOTTOM_STOP_STRETCH, StopCode.BOTTOM_STOP_STRETCH: StopCode.STOP_STRETCH}


def pole_stop(code: StopCode, upper: float) -> Stop:
    """The stop of a material pole's stretch reaching stop_stretch ``upper`` (north: STOP_STRETCH)."""
    pole = "north" if code == StopCode.STOP_STRETCH else "south"
    return Stop(code, f"{pole} pole stretch reached stop_stretch {upper:g}")


INTERRUPTED = Stop(StopCode.INTERRUPTED, "interrupted (SIGINT or SIGTERM): stopped at this point")


def _stop_rule(trace: SurfaceTrace, rejoin: tuple | None):
    """stop(point) -> Stop or None (module docstring); ``rejoin`` (φ, X*): the branch ends where it crosses the
    hyperplane of its branch point back (None: a primary branch); StopCode.RESOLUTION when a tail exceeds
    solver.max_error; StopCode.INTERRUPTED at the first point after a signal (``numerics.interrupt``)."""
    scene, basis = trace.scene, trace.basis
    upper, gap = scene.continuation.stop_stretch, scene.continuation.wire_gap

    def stop(point):
        if interrupt.requested():  # SIGINT/SIGTERM: the points so far are kept (numerics.interrupt)
            return INTERRUPTED
        if rejoin is not None and rejoin[0] @ (point.X - rejoin[1]) < 0:
            return Stop(StopCode.REJOINED, "rejoined the branch it was born on")
        c = trace.system.coefficients(point.X)
        m = measures(basis, c)
        if m["lam_top"] >= upper:
            return pole_stop(StopCode.STOP_STRETCH, upper)
        if m["lam_bottom"] >= upper:
            return pole_stop(StopCode.BOTTOM_STOP_STRETCH, upper)
        if trace.eq.has_field:
            distance = float(loop_distance(trace.eq.node_values(c)["state"][:3], trace.eq.coils).min())
            if distance < gap:
                return Stop(StopCode.WIRE_GAP, f"membrane within wire_gap {gap:g} of a coil (gap {distance:.3g})")
        error = tail(basis, c)
        if error > scene.solver.max_error:
            return Stop(StopCode.RESOLUTION, f"spectral tail {error:.2g} above solver.max_error "
                                             f"{scene.solver.max_error:g} at degree {basis.degree}, order "
                                             f"{basis.order}")
        return None

    return stop


def switch(trace: SurfaceTrace, X_star: np.ndarray, phi: np.ndarray, step: float = SWITCH_STEP):
    """The first point off the axisymmetric branch along φ (unit, in X = (a, P)), or the NewtonResult that failed:
    the corrector on the hyperplane φ·(X − X*) = δ, accepted when it lands within SWITCH_REACH·δ of X* (a
    solution farther away lies on another branch that crosses the hyperplane: δ is quartered, SWITCH_TRIES times)."""
    solver = trace.scene.solver
    for _ in range(SWITCH_TRIES):
        guess = X_star + step * phi
        result = newton(trace.system.residual, trace.system.jacobian, guess, phi, phi @ guess, solver.tol,
                        solver.max_newton)
        if result.converged and np.linalg.norm(result.x - X_star) <= SWITCH_REACH * step:
            return continuation.Point(result.x, continuation.tangent(trace.system, result.x, phi, result.factors),
                                      result.iterations, result.residual)
        if result.converged:
            far = float(np.linalg.norm(result.x - X_star))
            result = replace(result, outcome=Convergence.FAILED,
                             message=f"the corrector landed {far:.3g} from the branch point for a step {step:.3g} (on "
                                     "another branch)")
        step /= 4.0
    return result


@limited_blas
def trace_surface(branch: Branch, number: int, bp: SpecialPoint, sign: float, name: str, max_points: int,
                  progress=None) -> SurfaceBranch:
    """The branch born at the branch point ``bp`` (number ``number`` in ``branch.branch_points()``) of ``branch``
    along sign·φ (module docstring); SurfaceStartError when it cannot start."""
    t0 = time.perf_counter()
    scene = branch.scene
    if scene.geometry.shape not in (Shape.SPHERE, Shape.SPHEROID):
        raise SurfaceStartError(f"the whole-sphere engine has a sphere's or a spheroid's reference; the scene's is a "
                                f"{scene.geometry.shape.value} (its m = {bp.m} branch point is located, the branch "
                                "born there is not traced)")
    az_basis, vector = critical_mode(branch, bp, located_degree(branch, bp))
    symmetry = mode_symmetry(branch, az_basis, vector, scene.surface.degree)
    params = branch.params_at(bp.X)
    trace = SurfaceTrace(scene, initial_basis(scene, branch.disc, bp.X[:-1], symmetry), params, bp.block.held)
    c_star = axisymmetric_coefficients(trace.basis, branch.disc, bp.X[:-1])
    # point 0: the axisymmetric state as the whole-sphere solution at P* (its truncation differs), solved in the
    # axisymmetric family, where the Jacobian is regular at an m ≥ 1 point; where that Newton fails, the embedded
    # state itself; its residual is stored either way
    solved = axisymmetric_solve(trace, c_star, bp.X[-1])
    if solved is not None:
        c_star = solved
    X_star = trace.system.point(c_star, bp.X[-1])
    phi = np.append(trace.gauge.reduce(mode_coefficients(trace.basis, az_basis, vector)), 0.0)
    phi = sign * phi / np.linalg.norm(phi)
    with readers(trace, branch.params, "P") as stream:  # the points read beside the trace, on the other cores
        (E, kind), traced = leave(trace, X_star, phi, max_points, f"branch point {number} along its m = {bp.m} "
                                  "mode", progress, fed(stream))
        origin = replace(bp, index=0, X=np.append(c_star, bp.X[-1]), E=E, classification=kind, mode=None,
                         note=f"born here, on {branch.name} (m = {bp.m})")
        return branch_of(*traced, branch, number, origin, name, t0, stream=stream)


def leave(trace: SurfaceTrace, X_star: np.ndarray, phi: np.ndarray, max_points: int, what: str, progress=None,
          final=None):
    """((E2, E3, E4), Classification) of the branch point X* along the unit mode φ (``classify``) and the branch
    that leaves it along φ: (trace, segments, folds, stop) of ``follow`` from the first point off it (``switch``)
    until it crosses back the hyperplane φ·(X − X*) = 0 (``final``: as ``follow``'s); SurfaceStartError (naming
    ``what``) when that first correction does not converge."""
    classified = classify(trace, X_star, phi)
    first = switch(trace, X_star, phi)
    if not isinstance(first, continuation.Point):
        raise SurfaceStartError(f"the first correction from {what} did not converge: {first.message}")
    start = continuation.Point(X_star, phi, 0, float(np.abs(trace.system.residual(X_star)).max()))
    return classified, follow(trace, [start], first, max_points, (phi, X_star), progress, final)


def follow(trace: SurfaceTrace, points: list, first: continuation.Point, max_points: int, rejoin: tuple | None,
           progress=None, final=None) -> tuple:
    """Pseudo-arclength continuation in P from ``first`` (after the stored ``points``) until a stop of ``_stop_rule``
    (``rejoin``: (φ, X*) of a branch born at a branch point, None for a primary branch). A point whose tail exceeds
    solver.max_error (the overshoot: converged on its basis) refines the basis (the wire map re-centred on the
    state, then the degree and the order extended), is solved again there on the hyperplane through it normal to
    its tangent and, once the stop rule passes it there, is the next point; the trace goes on with the step it would
    have taken from it (``continuation.next_step``), at least the scene's first step. Where a fold lies in that
    step, the last point is solved again there instead and the step starts over (the fold is found again from it).
    (At fixed P the bordered Jacobian is near-singular where the branch is tangent to P = const: the free m = 1
    branch of the off-equator coil's free balloon at P = 1.6756, one point off its branch point, has its smallest
    singular value 1.3e-6 at fixed P, 1.0e-3 on that hyperplane.) The two-coil
    m = 1 branch refines at 11 of its 13 steps: carrying the overshoot costs one Newton solve from a converged
    state instead of solving the last point again and a second corrector (23 correctors then, 13 now). A signal
    before the refinement or during it: the stop INTERRUPTED, the points so far kept. Returns (the last trace, the
    segments [(trace, points)], the folds [(trace, Fold)] with indices over the whole branch, the Stop).
    ``final(trace, point)``: called on each point in order once it is kept as it is, i.e. once a later point is
    accepted or the trace ends (the last point may be solved again on a finer basis): the points read beside the
    trace (``assessment.readers``)."""
    segments, running = [(trace, list(points))], []  # running: (trace, point) of the continuation run under way
    handed = 0

    def hand(keep_last: bool):
        nonlocal handed
        kept = [(t, p) for t, kept_points in segments for p in kept_points] + running
        for t, p in kept[handed:len(kept) - keep_last] if final is not None else ():
            final(t, p)
        handed = max(handed, len(kept) - keep_last)

    def accepted(t: SurfaceTrace, p: continuation.Point):
        running.append((t, p))
        hand(True)
        if progress is not None:
            progress(p)

    try:
        return _follow(trace, segments, running, first, max_points, rejoin, accepted)
    finally:
        hand(False)


def _follow(trace: SurfaceTrace, segments: list, running: list, first: continuation.Point, max_points: int,
            rejoin: tuple | None, accepted) -> tuple:
    """``follow``'s loop on ``segments`` (extended in place); ``running``: the points of the continuation run under
    way (its first, then each one ``accepted(trace, point)`` is told of) until they join the segments. At a
    resolution stop the point the stop rejected (the overshoot: converged, its tail above max_error) is carried to
    the finer basis and solved there (``_carried``), and the trace goes on from it in a new run whose first step is
    the longer of the scene's and the one the trace would have taken from it (``Path.step``: a coarse basis' slow
    correctors shrank the step at every refinement, never grown in runs of one step); where a fold lies in that step
    (on the coarse basis, or dP/ds changed sign on the way to the finer one), the last point is solved again on the
    basis refined for the overshoot and the step taken again from it (the fold found again there, on one basis).
    The first point off a branch point (no stop rule checks it) is solved again on the finer basis too where its
    tail exceeds max_error."""
    scene, folds, step, fresh = trace.scene, [], None, False  # fresh: ``first`` is a new point, not yet accepted
    while True:
        done = sum(len(points) for _, points in segments)
        settings = continuation_settings(scene, max(max_points - done, 1))
        if step is not None:
            settings = replace(settings, step=step)
        running[:] = [] if fresh else [(trace, first)]
        if fresh:
            accepted(trace, first)
        path = continuation.trace(trace.system, first, settings, _stop_rule(trace, rejoin),
                                  {Kind.LP: np.eye(first.X.size)[-1]}, lambda point, on=trace: accepted(on, point))
        running.clear()
        stop = path.stop
        ahead = not any(f.index == len(path.points) - 1 for f in path.folds)  # no fold in the step to the overshoot
        # a fold in the step to a point the resolution stop rejects is found again from the re-solved last point
        folds += [(trace, replace(f, index=f.index + done)) for f in path.folds
                  if stop.code != StopCode.RESOLUTION or f.index < len(path.points) - 1]
        segments[-1][1].extend(path.points)
        if stop.code == TraceStop.MAX_POINTS:
            stop = Stop(TraceStop.MAX_POINTS, f"maximum number of points ({max_points}) reached")
        if stop.code != StopCode.RESOLUTION:
            return trace, segments, folds, stop
        if ahead:  # the overshoot carried to the finer basis: the next point
            moved = _resolved(trace, path.overshoot, rejoin, stop)
        else:  # a fold in the step to it: the step taken again, from the last point, on the basis refined for it
            moved = _finer(trace, path.overshoot, rejoin, stop)
        if isinstance(moved, Stop):  # the branch ends at its last point
            return trace, segments, folds, moved
        new, rejoin_there, last, again = moved[0], moved[-1], segments[-1][1][-1], None
        if ahead and moved[1].tangent[-1] * last.tangent[-1] <= 0:
            ahead = False  # dP/ds changed sign on the way to the finer basis: the step taken again over the fold there
        if not ahead or tail(trace.basis, trace.system.coefficients(last.X)) > scene.solver.max_error:
            # the last point solved again on the finer basis: the start of the step over the fold, or the first
            # point off a branch point (no stop rule checked its tail), unresolved
            again = _solved_on(trace, new, last)
            if isinstance(again, Stop):
                return trace, segments, folds, again
            segments[-1][1].pop()
        trace, rejoin = new, rejoin_there
        first, kept = (moved[1], [] if again is None else [again]) if ahead else (again, [])
        segments.append((trace, kept))
        # a new run: its first step the scene's, or the longer one the trace would take from the carried point
        step, fresh = (max(path.step, scene.continuation.step), True) if ahead else (None, False)


def _resolved(trace: SurfaceTrace, point: continuation.Point, rejoin: tuple | None, stop: Stop):
    """(trace, point, rejoin) of ``_carried`` repeated until the stop rule passes the point, or the Stop that ended
    it: its own (not RESOLUTION) or ``_carried``'s."""
    while True:
        moved = _carried(trace, point, rejoin, stop)
        if isinstance(moved, Stop):
            return moved
        trace, point, rejoin = moved
        stop = _stop_rule(trace, rejoin)(point)
        if stop is None:
            return moved
        if stop.code != StopCode.RESOLUTION:
            return stop


def _carried(trace: SurfaceTrace, point: continuation.Point, rejoin: tuple | None, stop: Stop):
    """(the trace on the finer basis, ``point`` solved there, ``rejoin`` moved there) for a point whose tail exceeds
    solver.max_error on ``trace``'s basis (``stop``: that resolution stop): ``_finer``, then the point transferred
    and solved on the hyperplane through it normal to its tangent (``_solved_on``); or the Stop of either."""
    finer = _finer(trace, point, rejoin, stop)
    if isinstance(finer, Stop):
        return finer
    new, rejoin = finer
    solved = _solved_on(trace, new, point)
    return solved if isinstance(solved, Stop) else (new, solved, rejoin)


def _finer(trace: SurfaceTrace, point: continuation.Point, rejoin: tuple | None, stop: Stop):
    """(the trace on the basis refined for ``point``, whose tail exceeds solver.max_error on ``trace``'s basis
    (``stop``: that resolution stop), and ``rejoin`` moved there): the wire map re-centred on the point, then the
    degree and the order extended (``follow``); or the Stop RESOLUTION_LIMIT where the basis would pass MAX_DEGREE
    or MAX_ORDER, INTERRUPTED at a signal before the refinement (~1 s of CPU on two coils with its first step)."""
    if interrupt.requested():
        return INTERRUPTED
    scene = trace.scene
    c = trace.system.coefficients(point.X)
    target = remapped(trace.basis, c, scene.field.coils)
    finer = refined(target, c if target is trace.basis else transfer(trace.basis, c, target), scene.solver.max_error)
    if finer is None:
        return Stop(StopCode.RESOLUTION_LIMIT, stop.message + f" (the basis would pass degree {MAX_DEGREE} or "
                                                              f"order {MAX_ORDER})")
    new = trace.on(finer)
    if rejoin is not None:
        rejoin = (trace.move_direction(rejoin[0], new), trace.move(rejoin[1], new))
    return new, rejoin


def _solved_on(trace: SurfaceTrace, new: SurfaceTrace, point: continuation.Point):
    """``point`` of ``trace`` transferred to ``new``'s finer basis and solved there on the hyperplane through it
    normal to its tangent (``follow``), with its tangent; the Stop REFINE_FAILED where Newton fails, INTERRUPTED at
    a signal during the solve."""
    scene, finer = trace.scene, new.basis
    moved, reference = trace.move(point.X, new), trace.move_direction(point.tangent, new)
    across = reference / np.linalg.norm(reference)  # the hyperplane through it normal to the branch
    X = newton(new.system.residual, new.system.jacobian, moved, across, across @ moved, scene.solver.tol,
               scene.solver.max_newton)
    if not X.converged:
        return Stop(StopCode.REFINE_FAILED, f"Newton failed on the refined basis (degree {finer.degree}, order "
                                            f"{finer.order}): {X.message}")
    if interrupt.requested():  # a signal while the point was solved again: the trace not gone on
        return INTERRUPTED
    return continuation.Point(X.x, continuation.tangent(new.system, X.x, reference, X.factors, across),
                              X.iterations, X.residual)


def collected(trace: SurfaceTrace, segments, folds, stop) -> dict:
    """The SurfaceBranch fields of traced segments, every point on the final basis: coefficients, values, solver
    records, error estimates, measures, and the special points of the trace (its folds, LP, and its end point, EP).
    A point's error estimate is the larger of its tail on the basis it was traced on (what the trace accepted: on
    the final basis a state of a coarser one has a tail of zeros) and on the final basis (a transfer to another map
    leaves one)."""
    basis = trace.basis
    own = traced_points(segments)
    coefficients = np.array([c if t is trace else transfer(t.basis, c, basis) for t, c in own])
    values = np.array([p.X[-1] for _, points in segments for p in points])
    per_point = [measures(basis, c) for c in coefficients]
    special = [SpecialPoint(Kind.LP, f.index, np.append(transfer(t.basis, t.system.coefficients(f.point.X),
                                                                 basis), f.point.X[-1]),
                            status=Status.LOCATED if f.status == continuation.RootStatus.LOCATED
                            else Status.APPROXIMATE) for t, f in folds]
    special.append(SpecialPoint(Kind.EP, len(values) - 1, np.append(coefficients[-1], values[-1]), stop=stop))
    return dict(basis=basis, coefficients=coefficients, values=values,
                iterations=np.array([p.iterations for _, points in segments for p in points]),
                residual=np.array([p.residual for _, points in segments for p in points]),
                error_estimate=np.array([max(tail(t.basis, c), tail(basis, moved))
                                         for (t, c), moved in zip(own, coefficients)]),
                measures={key: np.array([m[key] for m in per_point]) for key in MEASURES}, special=special,
                legs=(Leg("forward", stop),), kernel_signature=trace.eq.kernels.signature)


def traced_points(segments) -> list:
    """(the SurfaceTrace, the coefficients there) of every point: a point is assessed on its own basis."""
    return [(t, t.system.coefficients(p.X)) for t, points in segments for p in points]


def branch_of(trace: SurfaceTrace, segments, folds, stop, parent, number: int, bp: SpecialPoint, name: str, t0,
              readings=surface_stability.READINGS, fields: dict | None = None, stream=None) -> SurfaceBranch:
    """The SurfaceBranch of the traced segments (``collected``, or their ``fields``), born at point ``number`` of
    the ``parent`` branch, its origin ``bp`` first; the stability of each point read on the basis it was traced on
    (``assess``: ``readings``; ``stream``: read beside the trace, ``assessment.readers``)."""
    fields = fields or collected(trace, segments, folds, stop)
    first_basis = segments[0][0].basis
    if first_basis is not trace.basis:  # the origin was made on the first basis
        bp = replace(bp, X=np.append(transfer(first_basis, bp.X[:-1], trace.basis), bp.X[-1]))
    fields["special"].insert(0, bp)
    out = SurfaceBranch(name=name, scene=parent.scene, kernel_class=parent.kernel_class, params=parent.params,
                        m=bp.m, parent=(parent.name, number), held=trace.held, **fields)
    assess(out, traced_points(segments), readings, stream)
    out.wall_time = time.perf_counter() - t0
    return out


def classify(trace: SurfaceTrace, X_star: np.ndarray, phi: np.ndarray, delta: float = 2e-2) -> tuple:
    """((E2, E3, E4), Classification) of the reduced energy along the unit mode φ (in a) at P* (module docstring):
    E2 Λ² + E3 Λ³ + E4 Λ⁴ + E6 Λ⁶ through the constrained minimisations at Λ = −δ, δ, 2δ, 3δ (three amplitudes for
    the even part: the Λ⁶ term keeps E4 to O(δ⁴) at a pitchfork, whose energy is even in Λ, and the branch's
    normal form P − P* = −2 E4 Λ²/E2'(P*) reads its first points to 1e-4, where E2..E4 through ±δ, ±2δ were 2e-3
    off at δ = 2e-2; E3 from the odd part E(δ) − E(−δ) to O(δ²), as before); δ is halved (CLASSIFY_TRIES times)
    until all four converge, else Classification.NONE."""
    system, solver = trace.system, trace.scene.solver
    params = system.params_at(X_star)
    a_star, direction = X_star[:-1], phi[:-1]

    def residual(x):
        return system.gauge.reduce(trace.eq.residual(system.gauge.expand(x[:-1]), params)) + x[-1] * direction

    def jacobian(x):
        H = system.gauge.reduce_matrix(trace.eq.hessian(system.gauge.expand(x[:-1]), params))
        return np.hstack([H, direction[:, None]])

    def reduced_energy(lam):
        guess = np.append(a_star + lam * direction, 0.0)
        result = newton(residual, jacobian, guess, np.append(direction, 0.0), direction @ a_star + lam, solver.tol,
                        solver.max_newton)
        return trace.eq.energy(system.gauge.expand(result.x[:-1]), params) - E0 if result.converged else None

    E0 = trace.eq.energy(system.gauge.expand(a_star), params)
    for _ in range(CLASSIFY_TRIES):
        L = delta * np.array([-1.0, 1.0, 2.0, 3.0])
        energies = []
        for lam in L:
            energy = reduced_energy(lam)
            if energy is None:
                break
            energies.append(energy)
        if len(energies) == len(L):
            break
        delta /= 2
    else:
        return (np.nan, np.nan, np.nan), Classification.NONE
    E2, E3, E4, _ = linalg.solve(np.stack([L**2, L**3, L**4, L**6], axis=1), np.array(energies))
    if abs(E3) * delta > abs(E4) * delta**2:
        kind = Classification.TRANSCRITICAL
    else:
        kind = Classification.PITCHFORK_SUPER if E4 > 0 else Classification.PITCHFORK_SUB
    return (float(E2), float(E3), float(E4)), kind


def rotated(branch: SurfaceBranch, name: str) -> SurfaceBranch:
    """The image of ``branch`` under the rotation R by π about the axis (``reflected`` by HALF_TURN, diagonal):
    for an odd m the other direction −φ of its pitchfork (R maps the mode to −itself; coaxial loops and the held
    gauge are invariant under R; an even mode R maps to itself: ValueError)."""
    if branch.m % 2 == 0:
        raise ValueError(f"rotated: the rotation by π maps the m = {branch.m} mode of {branch.name} to itself, not "
                         "to the other direction of its pitchfork (trace that one along −φ)")
    return reflected(branch, HALF_TURN, name)


def reflected(branch: SurfaceBranch, S: tuple, name: str) -> SurfaceBranch:
    """The image of ``branch`` under a diagonal reflection S that the scene keeps (the coils' H², the held gauge),
    x ↦ S x(S X): a coefficient of e_c Y_{l,m,t} times s_c σ_S(l, m, t) (``SphericalBasis.reflection_signs``);
    P, the volume, the tilt and every eigenvalue unchanged, the centroid and the field's force F ↦ S F, its torque
    (a pseudovector) T ↦ det S · S T, and where S flips z the pole stretches and their stops swapped. A basis on a
    polar map is not reflected by a z-flip (the map is not symmetric): ValueError."""
    if S[2] < 0 and branch.basis.mapping is not None:
        raise ValueError(f"reflected: {branch.name}'s basis is mapped toward a wire; the reflection {S} does not "
                         "keep its map")
    signs = branch.basis.reflection_signs(S)
    flip, swap = np.array(S, dtype=float), S[2] < 0
    image = {"centroid": flip, "force": flip, "torque": float(np.prod(flip)) * flip}
    measures_ = {key: value * image[key] if key in image else value.copy()
                 for key, value in branch.measures.items()}
    if swap:
        measures_["lam_top"], measures_["lam_bottom"] = branch.measures["lam_bottom"], branch.measures["lam_top"]

    def stop(s: Stop | None) -> Stop | None:
        if s is None or not swap or s.code not in POLE_STOPS:
            return s
        return pole_stop(POLE_STOPS[s.code], branch.scene.continuation.stop_stretch)

    special = [replace(s, X=np.append(s.X[:-1] * signs, s.X[-1]), stop=stop(s.stop)) for s in branch.special]
    stability = None if branch.stability is None else {k: v.copy() for k, v in branch.stability.items()}
    return replace(branch, name=name, coefficients=branch.coefficients * signs, measures=measures_, special=special,
                   legs=tuple(Leg(leg.label, stop(leg.stop)) for leg in branch.legs), stability=stability,
                   origin=Origin.REFLECTED, reflection_of=branch.name, reflection=tuple(S))
