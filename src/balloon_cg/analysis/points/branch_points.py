"""Branch points of the primary branch, their classification, the pear-shaped branches and snap-through.

Detection: a sign change, between neighbouring points, of the lowest eigenvalue of a block of the second
variation (``stability``): the pear block (odd_held) gives symmetry-breaking pitchforks of the held balloon,
and with a field the pear block with the translation (odd_free) those of the free balloon; the even block gives
equator-symmetric (prolate/oblate) branch points unless the change coincides with a fold in P. All are BP
special points; their ``block`` says which (and ``gauge`` which reading: ``results.Gauge.of_block``).
Location: Newton on an extended system that is regular at the branch point (``branch_point``: Werner–Spence
for a pear point of either reading, Moore's system for an even-block point), from the detection bracket, on the plain degree in
x that holds it (``plain_degree``). The point is LOCATED when Newton converged, the crossing eigenvalue there is
below ``EIGENVALUE_TOL`` (and Moore's β too), and the crossing is resolved at the bracketing points (signs and
values agree at each point's assessment degree and its check degree, ``stability.assessed_degrees`` and
``check_degree``: ``crossings``); otherwise APPROXIMATE, with the bracket's uncertainty and the reason. The BP
``index`` is the interval that contains the located point.
Classification: the reduced energy at the bifurcation parameter (P, or Φ̄ on a voltage continuation at fixed P)
along the critical eigenvector φ,
E(Λ) − E* = E2 Λ² + E3 Λ³ + E4 Λ⁴, from constrained minimisations φ·(u − u*) = Λ (the other modes relax);
E3 ≠ 0: transcritical; else E4 > 0: supercritical pitchfork, E4 < 0: subcritical (``classification``).
Branch switching is in ``switching``.
"""
from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg

from ...galerkin.discretisation import Discretisation
from ...galerkin.equilibrium import Equilibrium
from ...numerics.newton import newton
from .extended_systems import MooreSystem, WernerSpence
from ..branches.problem import equilibrium_of
from ..branches.resolution import Resolution
from ..results import Block, Branch, Classification, Gauge, Kind, SpecialPoint, Status, approximate
from ..stability.crossings import branch_point_crossings
from ..stability.axisymmetric import (SecondVariation, Variations, assessed_degrees, assessment_cost, block_indices,
                                      convergence_problems)
from ..branches.tracer import Tracer
from ...numerics.threads import limited_blas

# a branch point located (Newton on its extended system) and classified (four constrained minima) costs about four
# dense m = 0 assessments at its plain degree N, N³ each: 0.6–3.5e-7 s per N³ at N = 40–320 on the shipped scenes
# against ~3e-8 s per unit of ``assessment_cost`` in their stability (one loaded run, session 27)
LOCATION_ASSESSMENTS = 4.0
EIGENVALUE_TOL = 1e-8  # |crossing eigenvalue| at a located branch point (eigenvalues are O(1): L2 normalisation)


def eigenpairs(variation, u, params, idx, count: int):
    """The ``count`` lowest eigenvalues of a block and their eigenvectors (columns, on the block's indices)."""
    H, _ = variation.matrices(u, params)
    return scipy.linalg.eigh(H[np.ix_(idx, idx)], variation.gram[np.ix_(idx, idx)], subset_by_index=[0, count - 1])


def followed_crossing(values, vectors, gram, k: int) -> tuple[int, int]:
    """(i, j): the eigenvalue i at one end of a bracket and j at the other that are one eigenvalue followed by its
    eigenvector (j the largest Gram overlap of i's) and change sign, the one nearest rank k; (k, k) when none does.
    By rank alone the crossing eigenvalue is misread where it passes another one inside the bracket (a free
    balloon's translation in a weak field: an eigenvalue ~1e-3 that the pear eigenvalue passes on its way to 0)."""
    (v0, V0), (v1, V1) = (values[0], vectors[0]), (values[1], vectors[1])
    overlap = np.abs(V0.T @ gram @ V1)
    candidates = [(abs(i - k), i, int(overlap[i].argmax())) for i in range(len(v0))
                  if v0[i] * v1[int(overlap[i].argmax())] < 0]
    return min(candidates)[1:] if candidates else (k, k)


def _eigenpair(variation, u, params, idx, k):
    """The k-th lowest eigenvalue (from 0) of a block and its eigenvector on the full perturbation basis."""
    H, _ = variation.matrices(u, params)
    Hb, Gb = H[np.ix_(idx, idx)], variation.gram[np.ix_(idx, idx)]
    values, vectors = scipy.linalg.eigh(Hb, Gb, subset_by_index=[k, k])
    mode = np.zeros(H.shape[0])
    mode[idx] = vectors[:, 0]
    return values[0], mode


def detect(branch: Branch, assessments) -> list[tuple[int, Block, int]]:
    """(index, block, k) of every change of the number of negative eigenvalues of the pear or even block
    between neighbouring points, one per eigenvalue k (from the lowest, 0) that crosses zero. Changes of the
    even block at a fold in the continuation parameter (P or Φ̄) are the fold itself, not a branch point."""
    return branch_point_crossings(assessments, 0, branch.fold_intervals)


@limited_blas
def locate(branch: Branch, index: int, block: Block, k: int = 0) -> SpecialPoint:
    """The branch point detected between points index and index + 1 (module docstring): a BP special point
    with its block, critical mode (on the perturbation basis of the extended system) and location status; its
    ``index`` is the interval that contains the located point."""
    block = Block(block)
    found = _solve_extended(branch, index, block, k)
    if found.converged:
        index = containing_interval(branch, found.X)
        # the located point may lie in an interval of finer degree than the detection interval: solve there
        if found.degree < max(extended_degrees(branch, index)):
            found = _solve_extended(branch, index, block, k, start=found)
            index = containing_interval(branch, found.X) if found.converged else index
    before, after = branch.X[index], branch.X[index + 1]
    problems = found.problems()
    if found.converged:
        problems += crossing_problems(branch, index, block, k)
    fields = {"status": Status.LOCATED} if not problems else approximate(
        branch.disc, before, after, f"branch point ({block.value} block): " + "; ".join(problems))
    return SpecialPoint(Kind.BP, index, found.X, block=block, mode=found.mode,
                        gauge=Gauge.of_block(block, branch.field_acts), **fields)


@dataclass
class ExtendedSolution:
    """The outcome of Newton on an extended system: X in the branch's layout, the critical mode on the
    perturbation basis of ``degree``, the crossing eigenvalue there and, for Moore's system, β."""

    X: np.ndarray
    mode: np.ndarray
    degree: int
    converged: bool
    message: str
    eigenvalue: float
    beta: float = 0.0

    def problems(self) -> list[str]:
        """Why the point is not a located branch point ([] if it is)."""
        if not self.converged:
            return [f"Newton on the extended system failed ({self.message}); the interpolated detection point is "
                    "stored"]
        out = []
        if abs(self.eigenvalue) > EIGENVALUE_TOL:
            out.append(f"crossing eigenvalue {self.eigenvalue:.2g} at the solution")
        if abs(self.beta) > EIGENVALUE_TOL:
            out.append(f"Moore's β = {self.beta:.2g}: not a branch point of the unperturbed problem")
        return out


def location_cost(branch: Branch, index: int) -> float:
    """``numerics.workers.spread``'s cost of locating and classifying the branch point detected between points index
    and index + 1 (``assessment_cost``'s units): LOCATION_ASSESSMENTS dense blocks at the plain degree there."""
    return LOCATION_ASSESSMENTS * assessment_cost(max(extended_degrees(branch, index)), 0)


def extended_degrees(branch: Branch, index: int) -> tuple[int, int]:
    """The plain degrees that hold points index and index + 1 (``plain_degree``)."""
    return tuple(int(d) for d in Resolution.of(branch.scene).plain_degrees(branch.disc, branch.X[index:index + 2]))


def _solve_extended(branch: Branch, index: int, block: Block, k: int, start: "ExtendedSolution | None" = None):
    """Newton on the extended system of ``block`` (branch_point) on the plain degree that holds the bracket,
    from the point of the bracket where the crossing eigenvalue (``followed_crossing``) interpolates to zero, with
    its mode there (or from ``start``, with the mode of the eigenvalue nearest zero)."""
    degree = max(extended_degrees(branch, index))
    plain = Discretisation(degree, True, branch.disc.pin_translation, joins=branch.disc.joins)
    eq = Equilibrium(branch.scene, plain)
    variation = SecondVariation(eq, degree)
    idx = block_indices(variation, block, field_on=True)
    params = branch.params
    count, gram = min(k + 3, idx.size), variation.gram[np.ix_(idx, idx)]
    reference = None  # the crossing mode at the bracket's start: the guess's mode is the one nearest it
    if start is None:
        ends = branch.disc.transfer(branch.X[index:index + 2], plain)
        pairs = [eigenpairs(variation, X[:-1], branch.params_at(X), idx, count) for X in ends]
        i, j = followed_crossing([p[0] for p in pairs], [p[1] for p in pairs], gram, k)
        s = float(np.clip(pairs[0][0][i] / (pairs[0][0][i] - pairs[1][0][j]), 0.0, 1.0))
        guess, reference = ends[0] + s * (ends[1] - ends[0]), pairs[0][1][:, i]
    else:
        guess = branch.disc.transfer(start.X, plain)
    values, vectors = eigenpairs(variation, guess[:-1], branch.params_at(guess), idx, count)
    n = np.argmin(np.abs(values)) if reference is None else np.argmax(np.abs(vectors.T @ gram @ reference))
    mode = np.zeros(variation.gram.shape[0])
    mode[idx] = vectors[:, n]
    if block != Block.EVEN:
        ell = mode[idx] / np.linalg.norm(mode[idx])
        system = WernerSpence(eq, params, ell, branch.parameter, block)
        X0 = np.concatenate([guess, ell])
    else:
        psi = plain.join(mode[: degree + 1], mode[degree + 1:])
        ell = psi / np.linalg.norm(psi)
        system = MooreSystem(eq, params, ell, branch.parameter)
        X0 = np.concatenate([guess, ell, [0.0]])
    solver = branch.scene.solver
    result = newton(system.residual, system.jacobian, X0, np.zeros((0, X0.size)), [], solver.tol, solver.max_newton)
    solution = result.x if result.converged else X0  # a failed Newton keeps its starting point (it says so)
    X = solution[:plain.size + 1]
    values = eigenpairs(variation, X[:-1], branch.params_at(X), idx, count)[0]
    eigenvalue = values[np.argmin(np.abs(values))]  # the crossing one: nearest zero at the branch point
    beta = system.beta(solution) if block == Block.EVEN else 0.0
    return ExtendedSolution(plain.transfer(X, branch.disc), system.mode(solution), degree, result.converged,
                            result.message, float(eigenvalue), float(beta))


def containing_interval(branch: Branch, X) -> int:
    """The interval i (between points i and i + 1) nearest to X in (p, north pole stretch), p the continuation
    parameter: the one that contains a point of the branch."""
    north = branch.disc.pole_rows()["lam2_top"]
    path = np.stack([branch.X[:, -1], branch.X[:, :-1] @ north], axis=1)
    target = np.array([X[-1], X[:-1] @ north])
    a, d = path[:-1], np.diff(path, axis=0)
    t = np.clip(np.einsum("ij,ij->i", target - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    return int(np.argmin(np.linalg.norm(a + t[:, None] * d - target, axis=1)))


def crossing_problems(branch: Branch, index: int, block: Block, k: int) -> list[str]:
    """Whether the crossing eigenvalue of ``block`` is converged at the bracketing points, at their
    assessment degrees (``stability.assessed_degrees``, ``stability.convergence_problems``)."""
    variations = Variations(equilibrium_of(branch))

    def eigenvalue(n, degree):
        variation, X = variations[degree], branch.X[n]
        idx = block_indices(variation, block, field_on=True)
        return _eigenpair(variation, X[:-1], branch.params_at(X), idx, k)[0]

    return convergence_problems(branch, index, eigenvalue, assessed_degrees(branch)[index:index + 2])


def general_tracer(scene, block: Block = Block.ODD_HELD) -> Tracer:
    """The general (non-symmetric) space of the reading of a branch point of ``block``: the balloon held at its
    centre (b_0 = 0, the 'odd_held' and 'even' blocks), or free (b_0 an unknown, its equation the vanishing net
    axial force: the 'odd_free' block, and the free balloon's blocks of a branch without equator symmetry,
    'all_free', ...)."""
    return Tracer(scene, symmetric=False, held=block == Block.EVEN or block.held)


def plain_degree(branch: Branch, X) -> int:
    """The Legendre degree in x that holds the point X of ``branch`` (``Resolution.plain_degree``)."""
    return Resolution.of(branch.scene).plain_degree(branch.disc, X)


def to_general(branch: Branch, tracer: Tracer, degree: int, u):
    """Coefficients of a (symmetric-layout) solution in the general layout of ``tracer`` at ``degree`` (in x:
    a branch stored on a mapped basis is projected)."""
    return branch.disc.transfer(u, tracer.system(degree, branch.params).eq.disc)


def padded_mode(mode: np.ndarray, degree: int) -> np.ndarray:
    """A mode (a_0..a_N, b_0..b_N) of the perturbation basis in x at another degree: the same function at a
    degree ≥ N, its L2 projection (the Legendre coefficients up to ``degree``) at a lower one."""
    n = mode.size // 2
    a, b = mode[:n][: degree + 1], mode[n:][: degree + 1]
    return np.concatenate([np.pad(a, (0, degree + 1 - a.size)), np.pad(b, (0, degree + 1 - b.size))])


def mode_direction(bp: SpecialPoint, disc: Discretisation):
    """The critical eigenvector as a unit direction in X = (u, P) of the general discretisation (its Legendre
    coefficients in x padded to that degree)."""
    mode = padded_mode(bp.mode, disc.degree)
    direction = np.append(disc.join(mode[: disc.degree + 1], mode[disc.degree + 1:]), 0.0)
    return direction / np.linalg.norm(direction)


def constrained_minimum(eq: Equilibrium, params, phi: np.ndarray, target: float, guess: np.ndarray, solver):
    """The stationary point of E(u) on the hyperplane φ·u = target (the other modes relax): Newton on
    R(u) + μφ = 0, φ·u = target in x = (u, μ) from (guess, 0); x[-1] = μ = −dE/dΛ along the constraint."""
    return newton(lambda x: eq.residual(x[:-1], params) + x[-1] * phi,
                  lambda x: np.hstack([eq.jacobian(x[:-1], params), phi[:, None]]),
                  np.append(guess, 0.0), np.append(phi, 0.0), target, solver.tol, solver.max_newton)


def classify(branch: Branch, bp: SpecialPoint, delta: float = 2e-2) -> SpecialPoint:
    """``bp`` with E2, E3, E4 of the reduced energy at its parameters (P, and Φ̄) and its classification (module
    docstring); unclassified (Classification.NONE) when fewer than three constrained minimisations converge."""
    solver = branch.scene.solver
    tracer = general_tracer(branch.scene, bp.block)
    degree = plain_degree(branch, bp.X)
    eq = tracer.system(degree, branch.params).eq
    u_star = to_general(branch, tracer, degree, bp.X[:-1])
    params = branch.params_at(bp.X)
    phi = mode_direction(bp, eq.disc)[:-1]
    E0 = eq.energy(u_star, params)
    lams, energies = [], []
    for lam in (-2 * delta, -delta, delta, 2 * delta):
        result = constrained_minimum(eq, params, phi, phi @ u_star + lam, u_star + lam * phi, solver)
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
