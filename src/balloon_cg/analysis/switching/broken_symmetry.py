"""The pear branch a broken equator symmetry disconnects, found by continuation in the coil heights.

A field off the equatorial plane breaks the pitchfork of the pear mode: one half of the pear branch joins the
primary branch, the other is disconnected from it, so no trace from the primary branch meets it. It is found from
the scene's symmetric relative, its coils' heights h_i scaled to t·h_i, at t = 0 (``symmetric_relative``): there
the held reading's first pear pitchfork is located and each half of its pear branch is traced (``bifurcation``,
``switching``) up to its first point of pear amplitude |A| ≥ SEED_AMPLITUDE (A = λ2(0) − λ2(π)), the seed, which
is continued in t from 0 to 1 at that amplitude, the pressure free,

    R(u, P; t) = 0,   A(u) = A_seed,

by Newton from the previous t (steps of 1/HEIGHT_STEPS, halved on failure down to MIN_STEP), on a plain general
basis (balloon held) of the degree the seed was computed at. At t = 1 a continued point within ON_BRANCH of the primary
branch (the polyline of its points in (P, λ2(0), λ2(π)), max norm) lies on it: the half that joins the primary
branch. The other is traced in P both ways from its continued point (held, stop rules of the primary branch and
the south pole reaching stop_stretch), its user points (``events``) located, and stored with origin
``Origin.CONTINUED_IN_HEIGHT`` (``broken_pear``). The two halves run on every core. Its legs start on the wire map
of the continued point's own state at the scene's degree (``wires.wire_map``, corrected there at its P: the tracer
refines from it as the primary branch's does), not on the seed's plain basis, whose degree is the relative's pear
branch's near its wire (320 in docs/numerics.md §6's off-equator scene: the legs 17× and their assessment 9× the
mapped start's CPU); where no wire gets a map, or the corrector does not converge there, on the plain basis.
"""
import enum
import time

import numpy as np

from ...galerkin.equilibrium import Equilibrium
from ...numerics import continuation, workers
from ...numerics.continuation import Stop
from ...numerics.newton import newton
from ...numerics.threads import limited_blas
from ..points import branch_points as bifurcation
from ..points.branch_points import general_tracer, plain_degree
from ..branches.assembly import assemble
from ..branches.events import with_events
from ..branches.primary import trace_primary
from ..branches.wires import wire_map
from ..branches.problem import ParameterSystem
from ..results import Block, Branch, Origin
from ..stability.axisymmetric import assess_branch, assessment_cost
from .pear import pear_landing, pear_leg, pear_stop_rule
from ..branches.tracer import Tracer

SEED_AMPLITUDE = 1.0  # |λ2(0) − λ2(π)| of the point continued in the coil heights: far from the primary branch
HEIGHT_STEPS = 10  # the first steps in t: 1/HEIGHT_STEPS
MIN_STEP = 1e-3  # a step in t halved below this: the continuation failed
ON_BRANCH = 1e-2  # max-norm distance in (P, λ2(0), λ2(π)) below which a continued point lies on the primary branch
SIGNS = (1.0, -1.0)  # the halves of the pear branch (along ±φ), the legs of the trace in P (±dP)
TRACE_ASSESSMENTS = 10  # a half costs at least ten assessments at its degree: tens of points, each factoring
#                         a Jacobian the size of an assessment's block (``workers.spread``'s cost)


class HomotopyError(RuntimeError):
    """The disconnected branch could not be found; the message says where the search stopped."""


def symmetric_relative(scene, t: float = 0.0):
    """The scene with every coil's height scaled by ``t`` (t = 0: every coil in the equatorial plane)."""
    return scene.with_overrides({f"field.coils[{i}].height": t * coil.height
                                 for i, coil in enumerate(scene.field.coils)}, name=scene.name)


def pitchfork(scene):
    """(the held primary branch of the symmetric relative, assessed; its first held pear pitchfork, located), or
    None when it has none (then there is no pear branch to break)."""
    relative = symmetric_relative(scene)
    primary = trace_primary(relative)
    primary.stability, _ = assess_branch(primary, relative.stability.degree, True)
    events = [e for e in bifurcation.detect(primary, primary.stability) if e[1] == Block.ODD_HELD]
    if not events:
        return None
    return primary, bifurcation.locate(primary, *events[0])


class SeedStop(enum.StrEnum):
    """Why a half of the symmetric relative's pear branch stopped early (``seed``)."""

    WIDE = "wide"  # a point of pear amplitude |A| ≥ SEED_AMPLITUDE: the seed


@limited_blas
def seed(scene, relative: Branch, bp, sign: float) -> tuple:
    """The half ``sign`` of the symmetric relative's pear branch at ``bp``, traced to its first point X = (u, P) of
    pear amplitude |A| ≥ SEED_AMPLITUDE (a refined basis' first point included): (X on the plain general held basis
    of the degree it was computed at, the branch's parameters); HomotopyError when the half cannot be started or
    stops below that amplitude."""

    def wide(disc, point):
        rows = disc.pole_rows()
        amplitude = (rows["lam2_top"] - rows["lam2_bottom"]) @ point.X[:-1]
        return Stop(SeedStop.WIDE, "the seed's pear amplitude") if abs(amplitude) >= SEED_AMPLITUDE else None

    traced = pear_leg(relative, bp, sign, until=wide)
    if traced is None:
        raise HomotopyError("the pear branch of the symmetric relative could not be started")
    _, leg = traced
    last, path = leg.segments[-1]
    candidates = [(disc, p) for disc, traced_path in leg.segments for p in traced_path.points]
    candidates += [(last, path.overshoot)] if leg.stop.code == SeedStop.WIDE else []
    for disc, point in candidates:
        if wide(disc, point) is not None:
            plain = held_tracer(scene).system(disc.degree, relative.params).eq.disc
            return disc.transfer(point.X, plain), relative.params
    raise HomotopyError(f"the pear branch of the symmetric relative stays below amplitude {SEED_AMPLITUDE:g}")


def held_tracer(scene) -> Tracer:
    """The general layout, balloon held (as the primary branch of a scene without equator symmetry)."""
    return Tracer(scene, symmetric=False, held=True)


def continued(scene, X: np.ndarray, params) -> np.ndarray:
    """The seed X (at t = 0, on a plain general held basis) continued to the scene's coil heights (t = 1) at its
    pear amplitude (module docstring); HomotopyError when a step fails at MIN_STEP."""
    disc = held_tracer(scene).system(_degree(X), params).eq.disc
    rows = disc.pole_rows()
    amplitude = np.append(rows["lam2_top"] - rows["lam2_bottom"], 0.0)
    target, t, step = float(amplitude @ X), 0.0, 1.0 / HEIGHT_STEPS
    while t < 1.0:
        trial = min(t + step, 1.0)
        system = ParameterSystem(Equilibrium(symmetric_relative(scene, trial), disc), params, "P")
        result = newton(system.residual, system.jacobian, X, amplitude, target, scene.solver.tol,
                        scene.solver.max_newton)
        if result.converged:
            X, t = result.x, trial
            continue
        step /= 2
        if step < MIN_STEP:
            raise HomotopyError(f"the continuation in the coil heights failed at t = {trial:.4g} ({result.message})")
    return X


def _mapped_start(scene, tracer: Tracer, X: np.ndarray, params) -> tuple:
    """(system, X) of the legs' start (module docstring): X moved onto the wire map of its state at the scene's
    degree and corrected there at its P, or X on its plain basis where there is no map or no convergence."""
    plain = tracer.system(_degree(X), params)
    mapping = wire_map(plain.eq.disc, X[:-1], scene.field.coils, False)
    if mapping is None:
        return plain, X
    system = tracer.system(scene.solver.degree, params, mapping)
    Y = plain.eq.disc.transfer(X, system.eq.disc)
    landed = newton(system.residual, system.jacobian, Y, np.eye(Y.size)[-1], Y[-1], scene.solver.tol,
                    scene.solver.max_newton)
    return (system, landed.x) if landed.converged else (plain, X)


def _degree(X: np.ndarray) -> int:
    """The degree N of a plain general held layout holding X = (u, P): N + 1 a's and N b's (b_0 pinned)."""
    return (X.size - 1) // 2


def distance_to(branch: Branch, X: np.ndarray, disc) -> float:
    """The max-norm distance in (P, λ2(0), λ2(π)) from X (on ``disc``) to the polyline of ``branch``'s points."""
    rows = disc.pole_rows()
    target = np.array([X[-1], rows["lam2_top"] @ X[:-1], rows["lam2_bottom"] @ X[:-1]])
    poles = branch.pole_values()
    path = np.stack([branch.X[:, -1], poles["lam2_top"], poles["lam2_bottom"]], axis=1)
    a, d = path[:-1], np.diff(path, axis=0)
    s = np.clip(np.einsum("ij,ij->i", target - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    return float(np.abs(a + s[:, None] * d - target).max(axis=1).min())


def half(scene, relative: Branch, bp, primary: Branch, sign: float):
    """The half ``sign`` of the symmetric relative's pear branch at ``bp`` (``seed``) continued to the scene's coil
    heights: (X, its parameters, whether X lies on ``primary``: within ON_BRANCH of it), or the HomotopyError that
    stopped it, returned (a half is needed only when the halves before it lie on the primary branch)."""
    try:
        X, params = seed(scene, relative, bp, sign)
        X = continued(scene, X, params)
    except HomotopyError as error:
        return error
    return X, params, distance_to(primary, X, held_tracer(scene).system(_degree(X), params).eq.disc) <= ON_BRANCH


def trace_cost(degree: int) -> float:
    """``workers.spread``'s cost of a trace at ``degree``: TRACE_ASSESSMENTS assessments there."""
    return TRACE_ASSESSMENTS * assessment_cost(degree, 0)


@limited_blas
def broken_pear(scene, primary: Branch, name: str = "broken_pear", progress=None) -> Branch | None:
    """The pear branch the scene's broken equator symmetry disconnects from ``primary`` (module docstring), None
    when the symmetric relative has no pear pitchfork; HomotopyError when it is not found. The two halves (seed and
    continuation in the coil heights) run on every core (``numerics.workers``: the numbers of the serial loop)."""
    t0 = time.perf_counter()
    found = pitchfork(scene)
    if found is None:
        return None
    relative, bp = found
    degree = plain_degree(relative, bp.X)
    general_tracer(scene, bp.block).system(degree, relative.params).eq.disc.projection  # a pseudo-inverse (~1 s
    #   at degree 320) both halves start with (``pear_leg``'s transfer to the plain basis): built here, inherited
    halves = workers.spread(lambda sign: half(scene, relative, bp, primary, sign), SIGNS,
                            [trace_cost(degree)] * len(SIGNS))
    for continued_half in halves:
        if isinstance(continued_half, HomotopyError):
            raise continued_half
        X, params, joins = continued_half
        if not joins:  # the half that joins the primary branch is passed over
            return trace_disconnected(scene, X, params, name, progress, t0)
    raise HomotopyError("both halves of the pear branch, continued in the coil heights, lie on the primary branch")


def trace_disconnected(scene, X: np.ndarray, params, name: str, progress, t0: float) -> Branch:
    """The disconnected branch traced in P both ways from its continued point X (module docstring), in this
    process: a leg that refines onto a wire-mapped basis builds that basis' projection (a pseudo-inverse, ~1 s at
    degree 320), which the assembly here transfers the other points with."""
    tracer = held_tracer(scene)
    system, X = _mapped_start(scene, tracer, X, params)
    pressure, disc = np.eye(X.size)[-1], system.eq.disc
    legs = [tracer.leg(continuation.Point(X, sign * continuation.tangent(system, X, pressure), 0, 0.0), params,
                       pear_stop_rule(scene), progress, degree=disc.degree, mapping=disc.mapping) for sign in SIGNS]
    branch = with_events(assemble(tracer, params, name, legs[0], legs[1], t0, land_on=pear_landing(scene),
                                  labels=("up", "down")))
    branch.origin = Origin.CONTINUED_IN_HEIGHT
    return branch
