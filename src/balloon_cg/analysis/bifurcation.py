"""Branch points of the primary branch, their classification, the pear-shaped branches and snap-through.

Detection: a sign change, between neighbouring points, of the lowest eigenvalue of a block of the second
variation (``stability``): the pear block (odd_held) gives symmetry-breaking pitchforks; the even block gives
equator-symmetric (prolate/oblate) branch points unless the change coincides with a fold in P. Both are BP
special points; their ``block`` says which.
Location: Brent's method (``continuation.locate_root``) on μ(s), the crossing eigenvalue at the point X(s)
corrected on the chord hyperplane, to |Δs| ≤ 1e-13 (with the discretisation of the branch itself); the point's
``status`` says whether the root was located or only the nearest evaluated point is known.
Classification: the reduced energy at the bifurcation pressure along the critical eigenvector φ,
E(Λ) − E* = E2 Λ² + E3 Λ³ + E4 Λ⁴, from constrained minimisations φ·(u − u*) = Λ (the other modes relax);
E3 ≠ 0: transcritical; else E4 > 0: supercritical pitchfork, E4 < 0: subcritical (``classification``).
Branch switching is in ``switching``.
"""
from dataclasses import replace

import numpy as np
import scipy.linalg

from ..galerkin.discretisation import Discretisation
from ..numerics import continuation
from ..numerics.newton import newton
from .problem import equilibrium_of, pressure_system
from .resolution import Resolution
from .results import Block, Branch, Classification, Kind, SpecialPoint, located_or_bracketed
from .stability import SecondVariation
from .tracer import Tracer


def _eigenpair(variation, u, params, idx, k):
    """The k-th lowest eigenvalue (from 0) of a block and its eigenvector on the full perturbation basis."""
    H, _ = variation.matrices(u, params)
    Hb, Gb = H[np.ix_(idx, idx)], variation.gram[np.ix_(idx, idx)]
    values, vectors = scipy.linalg.eigh(Hb, Gb, subset_by_index=[k, k])
    mode = np.zeros(H.shape[0])
    mode[idx] = vectors[:, 0]
    return values[0], mode


def block_indices(variation, block: Block, field_on: bool):
    """Indices of a block on the perturbation basis (odd_held plus b_0 for a free balloon in a field)."""
    i = variation.index
    if block == Block.EVEN:
        return np.concatenate([i["a_even"], i["b_odd"]])
    odd = np.concatenate([i["a_odd"], i["b_even"][1:]])
    return np.append(odd, variation.translation) if (block == "odd_free" and field_on) else odd


def detect(branch: Branch, assessments) -> list[tuple[int, Block, int]]:
    """(index, block, k) of every change of the number of negative eigenvalues of the pear or even block
    between neighbouring points; k is the eigenvalue (from the lowest, 0) that crosses zero. Changes of the
    even block at a fold in P are the fold itself, not a branch point."""
    folds = {s.index for s in branch.special if s.kind == Kind.LP}
    events = []
    for n in range(len(assessments) - 1):
        for block in (Block.ODD_HELD, Block.EVEN):
            a = int(np.sum(assessments[n].blocks[block] < 0))
            b = int(np.sum(assessments[n + 1].blocks[block] < 0))
            if a != b and not (block == Block.EVEN and n in folds):
                events.append((n, block, min(a, b)))
    return events


def locate(branch: Branch, index: int, block: Block, k: int = 0) -> SpecialPoint:
    """The branch point between points index and index + 1 (module docstring): a BP special point with its
    block, critical mode and location status."""
    eq, params, solver = equilibrium_of(branch), branch.params, branch.scene.solver
    variation = SecondVariation(eq, branch.disc.degree)
    idx = block_indices(variation, block, field_on=False)
    system = pressure_system(branch)
    X0, X1 = branch.X[index], branch.X[index + 1]
    chord = X1 - X0
    length = np.linalg.norm(chord)
    d = chord / length

    def value_at(s):
        result = newton(system.residual, system.jacobian, X0 + s * d, d, d @ X0 + s, solver.tol, solver.max_newton)
        if not result.converged:
            raise ArithmeticError(result.message)
        value, mode = _eigenpair(variation, result.x[:-1], params.with_value("P", result.x[-1]), idx, k)
        return value, (result.x, mode)

    found = continuation.locate_root(value_at, length)
    if found is None:
        raise RuntimeError(f"branch point between points {index} and {index + 1} could not be located")
    X, mode = found.payload
    found_fields = located_or_bracketed(found.status, branch.disc, X0, X1, f"branch point ({Block(block).value} block)")
    return SpecialPoint(Kind.BP, index, X, block=Block(block), mode=mode, **found_fields)


def general_tracer(scene) -> Tracer:
    """The general (non-symmetric) space, balloon held at its centre: the branch points are those of the held
    reading (the 'odd_held' block), so the branches leaving them are traced with b_0 = 0 too."""
    return Tracer(scene, symmetric=False, held=True)


def plain_degree(branch: Branch, X) -> int:
    """The Legendre degree in x that holds the point X of ``branch`` (``Resolution.plain_degree``)."""
    return Resolution.of(branch.scene.solver).plain_degree(branch.disc, X)


def to_general(branch: Branch, tracer: Tracer, degree: int, u):
    """Coefficients of a (symmetric-layout) solution in the general layout of ``tracer`` at ``degree`` (in x:
    a branch stored on a mapped basis is projected)."""
    return branch.disc.transfer(u, tracer.system(degree, branch.params).eq.disc)


def padded_mode(mode: np.ndarray, degree: int) -> np.ndarray:
    """A mode (a_0..a_N, b_0..b_N) of the stability basis in x, the same function at a degree ≥ N."""
    n = mode.size // 2
    return np.concatenate([np.pad(mode[:n], (0, degree + 1 - n)), np.pad(mode[n:], (0, degree + 1 - n))])


def mode_direction(bp: SpecialPoint, disc: Discretisation):
    """The critical eigenvector as a unit direction in X = (u, P) of the general discretisation (its Legendre
    coefficients in x padded to that degree)."""
    mode = padded_mode(bp.mode, disc.degree)
    direction = np.append(disc.join(mode[: disc.degree + 1], mode[disc.degree + 1:]), 0.0)
    return direction / np.linalg.norm(direction)


def classify(branch: Branch, bp: SpecialPoint, delta: float = 2e-2) -> SpecialPoint:
    """``bp`` with E2, E3, E4 of the reduced energy at fixed P* and its classification (module docstring);
    unclassified (Classification.NONE) when fewer than three constrained minimisations converge."""
    solver = branch.scene.solver
    tracer = general_tracer(branch.scene)
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
                        solver.tol, solver.max_newton)
        if result.converged:
            lams.append(lam)
            energies.append(eq.energy(result.x[:-1], params) - E0)
    if len(lams) < 3:
        return bp
    L = np.array(lams)
    E2, E3, E4 = np.linalg.lstsq(np.stack([L**2, L**3, L**4], axis=1), np.array(energies), rcond=None)[0]
    if abs(E3) * delta > abs(E4) * delta**2:
        kind = Classification.TRANSCRITICAL
    else:
        kind = Classification.PITCHFORK_SUPER if E4 > 0 else Classification.PITCHFORK_SUB
    return replace(bp, E=(float(E2), float(E3), float(E4)), classification=kind)
