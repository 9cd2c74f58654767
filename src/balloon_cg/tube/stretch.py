"""A tube whose ends are held apart continued in their held distance λ at a fixed pressure (``continue --parameter
axial_stretch`` from a located point of its primary branch; docs/tubes.md): the ends pulled apart or let together
with P held, the tube's mirror-symmetric states followed through that point.

Unknowns X = (u[even block], λ̄): λ̄ = u[axial_index], fixed on a branch in P (its row, the axial balance, is no
equation: the ends carry the force it takes), is here the continuation parameter; the equations are the even rows
R_e(u; P) = 0 (the odd rows vanish by symmetry), ∂R_e/∂λ̄ the Hessian's column of λ̄ (``StretchSystem``). Traced by
pseudo-arclength continuation from the stored point, λ rising first (``direction`` −1: falling); its folds in λ (LP:
the largest or smallest held distance at which the tube holds P) are located by the tracer's fold monitor on λ̄. It
stops where λ leaves [1, 5] (geometry.axial_stretch's range; the point beyond not stored: IntervalStop.HELD_RANGE),
the largest hoop stretch passes ``stop_stretch`` (HOOP_STRETCH), after ``max_points``, or at the next point after
SIGINT/SIGTERM. At every point, at its λ: the unstable directions under each control (tube/stability.unstable_counts
on the free unknowns), the mirror blocks' spectra and the smallest principal stress. Where a block's count of negative
eigenvalues changes between points, the eigenvalue that crossed is followed to its zero by Brent in the arclength
(tube/zeros.corrected_zero), a branch point (BP) where its null vector is orthogonal to ∂R/∂λ̄ (the odd block's
always: the onset of bulging at P as the ends are moved), the fold otherwise (not kept: the LP is the monitor's).
On sliding ends every state is the uniform tube at λz = λ with P = Φ_2(λz, λθ)/(λθλz) (tests/test_held_stretch.py).
"""
from dataclasses import replace

import numpy as np

from .events import along
from .primary import volume_ratio
from .results import IntervalBranch, IntervalSpecial, IntervalStop, signalled
from .stability import smallest_stress, spectrum, unstable_counts
from .zeros import corrected_zero, is_fold, off_mode_corrector
from ..analysis.branches.problem import continuation_settings
from ..analysis.stability.crossings import count_changes
from ..analysis.results import Kind
from ..galerkin.equilibrium import Equilibrium, Parameters
from ..galerkin.interval import Mirror
from ..numerics import continuation
from ..numerics.continuation import Stop
from ..numerics.threads import limited_blas
from ..scene.tables import MAX_AXIAL, MIN_AXIAL


class StretchSystem:
    """R_e(u; P) at the fixed ``params`` as a map of X = (u[even block], λ̄) (module docstring); ``full(X)`` is u."""

    def __init__(self, eq: Equilibrium, params: Parameters):
        disc = eq.disc
        self.eq, self.params, self.size = eq, params, disc.size
        self.even = disc.block(Mirror.EVEN)
        self.unknowns = np.append(self.even, disc.axial_index)

    def full(self, X) -> np.ndarray:
        u = np.zeros(self.size)
        u[self.unknowns] = X
        return u

    def residual(self, X):
        return self.eq.residual(self.full(X), self.params)[self.even]

    def jacobian(self, X):
        return self.eq.jacobian(self.full(X), self.params)[np.ix_(self.even, self.unknowns)]


@limited_blas
def stretch_branch(scene, disc, u: np.ndarray, pressure: float, direction: float = 1.0) -> IntervalBranch:
    """The held tube continued in λ at ``pressure`` from the mirror-symmetric state ``u`` on ``disc`` (a stored
    point's), λ rising (``direction`` 1) or falling (−1) first (module docstring)."""
    if not disc.held:
        raise ValueError("a continuation in axial_stretch needs the ends held apart (geometry.axial_stretch)")
    eq = Equilibrium(scene, disc)
    params = Parameters(pressure, scene.field.M, scene.field.chi, scene.voltage)
    system = StretchSystem(eq, params)
    settings = continuation_settings(scene)
    X = u[system.unknowns]
    start_residual = float(np.abs(system.residual(X)).max())
    if not start_residual <= scene.solver.tol * max(1.0, pressure):  # the start is stored as the branch's first point
        raise ValueError(f"the start is no equilibrium of this scene at P = {pressure:.10g} (residual "
                         f"{start_residual:.3g} > solver.tol {scene.solver.tol:g}): a stored point of another scene?")
    t = continuation.tangent(system, X, direction * np.eye(X.size)[-1])
    first = continuation.Point(X, t, 0, start_residual)
    limit = scene.continuation.stop_stretch

    def stop(point):
        if (interrupted := signalled()) is not None:
            return interrupted
        stretch = float(point.X[-1])
        if not MIN_AXIAL <= stretch <= MAX_AXIAL:
            return Stop(IntervalStop.HELD_RANGE, f"axial_stretch left [{MIN_AXIAL:g}, {MAX_AXIAL:g}] "
                                                 f"({stretch:.6g}) at P = {pressure:g}")
        hoop = disc.node_state(system.full(point.X))[0].max()
        if hoop > limit:
            return Stop(IntervalStop.HOOP_STRETCH, f"the largest hoop stretch {hoop:.6g} passed stop_stretch {limit:g}")
        return None

    path = continuation.trace(system, first, settings, stop, {Kind.LP: np.eye(X.size)[-1]})
    states = np.array([system.full(p.X) for p in path.points])
    full = [np.append(s, pressure) for s in states]
    spectra = {block: np.array([spectrum(eq, Y, disc.block(block), params) for Y in full]) for block in Mirror}
    found = [(Kind(f.label), system.full(f.point.X), f.index, f.status, None) for f in path.folds]
    for block in Mirror:
        for i, order in count_changes((spectra[block] < 0).sum(axis=1)):
            zero = _branch_point(system, path.points[i], path.points[i + 1], block, order, settings)
            if zero is not None:
                found.append((Kind.BP, zero[0], i, zero[1], block))
    special = [IntervalSpecial(kind, s, pressure, i, status, block, smallest_stress(eq, s))
               for kind, s, i, status, block in found]
    branch = IntervalBranch(disc, states, np.full(len(states), pressure),
                            np.array([volume_ratio(eq, Y) for Y in full]),
                            {block: values[:, 0] for block, values in spectra.items()},
                            unstable_counts(eq, full, params), (), path.stop,
                            np.array([smallest_stress(eq, s) for s in states]), params, stretched=True)
    return replace(branch, special=tuple(sorted(special, key=lambda s: along(branch, s))))


def _branch_point(system: StretchSystem, before, after, block: Mirror, order: int, settings) -> tuple | None:
    """(u, status) where the eigenvalue number ``order`` of ``block`` vanishes between two points of the trace, by
    Brent in the arclength from ``before`` (near a zero of the even block, the branch's own unknowns, Keller's
    corrector may diverge: then tube/zeros.off_mode_corrector along the crossing eigenvalue's vector at ``before``,
    as tube/primary's); None where it is the fold in λ (the null vector not orthogonal to ∂R/∂λ̄, the Hessian's
    column of λ̄)."""
    eq, params = system.eq, system.params
    index, k = eq.disc.block(block), eq.disc.axial_index
    fallback = None
    if block == Mirror.EVEN:
        H = eq.jacobian(system.full(before.X), params)[np.ix_(system.even, system.even)]
        mode = np.append(np.linalg.eigh(H)[1][:, order], 0.0)
        fallback = lambda predictor: off_mode_corrector(system, predictor, before.tangent, mode, settings)  # noqa: E731
    root = corrected_zero(system, settings, before.X, before.tangent, float(before.tangent @ (after.X - before.X)),
                          lambda u: spectrum(eq, np.append(u, params.P), index, params)[order], fallback=fallback)
    if root is None:
        return None
    u = root.payload
    if is_fold(eq, u, params, eq.jacobian(u, params)[:, k], index, order):
        return None
    return u, root.status
