"""Two-parameter continuation of a fold (LP, LV, LN) of the primary branch: the fold curve in (q, P) and its cusp.

A fold of the control parameter c of a loading (``control``: c = P under pressure control, V under volume
control, n = P V under gas control) is a point x = (u, P) of the branch R(u; P) = 0 whose tangent w = (v, μ)
(F_x w = 0, F_x = [J_u  R_P]) leaves c stationary, ∇c·w = 0. Following it in a second parameter q
(``second_parameter``) is the extended system

    unknowns  X = (u, P, w, q)           w = (v, μ): the branch tangent at the fold
    equations R(u; P, q)          = 0    (n)    equilibrium
              F_x(u; P, q) w      = 0    (n)    w is tangent to the branch
              ∇c(u, P)·w          = 0    (1)    c is stationary along it: ∇c·w = μ (LP), ∇V·v (LV),
                                                P ∇V·v + V μ (LN), with ∇_u V = −2π R_P
              ℓ·w − 1             = 0    (1)    normalisation (ℓ = the fold's tangent, unit)

— one equation fewer than unknowns: a curve, traced by ``codim2.trace_in_q`` as the curve of pear pitchforks is.
(Under pressure control μ = 0 and the second block is J_u v = 0: the classical fold system.)

Jacobian. ∂(F_x w)/∂x = D²F[w, ·] is the central difference of F_x along w (the second derivative is
symmetric), ∂(F_x w)/∂q that of F_x in q, ∂R/∂q as in ``codim2`` (exact or central); ∇_u(∇V·v) = ∇²V v =
−2π ∂R_P/∂u v, the last column of the same difference of F_x (R_P does not depend on P). Steps ``H_STEP``.

The cusp. Where the fold curve turns back in q (a fold of the curve in q, located by the continuation's fold
locator) the fold is degenerate if its quadratic coefficient a = ψ·D²F̃[w, w] changes sign there: F̃ = (R, c)
is the branch with c as its parameter, ψ the left null vector of ∂F̃/∂x normalised by its c component
(``fold_coefficient``). The two folds (a maximum and a minimum of c along the branch) merge there: a cusp, the
end of the snap-through region; the curve then comes back in q along the partner fold. The curve's ``end`` is
``CurveEnd.CUSP`` (its ``critical`` value q of the cusp) only when a fold in q at P > 0 has the coefficient of
opposite signs at the curve points bracketing it; another fold in q is FOLD (not verified).

Where the curve passes a branch point of the branch (F_x loses rank: the fold system is singular there, and the
trace steps across it, ``pitchfork_curve.curve_settings``) the crossing is bracketed and stored with the curve's
``meetings`` (``fold_crossing``: LP-BP, LV-BP, LN-BP).
"""
import time
from dataclasses import dataclass

import numpy as np

from ...galerkin.equilibrium import Equilibrium
from ...numerics import continuation
from ...scene import Control
from ..points.extended_systems import _parameter_step, _step
from .pitchfork_curve import (CurveEnd, TwoParameterCurve, TwoParameterError, _END_OF_STOP, _merge_status,
                              curve_settings, plain_branch, trace_in_q)
from ..branches.control import FOLD_KIND, control_gradient_at
from ..branches.problem import equilibrium_of
from ..results import Branch, Kind, SpecialPoint, StopCode
from .fold_crossing import fold_crossings
from .second_parameter import Derivative, SecondParameter, second_parameter
from ...numerics.threads import limited_blas

CONTROL_OF_FOLD = {kind: control for control, kind in FOLD_KIND.items()}  # LP, LV, LN -> the control


class FoldSystem:
    """R = 0, F_x w = 0, ∇c·w = 0, ℓ·w = 1 as a map of X = (u, P, w, q) (module docstring)."""

    def __init__(self, equilibrium: Equilibrium, params, parameter: SecondParameter, control: Control,
                 ell: np.ndarray):
        if equilibrium.disc.mapping is not None:
            raise TwoParameterError("the fold system needs a plain (unmapped) discretisation")
        if parameter.kernel_class is not None and equilibrium.kernels.name != parameter.kernel_class:
            # runtime exponents: an own equilibrium of the general class (as codim2.ExtendedSystem)
            equilibrium = Equilibrium(equilibrium.scene, equilibrium.disc, kernel_class=parameter.kernel_class)
        self.eq, self.params, self.parameter, self.control = equilibrium, params, parameter, control
        self.n = equilibrium.disc.size
        self.ell = np.asarray(ell, dtype=float)

    def split(self, X):
        n = self.n
        return X[:n], float(X[n]), X[n + 1:2 * n + 2], float(X[-1])

    def at(self, P: float, q: float):
        """The parameters at (P, q)."""
        return self.parameter.at(self.params, self.eq.scene.material, q).with_value("P", P)

    def tangent_matrix(self, u, params) -> np.ndarray:
        """F_x = [J_u  R_P] (n × (n + 1))."""
        return self.eq.bordered_jacobian(u, params, "P")

    def control_gradient(self, u, params) -> np.ndarray:
        """∇c = ∂c/∂(u, P) at the point (``control.control_gradient_at``: e_P under pressure control)."""
        return control_gradient_at(self.eq, u, params, self.control)

    def residual(self, X):
        u, P, w, q = self.split(X)
        params = self.at(P, q)
        F = self.tangent_matrix(u, params)
        return np.concatenate([self.eq.residual(u, params), F @ w,
                               [self.control_gradient(u, params) @ w, self.ell @ w - 1.0]])

    def second_derivative(self, u, P: float, w, q: float) -> np.ndarray:
        """D(F_x)[w] = (F_x(x + h w) − F_x(x − h w))/(2h): the n × (n + 1) matrix δ ↦ D²F[w, δ]."""
        x = np.append(u, P)
        h = _step(x, w)
        plus, minus = x + h * w, x - h * w
        return (self.tangent_matrix(plus[:-1], self.at(plus[-1], q))
                - self.tangent_matrix(minus[:-1], self.at(minus[-1], q))) / (2 * h)

    def jacobian(self, X):
        u, P, w, q = self.split(X)
        n = self.n
        params = self.at(P, q)
        F = self.tangent_matrix(u, params)
        D = self.second_derivative(u, P, w, q)
        hq = _parameter_step(q)
        plus, minus = self.at(P, q + hq), self.at(P, q - hq)
        out = np.zeros((2 * n + 2, 2 * n + 3))
        out[:n, :n + 1] = F
        if self.parameter.derivative == Derivative.EXACT:
            out[:n, -1] = self.eq.parameter_derivative(u, params, self.parameter.name)
        else:
            out[:n, -1] = (self.eq.residual(u, plus) - self.eq.residual(u, minus)) / (2 * hq)
        out[n:2 * n, :n + 1] = D
        out[n:2 * n, n + 1:2 * n + 2] = F
        out[n:2 * n, -1] = (self.tangent_matrix(u, plus) - self.tangent_matrix(u, minus)) @ w / (2 * hq)
        grad = self.control_gradient(u, params)
        out[2 * n, n + 1:2 * n + 2] = grad
        if self.control != Control.PRESSURE:  # ∇_x(∇c·w): ∇²V v = −2π ∂R_P/∂u v (module docstring)
            v, mu, grad_V, hessian_V_v = w[:n], w[n], -2 * np.pi * F[:, -1], -2 * np.pi * D[:, -1]
            if self.control == Control.VOLUME:
                out[2 * n, :n] = hessian_V_v
            else:  # ∇c·w = P ∇V·v + V μ
                out[2 * n, :n] = P * hessian_V_v + mu * grad_V
                out[2 * n, n] = grad_V @ v
        out[-1, n + 1:2 * n + 2] = self.ell
        return out

    def fold_coefficient(self, X) -> float:
        """a = ψ·D²F̃[w, w] of the fold at X (module docstring): zero at a cusp, its sign says whether c has a
        maximum or a minimum along the branch there."""
        u, P, w, q = self.split(X)
        params = self.at(P, q)
        F = self.tangent_matrix(u, params)
        psi = np.linalg.lstsq(F.T, -self.control_gradient(u, params), rcond=None)[0]  # F_xᵀψ_R + ∇c = 0
        D = self.second_derivative(u, P, w, q)
        v, mu = w[:self.n], w[self.n]
        Vvv, Vv = -2 * np.pi * D[:, -1] @ v, -2 * np.pi * F[:, -1] @ v  # ∇²V[v, v], ∇V·v
        curvature = {Control.PRESSURE: 0.0, Control.VOLUME: Vvv, Control.GAS: P * Vvv + 2 * mu * Vv}[self.control]
        return float(psi @ (D @ w) + curvature)


@dataclass
class FoldCurve(TwoParameterCurve):
    """A traced fold curve (plain data): X = (u, P, w, q) per point; ``merges`` are its folds in q (the cusp
    LOCATED only when verified, module docstring). ``mode`` is the fold's tangent w = (v, μ)."""

    control: Control = Control.PRESSURE

    @property
    def of(self) -> Kind:
        return FOLD_KIND[self.control]

    def system(self) -> FoldSystem:
        return FoldSystem(Equilibrium(self.scene, self.disc), self.params, self.second, self.control, self.ell)


def fold_tangent(eq: Equilibrium, X, control: Control, params) -> np.ndarray:
    """The unit null vector w of [F_x; ∇c] at the fold X = (u, P) (its smallest right singular vector)."""
    u, at = X[:-1], params.with_value("P", float(X[-1]))
    F = eq.bordered_jacobian(u, at, "P")
    return np.linalg.svd(np.vstack([F, control_gradient_at(eq, u, at, control)]))[2][-1]


@limited_blas
def continue_fold(branch: Branch, fold: SpecialPoint, parameter: str | SecondParameter, direction: float = 1.0,
                  settings: continuation.Settings | None = None, stop=None, progress=None,
                  max_points: int = 400) -> FoldCurve:
    """Trace the curve of folds through ``fold`` (an LP, LV or LN special point of the pressure-continued
    ``branch``) in q (``parameter``: a key of ``second_parameter``); ``direction`` +1 starts with q increasing.
    Stops as ``codim2.continue_branch_point`` (default: q returns past q0 after the cusp, at the partner fold).
    Returns a FoldCurve whose ``end`` is CUSP (``critical``: q at the cusp) when the cusp is verified."""
    t0 = time.perf_counter()
    if branch.parameter != "P":
        raise TwoParameterError(f"the fold curve is traced in (q, P): the branch is continued in {branch.parameter}")
    if fold.kind not in CONTROL_OF_FOLD:
        raise TwoParameterError(f"special point {fold.kind.value}: only folds (LP, LV, LN) are continued here")
    control = CONTROL_OF_FOLD[fold.kind]
    mapped = branch.disc
    branch = plain_branch(branch, fold.X)
    X = mapped.transfer(fold.X, branch.disc) if mapped.mapping is not None else fold.X
    eq = equilibrium_of(branch)
    if not isinstance(parameter, SecondParameter):
        parameter = second_parameter(branch.scene, eq, branch.params, parameter)
    q0 = parameter.q0
    params = branch.params.with_value("P", X[-1])
    w = fold_tangent(eq, X, control, params)
    system = FoldSystem(eq, params, parameter, control, w)
    X0 = np.concatenate([X, w, [q0]])
    settings = settings or curve_settings(branch.scene, max_points)
    path = trace_in_q(system, X0, f"the {fold.kind.value}", branch, parameter, q0, direction, settings, stop,
                      progress)
    end = _classify(system, path)
    name = parameter.name
    verdict = ": a cusp, the two folds merge" if end == CurveEnd.CUSP else " (not a verified cusp)"
    merges = [SpecialPoint(Kind.LP, f.index, f.point.X, **_merge_status(f, path, branch.disc, end, "a cusp"),
                           note=f"fold of the {fold.kind.value} curve in {name}{verdict}") for f in path.folds]
    crossings = fold_crossings(system, path.points, branch.disc, settings)
    return FoldCurve(parameter, branch.scene, branch.disc, params, w, np.array([p.X for p in path.points]),
                     np.array([p.iterations for p in path.points]), np.array([p.residual for p in path.points]),
                     merges, path.stop, time.perf_counter() - t0, end, float(q0), float(direction),
                     meetings=crossings, control=control)


def _classify(system: FoldSystem, path) -> CurveEnd:
    """How a fold curve ended (module docstring): CUSP when a fold in q at P > 0 has fold coefficients of
    opposite signs at the points bracketing it."""
    code, n = path.stop.code, system.n
    if code == StopCode.INTERRUPTED:
        return CurveEnd.INTERRUPTED
    for fold in path.folds:
        before, after = path.bracket(fold)
        if fold.point.X[n] > 0 and system.fold_coefficient(before) * system.fold_coefficient(after) < 0:
            return CurveEnd.CUSP
    if path.folds or code == StopCode.PARTNER:
        return CurveEnd.FOLD
    return _END_OF_STOP.get(code, CurveEnd.OTHER)
