"""Two-parameter continuation of a pear-shaped pitchfork: the curve of branch points in (q, P).

A pear branch point of the equator-symmetric primary branch (``bifurcation``) is an equilibrium where the odd
(pear) block of the Hessian is singular. Following it in a second parameter q — any runtime parameter of the
scene's kernels, named by its scene key (``second_parameter``: the field intensity ``M``, a strain energy's
``material.parameters.Jm``, an Ogden ``material.mu[i]``, or ``alpha1`` with μ1 = (4 − Σ_{i≥2} μ_i α_i)/α1 so
that Σ μ_i α_i = 4 stays true) — is a Moore–Spence type extended system in the equator-symmetric space at the
branch's Legendre degree N:

    unknowns  X = (u, P, φ, q)              u: symmetric-layout coefficients, φ: the odd block (a_odd, b_even
                                             without b_0) of the general-layout perturbation basis of degree N
    equations R(u; P, q)            = 0     (n)      equilibrium
              H_odd(u; P, q) φ      = 0     (m)      the pear block is singular, φ its null vector
              ℓ·φ − 1               = 0     (1)      normalisation (ℓ = the located critical mode)

— one equation fewer than unknowns: a curve, traced by the generic pseudo-arclength ``continuation.trace``. The
free balloon's pitchfork in a field (the odd_free block: φ has the axial translation b_0 as one more entry) is
followed by the same system with that block (``continue_branch_point`` from an odd_free point).

Jacobian. ∂R/∂u is the generated Hessian (``Equilibrium.jacobian``), ∂R/∂P comes from
``Equilibrium.parameter_derivative``, and so does ∂R/∂q where a generated kernel gives it (``Derivative.EXACT``:
M), else it is a central difference of the residual in q (``Derivative.CENTRAL``; exponents through the general
kernel class ``ogden_general_field``, exponents as runtime arguments); H_odd is the generated Hessian on the
perturbation basis (as ``SecondVariation.matrices``). The third-derivative terms are **central differences of
the generated Hessian along directions**: because the third derivative of E is symmetric, ∂(H_odd φ)/∂u is the
directional derivative of the full perturbation-basis Hessian along φ (one pair of Hessian evaluations, at the
non-symmetric states u ± hφ), restricted to the odd rows and the symmetric-layout columns; ∂(H_odd φ)/∂P and
∂(H_odd φ)/∂q are central differences of H in P and q. Difference steps are ``H_STEP`` (relative,
h = H_STEP·max(1, |q|) in q): the Jacobian is then accurate to ~1e-9, which only affects Newton's rate, not the
converged points (the residual itself is exact).

The two pitchforks of an isola lie on one such curve; where the curve turns back in q (a sign change of the
q-component of the tangent, located by the continuation's fold locator: an LP of the curve) they merge: that q is
the critical value (critical M, α1, Jm, …) — obtained directly, without bracketing in q.

How the curve ends (``CurveEnd``, the curve's ``end``). A fold in q is a merge of the isola's two pitchforks only
if the curve, after it, comes back to q0 at the partner pitchfork with P > 0 all the way. The trace stops when q
returns past q0 (stop ``PARTNER``), when P ≤ 0 (``StopCode.NONPOSITIVE_PRESSURE``: the pitchforks leave the
physical range of an inflated balloon; the message gives q where the curve crosses P = 0), when the membrane
comes within ``continuation.wire_gap`` of a coil (``WIRE_GAP``), when q reaches 0 for a parameter that must
not (α1, an exponent, a family's positive parameter) or falls below 0 (M, χ, Φ̄: ``ALPHA1_ZERO``), at
``max_points``, at the minimum step, or at the next point after SIGINT/SIGTERM (``numerics.interrupt``:
``StopCode.INTERRUPTED``). The end is then, in this order of precedence:

    INTERRUPTED            a signal stopped the trace: the curve is partial (folds so far are not verified)
    ISOLA_MERGE            a fold in q at P > 0, then the partner pitchfork (stop PARTNER): the isola is born or
                           dies there; ``critical`` is that fold (the fold of extreme q if there are several)
    FOLD                   folds in q, none verified as such a merge (P ≤ 0 at the fold, or the curve did not
                           come back to the partner; PARTNER without a located fold is also FOLD)
    NONPOSITIVE_PRESSURE   no fold, and P reached 0
    WIRE                   no fold, and the membrane reached continuation.wire_gap of a coil
    BUDGET                 no fold, and max_points were traced
    STEP_MIN               no fold, and the corrector failed at the minimum step
    ALPHA1_ZERO            no fold, and q reached 0 (α1, an exponent or a positive parameter) or fell below 0
                           (M, χ, Φ̄)
    OTHER                  a caller's own stop rule stopped the curve

The merge points (``merges``: every fold in q, LP special points) carry ``Status.LOCATED`` only for the merge of
an ISOLA_MERGE curve found by a converged root search; every other fold is ``Status.APPROXIMATE`` with the
reason (not verified as a merge, or the root search fell back) and the half-width of its bracket.
"""
import enum
import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from ...galerkin.discretisation import Discretisation
from ...galerkin.equilibrium import Equilibrium, Parameters
from ...model.sphere_modes import bifurcation_condition, bifurcation_stretches
from ...numerics import continuation, interrupt
from ...numerics.continuation import Stop, TraceStop
from ...numerics.newton import newton
from ...scene import Scene
from ..points.branch_points import padded_mode, plain_degree
from ..points.extended_systems import H_STEP, WernerSpence
from .fold_meeting import fold_meetings
from ..branches.problem import continuation_settings, equilibrium_of
from ..results import Block, Branch, Kind, SpecialPoint, Status, StopCode, approximate, located_or_bracketed
from .second_parameter import Derivative, SecondParameter, alpha1_material, second_parameter
from ..stability.axisymmetric import SecondVariation, block_indices
from ..branches.wires import wire_gap
from ...numerics.threads import limited_blas


class TwoParameterError(RuntimeError):
    """The extended system could not be set up or started; the message says why."""


class CurveEnd(enum.StrEnum):
    """How a two-parameter curve ended (module docstring): only ISOLA_MERGE gives a critical value."""

    INTERRUPTED = "interrupted"  # SIGINT/SIGTERM stopped the trace (numerics.interrupt): the curve is partial
    ISOLA_MERGE = "isola_merge"  # a fold in q at P > 0, then back to q0 at the partner pitchfork
    CUSP = "cusp"  # a fold curve (fold_curve) turns back in q where its fold coefficient changes sign
    FOLD = "fold"  # a fold in q not verified as a merge (P <= 0 there, or no return to the partner)
    NONPOSITIVE_PRESSURE = "nonpositive_pressure"  # P reached 0 (no fold before)
    WIRE = "wire"  # the membrane reached continuation.wire_gap of a coil (no fold before)
    BUDGET = "budget"  # max_points traced (no fold before)
    STEP_MIN = "step_min"  # the corrector failed at the minimum step (no fold before)
    ALPHA1_ZERO = "alpha1_zero"  # q reached 0 (α1, an exponent, a positive parameter) or fell below it (M, χ, Φ̄)
    OTHER = "other"  # a caller's stop rule


CODIM2_ENDS = (CurveEnd.ISOLA_MERGE, CurveEnd.CUSP)  # the ends that give a critical value
_END_OF_STOP = {StopCode.NONPOSITIVE_PRESSURE: CurveEnd.NONPOSITIVE_PRESSURE, StopCode.WIRE_GAP: CurveEnd.WIRE,
                TraceStop.MAX_POINTS: CurveEnd.BUDGET, TraceStop.STEP_MIN: CurveEnd.STEP_MIN,
                StopCode.ALPHA1_ZERO: CurveEnd.ALPHA1_ZERO}


class ExtendedSystem(WernerSpence):
    """R(u; P, q) = 0, H_odd φ = 0, ℓ·φ = 1 as a map of X = (u, P, φ, q) (module docstring): the pear system of
    ``branch_point`` with q as one more unknown. ``parameter``: a key of ``second_parameter`` or the looked-up
    SecondParameter (UnknownParameter, a ValueError, for a key the scene's kernels do not take)."""

    def __init__(self, equilibrium: Equilibrium, params, parameter: str | SecondParameter, ell: np.ndarray,
                 block: Block = Block.ODD_HELD):
        disc = equilibrium.disc
        if not disc.symmetric:
            raise TwoParameterError("the extended system needs the equator-symmetric layout of the primary branch")
        if not isinstance(parameter, SecondParameter):
            parameter = second_parameter(equilibrium.scene, equilibrium, params, parameter)
        if parameter.kernel_class is not None and equilibrium.kernels.name != parameter.kernel_class:
            # runtime exponents: an own equilibrium of the general class (same energy, μ and α as arguments)
            equilibrium = Equilibrium(equilibrium.scene, disc, kernel_class=parameter.kernel_class)
        super().__init__(equilibrium, params, ell, block=block)
        self.parameter = parameter

    def set_q(self, q: float):
        """Parameters at q (``SecondParameter.at``: the other values the branch's or the material's)."""
        return self.parameter.at(self.params, self.eq.scene.material, q)

    def split(self, X):
        n, m = self.n, self.m
        return X[:n], float(X[n]), X[n + 1:n + 1 + m], float(X[-1])

    def residual(self, X):
        u, P, phi, q = self.split(X)
        return self.equations(u, phi, self.set_q(q).with_value("P", P))

    def jacobian(self, X):
        u, P, phi, q = self.split(X)
        n, m = self.n, self.m
        params = self.set_q(q).with_value("P", P)
        J = np.zeros((n + m + 1, n + m + 2))
        J[:, :-1] = self.derivatives(u, P, phi, params)
        hq = H_STEP * max(1.0, abs(q))
        plus, minus = self.set_q(q + hq).with_value("P", P), self.set_q(q - hq).with_value("P", P)
        if self.parameter.derivative == Derivative.EXACT:
            J[:n, -1] = self.eq.parameter_derivative(u, params, self.parameter.name)
        else:
            J[:n, -1] = (self.eq.residual(u, plus) - self.eq.residual(u, minus)) / (2 * hq)
        J[n:n + m, -1] = (self.odd_hessian(u, plus) - self.odd_hessian(u, minus)) @ phi / (2 * hq)
        return J

    def initial(self, bp, q0: float):
        """X0 = (u*, P*, φ*, q0) from a located branch point; φ* normalised so that ℓ·φ* = 1."""
        phi = bp.mode[self.odd]
        return np.concatenate([bp.X[:-1], [bp.X[-1]], phi / (self.ell @ phi), [q0]])


@dataclass
class TwoParameterCurve:
    """A traced curve of pear branch points (plain data): X = (u, P, φ, q) per point on the symmetric layout
    ``disc``, and the merge points (LP special points: folds in q, X in the same layout)."""

    second: SecondParameter  # q: its key, short name, how ∂R/∂q is computed
    scene: Scene
    disc: Discretisation
    params: Parameters  # the branch's parameters (q replaces one of them along the curve)
    ell: np.ndarray  # normalisation row of φ
    X: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray
    merges: list = field(default_factory=list)  # every fold in q (LP); LOCATED only for a verified merge
    stop: Stop | None = None
    wall_time: float = 0.0
    end: CurveEnd | None = None  # how the curve ended (module docstring); None: not classified
    q0: float = np.nan  # the start value of q
    direction: float = 1.0  # +1: q increased from q0, −1: decreased
    block: Block = Block.ODD_HELD  # the pear block: odd_held, or odd_free (the free balloon's pitchforks)
    meetings: list = field(default_factory=list)  # codim-2 points LP-BP, LV-BP, LN-BP (``fold_meeting``,
    #                                                 on a fold curve ``fold_crossing``)

    def __post_init__(self):
        """Its merges' and meetings' X end in q: they name it (``SpecialPoint.parameter``)."""
        self.merges = [replace(s, parameter=self.parameter) for s in self.merges]
        self.meetings = [replace(s, parameter=self.parameter) for s in self.meetings]

    @property
    def n(self) -> int:
        return self.disc.size

    @property
    def parameter(self) -> str:
        """q's short name (M, alpha1, Jm, mu[0], …): labels and messages; ``second.key`` is its scene key."""
        return self.second.name

    def system(self) -> "ExtendedSystem":
        """The extended system the curve solves (rebuilt)."""
        return ExtendedSystem(Equilibrium(self.scene, self.disc), self.params, self.second, self.ell, self.block)

    def _parts(self, X):
        X = np.atleast_2d(X)
        return X[:, :self.n], X[:, self.n], X[:, -1]

    @property
    def q(self):
        return self._parts(self.X)[2]

    @property
    def pressure(self):
        return self._parts(self.X)[1]

    @property
    def mode(self):
        """φ per point, on the odd perturbation block."""
        return self.X[:, self.n + 1:-1]

    @property
    def stop_reason(self) -> str:
        return self.stop.message if self.stop else ""

    def branch_X(self, X=None):
        """(u, P) rows in the primary branch's layout."""
        u, P, _ = self._parts(self.X if X is None else X)
        return np.hstack([u, P[:, None]])

    def pole_values(self, X=None):
        rows = self.disc.pole_rows()
        u = self._parts(self.X if X is None else X)[0]
        return {name: u @ row for name, row in rows.items()}

    @property
    def pole_stretch(self):
        return self.pole_values()["lam2_top"]

    @property
    def merge(self) -> SpecialPoint | None:
        """The verified merge of the two pitchforks (ISOLA_MERGE) or folds (CUSP): the fold of extreme q, or None."""
        if self.end not in CODIM2_ENDS or not self.merges:
            return None
        return max(self.merges, key=lambda s: self.direction * s.X[-1])

    @property
    def critical(self):
        """(q, P, north pole stretch) of the verified merge point (``end`` is ISOLA_MERGE or CUSP), or None: a fold
        in q that is not such a merge is no critical value."""
        merge = self.merge
        if merge is None:
            return None
        X = merge.X
        return float(X[-1]), float(self._parts(X)[1][0]), float(self.pole_values(X)["lam2_top"][0])

    @property
    def of(self) -> Kind:
        """The kind of point the curve follows: BP (pear pitchforks); ``fold_curve.FoldCurve``: LP, LV or LN."""
        return Kind.BP

    def describe(self) -> str:
        """One line for people: how the curve ended and where (q, P, pole stretch of its last point or fold), and
        where a fold meets the pitchfork (``meetings``)."""
        return self._ending() + self.describe_meetings()

    def describe_meetings(self) -> str:
        """'; the LN fold meets the pitchfork at q = … (P = …, located)' per meeting (on a fold curve: 'meets a
        branch point', ``fold_crossing``; an approximate one with its ±uncertainty), or ''."""
        met = "the pitchfork" if self.of == Kind.BP else "a branch point"
        return "".join(f"; the {m.kind.value.removesuffix('-BP')} fold meets {met} at {self.parameter} = "
                       f"{m.X[-1]:.10g} (P = {m.X[self.n]:.10g}, {m.status.value}"
                       + (f" ±{m.uncertainty:.1g})" if m.status != Status.LOCATED else ")") for m in self.meetings)

    def _ending(self) -> str:
        """``describe`` without the meetings."""
        name, points = self.parameter, "pitchforks" if self.of == Kind.BP else f"{self.of.value} folds"
        q, P, stretch = self.q[-1], self.pressure[-1], self.pole_stretch[-1]
        at = f"last point {name} = {q:.6g}, P = {P:.6g}, pole stretch {stretch:.6g}"
        if self.end in CODIM2_ENDS:
            qc, Pc, sc = self.critical
            merge = f"the {points} merge" + (" in a cusp" if self.end == CurveEnd.CUSP else "")
            return (f"{merge} at {name} = {qc:.12g} (P = {Pc:.10g}, pole stretch {sc:.10g}) and the "
                    f"curve returns to {name} = {self.q0:g} at the partner point")
        if self.end == CurveEnd.INTERRUPTED:
            return f"a signal stopped the curve: it is partial ({len(self.q)} points, {at})"
        if self.end == CurveEnd.FOLD:
            folds = ", ".join(f"{name} = {s.X[-1]:.6g} at P = {s.X[self.n]:.4g}" for s in self.merges) or "not located"
            merge = "a merge of the isola's two pitchforks" if self.of == Kind.BP else "a cusp"
            return (f"the curve turns back in {name} ({folds}) but is not verified as {merge}: it ended by "
                    f"{self.stop_reason} ({at})")
        return f"{self.stop_reason or 'the curve stopped'} before the curve turned back in {name} ({at})"


@limited_blas
def continue_branch_point(branch: Branch, bp: SpecialPoint, parameter: str | SecondParameter,
                          direction: float = 1.0,
                          q0: float | None = None, settings: continuation.Settings | None = None, stop=None,
                          progress=None, max_points: int = 400) -> TwoParameterCurve:
    """Trace the curve of pear branch points through ``bp`` (located on the symmetric ``branch``) in q.

    ``parameter``: a key of ``second_parameter.second_parameter`` (``M``, ``material.parameters.Jm``, ``alpha1``,
    …; UnknownParameter lists the scene's) or a SecondParameter. ``direction``: +1 starts with q increasing, −1
    decreasing. ``q0``: the branch's value of q (default: the branch's or its material's). The trace stops when
    P ≤ 0, when the membrane comes within continuation.wire_gap of a coil, when q reaches 0 for a parameter that
    must not (α1, exponents, positive parameters), or when ``stop(point)`` (a continuation.Point) returns a Stop,
    by default when q returns past q0 after a fold (the curve has reached the partner pitchfork); or at
    ``max_points``; or at the next point after SIGINT/SIGTERM under ``numerics.interrupt.stop_on_signals``.
    Returns a TwoParameterCurve whose ``end`` says how it ended (``CurveEnd``) and whose ``merges`` are the folds
    in q; only an ISOLA_MERGE curve has a ``critical`` value (its merge, Status.LOCATED).
    """
    t0 = time.perf_counter()
    scene = branch.scene
    if branch.parameter != "P":  # the extended system's unknowns are (u, P, φ, q)
        raise TwoParameterError(f"the curve of pear points is traced in (q, P): the branch is continued in "
                                f"{branch.parameter}, not in P")
    if branch.disc.mapping is not None:  # the extended system shares coefficients with the stability basis (in x)
        mapped, branch = branch.disc, plain_branch(branch, bp.X)
        bp = replace(bp, X=mapped.transfer(bp.X, branch.disc), mode=padded_mode(bp.mode, branch.disc.degree))
    eq = equilibrium_of(branch)
    if parameter in ("M", "field.M") and not scene.field.coils:
        raise TwoParameterError("continuation in M needs coils: without a field R does not depend on M")
    if not isinstance(parameter, SecondParameter):
        parameter = second_parameter(scene, eq, branch.params, parameter)
    if q0 is None:
        q0 = parameter.q0
    if bp.block not in (Block.ODD_HELD, Block.ODD_FREE):
        raise TwoParameterError(f"branch point of block {bp.block.value!r}: only pear points (odd_held, odd_free) "
                                "are continued")
    variation = SecondVariation(eq, branch.disc.degree)
    odd = block_indices(variation, bp.block, field_on=True)
    ell = bp.mode[odd] / np.linalg.norm(bp.mode[odd])
    params = branch.params.with_value("P", bp.X[-1])
    system = ExtendedSystem(eq, params, parameter, ell, bp.block)
    X0 = system.initial(bp, q0)
    if settings is None:
        settings = curve_settings(scene, max_points)
    path = trace_in_q(system, X0, "the branch point", branch, parameter, q0, direction, settings, stop, progress)
    end = _classify(path, branch.disc.size)
    name = parameter.name
    merges = [SpecialPoint(Kind.LP, fold.index, fold.point.X, **_merge_status(fold, path, branch.disc, end),
                           note=f"fold of the curve in {name}"
                                + (": the two pitchforks merge" if end == CurveEnd.ISOLA_MERGE else
                                   " (not verified as a merge of the pitchforks)")) for fold in path.folds]
    points = path.points
    meetings = fold_meetings(system, points, branch.disc, settings, bp.block)
    return TwoParameterCurve(parameter, scene, branch.disc, params, ell, np.array([p.X for p in points]),
                             np.array([p.iterations for p in points]), np.array([p.residual for p in points]),
                             merges, path.stop, time.perf_counter() - t0, end, float(q0), float(direction), bp.block,
                             meetings)


def curve_settings(scene, max_points: int) -> continuation.Settings:
    """The scene's continuation settings (``continuation_settings``) for a curve of an extended system, which opts
    in to what no one-parameter trace does: a corrector at its rounding floor is accepted up to solver.max_error
    (newton's AT_ROUNDING), and one above it (ILL_CONDITIONED) makes the trace step across instead of halving
    (numerics/continuation.py). Such a curve passes singular points of its system: a fold curve where the branch
    has a branch point (``fold_crossing``)."""
    return replace(continuation_settings(scene, max_points), rounding_limit=scene.solver.max_error)


def plain_branch(branch: Branch, X) -> Branch:
    """``branch`` moved onto the plain (unmapped) discretisation of the degree that holds its point X
    (``bifurcation.plain_degree``): the extended systems work in x; ``branch`` itself when it is not mapped."""
    mapped = branch.disc
    if mapped.mapping is None:
        return branch
    plain = Discretisation(plain_degree(branch, X), mapped.symmetric, mapped.pin_translation,
                           held=mapped.held)
    return replace(branch, disc=plain, X=mapped.transfer(branch.X, plain))


def trace_in_q(system, X0, what: str, branch: Branch, parameter: SecondParameter, q0: float, direction: float,
               settings: continuation.Settings, stop=None, progress=None) -> continuation.Path:
    """Trace a curve X = (u, P, …, q) of an extended ``system`` in (q, P) from X0 (at ``what``, a located point
    of ``branch``, with q = q0), q first moving in ``direction``, with the stop rules of the module docstring
    (``stop(point)``: the caller's, default the return of q past q0, PARTNER) and the folds in q located (LP).
    TwoParameterError if Newton does not converge at X0 or the point is already a fold in q."""
    e_q = np.zeros(X0.size)
    e_q[-1] = 1.0
    # corrected at fixed q0 (it may differ from the branch's): for α1 the family's μ1 = (4 − Σ_{i≥2} μ_i α_i)/α1
    # may differ from the material's rounded μ1 (SPOM1: Σ μ_i α_i = 4.000004), and the located point carries the
    # locator's tolerance
    first = newton(system.residual, system.jacobian, X0, e_q, q0, settings.tol, settings.max_newton)
    if not first.converged:
        raise TwoParameterError(f"the extended system did not converge at {what}: {first.message}")
    X0 = first.x
    t = continuation.tangent(system, X0, direction * e_q)
    if abs(t[-1]) < 1e-8:
        raise TwoParameterError("the starting point is already a fold in q: no direction to start in")
    start = continuation.Point(X0, t, first.iterations, first.residual)

    def default_stop(point):
        if (point.X[-1] - q0) * direction < 0:
            return Stop(StopCode.PARTNER, f"q returned past its start value {q0:g} (reached the partner point)")
        return None

    rule = stop or default_stop
    n, coils, gap_limit = branch.disc.size, branch.scene.field.coils, branch.scene.continuation.wire_gap
    name = parameter.name

    def stop_point(point):
        if interrupt.requested():
            return Stop(StopCode.INTERRUPTED, "interrupted (SIGINT or SIGTERM): stopped at this point")
        if parameter.bound and point.X[-1] * q0 <= 0:
            return Stop(StopCode.ALPHA1_ZERO, f"{name} reached 0")
        if point.X[n] <= 0:
            return Stop(StopCode.NONPOSITIVE_PRESSURE, f"the pressure P reached 0 (P = {point.X[n]:.4g} "
                                                        f"at {name} = {point.X[-1]:.6g})")
        gap, coil = wire_gap(branch.disc, point.X[:n], coils, branch.scene.geometry)
        if gap < gap_limit:
            return Stop(StopCode.WIRE_GAP, f"membrane within wire_gap {gap_limit:g} of coil {coil} (gap {gap:.3g})")
        stopped = rule(point)  # first: a curve back at its partner past a small q0 > 0 is back, not out of range
        if stopped is None and parameter.nonnegative and point.X[-1] < 0:
            return Stop(StopCode.ALPHA1_ZERO, f"{name} fell below 0 (its range starts at 0)")
        return stopped

    path = continuation.trace(system, start, settings, stop_point, {Kind.LP: e_q}, progress)
    if path.stop.code == StopCode.NONPOSITIVE_PRESSURE:
        path.stop = _pressure_zero_stop(system, path, name, settings)
    return path


def _classify(path, n: int) -> CurveEnd:
    """How a traced curve ended (module docstring)."""
    code = path.stop.code
    if code == StopCode.INTERRUPTED:
        return CurveEnd.INTERRUPTED
    if path.folds:
        if code == StopCode.PARTNER and all(fold.point.X[n] > 0 for fold in path.folds):
            return CurveEnd.ISOLA_MERGE
        return CurveEnd.FOLD
    if code == StopCode.PARTNER:
        return CurveEnd.FOLD  # q came back without a located fold: no critical value to report
    return _END_OF_STOP.get(code, CurveEnd.OTHER)


def _pressure_zero_stop(system, path, parameter: str, settings) -> Stop:
    """The P ≤ 0 stop, its message naming q where the curve crosses P = 0 (Newton from the overshoot point with
    the row e_P; the crossing is only reported, not added to the curve)."""
    X = path.overshoot.X
    row = np.zeros(X.size)
    row[system.n] = 1.0
    result = newton(system.residual, system.jacobian, X, row, 0.0, settings.tol, settings.max_newton)
    if not result.converged:
        return path.stop
    return Stop(StopCode.NONPOSITIVE_PRESSURE, f"the pressure P reached 0 at {parameter} = "
                                                f"{result.x[-1]:.10g}")


def _merge_status(fold, path, disc, end: CurveEnd, unverified: str = "a merge of the pitchforks") -> dict:
    """Status fields of a fold of the curve in q, bracketed by the curve points around it: LOCATED only for a
    verified codim-2 point (``CODIM2_ENDS``) whose root search converged; else APPROXIMATE, not verified as
    ``unverified``."""
    before, after = path.bracket(fold)
    n = disc.size
    before, after = np.append(before[:n], before[n]), np.append(after[:n], after[n])
    if end in CODIM2_ENDS:
        return located_or_bracketed(fold.status, disc, before, after, f"codim-2 point ({end.value})")
    return approximate(disc, before, after, f"fold in q not verified as {unverified} (curve end: "
                                            f"{end.value}: {path.stop.message})")


def land_on_q(curve: TwoParameterCurve, q: float, near: int):
    """The curve point with q exactly (Newton from curve point ``near`` with the row e_q), or None."""
    system = curve.system()
    X = curve.X[near]
    row = np.zeros(X.size)
    row[-1] = 1.0
    guess = X.copy()
    guess[-1] = q
    solver = curve.scene.solver
    result = newton(system.residual, system.jacobian, guess, row, q, solver.tol, solver.max_newton)
    return result.x if result.converged else None


# -- the α1 family and its closed form at M = 0 (independent check: sphere_modes) ---------------------------
def sphere_pear_minimum(material, lam_max: float = 10.0):
    """(λ, value) of the minimum over λ ∈ (1, lam_max) of the closed-form pear condition 4(S − t)
    (sphere_modes.bifurcation_condition, n = 1)."""
    grid = np.geomspace(1.0, lam_max, 4000)
    values = bifurcation_condition(material, grid, 1)
    i = int(np.clip(np.argmin(values), 1, grid.size - 2))
    res = minimize_scalar(lambda lam: float(bifurcation_condition(material, lam, 1)), bounds=(grid[i - 1], grid[i + 1]),
                          method="bounded", options={"xatol": 1e-13})
    return float(res.x), float(res.fun)


def sphere_critical_alpha1(material, lo: float, hi: float, lam_max: float = 10.0) -> tuple[float, float]:
    """Closed-form critical α1 at M = 0: where the minimum over λ of the pear condition touches zero (the two
    pear points merge), root-found in α1 ∈ [lo, hi] (brentq, xtol 1e-14). Returns (α1, λ at the merge)."""
    def g(a1):
        return sphere_pear_minimum(alpha1_material(material, a1), lam_max)[1]

    a1 = brentq(g, lo, hi, xtol=1e-14, rtol=4 * np.finfo(float).eps)
    return a1, sphere_pear_minimum(alpha1_material(material, a1), lam_max)[0]


def sphere_pear_stretches(material, alpha1: float, lam_max: float = 10.0):
    """Closed-form pear branch-point stretches of the α1 family member (sphere_modes.bifurcation_stretches)."""
    return bifurcation_stretches(alpha1_material(material, alpha1), 1, lam_max=lam_max)
