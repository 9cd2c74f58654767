"""Branch points of the primary branch, their classification, the pear-shaped branches and snap-through.

Detection: a sign change, between neighbouring points, of the lowest eigenvalue of a block of the second
variation (``stability``): the pear block (odd) gives symmetry-breaking pitchforks 'BP'; the even block gives
equator-symmetric (prolate/oblate) branch points 'BP-even' unless the change coincides with a fold in P.
Location: Brent's method (``continuation.locate_root``) on μ(s), the crossing eigenvalue at the point X(s)
corrected on the chord hyperplane, to |Δs| ≤ 1e-13 (with the discretisation of the branch itself).
Classification: the reduced energy at the bifurcation pressure along the critical eigenvector φ,
E(Λ) − E* = E2 Λ² + E3 Λ³ + E4 Λ⁴, from constrained minimisations φ·(u − u*) = Λ (the other modes relax);
E3 ≠ 0: transcritical; else E4 > 0: supercritical pitchfork, E4 < 0: subcritical.
Branch switching: from u* + δφ, corrected on the hyperplane normal to φ, then pseudo-arclength in the general
(non-symmetric) space, both ways (the pear branch and its mirror image), until it rejoins the primary branch
(the amplitude φ·(u − u*) changes sign: a closed loop, the isola, when that happens at another branch point)
or a stop rule applies.
"""
import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ..numerics import continuation
from .branch import ParameterSystem, PrimaryTracer, _stop_rule, assemble, transfer_error
from ..galerkin.discretisation import Discretisation
from ..numerics.newton import newton
from .stability import SecondVariation

@dataclass
class BranchPoint:
    index: int  # between branch points index and index + 1
    block: str  # 'odd_held' (pear) or 'even'
    X: np.ndarray  # located point (u in the branch's layout, P)
    mode: np.ndarray  # critical eigenvector on the perturbation basis (a_0..a_N, b_0..b_N)
    kind: str = "BP"
    E: tuple = (np.nan, np.nan, np.nan)  # E2, E3, E4


def _eigenpair(variation, u, params, idx, k):
    """The k-th lowest eigenvalue (from 0) of a block and its eigenvector on the full perturbation basis."""
    H, _ = variation.matrices(u, params)
    Hb, Gb = H[np.ix_(idx, idx)], variation.gram[np.ix_(idx, idx)]
    values, vectors = scipy.linalg.eigh(Hb, Gb, subset_by_index=[k, k])
    mode = np.zeros(H.shape[0])
    mode[idx] = vectors[:, 0]
    return values[0], mode


def block_indices(variation, block: str, field_on: bool):
    i = variation.index
    if block == "even":
        return np.concatenate([i["a_even"], i["b_odd"]])
    odd = np.concatenate([i["a_odd"], i["b_even"][1:]])
    return np.append(odd, variation.translation) if (block == "odd_free" and field_on) else odd


def detect(branch, assessments):
    """(index, block, k) of every change of the number of negative eigenvalues of the pear or even block
    between neighbouring points; k is the eigenvalue (from the lowest, 0) that crosses zero. Changes of the
    even block at a fold in P are the fold itself, not a branch point."""
    folds = {s.index for s in branch.special if s.kind == "LP"}
    events = []
    for n in range(len(assessments) - 1):
        for block in ("odd_held", "even"):
            a = int(np.sum(assessments[n].blocks[block] < 0))
            b = int(np.sum(assessments[n + 1].blocks[block] < 0))
            if a != b and not (block == "even" and n in folds):
                events.append((n, block, min(a, b)))
    return events


def locate(branch, index: int, block: str, k: int = 0) -> BranchPoint:
    """The branch point between points index and index + 1 (see module docstring)."""
    eq, params = branch.equilibrium, branch.params
    variation = SecondVariation(eq, branch.disc.degree)
    idx = block_indices(variation, block, field_on=False)
    system = _system(branch)
    X0, X1 = branch.X[index], branch.X[index + 1]
    chord = X1 - X0
    length = np.linalg.norm(chord)
    d = chord / length

    def value_at(s):
        result = newton(system.residual, system.jacobian, X0 + s * d, d, d @ X0 + s,
                        eq.scene.solver.tol, eq.scene.solver.max_newton)
        if not result.converged:
            raise ArithmeticError(result.message)
        value, mode = _eigenpair(variation, result.x[:-1], params.with_value("P", result.x[-1]), idx, k)
        return value, (result.x, mode)

    found = continuation.locate_root(value_at, length)
    if found is None:
        raise RuntimeError(f"branch point between points {index} and {index + 1} could not be located")
    X, mode = found
    return BranchPoint(index, block, X, mode)


def _system(branch):
    return ParameterSystem(branch.equilibrium, branch.params, "P")


def general_tracer(scene) -> PrimaryTracer:
    """The general (non-symmetric) space, balloon held at its centre: the branch points are those of the held
    reading (the 'odd_held' block), so the branches leaving them are traced with b_0 = 0 too."""
    return PrimaryTracer(scene, symmetric=False, held=True)


def plain_degree(branch, X) -> int:
    """The Legendre degree in x that holds the point X of ``branch``: the branch's own degree if its basis is not
    mapped, else grown by half (up to solver.max_degree) until the projection loses at most max_error and its
    spectral tail is within max_error (the mapped degree is far below what x needs near a wire)."""
    disc, solver = branch.disc, branch.equilibrium.scene.solver
    degree = disc.degree
    while disc.mapping is not None and degree < solver.max_degree:
        plain = Discretisation(degree, disc.symmetric, disc.pin_translation)
        moved = disc.transfer(X, plain)
        if max(transfer_error(disc, X, plain, moved)[0], plain.tail(moved[: plain.size])) <= solver.max_error:
            break
        degree = min(int(degree * 1.5), solver.max_degree)
    return degree


def to_general(branch, tracer, degree, u):
    """Coefficients of a (symmetric-layout) solution in the general layout of ``tracer`` at ``degree`` (in x:
    a branch stored on a mapped basis is projected)."""
    return branch.disc.transfer(u, tracer.system(degree, branch.params).eq.disc)


def padded_mode(mode: np.ndarray, degree: int) -> np.ndarray:
    """A mode (a_0..a_N, b_0..b_N) of the stability basis in x, the same function at a degree ≥ N."""
    n = mode.size // 2
    return np.concatenate([np.pad(mode[:n], (0, degree + 1 - n)), np.pad(mode[n:], (0, degree + 1 - n))])


def mode_direction(bp: BranchPoint, disc: Discretisation):
    """The critical eigenvector as a unit direction in X = (u, P) of the general discretisation (its Legendre
    coefficients in x padded to that degree)."""
    mode = padded_mode(bp.mode, disc.degree)
    direction = np.append(disc.join(mode[: disc.degree + 1], mode[disc.degree + 1:]), 0.0)
    return direction / np.linalg.norm(direction)


def classify(branch, bp: BranchPoint, delta: float = 2e-2) -> BranchPoint:
    """E2, E3, E4 of the reduced energy at fixed P* and the kind (module docstring)."""
    scene = branch.equilibrium.scene
    tracer = general_tracer(scene)
    degree = plain_degree(branch, bp.X)
    eq = tracer.system(degree, branch.params).eq
    u_star = to_general(branch, tracer, degree, bp.X[:-1])
    params = branch.params.with_value("P", bp.X[-1])
    phi = mode_direction(bp, eq.disc)[:-1]
    E0 = eq.energy(u_star, params)
    lams, energies = [], []
    for lam in (-2 * delta, -delta, delta, 2 * delta):
        result = newton(lambda x: eq.residual(x[:-1], params) + x[-1] * phi,
                        lambda x: np.hstack([eq.jacobian(x[:-1], params), phi[:, None]]),
                        np.append(u_star + lam * phi, 0.0), np.append(phi, 0.0), phi @ u_star + lam,
                        scene.solver.tol, scene.solver.max_newton)
        if result.converged:
            lams.append(lam)
            energies.append(eq.energy(result.x[:-1], params) - E0)
    if len(lams) < 3:
        return bp
    L = np.array(lams)
    E2, E3, E4 = np.linalg.lstsq(np.stack([L**2, L**3, L**4], axis=1), np.array(energies), rcond=None)[0]
    bp.E = (float(E2), float(E3), float(E4))
    if abs(E3) * delta > abs(E4) * delta**2:
        bp.kind = "transcritical"
    else:
        bp.kind = "pitchfork-super" if E4 > 0 else "pitchfork-sub"
    return bp


def trace_pear(branch, bp: BranchPoint, sign: float, name: str, progress=None, delta: float = 1e-3):
    """The bifurcating branch leaving ``bp`` along ±φ, in the general space, until it rejoins or stops."""
    t0 = time.perf_counter()
    scene = branch.equilibrium.scene
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
    base = _stop_rule(scene, scene.continuation.stop_stretch)
    anchors = {}

    def stop(disc, point):
        if disc not in anchors:
            coarse = system.eq.disc
            anchors[disc] = (coarse.transfer(phi, disc), coarse.transfer(X_star, disc))
        direction, star = anchors[disc]
        if direction @ (point.X - star) < 0:
            return "rejoined the primary branch"
        south = float(disc.pole_rows()["lam2_south"] @ point.X[:-1])
        if south >= scene.continuation.stop_stretch:
            return f"south pole stretch reached stop_stretch {scene.continuation.stop_stretch:g}"
        return base(disc, point)

    return assemble(tracer, params, name, tracer.leg(start, params, stop, progress, degree=degree), t0=t0)
