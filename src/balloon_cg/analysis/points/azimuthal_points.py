"""Branch points of the non-axisymmetric blocks m = 1..m_max (``azimuthal``, docs/second_variation.md).

Detection: between neighbouring points i and i + 1 of an assessed branch, the number of negative eigenvalues
among the lowest ones of a block 'm<m>_held' (and 'm<m>_free' with a field, ``stability.Assessment.blocks``)
changes from a to b: the eigenvalues μ_k, k = min(a, b) .. max(a, b) − 1, of

    H_m c = μ G_m c   (cos mφ perturbations, symmetry zero modes removed: ``azimuthal.spectrum``)

cross zero there.
Location: Brent's method (``continuation.locate_root``) on μ_k(s), the eigenvalue at the point X(s) with

    R(X(s)) = 0,   d·X(s) = d·X_i + s,   d = (X_{i+1} − X_i)/|X_{i+1} − X_i|

(the corrector on the chord hyperplane, as ``bifurcation.locate`` for m = 0), with the branch's own
discretisation and the perturbation degree of its assessments. Every evaluation is a dense eigensolve: the
location is only as certain as the eigenvalue's rounding ε‖H‖ over its slope (~5e-11 at degree 225 on the two-coil
pear branch), and an eigenvalue rounded otherwise (a Lanczos follower) moves the point by as much
(docs/numerics.md §6). LOCATED when Brent converged (|Δs| ≤ 1e-13) and the crossing eigenvalue is converged at
the bracketing points between that degree and the check degree (``crossing_problems``, as for m = 0; it reads
the stored eigenvalue where a point was assessed at that degree), else APPROXIMATE with the bracket and the reason.
Without a field (M = 0 or no coils) the energy is invariant under every rotation and the primary branch is a
sphere, on which a mode of spherical degree n has copies for every m ≤ n: the m = 0 mode about a tilted axis
(the tilted pear, n = 1; the tilted n = 2 mode). So without a field a crossing in the interval of an m = 0
branch point of the branch is that point, and the m = 0 point stands for it (``is_copy``); every other crossing
is a BP special point with its ``m`` and ``block``.
Not classified (``Classification.NONE``): the reduced energy along a non-axisymmetric mode needs the
three-dimensional problem; the critical mode is not stored (``SpecialPoint.mode`` is an axisymmetric layout).
"""
import numpy as np

from ...numerics import continuation
from ...numerics.newton import newton
from ..stability.azimuthal import spectrum
from ..branches.problem import branch_system
from ..results import Block, Branch, Kind, SpecialPoint, approximate, located_or_bracketed
from ..stability.crossings import branch_point_crossings
from ..stability.axisymmetric import convergence_problems


def crossings(assessments, m_max: int) -> list[tuple[int, int, bool, Block, int]]:
    """(index, m, held, block, k) of every eigenvalue μ_k of an azimuthal block m ≤ m_max that changes sign
    between points index and index + 1 (module docstring); the free blocks are those the assessments hold
    (with a field)."""
    return [(n, block.m, block.held, block, k) for n, block, k in branch_point_crossings(assessments, m_max)
            if block.m]


def eigenvalue(system, X, m: int, held: bool, k: int, degree: int) -> float:
    """μ_k of block m (held or free) at the point X = (u, p) of the branch's ``problem.ParameterSystem``,
    perturbation degree ``degree`` (``azimuthal.spectrum``)."""
    return float(spectrum(system.eq, X[:-1], system.params_at(X), m, degree, k + 1, held=held)[k])


def assessed(branch: Branch, n: int, block: Block, k: int, degree: int) -> float | None:
    """μ_k of ``block`` at point n as stored in its assessment, if it was assessed at ``degree`` (else None)."""
    assessment = branch.stability[n]
    return float(assessment.blocks[block][k]) if assessment.degree == degree else None


def locate(branch: Branch, index: int, m: int, held: bool, block: Block, k: int, degree: int) -> SpecialPoint:
    """The zero of μ_k of block m between points index and index + 1 (module docstring), a BP special point."""
    system, solver = branch_system(branch), branch.scene.solver
    X0, X1 = branch.X[index], branch.X[index + 1]
    chord = X1 - X0
    length = np.linalg.norm(chord)
    d = chord / length

    def value_at(s):
        result = newton(system.residual, system.jacobian, X0 + s * d, d, d @ X0 + s, solver.tol, solver.max_newton)
        if not result.converged:
            raise ArithmeticError(result.message)
        return eigenvalue(system, result.x, m, held, k, degree), result.x

    found = continuation.locate_root(value_at, length)
    reading = "held at its centre" if held else "free"
    note = f"non-axisymmetric m = {m} mode, balloon {reading}"
    if found is None:  # not one evaluation converged: the bracket is all that is known
        fields = approximate(branch.disc, X0, X1, f"branch point ({block.value} block): the corrector failed at "
                                                  "every evaluation inside its bracket; its start is stored")
        return SpecialPoint(Kind.BP, index, X0, block=block, m=m, note=note, **fields)
    fields = located_or_bracketed(found.status, branch.disc, X0, X1, f"branch point ({block.value} block)")
    problems = crossing_problems(branch, index, m, held, block, k, degree)
    if problems and not fields.get("reason"):
        fields = approximate(branch.disc, X0, X1, f"branch point ({block.value} block): " + "; ".join(problems))
    return SpecialPoint(Kind.BP, index, found.payload, block=block, m=m, note=note, **fields)


def crossing_problems(branch: Branch, index: int, m: int, held: bool, block: Block, k: int,
                      degree: int) -> list[str]:
    """Whether μ_k of block m is converged at the bracketing points, both at ``degree``
    (``stability.convergence_problems``, as for m = 0; the stored μ_k where a point was assessed at that degree)."""
    system = branch_system(branch)

    def value(n, N):
        stored = assessed(branch, n, block, k, N)
        return stored if stored is not None else eigenvalue(system, branch.X[n], m, held, k, N)

    return convergence_problems(branch, index, value, (degree, degree))


def is_copy(branch: Branch, index: int) -> bool:
    """Whether an m ≥ 1 crossing between points index and index + 1 is a copy of an m = 0 branch point there:
    no field, and an m = 0 branch point in that interval or a neighbouring one (its located point may lie just
    outside the interval where the m ≥ 1 eigenvalue changed sign; module docstring)."""
    field_free = branch.params.M == 0 or not branch.scene.field.coils
    return field_free and any(bp.m == 0 and abs(bp.index - index) <= 1 for bp in branch.branch_points())


def find(branch: Branch, degrees, m_max: int) -> list[SpecialPoint]:
    """The m ≥ 1 branch points, m ≤ m_max, of a branch assessed at the perturbation degrees ``degrees`` (one per
    point, ``Assessment.degree`` of ``branch.stability``), in order along it, each located at the larger
    degree of its two bracketing points; without a field, the copies of its m = 0 branch points are left to
    them (module docstring)."""
    return [locate(branch, index, m, held, block, k, max(degrees[index], degrees[index + 1]))
            for index, m, held, block, k in crossings(branch.stability, m_max) if not is_copy(branch, index)]
