"""A capsule's point on a graded basis: a degree per element group, each chosen from its own tail.

A long capsule's bulge wants a high degree only in the elements holding its fronts (docs/shapes.md: at L = 40 the
middle elements' tails 6.5e-10 where the others' are below 1e-12), so one degree for every element reaches
max_degree long before the fronts are resolved. Here the point X = (u, p) of a system on ``disc`` is moved to the
graded basis (galerkin/elements.graded_sequence) whose degrees ``Resolution.element_degrees`` reads from each
group's own tail, solved again there by Newton on the hyperplane r·X = r·X0 (r moved with the point: a tangent, or
the unit row of p for a point at fixed p), and so on until every group is resolved or at max_degree. Moving a point
to a basis holding all of its functions is exact (``Discretisation.transfer``), so the solve starts where it was.
"""
from dataclasses import dataclass

import numpy as np

from ...galerkin.discretisation import Discretisation, graded
from ...galerkin.elements import group_degrees
from ...numerics.newton import NewtonResult, newton
from .resolution import Resolution


@dataclass
class GradedPoint:
    """The point X = (u, p) on its last basis with the row r moved there, each basis's (element degrees, element
    tails) in order, the last Newton result (None: no basis past the first), whether every group ended resolved,
    and why the rounds ended."""

    disc: Discretisation
    X: np.ndarray
    row: np.ndarray
    rounds: list
    result: NewtonResult | None
    resolved: bool  # every element group's tail at most max_error on the last basis
    message: str


def graded_point(system_on, disc: Discretisation, X: np.ndarray, row: np.ndarray, policy: Resolution, tol: float,
                 max_newton: int, ahead: np.ndarray | None = None, max_rounds: int = 8) -> GradedPoint:
    """X = (u, p) of R(u; p) = 0 on ``disc`` (a capsule's, with joins; ``system_on(disc)`` its ParameterSystem)
    solved again on graded bases with r·X = r·X0 (``row`` r on ``disc``) until each element group's own tail is at
    most ``policy.max_error`` or its degree is max_degree (module docstring); at most ``max_rounds`` bases. The
    first basis is the one wanted by ``ahead`` (given: the point past X on ``disc`` that was not resolved, so that
    the continuation from X can pass it), the others by X's own tails."""
    rounds = [(group_degrees(disc.degree, disc.joins, disc.element_degrees), disc.element_tails(X[:-1]))]
    result, resolved, message = None, False, f"not resolved on {max_rounds} bases"
    for _ in range(max_rounds):
        read = X if ahead is None else ahead  # the point whose tails choose this round's degrees
        wanted, ahead = policy.element_degrees(disc, read[:-1]), None
        if wanted == rounds[-1][0]:
            resolved = disc.tail(read[:-1]) <= policy.max_error
            message = "every element group resolved" if resolved else (
                f"an element group above solver.max_error = {policy.max_error:g} at solver.max_degree = "
                f"{policy.max_degree}")
            break
        target = graded(disc, wanted)
        moved, moved_row = disc.transfer(X, target), disc.transfer(row, target)
        system = system_on(target)
        result = newton(system.residual, system.jacobian, moved, moved_row, moved_row @ moved, tol, max_newton)
        if not result.converged:
            message = f"Newton on element degrees {wanted}: {result.message}"
            break
        disc, X, row = target, result.x, moved_row
        rounds.append((wanted, disc.element_tails(X[:-1])))
    return GradedPoint(disc, X, row, rounds, result, resolved, message)


def covering_basis(used: list) -> Discretisation:
    """The graded basis holding every function of the ``used`` bases (a capsule's, with the same joins and layout):
    per element group the highest degree any of them has, so that each moves there exactly."""
    degrees = np.max([group_degrees(d.degree, d.joins, d.element_degrees) for d in used], axis=0)
    return graded(used[-1], tuple(degrees))
