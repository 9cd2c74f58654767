"""Branch switching at a pear branch point: the bifurcating branch and its mirror image.

From u* + δφ (φ the critical mode, ±), corrected on the hyperplane normal to φ, then pseudo-arclength in the
general (non-symmetric) space, balloon held (``bifurcation.general_tracer``), until it rejoins the primary
branch (the amplitude φ·(u − u*) changes sign: a closed loop, the isola, when that happens at another branch
point) or a stop rule applies (those of the primary branch, and the south pole stretch reaching stop_stretch);
it ends exactly on stop_stretch (north or south), or on the loading's stop_volume/stop_amount, when it stops
there.
"""
import time

import numpy as np

from ..numerics import continuation
from ..numerics.continuation import Stop
from ..numerics.newton import newton
from .assembly import assemble
from .bifurcation import general_tracer, mode_direction, plain_degree, to_general
from .control import landing
from .primary import stop_rule
from .results import Branch, SpecialPoint, StopCode
from ..numerics.threads import limited_blas


@limited_blas
def trace_pear(branch: Branch, bp: SpecialPoint, sign: float, name: str, progress=None,
               delta: float = 1e-3) -> Branch | None:
    """The bifurcating branch leaving ``bp`` along sign·φ until it rejoins or stops; None if the first
    correction fails."""
    t0 = time.perf_counter()
    scene = branch.scene
    tracer = general_tracer(scene)
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
    base = stop_rule(scene, scene.continuation.stop_stretch)
    anchors = {}

    def stop(disc, point):
        if disc not in anchors:
            coarse = system.eq.disc
            anchors[disc] = (coarse.transfer(phi, disc), coarse.transfer(X_star, disc))
        direction, star = anchors[disc]
        if direction @ (point.X - star) < 0:
            return Stop(StopCode.REJOINED, "rejoined the primary branch")
        south = float(disc.pole_rows()["lam2_south"] @ point.X[:-1])
        if south >= scene.continuation.stop_stretch:
            return Stop(StopCode.SOUTH_STOP_STRETCH,
                        f"south pole stretch reached stop_stretch {scene.continuation.stop_stretch:g}")
        return base(disc, point)

    stretch = scene.continuation.stop_stretch
    land_on = {StopCode.STOP_STRETCH: ("lam2_north", stretch), StopCode.SOUTH_STOP_STRETCH: ("lam2_south", stretch),
               StopCode.MIN_STRETCH: ("lam2_north", scene.continuation.min_stretch)} | landing(scene.loading)
    return assemble(tracer, params, name, tracer.leg(start, params, stop, progress, degree=degree), t0=t0,
                    land_on=land_on)
