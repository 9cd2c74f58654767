"""A tube's bulge branch resolved through its propagating front: traced on spectral elements refined where it passes.

One Legendre series over the tube cannot resolve the front that joins the bulge to the tube on the propagation plateau
(tube/resolution.py stops "unresolved" there). Here the bulge branch is traced on spectral elements in S
(galerkin/interval_elements.py), switched at the primary branch's odd branch point onto them (tube/bulge.py ``on``),
and the layout is refined locally, where and when a traced point needs it (tube/bulge.py ``refine``):

1. the trace starts on START_ELEMENTS elements of equal length, of ORDER;
2. where a point's tail passes ``max_error``, each of its elements whose own tail does is cut into k equal elements,
   k = ceil((tail/max_error)^(1/(RATE p))) ≥ 2 (RATE p: the tail's decay per halving of the element length
   assumed, in powers of 2: spectral convergence gives ~2^p once the front is resolved; measured on the Ogden
   tube's front at order 10, 2^6.6 from elements of 2 radii to 1);
3. the last stored point and its tangent are moved onto the refined layout (exact: it holds the coarser one's
   space), re-solved there, and the trace continues from it with the step that reached the unresolved point, which
   is traced again on the refined layout (its folds located there); a point still unresolved there refines again;
4. the branch is returned when it reaches its stop with every stored point's estimate (the largest of its elements'
   tails, on the layout it was traced on) at most ``max_error``, or stopped UNRESOLVED at the first point whose
   refined layout would pass the layout's cap, its message saying so in one line: ``element_cap`` unknowns per field
   (E p), elements of ORDER of mean length 1/ELEMENTS_PER_LENGTH radii over the whole tube, its own and not
   solver.max_degree's (a Legendre series' cap: its dense matrices cost (E p)³, the elements' banded ones E p³).

The layout only grows along the branch (the front sweeps the tube once: its elements are cut where it passes, the
rest stays long), so the last layout holds every earlier one's space: the stored branch is on it, each earlier
point's state moved there exactly (galerkin/interval_elements.collocated), and each point's tail, first-integral
spread, stability counts and smallest stress are those of the layout it was traced and solved on (on the last
layout an earlier state is not re-solved: its residual there is its own layout's discretisation error). A fold is
the exception: it is located again on the last layout (its step's ends moved there and re-solved), so that what is
read at it there (an m = 0 frequency's zero, its stability) is read at an equilibrium of that layout. Earlier
points are never retraced: the branch costs one trace.
"""
from dataclasses import replace

import numpy as np

from .bulge import bulge_branch
from ..analysis.results import IntervalStop
from ..analysis.branches.resolution import Resolution
from ..galerkin.interval_elements import ElementInterval, element_interval
from ..numerics.continuation import Stop

START_ELEMENTS = 10  # the first layout's elements of equal length
ORDER = 16  # the elements' polynomial degree
RATE = 0.5  # the assumed decay of an element's tail per halving of its length: 2^(RATE p) (module docstring)
ELEMENTS_PER_LENGTH = 2  # the layout's cap: elements of mean length half a reference radius (a front is ~3 wide)


def element_cap(scene) -> int:
    """The layout's cap in unknowns per field, E p ≤ ORDER max(⌈ELEMENTS_PER_LENGTH L⌉, 2 START_ELEMENTS) (module
    docstring): 320 on L = 10, 960 on L = 30 (whose branch to V/V0 = 50 ends on 22 elements); on a short tube room
    for twice the first layout (L = 3: 320, not 96, below the 160 it starts on)."""
    return ORDER * max(int(np.ceil(ELEMENTS_PER_LENGTH * scene.geometry.length)), 2 * START_ELEMENTS)


def uniform_layout(scene, elements: int, order: int) -> ElementInterval:
    """``elements`` elements of equal length and ``order`` p over the scene's tube."""
    geometry = scene.geometry
    return element_interval(geometry.length, order, np.linspace(-1.0, 1.0, elements + 1)[1:-1], geometry.ends,
                            scene.solver.quadrature, geometry.axial_stretch)


def refined_layout(disc: ElementInterval, tails: np.ndarray, max_error: float) -> ElementInterval:
    """``disc`` with each element whose largest tail over ``tails``' points (points × elements) passes
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
    """The bulge branch switched at ``point`` (an odd branch point of ``primary``) on spectral elements refined
    locally until every stored point's estimate is at most ``policy.max_error``, the layout at most
    ``policy.max_degree`` unknowns per field (None: solver.max_error and ``element_cap``; module docstring), from ``layout`` (None: ``uniform_layout`` of START_ELEMENTS and ORDER); ``trace``: tube/bulge.
    bulge_branch's stop_volume, step, stop_stretch."""
    policy = Resolution(scene.solver.max_error, element_cap(scene)) if policy is None else policy
    disc = uniform_layout(scene, START_ELEMENTS, ORDER) if layout is None else layout
    refused = []  # the layout a refinement would have passed max_degree with

    def refine(coarse: ElementInterval, u: np.ndarray) -> ElementInterval | None:
        finer = refined_layout(coarse, coarse.element_tails(u)[None, :], policy.max_error)
        if finer.degree <= policy.max_degree:
            return finer
        refused.append(finer)
        return None

    branch = bulge_branch(scene, primary, point, max_error=policy.max_error, on=disc, refine=refine, **trace)
    if branch.stop.code != IntervalStop.UNRESOLVED or not refused:
        return branch
    message = (f"{branch.stop.message}: {refused[-1].count} elements of order {disc.order} would pass the layout's "
               f"cap of {policy.max_degree} unknowns per field (elements × order; tube/front.element_cap): raise "
               "solver.max_error")
    return replace(branch, stop=Stop(IntervalStop.UNRESOLVED, message))
