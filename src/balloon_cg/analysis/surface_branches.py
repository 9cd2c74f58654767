"""Non-axisymmetric branches born at the m ≥ 1 branch points of an axisymmetric branch, traced on the whole sphere
(``surface``; MODEL.md §8).

At a located BP of block m<m>_held the critical mode is the lowest eigenvector of the held m-block
(``azimuthal``, its zero modes removed), δx = R cos mφ e_ρ + T sin mφ e_φ + Z cos mφ e_z. The branch it starts
keeps the symmetry of that mode: the mirror y → −y always, and on an equator-symmetric state the reflection
z → −z (a mode even in z) or the inversion x → −x (a mode odd in z, which rotation by π about the axis maps to
−itself); it is solved in that invariant subspace of degree L (``surface.degree``), with the balloon's centre
held and the relabelling modes removed (``surface.gauge``).

Switching: from (c*, P*) (the BP state embedded) the predictor c* + δφ (φ the embedded mode, unit) is corrected on
the hyperplane normal to φ, then the branch is followed by pseudo-arclength continuation until it rejoins the
axisymmetric branch (the amplitude φ·(c − c*) changes sign), a pole stretch reaches stop_stretch, the membrane
comes within wire_gap of a coil, or max_points; a point whose spectral tail exceeds solver.max_error refines the
basis (``refined``: up to MAX_DEGREE, MAX_ORDER; past them the branch stops, flagged). The sign −φ is the image
of the +φ branch under the rotation by π about the axis (``rotated``). Folds in P are located (LP).

Every point carries its measures (pole stretches, volume, centroid offset, tilt) and the lowest eigenvalues of
its second variation over every symmetry sector, held and free (``surface.stability``); a change of the number
of negative held eigenvalues of a sector between two points is a secondary branch point, located by Brent's
method on that eigenvalue (``assess``).

Classification of the parent point: the reduced energy E(Λ) − E* along φ at P* (the other coefficients relax on
φ·(c − c*) = Λ, as ``bifurcation.classify`` for the pear points), fitted by E2 Λ² + E3 Λ³ + E4 Λ⁴.
"""
import time
from dataclasses import replace

import numpy as np
from scipy import linalg

from ..galerkin.equilibrium import Parameters
from ..model.field import wire_distance
from ..numerics import continuation
from ..numerics.continuation import Stop
from ..numerics import eigen
from ..numerics.newton import newton
from ..numerics.threads import limited_blas
from ..surface import stability as surface_stability
from ..surface.basis import EQUATOR, INVERSION, MIRROR_Y, SphericalBasis
from ..surface.embedding import axisymmetric_coefficients, mode_coefficients, transfer
from ..surface.equilibrium import SurfaceEquilibrium
from ..surface.gauge import Gauge
from ..surface.measures import MEASURES, measures, tail, tails
from ..surface.system import SurfaceSystem
from . import azimuthal, wires
from .problem import continuation_settings, equilibrium_of
from .results import (Branch, Classification, Kind, Leg, Origin, SpecialPoint, Status, StopCode,
                      SurfaceBranch, TraceStop)

STABILITY_COUNT = 4  # lowest eigenvalues stored per point and reading
SWITCH_STEP = 2e-2  # the first step off the axisymmetric branch, along the unit mode in coefficient space


class SurfaceStartError(ArithmeticError):
    """A branch could not be started: its start needs a degree above MAX_DEGREE, or the first correction off the
    axisymmetric branch did not converge."""


def critical_mode(branch: Branch, bp: SpecialPoint, degree: int):
    """(the azimuthal basis, the lowest held eigenvector of block m at the BP) (module docstring)."""
    eq = equilibrium_of(branch)
    u, params = bp.X[:-1], branch.params_at(bp.X)
    b = azimuthal.perturbation_basis(eq, bp.m, degree)
    H, G = azimuthal.azimuthal_hessian(eq, u, params, bp.m, degree)
    exclude = None
    if bp.m == 1:
        modes = azimuthal.special_modes(eq, u, degree)
        exclude = np.array([modes[azimuthal.MODES[k]] for k in azimuthal.excluded_modes(eq, params, True)])
    _, vectors = azimuthal.lowest_eigenvalues(H, G, 1, exclude, vectors=True)
    return b, vectors[:, 0]


def mode_symmetry(branch: Branch, az_basis, vector, degree: int) -> tuple:
    """The reflections the branch born along the mode keeps (module docstring): MIRROR_Y, with EQUATOR or
    INVERSION on an equator-symmetric branch when the mode is even or odd in z."""
    if not branch.disc.symmetric:
        return (MIRROR_Y,)
    mirror = SphericalBasis(degree, (MIRROR_Y,))
    whole = np.linalg.norm(mode_coefficients(mirror, az_basis, vector))
    for reflection in (EQUATOR, INVERSION):
        part = np.linalg.norm(mode_coefficients(SphericalBasis(degree, (MIRROR_Y, reflection)), az_basis, vector))
        if abs(part - whole) <= 1e-8 * whole:
            return (MIRROR_Y, reflection)
    raise ValueError("the critical mode has no definite parity under z → −z on an equator-symmetric branch")


MAX_DEGREE = 128  # the finest polar degree the resolution policy raises to
MAX_ORDER = 48  # the finest order of an anisotropic basis (a state pressed against a wire on one side needs more:
#                 flagged); an isotropic basis (order = degree) is capped by MAX_DEGREE
DEGREE_STEP, ORDER_STEP = 8, 2  # the smallest increments; larger ones where the decay asks for them


def _increment(maxima: np.ndarray, target: float, step: int, most: int) -> int:
    """How far to extend a spectrum whose largest coefficient per index is ``maxima`` (the last ones being the tail)
    for its predicted tail to fall below ``target``: geometric decay fitted to the last four indices, rounded up to
    a multiple of ``step``, at least ``step`` and at most ``most``."""
    tail = np.maximum(maxima[-4:], 1e-300)
    rate = np.polyfit(np.arange(tail.size), np.log(tail), 1)[0]
    if rate >= 0.0:
        return most
    needed = np.log(target / tail[-1]) / rate
    return int(min(most, max(step, step * np.ceil(needed / step))))


def refined(basis: SphericalBasis, c: np.ndarray, max_error: float) -> SphericalBasis | None:
    """The next finer basis when a tail of c exceeds ``max_error`` (``surface.measures.tails``): the degree and the
    order extended as far as the fitted decay of the coefficients predicts is needed for a tail of max_error/4
    (an isotropic basis stays isotropic); the same basis when both tails are below max_error, None when the degree
    would pass MAX_DEGREE or a capped order MAX_ORDER."""
    theta, phi = tails(basis, c)
    degree, order = basis.degree, basis.order
    if theta > max_error:
        by_degree = np.array([max((abs(c[b.offset + i]) for b in basis.blocks for i, l in enumerate(b.degrees)
                                   if l == degree_), default=0.0) for degree_ in range(basis.degree + 1)])
        degree += _increment(by_degree, max_error / 4, DEGREE_STEP, 4 * DEGREE_STEP)
        order = degree if basis.order == basis.degree else order
    if phi > max_error:
        by_order = np.array([max((np.abs(c[b.slice]).max() for b in basis.blocks if b.m == m), default=0.0)
                             for m in range(basis.order + 1)])
        order = min(order + _increment(by_order, max_error / 4, ORDER_STEP, 4 * ORDER_STEP), degree)
    if degree > MAX_DEGREE or (order < degree and order > max(MAX_ORDER, basis.order)):
        return None
    if (degree, order) == (basis.degree, basis.order):
        return basis
    return replace(basis, degree=degree, order=order, n_theta=0, n_phi=0)


def remapped(basis: SphericalBasis, c: np.ndarray, coils) -> SphericalBasis:
    """``basis`` on the wire map of the state c's own closest approaches to the wires (analysis.wires: the
    axisymmetric solver's widths, centres mirrored on a basis that keeps z → −z or the inversion) when that map is
    not ``close_to`` the basis' own: a state that moves toward a wire on one side needs a narrower map than the
    branch point's. ``basis`` itself without a map or without coils."""
    if basis.mapping is None or not len(coils):
        return basis
    found = wires.surface_approaches(basis.node_state(c), np.repeat(basis.nodes["cos_theta"], basis.n_phi), coils)
    mapping = wires.centred_map(found, [wires.map_width(a) for a in found],
                                any(S[2] < 0 for S in basis.symmetry))
    if mapping is None or mapping.close_to(basis.mapping):
        return basis
    return replace(basis, mapping=mapping)


class SurfaceTrace:
    """The problem of one surface branch on one basis: the equilibrium, gauge and continuation system at the
    branch's parameters."""

    def __init__(self, scene, basis: SphericalBasis, params: Parameters):
        self.scene, self.basis = scene, basis
        self.eq = SurfaceEquilibrium(scene, basis)
        self.gauge = Gauge(basis, held=True, in_field=surface_stability.in_field(self.eq, params))
        self.system = SurfaceSystem(self.eq, self.gauge, params, "P")

    def on(self, basis: SphericalBasis) -> "SurfaceTrace":
        return SurfaceTrace(self.scene, basis, self.system.params)

    def move(self, X: np.ndarray, to: "SurfaceTrace") -> np.ndarray:
        """A point X = (a, p) of this trace's system on ``to``'s (its coefficients transferred)."""
        return to.system.point(transfer(self.basis, self.system.coefficients(X), to.basis), X[-1])

    def move_direction(self, t: np.ndarray, to: "SurfaceTrace") -> np.ndarray:
        """A direction (δa, δp) on ``to``'s system (linear: the transfer of δc without the reference sphere)."""
        zero = transfer(self.basis, np.zeros(self.basis.size), to.basis)
        moved = transfer(self.basis, self.system.gauge.expand(t[:-1]), to.basis) - zero
        return np.append(to.gauge.reduce(moved), t[-1])


def initial_basis(scene, disc, u, symmetry: tuple) -> SphericalBasis:
    """The basis of a branch's start: degree surface.degree on the axisymmetric state's wire map (isotropic without
    one, order min(degree, 6) with one: a field's fine features are in θ), refined until the embedded state's
    tails are below solver.max_error / 10 (``refined``); SurfaceStartError past MAX_DEGREE."""
    degree = scene.surface.degree
    order = degree if disc.mapping is None else min(degree, 6)
    basis = SphericalBasis(degree, symmetry, order=order, mapping=disc.mapping)
    while True:
        finer = refined(basis, axisymmetric_coefficients(basis, disc, u), scene.solver.max_error / 10)
        if finer is None:
            raise SurfaceStartError(f"the branch point's state needs a whole-sphere degree above {MAX_DEGREE} "
                                    f"(tails {tails(basis, axisymmetric_coefficients(basis, disc, u))})")
        if finer is basis:
            return basis
        basis = finer


def _stop_rule(trace: SurfaceTrace, direction: np.ndarray, X_star: np.ndarray):
    """stop(point) -> Stop or None (module docstring); StopCode.RESOLUTION when a tail exceeds solver.max_error."""
    scene, basis = trace.scene, trace.basis
    upper, gap = scene.continuation.stop_stretch, scene.continuation.wire_gap
    coils = [[k.radius, k.height, k.current] for k in scene.field.coils]

    def stop(point):
        if direction @ (point.X - X_star) < 0:
            return Stop(StopCode.REJOINED, "rejoined the axisymmetric branch")
        c = trace.system.coefficients(point.X)
        m = measures(basis, c)
        if m["lam_north"] >= upper:
            return Stop(StopCode.STOP_STRETCH, f"north pole stretch reached stop_stretch {upper:g}")
        if m["lam_south"] >= upper:
            return Stop(StopCode.SOUTH_STOP_STRETCH, f"south pole stretch reached stop_stretch {upper:g}")
        if coils:
            x = trace.eq.node_values(c)["state"][:3]
            distance = float(wire_distance(np.hypot(x[0], x[1]), x[2], coils).min())
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
    """The first point off the axisymmetric branch along φ (unit, in X = (a, P)), or the NewtonResult that failed."""
    solver = trace.scene.solver
    guess = X_star + step * phi
    result = newton(trace.system.residual, trace.system.jacobian, guess, phi, phi @ guess, solver.tol,
                    solver.max_newton)
    if not result.converged:
        return result
    return continuation.Point(result.x, continuation.tangent(trace.system, result.x, phi), result.iterations,
                              result.residual)


@limited_blas
def trace_surface(branch: Branch, number: int, bp: SpecialPoint, sign: float, name: str, max_points: int,
                  progress=None) -> SurfaceBranch:
    """The branch born at the branch point ``bp`` (number ``number`` in ``branch.branch_points()``) of ``branch``
    along sign·φ (module docstring); SurfaceStartError when it cannot start."""
    t0 = time.perf_counter()
    scene = branch.scene
    az_basis, vector = critical_mode(branch, bp, scene.stability.degree)
    symmetry = mode_symmetry(branch, az_basis, vector, scene.surface.degree)
    params = branch.params_at(bp.X)
    try:
        trace = SurfaceTrace(scene, initial_basis(scene, branch.disc, bp.X[:-1], symmetry), params)
    except NotImplementedError as error:  # codegen: no whole-sphere kernels for a formula in the stretches yet
        raise SurfaceStartError(f"no whole-sphere kernels for this material: {error}") from None
    c_star = axisymmetric_coefficients(trace.basis, branch.disc, bp.X[:-1])
    # point 0: the axisymmetric state as the whole-sphere solution at P* (its truncation differs), or, where Newton
    # does not converge at the branch point (its Jacobian is singular there), the embedded state itself; its
    # residual is stored either way
    X_star = trace.system.point(c_star, bp.X[-1])
    solved = trace.system.solve(X_star, scene.solver.tol, scene.solver.max_newton)
    if solved.converged:
        X_star, c_star = solved.x, trace.system.coefficients(solved.x)
    phi = np.append(trace.gauge.reduce(mode_coefficients(trace.basis, az_basis, vector)), 0.0)
    phi = sign * phi / np.linalg.norm(phi)
    E, kind = classify(trace, X_star, phi)
    origin = replace(bp, index=0, X=np.append(c_star, bp.X[-1]), E=E, classification=kind, mode=None,
                     note=f"born here: branch point {number} of {branch.name} (m = {bp.m})")
    first = switch(trace, X_star, phi)
    if not isinstance(first, continuation.Point):
        raise SurfaceStartError(f"the first correction from branch point {number} along its m = {bp.m} mode did "
                                f"not converge: {first.message}")
    start = continuation.Point(X_star, phi, 0, float(np.abs(trace.system.residual(X_star)).max()))
    segments, folds = [(trace, [start])], []
    while True:
        done = sum(len(points) for _, points in segments)
        settings = continuation_settings(scene, max(max_points - done, 1))
        path = continuation.trace(trace.system, first, settings, _stop_rule(trace, phi, X_star),
                                  {Kind.LP: np.eye(X_star.size)[-1]}, progress)
        folds += [(trace, replace(f, index=f.index + done)) for f in path.folds]
        segments[-1][1].extend(path.points)
        stop = path.stop
        if stop.code == TraceStop.MAX_POINTS:
            stop = Stop(TraceStop.MAX_POINTS, f"maximum number of points ({max_points}) reached")
        if stop.code != StopCode.RESOLUTION:
            break
        c = trace.system.coefficients(path.overshoot.X)
        target = remapped(trace.basis, c, scene.field.coils)
        finer = refined(target, c if target is trace.basis else transfer(trace.basis, c, target),
                        scene.solver.max_error)
        if finer is None:
            stop = Stop(StopCode.RESOLUTION_LIMIT, stop.message + f" (the basis would pass degree {MAX_DEGREE} or "
                                                                  f"order {MAX_ORDER})")
            break
        new = trace.on(finer)
        last = segments[-1][1].pop()  # solved again on the finer basis: the first point of the next segment
        X = newton(new.system.residual, new.system.jacobian, trace.move(last.X, new), np.eye(new.gauge.size + 1)[-1],
                   last.X[-1], scene.solver.tol, scene.solver.max_newton)
        if not X.converged:
            segments[-1][1].append(last)
            stop = Stop(StopCode.REFINE_FAILED, f"Newton failed on the refined basis (degree {finer.degree}, order "
                                                f"{finer.order}): {X.message}")
            break
        reference = trace.move_direction(last.tangent, new)
        first = continuation.Point(X.x, continuation.tangent(new.system, X.x, reference), X.iterations, X.residual)
        phi, X_star = trace.move_direction(phi, new), trace.move(X_star, new)
        trace = new
        segments.append((trace, []))
    return _branch(trace, segments, folds, stop, branch, number, origin, name, t0)


def _branch(trace: SurfaceTrace, segments, folds, stop, parent: Branch, number: int, bp: SpecialPoint, name: str,
            t0) -> SurfaceBranch:
    """The SurfaceBranch of the traced segments, every point on the final basis: measures, folds, end point; the
    stability of each point read on the basis it was traced on (``assess``)."""
    basis = trace.basis
    coefficients = np.array([transfer(t.basis, t.system.coefficients(p.X), basis) if t is not trace
                             else t.system.coefficients(p.X) for t, points in segments for p in points])
    values = np.array([p.X[-1] for _, points in segments for p in points])
    per_point = [measures(basis, c) for c in coefficients]
    first_basis = segments[0][0].basis
    if first_basis is not basis:  # the origin was made on the first basis
        bp = replace(bp, X=np.append(transfer(first_basis, bp.X[:-1], basis), bp.X[-1]))
    special = [bp] + [SpecialPoint(Kind.LP, f.index, np.append(transfer(t.basis, t.system.coefficients(f.point.X),
                                                                        basis), f.point.X[-1]),
                                   status=Status.LOCATED if f.status == continuation.RootStatus.LOCATED
                                   else Status.APPROXIMATE) for t, f in folds]
    special.append(SpecialPoint(Kind.EP, len(values) - 1, np.append(coefficients[-1], values[-1]), stop=stop))
    out = SurfaceBranch(
        name=name, scene=parent.scene, basis=basis, kernel_class=parent.kernel_class,
        kernel_signature=trace.eq.kernels.signature, params=parent.params, coefficients=coefficients, values=values,
        iterations=np.array([p.iterations for _, points in segments for p in points]),
        residual=np.array([p.residual for _, points in segments for p in points]),
        error_estimate=np.array([tail(basis, c) for c in coefficients]),
        measures={key: np.array([m[key] for m in per_point]) for key in MEASURES}, m=bp.m,
        parent=(parent.name, number), legs=(Leg("forward", stop),), special=special)
    assess(out, [(t, t.system.coefficients(p.X)) for t, points in segments for p in points])
    out.wall_time = time.perf_counter() - t0
    return out


def assess(sb: SurfaceBranch, traced: list) -> None:
    """The stability readings of every point (held and free, under pressure, volume and gas control:
    ``surface.stability.READINGS``) and the secondary branch points: where the number of negative held eigenvalues
    of a sector under pressure control changes between points i and i + 1 (i ≥ 1: point 0 is the parent point),
    the zero of the crossing eigenvalue, located by Brent's method along the chord with the corrector on its
    hyperplane (as azimuthal_points.locate); APPROXIMATE with the bracket when the search fails. ``traced``: per
    point, (the SurfaceTrace it was traced on, its coefficients there): a point is read on its own basis (resolved
    there; the final basis of a branch that refined is several times larger than its first points need)."""
    held = surface_stability.Reading(True)
    readings = {r: [] for r in surface_stability.READINGS}
    counts, held_spectra, spectra = [], [], None
    for (trace, c), value in zip(traced, sb.values):
        params = sb.params.with_value(sb.parameter, value)
        spectra = surface_stability.sector_spectra(trace.eq, c, params, STABILITY_COUNT, readings, guesses=spectra)
        for r in readings:
            readings[r].append(surface_stability.lowest_over(spectra[r], STABILITY_COUNT))
        counts.append(_negative_counts(trace, c, params, spectra[held]))
        held_spectra.append(spectra[held])
    sb.stability = {r.name: np.array(rows) for r, rows in readings.items()}
    for i in range(1, len(counts) - 1):
        for key in counts[i]:
            if counts[i][key] != counts[i + 1][key]:
                sb.special.append(_secondary(sb, traced, i, key, min(counts[i][key], counts[i + 1][key]),
                                             float(held_spectra[i][key][0])))
    sb.special.sort(key=lambda s: s.index)


def _negative_counts(trace: SurfaceTrace, c, params, lowest: dict) -> dict:
    """{characters: the number of negative held eigenvalues of the sector}: from its lowest STABILITY_COUNT, or,
    when they are all negative, from the inertia of its matrix (numerics.eigen.negative_count)."""
    counts = {}
    for key, values in lowest.items():
        counts[key] = int((values < 0).sum())
        if counts[key] == values.size:
            held = surface_stability.Reading(True)
            A = surface_stability.restricted_sectors(trace.eq, c, params, (held,), key)[held][key]
            counts[key] = eigen.negative_count(A)
    return counts


def _secondary(sb: SurfaceBranch, traced: list, i: int, sector: tuple, k: int, lowest: float) -> SpecialPoint:
    """The secondary branch point between points i and i + 1 where eigenvalue k of ``sector`` crosses zero, searched
    on the basis of point i + 1 (``lowest``: the sector's lowest eigenvalue at point i, which the spectra follow)."""
    (before, c0), (trace, c1) = traced[i], traced[i + 1]
    if before is not trace:
        c0 = transfer(before.basis, c0, trace.basis)
    system, solver = trace.system, trace.scene.solver
    X0, X1 = system.point(c0, sb.values[i]), system.point(c1, sb.values[i + 1])
    chord = X1 - X0
    d = chord / np.linalg.norm(chord)
    held = surface_stability.Reading(True)

    def value_at(s):
        result = newton(system.residual, system.jacobian, X0 + s * d, d, d @ X0 + s, solver.tol, solver.max_newton)
        if not result.converged:
            raise ArithmeticError(result.message)
        c, params = system.coefficients(result.x), system.params_at(result.x)
        A = surface_stability.restricted_sectors(trace.eq, c, params, (held,), sector)[held][sector]
        final = c if trace.basis == sb.basis else transfer(trace.basis, c, sb.basis)
        return float(eigen.lowest_following(A, k + 1, lowest)[k]), np.append(final, result.x[-1])

    found = continuation.locate_root(value_at, float(np.linalg.norm(chord)))
    note = f"secondary branch point: held eigenvalue {k} of the symmetry sector {sector} crosses zero"
    if found is not None and found.status == continuation.RootStatus.LOCATED:
        return SpecialPoint(Kind.BP, i, found.payload, m=sb.m, note=note)
    X = np.append(sb.coefficients[i], sb.values[i]) if found is None else found.payload
    return SpecialPoint(Kind.BP, i, X, m=sb.m, status=Status.APPROXIMATE,
                        uncertainty=0.5 * float(abs(sb.values[i + 1] - sb.values[i])),
                        reason="the root search along the chord failed; the nearest evaluated point is stored",
                        note=note)


def classify(trace: SurfaceTrace, X_star: np.ndarray, phi: np.ndarray, delta: float = 2e-2) -> tuple:
    """(E2, E3, E4, Classification) of the reduced energy along the unit mode φ (in a) at P* (module docstring);
    Classification.NONE when fewer than three constrained minimisations converge."""
    system, solver = trace.system, trace.scene.solver
    params = system.params_at(X_star)
    a_star, direction = X_star[:-1], phi[:-1]

    def residual(x):
        return system.gauge.reduce(trace.eq.residual(system.gauge.expand(x[:-1]), params)) + x[-1] * direction

    def jacobian(x):
        H = system.gauge.reduce_matrix(trace.eq.hessian(system.gauge.expand(x[:-1]), params))
        return np.hstack([H, direction[:, None]])

    E0 = trace.eq.energy(system.gauge.expand(a_star), params)
    lams, energies = [], []
    for lam in (-2 * delta, -delta, delta, 2 * delta):
        guess = np.append(a_star + lam * direction, 0.0)
        result = newton(residual, jacobian, guess, np.append(direction, 0.0), direction @ a_star + lam, solver.tol,
                        solver.max_newton)
        if result.converged:
            lams.append(lam)
            energies.append(trace.eq.energy(system.gauge.expand(result.x[:-1]), params) - E0)
    if len(lams) < 3:
        return (np.nan, np.nan, np.nan), Classification.NONE
    L = np.array(lams)
    E2, E3, E4 = linalg.lstsq(np.stack([L**2, L**3, L**4], axis=1), np.array(energies))[0]
    if abs(E3) * delta > abs(E4) * delta**2:
        kind = Classification.TRANSCRITICAL
    else:
        kind = Classification.PITCHFORK_SUPER if E4 > 0 else Classification.PITCHFORK_SUB
    return (float(E2), float(E3), float(E4)), kind


def rotated(branch: SurfaceBranch, name: str) -> SurfaceBranch:
    """The image of ``branch`` under the rotation R by π about the axis, x ↦ R x(R⁻¹X): the other direction −φ of
    its pitchfork (R maps the mode to −itself; coaxial loops and the held gauge are invariant under R). A
    coefficient of e_c Y_{l,m,t} changes by the sign of e_c under R (−1 for x, y) times (−1)^m; P, the pole
    stretches, volume, tilt and every eigenvalue are unchanged, the centroid turns with R."""
    signs = np.concatenate([np.full(len(b.degrees), (-1.0 if b.component < 2 else 1.0) * (-1.0) ** b.m)
                            for b in branch.basis.blocks])
    turn = np.array([-1.0, -1.0, 1.0])
    measures_ = {**branch.measures, "centroid": branch.measures["centroid"] * turn}
    special = [replace(s, X=np.append(s.X[:-1] * signs, s.X[-1])) for s in branch.special]
    return replace(branch, name=name, coefficients=branch.coefficients * signs, measures=measures_, special=special,
                   origin=Origin.REFLECTED, reflection_of=branch.name)
