"""A tube's bulge branch resolved through its propagating front: traced on spectral elements refined where it passes.

One Legendre series over the tube cannot resolve the front that joins the bulge to the tube on the propagation plateau
(tube/resolution.py stops "unresolved" there). Here the bulge branch is traced on spectral elements in S
(galerkin/interval_elements.py), switched at the primary branch's odd branch point onto them (tube/bulge.py ``on``),
and the layout is refined from the per-element tails read over the whole branch:

1. trace the branch on the layout (from START_ELEMENTS elements of equal length, of ORDER) to its stop, every
   point's element tails kept;
2. every element whose tail passed ``max_error`` at some point of the branch is cut into k equal elements,
   k = ceil((tail/max_error)^(1/(RATE p))) ≥ 2 (RATE p: the tail's decay per halving of the element length
   assumed, in powers of 2: spectral convergence gives ~2^p once the front is resolved; measured on the Ogden
   tube's front at order 10, 2^6.6 from elements of 2 radii to 1);
3. retrace from the onset on the refined layout; the branch is returned when no element's tail passed max_error
   at any of its points (every stored point's estimate, the largest of its elements', is then at most max_error),
   or when the refined layout would have more than ``solver.max_degree`` unknowns per field (E p): then the last
   layout is traced once more with the check (bulge_branch stops UNRESOLVED at its first point past max_error,
   that point not stored) and returned so, its message naming max_degree.

The front sweeps the tube once, so each round refines where it has passed and the last trace's layout is graded
towards the front's path: short elements over the reference arclength the front crossed, the rest long.
"""
from dataclasses import replace

import numpy as np

from .bulge import bulge_branch
from .results import IntervalStop
from ..analysis.branches.resolution import Resolution
from ..analysis.results import StopCode
from ..galerkin.interval_elements import ElementInterval, element_interval
from ..numerics.continuation import Stop

START_ELEMENTS = 10  # the first layout's elements of equal length
ORDER = 16  # the elements' polynomial degree
RATE = 0.5  # the assumed decay of an element's tail per halving of its length: 2^(RATE p) (module docstring)


def uniform_layout(scene, elements: int, order: int) -> ElementInterval:
    """``elements`` elements of equal length and ``order`` p over the scene's tube."""
    geometry = scene.geometry
    return element_interval(geometry.length, order, np.linspace(-1.0, 1.0, elements + 1)[1:-1], geometry.ends,
                            scene.solver.quadrature, geometry.axial_stretch)


def refined_layout(disc: ElementInterval, tails: np.ndarray, max_error: float) -> ElementInterval:
    """``disc`` with each element whose largest tail over the branch (``tails``: points × elements) passes
    ``max_error`` cut into k equal elements (module docstring); ``disc`` itself where none does."""
    worst = tails.max(axis=0)
    edges = disc.edges
    bounds = []
    for e, tail in enumerate(worst):
        if e > 0:
            bounds.append(edges[e])
        if tail > max_error:
            pieces = max(2, int(np.ceil((tail / max_error) ** (1.0 / (RATE * disc.order)))))
            bounds.extend(np.linspace(edges[e], edges[e + 1], pieces + 1)[1:-1])
    return replace(disc, degree=(len(bounds) + 1) * disc.order, bounds=tuple(bounds))


def front_bulge(scene, primary, point, policy: Resolution | None = None, layout: ElementInterval | None = None,
                **trace):
    """The bulge branch switched at ``point`` (an odd branch point of ``primary``) on spectral elements refined until
    every stored point's estimate is at most ``policy.max_error`` (None: the scene's; module docstring), from
    ``layout`` (None: ``uniform_layout`` of START_ELEMENTS and ORDER); ``trace``: tube/bulge.bulge_branch's
    stop_volume, step, stop_stretch."""
    policy = Resolution.of(scene) if policy is None else policy
    disc = uniform_layout(scene, START_ELEMENTS, ORDER) if layout is None else layout
    while True:
        branch = bulge_branch(scene, primary, point, on=disc, **trace)
        if branch.stop.code == StopCode.INTERRUPTED:  # a signal: the points traced on this layout, not a retrace
            return branch
        tails = np.array([disc.element_tails(u) for u in branch.states])
        finer = refined_layout(disc, tails, policy.max_error)
        if finer == disc:
            return branch
        if finer.degree > policy.max_degree:
            checked = bulge_branch(scene, primary, point, on=disc, max_error=policy.max_error, **trace)
            if checked.stop.code == StopCode.INTERRUPTED:
                return checked
            message = (f"{checked.stop.message}: {finer.count} elements of order {disc.order} would pass "
                       f"solver.max_degree {policy.max_degree} (elements × order): raise it or solver.max_error")
            return replace(checked, stop=Stop(IntervalStop.UNRESOLVED, message))
        disc = finer
