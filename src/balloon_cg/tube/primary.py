"""The primary branch of a meridian over an interval (galerkin/interval.py): a tube inflated from its unstressed
reference by continuation in P, its pressure folds and the branch points of its mirror blocks.

The unstressed tube (λ2 = 1, λ̄ = 1, P = 0) is an exact equilibrium; with its ends held at λL
(``geometry.axial_stretch``) the start is the tube stretched to it at P = 0 (``_start``). From it the branch is traced
by pseudo-arclength continuation in X = (u, P) (numerics/continuation.py) on the mirror-symmetric states (u restricted
to the even block, interval.Mirror: the odd residual rows vanish there by symmetry, as the sphere's primary branch keeps
its equator symmetry), until the largest hoop stretch at the nodes passes ``continuation.stop_stretch`` (on a tube the
north pole stretch means nothing), in a coil field where its states turn compressed after being taut
(IntervalStop.COMPRESSED: tube/stability.CompressionStop), after ``continuation.max_points``, or at the next point
after SIGINT/SIGTERM
(numerics.interrupt: StopCode.INTERRUPTED); the points located up to stop_stretch are kept,
those in the step that passed it included. Folds in P (LP) are located by the tracer's fold monitor. At every point the
second variation ∂R/∂u (the whole Hessian) is split into its mirror blocks and the spectrum of each is computed (its
lowest eigenvalue stored); where a block's number of negative eigenvalues changes between neighbours, each eigenvalue
that crossed (by its order in the spectrum) is followed to the point where it vanishes, located by Brent's method in the
arclength from the earlier point (``continuation.locate_root``, each evaluation a Keller corrector), and kept as a
branch point (BP) when its null vector φ is orthogonal to ∂R/∂P (|φ·∂R/∂P| ≤ ORTHOGONAL·|φ||∂R/∂P|, tube/zeros.py); the even block's
zero where it is not is the fold in P itself (LP). Stability at every point: tube/stability.py's ``unstable_counts``.

On a tube with sliding closed ends the branch is the uniform tube (model/tube.py's closed-end path, exact in the
basis) and its first odd-block branch point is the onset of the bulge mode cos(πS/L) (model/tube.bulge_onset).
"""
from dataclasses import replace

import numpy as np

from .control import VolumeStop, control_monitors
from .events import with_events
from .results import IntervalBranch, IntervalSpecial, IntervalStop, signalled
from .stability import CompressionStop, smallest_stress, spectrum, unstable_counts
from .zeros import corrected_zero, is_fold, off_mode_corrector
from ..analysis.stability.crossings import count_changes
from ..analysis.branches.problem import ParameterSystem, continuation_settings
from ..analysis.results import Kind, StopCode
from ..analysis.branches.tracer import ContinuationError
from ..galerkin.equilibrium import Equilibrium, Parameters
from ..galerkin.interval import IntervalDiscretisation, Mirror
from ..galerkin.interval_elements import ElementInterval
from ..numerics import continuation
from ..numerics.continuation import Stop
from ..numerics.threads import limited_blas
from ..numerics.newton import newton
from ..scene.tables import Shape
from ..scene.validation import SceneError



class TubeSystem:
    """R(u; P) on a subset of the unknowns: X = (u[``unknowns``], P), the others at ``fixed`` (u, zero but λ̄ at the
    held ends' distance: the residual's rows of the unknowns only, so that a held λ̄'s row, the axial balance, is
    not an equation). The primary branch takes the even block (the mirror-symmetric states: the odd residual rows
    vanish there by symmetry), the bulge branch every unknown."""

    def __init__(self, system: ParameterSystem, unknowns: np.ndarray, fixed: np.ndarray):
        self.system, self.unknowns = system, unknowns
        self.columns = np.append(unknowns, fixed.size)
        self.fixed = np.append(fixed, 0.0)
        self.sparse = isinstance(system.eq.disc, ElementInterval)  # J sparse: newton factors it by SuperLU
        self.whole = np.array_equal(unknowns, np.arange(fixed.size))

    def full(self, X) -> np.ndarray:
        """Y = (u, P) of X."""
        Y = self.fixed.copy()
        Y[self.columns] = X
        return Y

    def residual(self, X):
        return self.system.residual(self.full(X))[self.unknowns]

    def jacobian(self, X):
        """∂R/∂X on the unknowns' rows: dense, or on spectral elements a scipy.sparse matrix."""
        if not self.sparse:
            return self.system.jacobian(self.full(X))[np.ix_(self.unknowns, self.columns)]
        J = self.system.sparse_jacobian(self.full(X))
        return J if self.whole else J.tocsr()[self.unknowns][:, self.columns]

    @property
    def jacobian_vector(self):
        """X, v ↦ J(X) v without assembling J (``_jacobian_vector``), on spectral elements: the tracer's tangent is
        then refined on the corrector's factors (numerics/continuation.tangent reads this attribute). On a Legendre
        series there is none (AttributeError): an assembly and a dense solve are cheaper at its sizes (spom1_L10's
        bulge at degree 40: 0.7 s against 1.0 s with it)."""
        if not self.sparse:
            raise AttributeError("a tube's Jacobian-vector product serves spectral elements only")
        return self._jacobian_vector

    def _jacobian_vector(self, X, v):
        """J(X) v = (∂R/∂u v_u + ∂R/∂P v_P)[unknowns] (Equilibrium.hessian_product)."""
        Y, direction = self.full(X), np.zeros(self.fixed.size)
        direction[self.columns] = v
        system = self.system
        at = system.params_at(Y)
        product = system.eq.hessian_product(Y[:-1], at, direction[:-1])
        product += direction[-1] * system.eq.parameter_derivative(Y[:-1], at, system.name)
        return product[self.unknowns]


def in_field(scene) -> bool:
    """Whether coils act on the tube (field.M > 0 and at least one coil)."""
    return scene.field.M > 0 and bool(scene.field.coils)


def scene_parameters(scene, pressure: float = 0.0) -> Parameters:
    """The branch parameters of a tube scene at ``pressure``: the field's M and χ (M = 0 without coils) and the
    voltage Φ̄ of [electric] (0 without)."""
    return Parameters(pressure, scene.field.M, scene.field.chi, scene.voltage)


def held(disc: IntervalDiscretisation, stretch: float | None = None) -> np.ndarray:
    """u of the fixed unknowns (``TubeSystem``): zero but λ̄ at ``stretch`` (None: the disc's ``axial_stretch``)."""
    fixed = np.zeros(disc.size)
    if disc.held:
        fixed[disc.axial_index] = disc.axial_stretch if stretch is None else stretch
    return fixed


def discretisation(scene, degree: int | None = None) -> IntervalDiscretisation:
    """The interval discretisation of a tube scene at Legendre ``degree`` (None: solver.degree)."""
    geometry = scene.geometry
    if geometry.shape != Shape.TUBE:
        raise SceneError(f'geometry.shape = "{geometry.shape.value}": an interval branch is a tube\'s; allowed: "tube"')
    return IntervalDiscretisation(scene.solver.degree if degree is None else degree, geometry.length,
                                  scene.solver.quadrature, geometry.ends, geometry.axial_stretch)


@limited_blas
def primary_branch(scene, degree: int | None = None) -> IntervalBranch:
    """The primary branch of a tube scene (module docstring) at Legendre ``degree`` (None: solver.degree)."""
    disc = discretisation(scene, degree)
    eq = Equilibrium(scene, disc)
    params = scene_parameters(scene)
    parameters = ParameterSystem(eq, params, "P")
    system = TubeSystem(parameters, disc.block(Mirror.EVEN), held(disc))
    settings = continuation_settings(scene)
    X = _start(parameters, disc, scene.solver)
    t = continuation.tangent(system, X, np.eye(X.size)[-1])
    start = continuation.Point(X, t, 0, float(np.abs(system.residual(X)).max()))
    limit = scene.continuation.stop_stretch
    compressed = CompressionStop(eq, in_field(scene))
    compressed(system.full(X)[:-1])
    volume_stop = VolumeStop(scene.continuation.stop_volume, system)

    def stop(point):
        if (interrupted := signalled()) is not None:
            return interrupted
        u = system.full(point.X)[:-1]
        hoop = eq.disc.node_state(u)[0].max()
        if hoop > limit:
            return Stop(IntervalStop.HOOP_STRETCH, f"the largest hoop stretch {hoop:.6g} passed stop_stretch {limit:g}")
        return volume_stop(point.X) or compressed(u)

    monitors = {Kind.LP: np.eye(X.size)[-1]} | control_monitors(system, scene.loading.control)
    path = continuation.trace(system, start, settings, stop, monitors)
    reached = path.points + ([path.overshoot] if path.overshoot is not None else [])  # the last step's too
    full = [system.full(p.X) for p in reached]
    spectra = {block: np.array([spectrum(eq, Y, disc.block(block), params) for Y in full]) for block in Mirror}
    special = [IntervalSpecial(Kind(f.label), system.full(f.point.X)[:-1], float(f.point.X[-1]), f.index, f.status)
               for f in path.folds]
    for block in Mirror:
        for i, order in count_changes((spectra[block] < 0).sum(axis=1)):
            found = _located_zero(system, eq, reached[i], reached[i + 1], block, order, settings, params)
            if found is not None:
                special.append(IntervalSpecial(Kind.BP, found[0][:-1], float(found[0][-1]), int(i), found[1], block))
    special = sorted((s for s in special if disc.node_state(s.u)[0].max() <= limit),
                     key=lambda s: _position(system, reached, s))
    kept = len(path.points)
    full, spectra = full[:kept], {block: values[:kept] for block, values in spectra.items()}
    end, stopped = volume_stop.end(path, settings)
    if path.stop.code == StopCode.STOP_VOLUME:
        special = [s for s in special if s.index < kept - 1 or volume_stop.kept(path, end, _in(system, s))]
        full.append(end)
        spectra = {block: np.vstack([values, spectrum(eq, end, disc.block(block), params)])
                   for block, values in spectra.items()}
    volume = np.array([volume_ratio(eq, Y) for Y in full])
    lowest = {block: spectra[block][:, 0] for block in Mirror}
    return with_events(scene, system, IntervalBranch(
        disc, np.array([Y[:-1] for Y in full]), np.array([Y[-1] for Y in full]), volume, lowest,
        unstable_counts(eq, full, params), stressed(eq, special), stopped,
        np.array([smallest_stress(eq, Y[:-1]) for Y in full]), params), settings)


def _in(system: TubeSystem, special: IntervalSpecial) -> np.ndarray:
    """X of a located point in the coordinates of ``system``."""
    return np.append(special.u, special.pressure)[system.columns]


def stressed(eq: Equilibrium, special) -> tuple:
    """The located points with their ``smallest_stress``."""
    return tuple(replace(s, smallest_stress=smallest_stress(eq, s.u)) for s in special)


def _start(parameters: ParameterSystem, disc: IntervalDiscretisation, solver) -> np.ndarray:
    """X = (u[even block], P = 0) of the tube at P = 0: the unstressed reference (exact) where the ends' distance is
    free; where it is held at λ, the tube stretched to it by natural continuation in the held distance from 1
    (``continuation.natural``); in a field (M > 0), then the field switched on by natural continuation in M from 0
    (the coils' pull on the tube at P = 0); under a voltage (Φ̄ > 0), then the voltage switched on by natural
    continuation in Φ̄ from 0 (the wall thinned by it: the tube widens and, with free ends, lengthens). Each point
    is solved by Newton on the even rows with P = 0 prescribed. ContinuationError when it does not get there."""
    even = disc.block(Mirror.EVEN)
    X = np.append(disc.reference(), 0.0)[np.append(even, disc.size)]
    field, voltage = parameters.params.M, parameters.params.voltage

    def solve(X, stretch, M=0.0, charge=0.0):
        at = parameters.params.with_value("M", M).with_value("voltage", charge)
        system = TubeSystem(ParameterSystem(parameters.eq, at, "P"), even, held(disc, stretch))
        return newton(system.residual, system.jacobian, X, np.eye(X.size)[-1], 0.0, solver.tol, solver.max_newton)

    stretch = disc.axial_stretch if disc.held else 1.0
    if disc.held:
        X, reached, message = continuation.natural(solve, X, 1.0, stretch)
        if reached < stretch:
            raise ContinuationError(f"could not stretch the tube to geometry.axial_stretch = {stretch:g} at P = 0 "
                                    f"beyond {reached:.6g} ({message})")
    if field > 0:
        X, reached, message = continuation.natural(lambda X, M: solve(X, stretch, M), X, 0.0, field)
        if reached < field:
            raise ContinuationError(f"could not switch the field on at P = 0 beyond M = {reached:.6g} of field.M = "
                                    f"{field:g} ({message})")
    if voltage > 0:
        X, reached, message = continuation.natural(lambda X, charge: solve(X, stretch, field, charge), X, 0.0,
                                                   voltage)
        if reached < voltage:
            raise ContinuationError(f"could not switch the voltage on at P = 0 beyond {reached:.6g} of "
                                    f"electric.voltage = {voltage:g} ({message}): past the tube's pull-in voltage")
    return X


def volume_ratio(eq: Equilibrium, Y: np.ndarray) -> float:
    """V/V0 at Y = (u, P), V0 = πL the reference tube's (the volume per 2π: 2V/(2πL))."""
    return 2 * eq.volume(Y[:-1]) / eq.disc.length


def _position(system: TubeSystem, points: list, special: IntervalSpecial) -> float:
    """Where a located point lies along the branch: its index plus its arclength from that point along the point's
    tangent, over the step's (the order of points located in one step)."""
    before, after = points[special.index], points[special.index + 1]
    tangent = system.full(before.tangent)
    along = tangent @ (np.append(special.u, special.pressure) - system.full(before.X))
    return special.index + along / (tangent @ (system.full(after.X) - system.full(before.X)))


def _located_zero(system: TubeSystem, eq: Equilibrium, before, after, block: Mirror, order: int, settings,
                  params: Parameters):
    """(Y = (u, P), status) where the eigenvalue number ``order`` (ascending, from 0) of ``block`` vanishes between
    two points, by Brent in the arclength from ``before`` (``params``: the branch's, P replaced); None when it is
    the fold in P (the null vector not orthogonal to ∂R/∂P). Each value is a Keller corrector; near a branch point
    of the even block (the branch's own unknowns) that one may diverge, and then ``off_mode_corrector`` is used."""
    index = eq.disc.block(block)
    mode = None  # the crossing eigenvalue's vector at ``before`` where the branch's own unknowns hold it (even block)
    if block == Mirror.EVEN:
        Y = system.full(before.X)
        H = eq.jacobian(Y[:-1], params.with_value("P", Y[-1]))[np.ix_(system.unknowns, system.unknowns)]
        mode = np.append(np.linalg.eigh(H)[1][:, order], 0.0)

    length = float(before.tangent @ (after.X - before.X))
    end = system.full(after.X)
    fallback = None if mode is None else (
        lambda predictor: off_mode_corrector(system, predictor, before.tangent, mode, settings))
    root = corrected_zero(system, settings, before.X, before.tangent, length,
                          lambda Y: spectrum(eq, Y, index, params)[order],
                          {length: (spectrum(eq, end, index, params)[order], end)}, fallback)
    Y = root.payload
    at = params.with_value("P", Y[-1])
    if is_fold(eq, Y[:-1], at, eq.parameter_derivative(Y[:-1], at, "P"), index, order):
        return None
    return Y, root.status
