"""The primary branch of a scene whose field is not axisymmetric (loops anywhere, MODEL.md §9), traced on the whole
sphere from the start (``surface``), as ``primary`` traces an axisymmetric one:

1. Start: the inflated sphere x = λ X at continuation.start_stretch, an exact equilibrium at M = 0, at its pressure
   (``primary.start_parameters``).
2. Field on: natural continuation in M at that pressure from 0 to the scene's M, the step halved (down to
   FIELD_STEPS halvings) where Newton fails.
3. Continuation: pseudo-arclength in (a, P) upwards (the direction of growing P at the start) until a material
   pole stretch reaches stop_stretch, the membrane comes within wire_gap of a wire, or continuation.max_points;
   folds in P are located (LP); a point whose tail exceeds solver.max_error refines the basis
   (``surface_branches.follow``).

The basis keeps every reflection under which H² is invariant (``field_reflections``: for a loop tilted in the plane
y = 0, or displaced within it, the mirror y → −y): the states of the branch lie in that subspace, and a reflection
that the field keeps is where pitchforks can break it (its odd sectors, ``surface.assessment``). The balloon is held
at its centre in every direction (``surface.gauge.FieldSymmetry.GENERAL``: the reaction is the field's net force,
``surface.loads``) and free to turn (the field's torque about the centre vanishes at every state: a check, stored).
A free balloon has no equilibrium in such a field unless the net force vanishes: the free readings are not made.
"""
import time

import numpy as np

from ...model.loop import field_squared_cartesian, loop_table
from ...numerics import continuation
from ...numerics.newton import newton
from ...numerics.threads import limited_blas
from ...surface.basis import EQUATOR, HALF_TURN, INVERSION, MIRROR_Y, SphericalBasis
from ...surface.embedding import displacement_coefficients
from ...surface.gauge import FieldSymmetry
from ...surface.loads import LOADS, loads
from ...surface.stability import Reading
from ...surface.system import SurfaceSystem
from ...scene import Control
from ..branches.primary import start_parameters
from ..results import SurfaceBranch
from .assessment import assess
from .branches import SurfaceStartError, SurfaceTrace, collected, follow, traced_points
from ..timing import Clock, Step
from ..branches.tracer import ContinuationError

FIELD_STEPS = 12  # halvings of the step in M before the field cannot be switched on
MIRROR_X = (-1, 1, 1)
REFLECTIONS = (MIRROR_Y, MIRROR_X, EQUATOR, HALF_TURN, INVERSION)  # tried in this order (``field_reflections``)
PROBES, PROBE_SEED = 64, 20261202  # points where a reflection of H² is tested, and their seed
SYMMETRY_TOLERANCE = 1e-12  # |H²(S x) − H²(x)| relative to max H² at the probes: the closed form is exact
READINGS = tuple(Reading(True, control) for control in Control)  # held only (module docstring)


def field_reflections(coils) -> tuple:
    """The diagonal reflections S of REFLECTIONS under which H² of the loops is invariant, H²(S x) = H²(x),
    tested at PROBES seeded points of the shell 0.5 ≤ |x| ≤ 3 (each loop's field is a closed form: symmetric fields
    agree to rounding, others differ at O(1)); an independent set (a product of kept ones is not listed)."""
    table = loop_table(coils)
    rng = np.random.default_rng(PROBE_SEED)
    direction = rng.normal(size=(3, PROBES))
    points = direction / np.linalg.norm(direction, axis=0) * rng.uniform(0.5, 3.0, PROBES)

    def squared(x):
        out = np.empty((10, x.shape[1]))
        field_squared_cartesian(np.ascontiguousarray(x), table, out)
        return out[0]

    reference = squared(points)
    scale = np.abs(reference).max()
    kept, group = [], {(1, 1, 1)}
    for S in REFLECTIONS:
        if S in group:
            continue
        if np.abs(squared(np.array(S, dtype=float)[:, None] * points) - reference).max() <= SYMMETRY_TOLERANCE * scale:
            kept.append(S)
            group |= {tuple(a * b for a, b in zip(S, g)) for g in group}
    return tuple(kept)


def _field_on(trace: SurfaceTrace, c: np.ndarray, params) -> np.ndarray:
    """The state at the scene's M from the sphere c at M = 0 (module docstring, step 2): the coefficients."""
    system = SurfaceSystem(trace.eq, trace.gauge, params, "M")
    solver, target = trace.scene.solver, params.M
    X, M, dM = system.point(c, 0.0), 0.0, target
    row = np.eye(X.size)[-1]
    for _ in range(FIELD_STEPS + 1):
        while M < target:
            trial = min(M + dM, target)
            result = newton(system.residual, system.jacobian, np.append(X[:-1], trial), row, trial, solver.tol,
                            solver.max_newton)
            if not result.converged:
                break
            X, M = result.x, trial
        if M >= target:
            return system.coefficients(X)
        dM /= 2
    raise ContinuationError(f"the field could not be switched on: Newton failed at M = {M + dM:.6g} with steps "
                            f"down to {dM:.3g} (field.M = {target:g})")


def with_loads(trace: SurfaceTrace, fields: dict) -> dict:
    """The fields of a branch (``collected``) with the field's net force and torque on each state among its
    measures (``surface.loads``)."""
    per_point = [loads(trace.eq, c, trace.system.params) for c in fields["coefficients"]]
    fields["measures"] |= {key: np.array([load[key] for load in per_point]) for key in LOADS}
    return fields


@limited_blas
def trace_surface_primary(scene, progress=None, clock: Clock | None = None) -> SurfaceBranch:
    """The primary branch of ``scene`` on the whole sphere (module docstring), assessed held under every control,
    with the field's net force and torque at every point; ``clock``: the Clock the trace and the stability are
    charged to."""
    t0, clock = time.perf_counter(), clock or Clock()
    params = start_parameters(scene, "P").with_value("M", scene.field.M)
    symmetry = field_reflections(scene.field.coils)
    basis = SphericalBasis(scene.surface.degree, symmetry)
    trace = SurfaceTrace(scene, basis, params)
    if trace.gauge.field_symmetry != FieldSymmetry.GENERAL:
        raise ValueError("trace_surface_primary: the field of this scene is axisymmetric (or off): trace it with "
                         "analysis.branches.primary")
    with clock.step(Step.TRACE):
        lam = scene.continuation.start_stretch
        sphere = displacement_coefficients(basis, (lam - 1.0) * basis.nodes["reference"][:3])
        c = _field_on(trace, sphere, params)
        X = trace.system.point(c, params.P)
        solved = newton(trace.system.residual, trace.system.jacobian, X, np.eye(X.size)[-1], X[-1],
                        scene.solver.tol, scene.solver.max_newton)
        if not solved.converged:
            raise SurfaceStartError(f"the start at M = {params.M:g} did not converge in P: {solved.message}")
        start = continuation.Point(solved.x, continuation.tangent(trace.system, solved.x, np.eye(X.size)[-1]),
                                   solved.iterations, solved.residual)
        trace, segments, folds, stop = follow(trace, [], start, scene.continuation.max_points, None, progress)
        fields = with_loads(trace, collected(trace, segments, folds, stop))
        out = SurfaceBranch(name="primary", scene=scene, kernel_class=trace.eq.kernels.name,
                            params=trace.system.params, m=0, parent=("", -1), **fields)
        out.wall_time = time.perf_counter() - t0
    with clock.step(Step.STABILITY):
        assess(out, traced_points(segments), READINGS)
    return out
