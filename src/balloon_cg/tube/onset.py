"""The onset of bulging followed in a second parameter: the curve of a tube's first odd branch point in (q, P).

At a branch point of the odd block (interval.Mirror) the mirror-symmetric primary branch (tube/primary.py) is crossed
by the bulge's pitchfork: the odd block of ∂R/∂u is singular there. Following it in q, a runtime scalar of the tube's
kernels (the field intensity M of coils mirror-symmetric about the tube's middle, which keep the mirror symmetry, or
the voltage Φ̄ under [electric]) or the held distance of the ends λ (``axial_stretch``: λ̄ = u[axial_index], fixed
on the branch, is q), is a Moore–Spence extended system on the even block's unknowns u_e (the mirror-symmetric
states; a held λ̄ stays out of them) and the odd block's null vector φ:

    unknowns  X = (u_e, P, φ, q)
    equations R_e(u; P, q)      = 0    equilibrium (the even rows; the odd rows vanish by symmetry)
              H_oo(u; P, q) φ   = 0    the odd block is singular, φ its null vector
              ℓ·φ − 1           = 0    normalisation (ℓ: the branch point's null vector, unit)

one equation fewer than unknowns: a curve, traced by pseudo-arclength continuation (numerics/continuation.py).
Jacobian: ∂R_e/∂(u_e, P, q) from the generated kernels (the Hessian, ∂R/∂P, ∂R/∂M; for λ the Hessian's column
of λ̄); ∂(H_oo φ)/∂u_e is the central difference of the whole Hessian along φ restricted to the odd rows and even
columns (the third derivative of E is symmetric), ∂(H_oo φ)/∂P and ∂/∂q central differences (H is affine in P and
M, quadratic in Φ̄: exact to rounding; for λ a central difference along λ̄'s unit vector); the steps ``H_STEP`` only set Newton's rate,
never the converged points (the residual is exact).

The curve in λ stops where the largest hoop stretch passes ``continuation.stop_stretch`` (as the primary branch:
past the fold of a strain-stiffening material it runs along the upper onset towards the locking stretch); every curve
stops where P ≤ 0, where q leaves its range (``RANGES``: M and Φ̄ ≥ 0, λ in [1, 5] as
geometry.axial_stretch; the last point is then landed exactly on the end it passed: the field-free onset, the tube
held at its reference length or at 5L), at ``continuation.max_points``, at the minimum step, or at the next point after
SIGINT/SIGTERM (StopCode.INTERRUPTED); its folds in q (LP: the onset's largest or smallest q) are located by the
tracer's fold monitor.
"""
import enum
from dataclasses import dataclass

import numpy as np

from .primary import held, volume_ratio
from .results import IntervalBranch, IntervalSpecial, IntervalStop, signalled
from ..analysis.branches.problem import continuation_settings
from ..analysis.results import Kind
from ..galerkin.equilibrium import Equilibrium, Parameters
from ..galerkin.interval import Mirror
from ..numerics import continuation
from ..numerics.continuation import Stop
from ..numerics.newton import newton
from ..numerics.threads import limited_blas
from ..scene.tables import MAX_AXIAL, MIN_AXIAL

STRETCH = "axial_stretch"  # q: the held distance of the ends over L (λ̄, an unknown held fixed on the branch)
RANGES = {"M": (0.0, np.inf), "voltage": (0.0, np.inf), STRETCH: (MIN_AXIAL, MAX_AXIAL)}  # q's allowed range
H_STEP = 1e-6  # the central differences' step in u (along φ, |φ| ~ 1), P and q (relative to max(1, |q|))


class OnsetStop(enum.StrEnum):
    """Why an onset curve stopped (beside the tracer's TraceStop)."""

    FIELD_FREE = "field_free"  # q fell below 0: the last point is an odd branch point of the tube at q = 0 (not
    #                            necessarily its first: the curve may return along another bulge mode)
    UNSTRETCHED = "unstretched"  # λ fell below 1: the last point is an odd branch point of the tube held at λ = 1
    STRETCH_LIMIT = "stretch_limit"  # λ passed the largest geometry.axial_stretch: the last point is landed on 5
    NONPOSITIVE_PRESSURE = "nonpositive_pressure"  # P reached 0


class OnsetSystem:
    """R_e = 0, H_oo φ = 0, ℓ·φ = 1 as a map of X = (u_e, P, φ, q) (module docstring); ``name``: q's Parameters
    field (M, voltage) or ``STRETCH`` (λ̄, held)."""

    def __init__(self, eq: Equilibrium, params: Parameters, name: str, ell: np.ndarray):
        disc = eq.disc
        self.eq, self.params, self.name, self.ell = eq, params, name, ell
        self.even = np.setdiff1d(disc.block(Mirror.EVEN), [] if not disc.held else [disc.axial_index])
        self.odd = disc.block(Mirror.ODD)
        self.fixed = held(disc)

    def split(self, X) -> tuple:
        """(u, P, φ on the odd block, q) of X."""
        ne, no = self.even.size, self.odd.size
        u = self.fixed.copy()
        u[self.even] = X[:ne]
        if self.name == STRETCH:
            u[self.eq.disc.axial_index] = X[-1]
        return u, float(X[ne]), X[ne + 1:ne + 1 + no], float(X[-1])

    def join(self, u, P, phi, q) -> np.ndarray:
        return np.concatenate([u[self.even], [P], phi, [q]])

    def at(self, P: float, q: float) -> Parameters:
        params = self.params.with_value("P", P)
        return params if self.name == STRETCH else params.with_value(self.name, q)

    def _moved(self, u, P, q, step) -> tuple:
        """(u, parameters) with q moved by ``step`` (λ: u's λ̄)."""
        if self.name != STRETCH:
            return u, self.at(P, q + step)
        moved = u.copy()
        moved[self.eq.disc.axial_index] += step
        return moved, self.at(P, q)

    def _odd_hessian(self, u, params) -> np.ndarray:
        return self.eq.jacobian(u, params)[np.ix_(self.odd, self.odd)]

    def residual(self, X):
        u, P, phi, q = self.split(X)
        params = self.at(P, q)
        R = self.eq.residual(u, params)[self.even]
        return np.concatenate([R, self._odd_hessian(u, params) @ phi, [self.ell @ phi - 1.0]])

    def jacobian(self, X):
        u, P, phi, q = self.split(X)
        ne, no, size = self.even.size, self.odd.size, self.eq.disc.size
        params = self.at(P, q)
        J = np.zeros((ne + no + 1, ne + no + 2))
        H = self.eq.jacobian(u, params)
        J[:ne, :ne] = H[np.ix_(self.even, self.even)]
        J[:ne, ne] = self.eq.parameter_derivative(u, params, "P")[self.even]
        J[:ne, -1] = (H[self.even, self.eq.disc.axial_index] if self.name == STRETCH
                      else self.eq.parameter_derivative(u, params, self.name)[self.even])
        along = np.zeros(size)
        along[self.odd] = phi
        plus, minus = (self.eq.jacobian(u + sign * H_STEP * along, params) for sign in (1, -1))
        J[ne:ne + no, :ne] = (plus - minus)[np.ix_(self.odd, self.even)] / (2 * H_STEP)
        J[ne:ne + no, ne] = (self._odd_hessian(u, self.at(P + H_STEP, q))
                             - self._odd_hessian(u, self.at(P - H_STEP, q))) @ phi / (2 * H_STEP)
        J[ne:ne + no, ne + 1:ne + 1 + no] = H[np.ix_(self.odd, self.odd)]
        hq = H_STEP * max(1.0, abs(q))
        J[ne:ne + no, -1] = (self._odd_hessian(*self._moved(u, P, q, hq))
                             - self._odd_hessian(*self._moved(u, P, q, -hq))) @ phi / (2 * hq)
        J[-1, ne + 1:ne + 1 + no] = self.ell
        return J


@dataclass(frozen=True)
class OnsetCurve:
    """The traced curve of onsets (plain data): per point the state ``states`` (rows u of the interval
    discretisation), the pressure, q, V/V0, the odd null vector ``modes`` (rows on the odd block) and the state's
    Legendre tail (``tail``: IntervalDiscretisation.tail, the error estimate solver.max_error bounds: a point above
    it is not resolved at the scene's degree); the folds in q (IntervalSpecial LP, ``pressure`` its P, ``fold_q``
    and ``fold_tail`` below), why it stopped, q's name and its start value."""

    disc: object
    name: str
    q0: float
    states: np.ndarray
    pressure: np.ndarray
    q: np.ndarray
    volume: np.ndarray
    modes: np.ndarray
    tail: np.ndarray
    folds: tuple
    fold_q: np.ndarray
    fold_tail: np.ndarray
    stop: Stop


@limited_blas
def onset_curve(scene, primary: IntervalBranch, point: IntervalSpecial, name: str = "M", direction: float = 1.0,
                max_points: int | None = None) -> OnsetCurve:
    """The curve of the odd branch point ``point`` of ``primary`` in ``name`` (a Parameters field with a derivative
    kernel: M, voltage; or ``STRETCH``, the held ends' distance), starting at the branch's value with q increasing
    (``direction`` 1) or decreasing (−1) (module docstring)."""
    if point.kind != Kind.BP or point.block != Mirror.ODD:
        raise ValueError(f"an onset curve starts at a branch point of the odd block, not at {point.kind} "
                         f"({point.block})")
    disc = primary.disc
    eq = Equilibrium(scene, disc)
    if name == "M" and not eq.coils.shape[0]:
        raise ValueError("an onset curve in M needs coils: without a field R does not depend on M")
    if name == STRETCH and not disc.held:
        raise ValueError("an onset curve in axial_stretch needs the ends held apart (geometry.axial_stretch)")
    if name != STRETCH and eq.derivative_kernel(name) is None:
        raise ValueError(f"no generated derivative of the residual in {name!r}: a tube's onset is followed in M, "
                         "the voltage or axial_stretch")
    q0 = disc.axial_stretch if name == STRETCH else float(getattr(primary.params, name))
    low, high = RANGES[name]
    params = primary.params.with_value("P", point.pressure)
    odd = disc.block(Mirror.ODD)
    phi = np.linalg.eigh(eq.jacobian(point.u, params)[np.ix_(odd, odd)])[1][:, 0]
    system = OnsetSystem(eq, params, name, phi / np.linalg.norm(phi))
    X = system.join(point.u, point.pressure, phi / (system.ell @ phi), q0)
    first = newton(system.residual, system.jacobian, X, np.eye(X.size)[-1], q0, scene.solver.tol,
                   scene.solver.max_newton)
    if not first.converged:
        raise ArithmeticError(f"the extended system at the branch point did not converge: {first.message}")
    X = first.x
    t = continuation.tangent(system, X, direction * np.eye(X.size)[-1])
    start = continuation.Point(X, t, first.iterations, first.residual)
    settings = continuation_settings(scene, max_points)
    below = Stop(OnsetStop.UNSTRETCHED, "axial_stretch fell below 1: the last point is an odd branch point of the "
                                        "tube held at its reference length (λ = 1)") if name == STRETCH else \
        Stop(OnsetStop.FIELD_FREE, f"{name} fell below 0: the last point is an odd branch point at {name} = 0 (not "
                                   "necessarily the first onset: the curve may return along another bulge mode)")
    beyond = Stop(OnsetStop.STRETCH_LIMIT, f"axial_stretch passed {high:g} (geometry.axial_stretch's largest value): "
                                           f"the last point is an odd branch point of the tube held at λ = {high:g}")

    stored = [q0]  # q of the last point kept: a stop's point (the step that passed it) is not stored

    def stop(p):
        if (interrupted := signalled()) is not None:
            return interrupted
        u, P, _, q = system.split(p.X)
        last = f"after {name} = {stored[-1]:.6g}, the last point"
        if name == STRETCH and (hoop := disc.node_state(u)[0].max()) > scene.continuation.stop_stretch:
            return Stop(IntervalStop.HOOP_STRETCH, f"the largest hoop stretch {hoop:.6g} passed stop_stretch "
                                                   f"{scene.continuation.stop_stretch:g} {last}")
        if P <= 0:
            return Stop(OnsetStop.NONPOSITIVE_PRESSURE, f"P reached 0 {last}")
        if q < low:
            return below
        if q > high:
            return beyond
        stored.append(q)
        return None

    path = continuation.trace(system, start, settings, stop, {Kind.LP: np.eye(X.size)[-1]})
    points = [p.X for p in path.points]
    end = {below.code: low, beyond.code: high}.get(path.stop.code)
    if end is not None:  # landed on the end of q's range it passed
        landed = newton(system.residual, system.jacobian, path.overshoot.X, np.eye(X.size)[-1], end,
                        scene.solver.tol, scene.solver.max_newton)
        if not landed.converged:
            raise ArithmeticError(f"the onset at {name} = {end:g} did not converge: {landed.message}")
        points.append(landed.x)
    parts = [system.split(Z) for Z in points]
    states = np.array([u for u, *_ in parts])
    pressure = np.array([P for _, P, _, _ in parts])
    folds = tuple(IntervalSpecial(Kind.LP, system.split(f.point.X)[0], system.split(f.point.X)[1], f.index, f.status)
                  for f in path.folds)
    return OnsetCurve(disc, name, q0, states, pressure, np.array([q for *_, q in parts]),
                      np.array([volume_ratio(eq, np.append(u, P)) for u, P in zip(states, pressure)]),
                      np.array([phi for _, _, phi, _ in parts]), np.array([disc.tail(u) for u in states]), folds,
                      np.array([system.split(f.point.X)[3] for f in path.folds]),
                      np.array([disc.tail(f.u) for f in folds]), path.stop)
