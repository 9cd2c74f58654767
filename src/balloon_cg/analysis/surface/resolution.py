"""The resolution policy of a branch on the whole sphere (``surface.branches``): when a point's spectral tail in the
degree or the order exceeds solver.max_error, the next basis: the wire map re-centred on the state's own closest
approach to the wires (``remapped``), then the degree and the order extended as far as the fitted geometric decay
of the coefficients asks (``refined``), up to MAX_DEGREE and MAX_ORDER.
"""
from dataclasses import replace

import numpy as np

from ...surface.basis import SphericalBasis
from ...surface.measures import tails
from ..branches import wires

MAX_DEGREE = 128  # the finest polar degree the resolution policy raises to
MAX_ORDER = 48  # the finest order of an anisotropic basis (a state pressed against a wire on one side needs more:
#                 flagged); an isotropic basis (order = degree) is capped by MAX_DEGREE
DEGREE_STEP, ORDER_STEP = 8, 2  # the smallest increments; larger ones where the decay asks for them


def increment(maxima: np.ndarray, target: float, step: int, most: int) -> int:
    """How far to extend a spectrum whose largest coefficient per index is ``maxima`` (the last ones being the tail)
    for its predicted tail to fall below ``target``: geometric decay fitted to the last four indices, rounded up to
    a multiple of ``step``, at least ``step`` and at most ``most``."""
    tail = np.maximum(maxima[-4:], 1e-300)
    rate = np.polyfit(np.arange(tail.size), np.log(tail), 1)[0]
    if rate >= 0.0:
        return most
    needed = np.log(target / tail[-1]) / rate
    return int(min(most, max(step, step * np.ceil(needed / step))))


def refined(basis: SphericalBasis, c: np.ndarray, max_error: float) -> SphericalBasis | None:
    """The next finer basis when a tail of c exceeds ``max_error`` (``surface.measures.tails``): the degree and the
    order extended as far as the fitted decay of the coefficients predicts is needed for a tail of max_error/4
    (an isotropic basis stays isotropic); the same basis when both tails are below max_error, None when the degree
    would pass MAX_DEGREE or a capped order MAX_ORDER."""
    theta, phi = tails(basis, c)
    degree, order = basis.degree, basis.order
    if theta > max_error:
        by_degree = np.array([max((abs(c[b.offset + i]) for b in basis.blocks for i, l in enumerate(b.degrees)
                                   if l == degree_), default=0.0) for degree_ in range(basis.degree + 1)])
        degree += increment(by_degree, max_error / 4, DEGREE_STEP, 4 * DEGREE_STEP)
        order = degree if basis.order == basis.degree else order
    if phi > max_error:
        by_order = np.array([max((np.abs(c[b.slice]).max() for b in basis.blocks if b.m == m), default=0.0)
                             for m in range(basis.order + 1)])
        order = min(order + increment(by_order, max_error / 4, ORDER_STEP, 4 * ORDER_STEP), degree)
    if degree > MAX_DEGREE or (order < degree and order > max(MAX_ORDER, basis.order)):
        return None
    if (degree, order) == (basis.degree, basis.order):
        return basis
    return replace(basis, degree=degree, order=order, n_theta=0, n_phi=0)


def remapped(basis: SphericalBasis, c: np.ndarray, coils) -> SphericalBasis:
    """``basis`` on the wire map of the state c's own closest approaches to the wires (analysis.branches.wires: the
    axisymmetric solver's widths, centres mirrored on a basis that keeps z → −z or the inversion) when that map is
    not ``close_to`` the basis' own: a state that moves toward a wire on one side needs a narrower map than the
    branch point's. ``basis`` itself without a map or without coils."""
    if basis.mapping is None or not len(coils):
        return basis
    found = wires.surface_approaches(basis.node_state(c), np.repeat(basis.nodes["cos_theta"], basis.n_phi), coils)
    mapping = wires.centred_map(found, [wires.map_width(a) for a in found],
                                any(S[2] < 0 for S in basis.symmetry))
    if mapping is None or mapping.close_to(basis.mapping):
        return basis
    return replace(basis, mapping=mapping)
