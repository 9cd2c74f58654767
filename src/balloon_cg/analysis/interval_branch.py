"""The primary branch of a meridian over an interval (galerkin/interval.py): a tube inflated from its unstressed
reference by continuation in P, its pressure folds and the branch points of its mirror blocks.

The unstressed tube (λ2 = 1, λ̄ = 1, P = 0) is an exact equilibrium. From it the branch is traced by pseudo-arclength
continuation in X = (u, P) (numerics/continuation.py) on the mirror-symmetric states (u restricted to the even block,
interval.Mirror: the odd residual rows vanish there by symmetry, as the sphere's primary branch keeps its equator
symmetry), until the largest hoop stretch at the nodes passes ``continuation.stop_stretch`` (on a tube the north
pole stretch means nothing), or after ``continuation.max_points``; the points located up to stop_stretch are kept,
those in the step that passed it included. Folds in P (LP) are located by the tracer's fold
monitor. At every point the second variation ∂R/∂u (the whole Hessian) is split into its mirror blocks and the
spectrum of each is computed (its lowest eigenvalue stored); where a block's number of negative eigenvalues
changes between neighbours, each eigenvalue that crossed (by its order in the spectrum) is followed to the point
where it vanishes, located by Brent's method in the arclength from the earlier point (``continuation.locate_root``,
each evaluation a Keller corrector), and kept as a branch point (BP) when its null vector φ is orthogonal to ∂R/∂P
(|φ·∂R/∂P| ≤ ORTHOGONAL·|φ||∂R/∂P|); the even block's zero where it is not is the fold in P itself (LP).
Stability at every point (``unstable_counts``): the number of negative eigenvalues of ∂R/∂u under pressure control
(all of u) and under volume control (on δV = ∇V·δu = 0, ∇V = −∂R/∂P), by the inertia of a Bunch–Kaufman
factorisation (numerics/eigen.py: ``restricted`` removes the constraint).

On a tube with sliding closed ends the branch is the uniform tube (model/tube.py's closed-end path, exact in the
basis) and its first odd-block branch point is the onset of the bulge mode cos(πS/L) (model/tube.bulge_onset).
"""
import enum
from dataclasses import dataclass

import numpy as np

from .problem import ParameterSystem, continuation_settings
from .results import Kind
from ..galerkin.equilibrium import Equilibrium, Parameters
from ..galerkin.interval import IntervalDiscretisation, Mirror
from ..numerics import continuation
from ..numerics.continuation import RootStatus, Stop
from ..numerics.eigen import GramFactor, negative_count, restricted
from ..scene.loading import Control
from ..scene.tables import Shape
from ..scene.validation import SceneError

ORTHOGONAL = 1e-6  # |φ·∂R/∂P| relative to |φ||∂R/∂P| below which a block's zero is a branch point, not the fold
BRENT_XTOL = 1e-13  # Brent's tolerance in the arclength, relative to the step


class IntervalStop(enum.StrEnum):
    """Why an interval branch stopped (beside the tracer's TraceStop)."""

    HOOP_STRETCH = "hoop_stretch"  # the largest hoop stretch passed continuation.stop_stretch
    REJOINED = "rejoined"  # a bulge branch met the mirror-symmetric states again (analysis/interval_bulge.py)
    VOLUME = "volume"  # V/V0 passed the stop_volume asked for


@dataclass(frozen=True)
class IntervalSpecial:
    """A located point: LP (fold in P) or BP (``block`` the mirror block whose lowest eigenvalue vanishes), its
    state ``u`` and pressure, between points ``index`` and ``index + 1`` (the last index: in the step that passed
    the stop, whose end is not stored); ``status`` of its location."""

    kind: Kind
    u: np.ndarray
    pressure: float
    index: int
    status: RootStatus
    block: Mirror | None = None


@dataclass(frozen=True)
class IntervalBranch:
    """The points (``states`` rows u, ``pressure``), the enclosed volume over the reference one (V/V0, V0 = πL), the
    lowest eigenvalue of each mirror block at every point (``lowest``: Mirror -> array; empty on a branch without
    mirror symmetry), the number of unstable directions at every point under each control (``unstable``:
    Control.PRESSURE and Control.VOLUME -> int array), the located points and why the trace stopped."""

    disc: IntervalDiscretisation
    states: np.ndarray
    pressure: np.ndarray
    volume: np.ndarray
    lowest: dict
    unstable: dict
    special: tuple
    stop: Stop

    def branch_points(self, block: Mirror | None = None) -> list:
        return [s for s in self.special if s.kind == Kind.BP and (block is None or s.block == block)]


class MirrorSystem:
    """R(u; P) on the mirror-symmetric states: X = (u[even block], P) (module docstring)."""

    def __init__(self, system: ParameterSystem, disc: IntervalDiscretisation):
        self.system, self.even = system, disc.block(Mirror.EVEN)
        self.columns = np.append(self.even, disc.size)
        self.size = disc.size

    def full(self, X) -> np.ndarray:
        Y = np.zeros(self.size + 1)
        Y[self.columns] = X
        return Y

    def residual(self, X):
        return self.system.residual(self.full(X))[self.even]

    def jacobian(self, X):
        return self.system.jacobian(self.full(X))[np.ix_(self.even, self.columns)]


def primary_branch(scene, degree: int | None = None) -> IntervalBranch:
    """The primary branch of a tube scene (module docstring) at Legendre ``degree`` (None: solver.degree)."""
    geometry = scene.geometry
    if geometry.shape != Shape.TUBE:
        raise SceneError(f'geometry.shape = "{geometry.shape.value}": an interval branch is a tube\'s; allowed: "tube"')
    disc = IntervalDiscretisation(scene.solver.degree if degree is None else degree, geometry.length,
                                  scene.solver.quadrature, geometry.ends)
    eq = Equilibrium(scene, disc)
    system = MirrorSystem(ParameterSystem(eq, Parameters(0.0), "P"), disc)
    settings = continuation_settings(scene)
    X = np.append(disc.reference(), 0.0)[system.columns]
    t = continuation.tangent(system, X, np.eye(X.size)[-1])
    start = continuation.Point(X, t, 0, float(np.abs(system.residual(X)).max()))
    limit = scene.continuation.stop_stretch

    def stop(point):
        hoop = eq.disc.node_state(system.full(point.X)[:-1])[0].max()
        if hoop > limit:
            return Stop(IntervalStop.HOOP_STRETCH, f"the largest hoop stretch {hoop:.6g} passed stop_stretch {limit:g}")
        return None

    path = continuation.trace(system, start, settings, stop, {Kind.LP: np.eye(X.size)[-1]})
    reached = path.points + ([path.overshoot] if path.overshoot is not None else [])  # the last step's too
    full = [system.full(p.X) for p in reached]
    spectra = {block: np.array([_spectrum(eq, Y, disc.block(block)) for Y in full]) for block in Mirror}
    special = [IntervalSpecial(Kind.LP, system.full(f.point.X)[:-1], float(f.point.X[-1]), f.index, f.status)
               for f in path.folds]
    for block in Mirror:
        negatives = (spectra[block] < 0).sum(axis=1)
        for i in np.flatnonzero(negatives[:-1] != negatives[1:]):
            for order in range(min(negatives[i:i + 2]), max(negatives[i:i + 2])):
                found = _located_zero(system, eq, reached[i], reached[i + 1], block, order, settings)
                if found is not None:
                    special.append(IntervalSpecial(Kind.BP, found[0][:-1], float(found[0][-1]), int(i), found[1],
                                                   block))
    special = sorted((s for s in special if disc.node_state(s.u)[0].max() <= limit),
                     key=lambda s: _position(system, reached, s))
    full, spectra = full[: len(path.points)], {block: values[: len(path.points)] for block, values in spectra.items()}
    volume = np.array([volume_ratio(eq, Y) for Y in full])
    lowest = {block: spectra[block][:, 0] for block in Mirror}
    return IntervalBranch(disc, np.array([Y[:-1] for Y in full]), np.array([Y[-1] for Y in full]), volume, lowest,
                          unstable_counts(eq, full), tuple(special), path.stop)


def volume_ratio(eq: Equilibrium, Y: np.ndarray) -> float:
    """V/V0 at Y = (u, P), V0 = πL the reference tube's (the volume per 2π: 2V/(2πL))."""
    return 2 * eq.volume(Y[:-1]) / eq.disc.length


def unstable_counts(eq: Equilibrium, points) -> dict:
    """{Control.PRESSURE, Control.VOLUME: the number of negative eigenvalues of ∂R/∂u at each Y = (u, P) of
    ``points``, without and with δV = 0} (module docstring)."""
    counts = {Control.PRESSURE: [], Control.VOLUME: []}
    unit = GramFactor(np.ones(eq.disc.size), orthogonal=True)
    for Y in points:
        params = Parameters(Y[-1])
        H = eq.jacobian(Y[:-1], params)
        counts[Control.PRESSURE].append(negative_count(H))
        gradient = -eq.parameter_derivative(Y[:-1], params, "P")
        counts[Control.VOLUME].append(negative_count(restricted(H, unit, gradient[None, :])))
    return {control: np.array(values, dtype=int) for control, values in counts.items()}


def _position(system: MirrorSystem, points: list, special: IntervalSpecial) -> float:
    """Where a located point lies along the branch: its index plus its arclength from that point along the point's
    tangent, over the step's (the order of points located in one step)."""
    before, after = points[special.index], points[special.index + 1]
    tangent = system.full(before.tangent)
    along = tangent @ (np.append(special.u, special.pressure) - system.full(before.X))
    return special.index + along / (tangent @ (system.full(after.X) - system.full(before.X)))


def _spectrum(eq: Equilibrium, Y: np.ndarray, index: np.ndarray) -> np.ndarray:
    """The eigenvalues (ascending) of the Hessian ∂R/∂u at Y = (u, P) restricted to the unknowns ``index``."""
    H = eq.jacobian(Y[:-1], Parameters(Y[-1]))
    return np.linalg.eigvalsh(H[np.ix_(index, index)])


def _located_zero(system: MirrorSystem, eq: Equilibrium, before, after, block: Mirror, order: int, settings):
    """(Y = (u, P), status) where the eigenvalue number ``order`` (ascending, from 0) of ``block`` vanishes between
    two points, by Brent in the arclength from ``before``; None when it is the fold in P (the null vector not
    orthogonal to ∂R/∂P)."""
    index = eq.disc.block(block)

    def value_at(s):
        result = continuation.correct(system, before.X + s * before.tangent, before.tangent, settings)
        if not result.converged:
            raise ArithmeticError(result.message)
        Y = system.full(result.x)
        return _spectrum(eq, Y, index)[order], Y

    length = float(before.tangent @ (after.X - before.X))
    end = system.full(after.X)
    root = continuation.locate_root(value_at, length, BRENT_XTOL, known={length: (_spectrum(eq, end, index)[order],
                                                                                  end)})
    Y = root.payload
    params = Parameters(Y[-1])
    H = eq.jacobian(Y[:-1], params)[np.ix_(index, index)]
    phi = np.linalg.eigh(H)[1][:, order]
    dP = eq.parameter_derivative(Y[:-1], params, "P")
    if abs(phi @ dP[index]) > ORTHOGONAL * np.linalg.norm(dP):
        return None
    return Y, root.status
