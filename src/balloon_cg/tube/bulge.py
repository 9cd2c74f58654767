"""The branch born at a mirror-odd branch point of a tube's primary branch (tube/primary.py): the bulge.

At a branch point of the odd block (interval.Mirror) the mirror-symmetric branch is crossed by a pitchfork whose states
break the symmetry (u_odd → −u_odd maps it onto its other half, the mirror image). It leaves the branch point X* = (u*,
P*) along the odd block's null vector φ with dP = 0: the first point is the Keller corrector from X* + σ(φ, 0)/|φ| on
the hyperplane normal to (φ, 0) (which the symmetric branch never meets), oriented so that the tube bulges at S = 0
(ρ(0) > ρ(L)), and the trace starts there: at X* itself dP/ds and dV/ds vanish by the symmetry (P and V are even in the
arclength along a pitchfork), so the fold monitors start from the first point. It is traced by pseudo-arclength
continuation in X = (u, P) on every unknown (a held λ̄ stays fixed), its folds in P (LP) and in the enclosed volume (LV:
V/(2π) = −∂E/∂P, whose gradient is −∂R/∂P) located by the tracer's fold monitors, until it rejoins the mirror-symmetric
states (ρ(0) − ρ(L) = −2 Σ_{k odd} a_k changes sign: the bulge has filled the tube and the branch meets the primary
branch again at another odd branch point, the other end of the pitchfork's loop, where P and V are again even in the
arclength: the monitors' sign changes in that last step are that symmetry, not folds, and are not kept), its V/V0 passes
``stop_volume``, its largest hoop stretch ``stop_stretch``, after ``continuation.max_points``, or at the next point
after SIGINT/SIGTERM (StopCode.INTERRUPTED). The branch point X* is
the branch's first point; the stability of every point is ``unstable_counts``' (at X* itself one eigenvalue is zero, its
sign rounding).
"""
import numpy as np

from .primary import TubeSystem, held, stressed, volume_ratio
from .results import IntervalBranch, IntervalSpecial, IntervalStop, signalled
from .stability import smallest_stress, unstable_counts
from ..analysis.branches.problem import ParameterSystem, continuation_settings
from ..analysis.results import Kind
from ..galerkin.equilibrium import Equilibrium
from ..galerkin.interval import Mirror
from ..numerics import continuation
from ..numerics.continuation import Stop
from ..numerics.threads import limited_blas
from ..scene.tables import Ends


@limited_blas
def bulge_branch(scene, primary: IntervalBranch, point: IntervalSpecial, stop_volume: float | None = None,
                 step: float | None = None, stop_stretch: float | None = None) -> IntervalBranch:
    """The branch switched at ``point``, a branch point of the odd block of ``primary`` (module docstring);
    ``step``: the first arclength step (None: continuation.step); ``stop_stretch``: also stop where the largest hoop
    stretch at the nodes passes it."""
    if point.kind != Kind.BP or point.block != Mirror.ODD:
        raise ValueError(f"a bulge branch starts at a branch point of the odd block, not at {point.kind} "
                         f"({point.block})")
    disc = primary.disc
    if disc.ends != Ends.SLIDING:
        raise ValueError(f"a bulge branch is switched on a tube with sliding ends, not {disc.ends.value}")
    eq = Equilibrium(scene, disc)
    odd = disc.block(Mirror.ODD)
    params = primary.params.with_value("P", point.pressure)
    H = eq.jacobian(point.u, params)[np.ix_(odd, odd)]
    phi = np.zeros(disc.size)
    phi[odd] = np.linalg.eigh(H)[1][:, 0]
    odd_hoop = np.arange(1, disc.degree + 1, 2)

    def bulge(u) -> float:
        """ρ(0) − ρ(L) = −2 Σ_{k odd} a_k."""
        return -2 * float(u[odd_hoop].sum())

    if bulge(phi) < 0:
        phi = -phi
    system = TubeSystem(ParameterSystem(eq, params, "P"), disc.free, held(disc))
    settings = continuation_settings(scene)
    settings.step = settings.step if step is None else step
    X = np.append(point.u, point.pressure)[system.columns]
    direction = np.append(phi, 0.0)[system.columns] / np.linalg.norm(phi)
    first = continuation.correct(system, X + settings.step * direction, direction, settings)
    if not first.converged:
        raise ArithmeticError(f"the first step of the bulge branch did not converge: {first.message}")
    start = continuation.Point(first.x, continuation.tangent(system, first.x, direction), first.iterations,
                               first.residual)

    def stop(p):
        if (interrupted := signalled()) is not None:
            return interrupted
        Y = system.full(p.X)
        if bulge(Y[:-1]) < 0:
            return Stop(IntervalStop.REJOINED, "the branch rejoined the mirror-symmetric states")
        if stop_volume is not None and volume_ratio(eq, Y) > stop_volume:
            return Stop(IntervalStop.VOLUME, f"V/V0 passed stop_volume {stop_volume:g}")
        hoop = disc.node_state(Y[:-1])[0].max()
        if stop_stretch is not None and hoop > stop_stretch:
            return Stop(IntervalStop.HOOP_STRETCH, f"the largest hoop stretch {hoop:.6g} passed stop_stretch "
                                                   f"{stop_stretch:g}")
        return None

    def volume_gradient(X):
        Y = system.full(X)
        return np.append(-eq.parameter_derivative(Y[:-1], params.with_value("P", Y[-1]), "P"), 0.0)[system.columns]

    path = continuation.trace(system, start, settings, stop, {Kind.LP: np.eye(X.size)[-1], Kind.LV: volume_gradient})
    last = len(path.points) - 1
    folds = [f for f in path.folds if not (path.stop.code == IntervalStop.REJOINED and f.index == last)]
    special = tuple(IntervalSpecial(Kind(f.label), system.full(f.point.X)[:-1], float(f.point.X[-1]), f.index + 1,
                                    f.status) for f in sorted(folds, key=lambda f: f.index))
    points = [system.full(X)] + [system.full(p.X) for p in path.points]
    return IntervalBranch(disc, np.array([Y[:-1] for Y in points]), np.array([Y[-1] for Y in points]),
                          np.array([volume_ratio(eq, Y) for Y in points]), {}, unstable_counts(eq, points, params),
                          stressed(eq, special), path.stop, np.array([smallest_stress(eq, Y[:-1]) for Y in points]),
                          primary.params)
