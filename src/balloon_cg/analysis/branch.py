"""The primary (axisymmetric) branch: start at the inflated M = 0 sphere, switch the field on, trace in P.

1. Start: the exact sphere (``sphere``) at the scene's start stretch, where the membrane is taut (the
   first-order system is singular at the undeformed state, MODEL.md §4).
2. Field on: natural continuation in M at that pressure from 0 to the scene's M.
3. Pressure: pseudo-arclength in (u, P) downwards to ``min_stretch`` and upwards to ``stop_stretch`` (landing
   exactly on it), ``stop_pressure``, a wire gap or ``max_points``; folds in P (LP) and in the north pole
   stretch (TP) are located and recorded.
4. Resolution: when a point's spectral error estimate exceeds ``solver.max_error`` the Legendre degree grows
   by half (up to ``solver.max_degree``) and the point is recomputed; past that the branch stops, saying so.
   With coils a mapped basis (``wire_map``) clusters the nodes where the membrane is closest to each wire:
   on a resolution stop the map is first re-centred at the same degree (kept if the estimate is below
   max_error/4, at most MAX_RECENTRES times per degree); otherwise the degree grows and the better of the
   current and the re-centred map is kept. Stored points are transferred to the last, finest
   discretisation (exact for the same map: higher coefficients are zero; a projection otherwise).

The equator-symmetric subspace is used whenever the field allows it; without a field the axial translation is
removed from the unknowns; with a field that is not equator-symmetric the balloon is held at the centre
(the translation coefficient b_0 is constrained to zero, a reaction force balances the net magnetic pull).
"""
import time
from dataclasses import dataclass, field

import numpy as np

from ..numerics import continuation
from ..galerkin.coordinate_map import WireMap
from ..galerkin.discretisation import Discretisation
from ..galerkin.equilibrium import Equilibrium, Parameters
from ..numerics.newton import newton
from ..model.sphere import sphere_pressure

RESOLUTION = "resolution"
MAP_WIDTH = 0.4  # map width ε_j per unit gap to wire j (x units); measured best 0.15–0.5 (docs/numerics.md)
MAX_RECENTRES = 6  # re-centrings of the map at one degree before the degree grows
MAP_GAP = 0.5  # wires farther than this from the membrane get no map centre (their field is smooth there)


class ContinuationError(RuntimeError):
    """The branch could not be started or continued; the message says what to change."""


class ParameterSystem:
    """R(u; p) as a map of X = (u, p) for one continuation parameter p ∈ {P, M}."""

    def __init__(self, equilibrium: Equilibrium, params: Parameters, name: str):
        self.eq, self.params, self.name = equilibrium, params, name

    def _params(self, X):
        return self.params.with_value(self.name, X[-1])

    def residual(self, X):
        return self.eq.residual(X[:-1], self._params(X))

    def jacobian(self, X):
        p = self._params(X)
        return np.hstack([self.eq.jacobian(X[:-1], p), self.eq.parameter_derivative(X[:-1], p, self.name)[:, None]])


@dataclass
class SpecialPoint:
    """'LP' fold in P, 'TP' turning point of the north pole stretch, branch points 'pitchfork-super',
    'pitchfork-sub', 'transcritical' (all lie between points ``index`` and ``index + 1``, X is the located
    point), 'EP' end point (X is point ``index``, ``note`` the stop reason)."""

    kind: str
    index: int
    X: np.ndarray
    note: str = ""
    E: tuple = (np.nan, np.nan, np.nan)  # normal-form coefficients E2, E3, E4 at branch points


@dataclass
class Branch:
    """A traced branch: unknowns u and pressure P per point (all converged), solver records, special points."""

    name: str
    equilibrium: Equilibrium
    disc: Discretisation
    params: Parameters  # M and χ of the branch (P varies along it)
    X: np.ndarray  # (n_points, n + 1): (u, P), u at the finest degree used
    iterations: np.ndarray
    residual: np.ndarray
    error_estimate: np.ndarray
    degree: np.ndarray  # Legendre degree each point was solved at
    special: list = field(default_factory=list)
    stop_reason: str = ""
    wall_time: float = 0.0

    @property
    def pressure(self):
        return self.X[:, -1]

    @property
    def converged(self):
        """Every stored point is a converged solution (unconverged corrections are never stored)."""
        return np.ones(len(self.X), dtype=bool)

    def pole_values(self, X=None):
        """dict of λ2 and η at both poles for every point (or for one X)."""
        rows = self.disc.pole_rows()
        U = (self.X if X is None else np.atleast_2d(X))[:, :-1]
        return {name: U @ row for name, row in rows.items()}


def _unit(size, index):
    e = np.zeros(size)
    e[index] = 1.0
    return e


def wire_gap(disc: Discretisation, u, coils, n_theta: int = 361) -> tuple[float, int]:
    """Smallest distance from the membrane profile to a coil wire, and the coil index."""
    if not len(coils):
        return np.inf, -1
    theta = np.linspace(0.0, np.pi, n_theta)
    lam2, _, eta, _ = disc.evaluate(u, theta)
    rho = lam2 * np.sin(theta)
    gaps = [np.hypot(rho - c.radius, eta - c.height).min() for c in coils]
    return float(min(gaps)), int(np.argmin(gaps))


def wire_map(disc: Discretisation, u, coils, symmetric: bool, n_theta: int = 2001) -> WireMap | None:
    """The map clustering a basis at the membrane's closest approach to each wire within MAP_GAP (centres
    x_j = cos θ_j, mirrored ±x_j for an equator-symmetric basis; widths MAP_WIDTH·gap_j); None if there is no
    such wire."""
    if not len(coils):
        return None
    theta = np.linspace(0.0, np.pi, n_theta)
    lam2, _, eta, _ = disc.evaluate(u, theta)
    rho = lam2 * np.sin(theta)
    centres, widths = [], []
    for c in coils:
        distance = np.hypot(rho - c.radius, eta - c.height)
        j = int(np.argmin(distance))
        if distance[j] >= MAP_GAP:
            continue
        x = float(np.clip(np.cos(theta[j]), -0.999, 0.999))
        for centre in ((x, -x) if symmetric and abs(x) > 1e-3 else (x,)):
            if all(abs(centre - other) > 1e-6 for other in centres):
                centres.append(centre)
                widths.append(MAP_WIDTH * float(distance[j]))
    return WireMap(tuple(centres), tuple(widths)) if centres else None


def transfer_error(source: Discretisation, X, target: Discretisation, moved, n_theta: int = 721) -> np.ndarray:
    """Per row: max |Δλ2|, |Δη| / |a_0| on a θ grid between X in ``source`` and ``moved`` = its transfer to
    ``target`` (zero when the transfer is exact: same map, no lower degree)."""
    X, moved = np.atleast_2d(X), np.atleast_2d(moved)
    if source.nests_in(target):
        return np.zeros(len(X))
    theta = np.linspace(0.0, np.pi, n_theta)
    before = source.evaluate(X[:, : source.size], theta)
    after = target.evaluate(moved[:, : target.size], theta)
    difference = np.maximum(np.abs(before[0] - after[0]).max(axis=1), np.abs(before[2] - after[2]).max(axis=1))
    return difference / np.abs(before[0][:, 0])


class PrimaryTracer:
    """Discretisations of growing degree for one scene, and the legs of the primary branch traced on them."""

    def __init__(self, scene, symmetric: bool | None = None, held: bool | None = None):
        """``held``: constrain the axial translation b_0 = 0 (default: with coils that are not equator-symmetric;
        without coils b_0 is always removed, being a zero mode)."""
        self.scene = scene
        if symmetric is None:
            symmetric = scene.continuation.symmetry != "none" and scene.field.is_equator_symmetric
        self.symmetric = symmetric
        if held is None:
            held = bool(scene.field.coils) and not scene.field.is_equator_symmetric
        self.pin = (not scene.field.coils) or held
        c, s = scene.continuation, scene.solver
        self.settings = continuation.Settings(c.step, c.step_min, c.step_max, c.max_points, s.tol, s.max_newton)
        self._systems = {}

    def system(self, degree: int, params: Parameters, mapping: WireMap | None = None) -> ParameterSystem:
        if (degree, mapping) not in self._systems:
            quadrature = self.scene.solver.quadrature if degree == self.scene.solver.degree else 0
            disc = Discretisation(degree, self.symmetric, self.pin, quadrature, mapping)
            self._systems[degree, mapping] = Equilibrium(self.scene, disc)
        return ParameterSystem(self._systems[degree, mapping], params, "P")

    def start(self) -> tuple[np.ndarray, Parameters]:
        """The inflated M = 0 sphere, then the field switched on by natural continuation in M (bounded halving)."""
        scene = self.scene
        eq = self.system(scene.solver.degree, Parameters(0.0)).eq
        disc = eq.disc
        lam = scene.continuation.start_stretch
        a, b = np.zeros(disc.degree + 1), np.zeros(disc.degree + 1)
        a[0], b[1] = lam, lam
        u = disc.join(a, b)
        params = Parameters(sphere_pressure(scene.material, lam), 0.0, scene.field.chi)
        target, M, dM = scene.field.M, 0.0, scene.field.M
        while M < target:
            trial = min(M + dM, target)
            system = ParameterSystem(eq, params, "M")
            result = newton(system.residual, system.jacobian, np.append(u, trial), _unit(u.size + 1, -1), trial,
                            scene.solver.tol, scene.solver.max_newton)
            if result.converged:
                u, M = result.x[:-1], trial
                dM *= 2
            else:
                dM *= 0.5
                if dM < 1e-6 * target:
                    raise ContinuationError(
                        f"could not switch the field on at start stretch {lam}: Newton failed at M = {trial:.6g} "
                        f"({result.message}); try a smaller continuation.start_stretch or a smaller field.M"
                    )
        return np.append(u, params.P), params.with_value("M", target)

    def initial_point(self, X0, direction: float, params: Parameters) -> continuation.Point:
        """X0 with its unit tangent oriented so that the north pole stretch moves in ``direction``."""
        system = self.system(self.scene.solver.degree, params)
        north = np.append(system.eq.disc.pole_rows()["lam2_north"], 0.0)
        return continuation.Point(X0, direction * continuation.tangent(system, X0, north), 0, 0.0)

    def leg(self, start: continuation.Point, params: Parameters, stop, progress=None, degree=None, mapping=None):
        """Trace from ``start`` (at ``degree``, default the scene's, and ``mapping``) along its tangent, refining
        as needed.

        Returns ([(discretisation, path), ...], stop reason).
        """
        degree = degree or self.scene.solver.degree
        max_error, max_degree = self.scene.solver.max_error, self.scene.solver.max_degree
        system = self.system(degree, params, mapping)
        segments, recentres = [], 0
        while True:
            disc = system.eq.disc
            north = np.append(disc.pole_rows()["lam2_north"], 0.0)
            monitors = {"LP": _unit(start.X.size, -1), "TP": north}

            def checked_stop(point, disc=disc):
                if disc.tail(point.X[:-1]) > max_error:
                    return RESOLUTION
                return stop(disc, point)

            path = continuation.trace(system, start, self.settings, checked_stop, monitors, progress)
            segments.append((disc, path))
            if path.stop_reason != RESOLUTION:
                return segments, path.stop_reason
            last = path.points.pop()  # recomputed on the new basis as the next segment's first point
            path.folds = [f for f in path.folds if f.index < len(path.points)]  # later ones are found again
            recentred = wire_map(disc, last.X[:-1], self.scene.field.coils, self.symmetric)
            refined = None
            if recentred is not None and not recentred.close_to(disc.mapping) and recentres < MAX_RECENTRES:
                # first the map re-centred on the closer wire, at the same degree, if it leaves headroom
                refined = self._refine(disc, last, degree, [recentred], params, 0.25 * max_error)
                recentres += not isinstance(refined, str)
            if refined is None or isinstance(refined, str):
                if degree >= max_degree:
                    path.points.append(last)
                    return segments, (
                        f"resolution: spectral error estimate above solver.max_error = {max_error:g} at "
                        f"solver.max_degree = {max_degree}; raise max_degree or shorten the branch"
                    )
                degree, recentres = min(int(degree * 1.5), max_degree), 0
                candidates = [disc.mapping] + ([recentred] if recentred not in (None, disc.mapping) else [])
                refined = self._refine(disc, last, degree, candidates, params, np.inf)
                if isinstance(refined, str):
                    path.points.append(last)
                    return segments, f"could not refine to degree {degree}: {refined}"
            system, result, t = refined
            start = continuation.Point(result.x, continuation.tangent(system, result.x, t), result.iterations,
                                       result.residual)

    def _refine(self, disc: Discretisation, last: continuation.Point, degree: int, mappings, params: Parameters,
                accept: float):
        """``last`` recomputed at ``degree`` on each basis map of ``mappings``: (system, Newton result, tangent
        reference) of the one with the smallest error estimate, if that is ≤ ``accept``; else a message."""
        best, message = None, "no candidate basis"
        for mapping in mappings:
            system = self.system(degree, params, mapping)
            X = disc.transfer(last.X, system.eq.disc)
            t = disc.transfer(last.tangent, system.eq.disc)
            result = newton(system.residual, system.jacobian, X, t, t @ X, self.settings.tol, self.settings.max_newton)
            message = result.message
            if result.converged:
                estimate = system.eq.disc.tail(result.x[:-1])
                if estimate <= accept and (best is None or estimate < best[0]):
                    best = (estimate, system, result, t)
                message = f"error estimate {estimate:.2g} above {accept:.2g}"
        return message if best is None else best[1:]


def _stop_rule(scene, upper: float):
    cont = scene.continuation

    def stop(disc, point):
        stretch = float(disc.pole_rows()["lam2_north"] @ point.X[:-1])
        if stretch >= upper:
            return f"reached stop_stretch {upper:g}"
        if stretch <= cont.min_stretch:
            return f"reached min_stretch {cont.min_stretch:g}"
        if cont.stop_pressure is not None and point.X[-1] >= cont.stop_pressure:
            return f"reached stop_pressure {cont.stop_pressure:g}"
        gap, coil = wire_gap(disc, point.X[:-1], scene.field.coils)
        if gap < cont.wire_gap:
            return f"membrane within wire_gap {cont.wire_gap:g} of coil {coil} (gap {gap:.3g})"
        return None

    return stop


def trace_primary(scene, symmetric: bool | None = None, stop_stretch: float | None = None, down: bool = True,
                  progress=None) -> Branch:
    """Trace the primary branch of a scene (module docstring). ``down=False`` skips the leg below the start."""
    t0 = time.perf_counter()
    tracer = PrimaryTracer(scene, symmetric)
    X0, params = tracer.start()
    upper = scene.continuation.stop_stretch if stop_stretch is None else stop_stretch
    stop = _stop_rule(scene, upper)
    up = tracer.leg(tracer.initial_point(X0, 1.0, params), params, stop, progress)
    below = tracer.leg(tracer.initial_point(X0, -1.0, params), params, stop, progress) if down else None
    return assemble(tracer, params, "primary", up, below, t0, land_on=(upper, scene.continuation.min_stretch),
                    labels=("up", "down"))


def assemble(tracer, params, name, forward, backward=None, t0=0.0, land_on=None,
             labels=("forward", "backward")) -> Branch:
    """One Branch from the legs of a trace: reversed ``backward`` (without its first point), then ``forward``.

    Points are transferred to the finest discretisation used (its degree raised, up to max_degree, while the
    projection would lose more than max_error/2 of any point and raising it helps). With ``land_on`` = (upper,
    lower) north pole stretches, a forward leg that stopped on passing ``upper`` and a backward leg that stopped
    on passing ``lower`` get their exact end points.
    """
    legs = [leg for leg in (backward, forward) if leg is not None]
    # the finest discretisation used (the last one of the most refined leg: its map is the latest)
    used = [d for segments, _ in legs for d, _ in segments]
    disc = [d for d in used if d.degree == max(u.degree for u in used)][-1]
    solver = tracer.scene.solver

    def transferred(target):
        """Per path with points (by id): its points in ``target`` and their projection losses."""
        out = {}
        for segments, _ in legs:
            for coarse, path in segments:
                if path.points:
                    own = np.array([p.X for p in path.points])
                    moved = coarse.transfer(own, target)
                    out[id(path)] = moved, transfer_error(coarse, own, target, moved)
        return out

    def worst(moves):
        return max(loss.max() for _, loss in moves.values())

    moves = transferred(disc)
    while worst(moves) > 0.5 * solver.max_error and disc.degree < solver.max_degree:
        # a narrow final map may not hold the early points: store at a higher degree while that helps
        finer = tracer.system(min(int(disc.degree * 1.5), solver.max_degree), params, disc.mapping).eq.disc
        finer_moves = transferred(finer)
        if worst(finer_moves) >= worst(moves):
            break
        disc, moves = finer, finer_moves
    final = tracer.system(disc.degree, params, disc.mapping)
    finest = disc.degree
    lossy = []  # projection losses above max_error/2

    def collect(segments):
        """Points and folds in ``disc``; a point's error estimate adds its measured projection loss. Losses above
        max_error/2 (a narrow final map at max_degree) are counted for the stop reason."""
        points, folds = [], []
        for coarse, path in segments:
            base = len(points)
            if not path.points:
                continue
            moved, loss = moves[id(path)]
            lossy.extend(float(lost) for lost in loss if lost > 0.5 * solver.max_error)
            for p, X, lost in zip(path.points, moved, loss):
                points.append((X, p, coarse.degree, coarse.tail(p.X[:-1]) + lost))
            folds += [(f.label, base + f.index, coarse.transfer(f.point.X, disc)) for f in path.folds]
        return points, folds

    north = np.append(disc.pole_rows()["lam2_north"], 0.0)

    targets = dict(zip(("reached stop_stretch", "reached min_stretch"), land_on or (None, None)))

    def landed(leg, leg_points):
        """(points, reason) of a leg, with its exact end point when it stopped on passing a ``land_on`` stretch."""
        segments, reason = leg
        target = next((t for key, t in targets.items() if reason.startswith(key)), None)
        if target is None or not leg_points:
            return leg_points, reason
        last_disc, last_path = segments[-1]
        overshoot = last_disc.transfer(last_path.overshoot.X, disc)
        end = _land(final, leg_points[-1][0], overshoot, north, target, tracer.settings)
        if end is None:
            return leg_points, f"could not land on {reason.removeprefix('reached ')} (Newton failed); stopped before it"
        return leg_points + [(end.X, end, finest, disc.tail(end.X[:-1]))], reason

    forward_points, forward_folds = collect(forward[0])
    forward_points, reason = landed(forward, forward_points)
    backward_points, backward_folds, backward_reason = [], [], None
    if backward:
        backward_points, backward_folds = collect(backward[0])
        backward_points, backward_reason = landed(backward, backward_points)
    points = backward_points[:0:-1] + forward_points
    if not points:
        raise ContinuationError(f"{name}: no converged point ({forward[1]})")
    offset = max(len(backward_points) - 1, 0)
    special = [SpecialPoint(kind, offset - index - 1, X) for kind, index, X in backward_folds[::-1]]
    special += [SpecialPoint(kind, offset + index, X) for kind, index, X in forward_folds]
    special.append(SpecialPoint("EP", len(points) - 1, points[-1][0], reason))
    if backward and backward_points:
        special.insert(0, SpecialPoint("EP", 0, points[0][0], backward_reason))
    stop_reason = f"{labels[0]}: {reason}" + (f"; {labels[1]}: {backward_reason}" if backward else "")
    if lossy:
        stop_reason += (f"; {len(lossy)} points stored on the final basis with a projection loss up to "
                        f"{max(lossy):.1g} (in their error estimate)")
    return Branch(
        name=name,
        equilibrium=final.eq,
        disc=disc,
        params=params,
        X=np.array([p[0] for p in points]),
        iterations=np.array([p[1].iterations for p in points]),
        residual=np.array([p[1].residual for p in points]),
        error_estimate=np.array([p[3] for p in points]),
        degree=np.array([p[2] for p in points]),
        special=special,
        stop_reason=stop_reason,
        wall_time=time.perf_counter() - t0,
    )


def _land(system, before, after, row, target, settings):
    """The point with row·X = target between two branch points (Newton from the linear interpolant)."""
    f0, f1 = row @ before, row @ after
    guess = before + (target - f0) / (f1 - f0) * (after - before)
    result = newton(system.residual, system.jacobian, guess, row, target, settings.tol, settings.max_newton)
    if not result.converged:
        return None
    return continuation.Point(result.x, np.zeros_like(result.x), result.iterations, result.residual)
