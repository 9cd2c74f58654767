"""User points (UZ) on a tube's branches (``[[events]]``, scene/events.py): where a quantity q passes a value v
between two stored points of a branch, the equilibrium there, landed on as on the sphere
(analysis/branches/events.crossings: Newton on R(X) = 0 and the linearised constraint
∇q(X_k)·(X − X_k) = v − q(X_k), repeated until |q − v| ≤ LANDING_RTOL·max(1, |v|)), in the coordinates
X = (u[unknowns], P) of the branch's TubeSystem (tube/primary.py: the even block on the primary branch, every unknown
on an odd bulge branch).

The quantities, functions of Y = (u, P):

- ``volume`` V = 2π Ṽ(u) (V/R0³), ∇_u V = −2π ∂R/∂P (tube/control.py); ``volume_ratio`` V/V0, V0 = πL;
  ``amount`` n = P V, ∇n = (P ∇_u V, V);
- ``pressure`` P, X's last entry;
- ``lam2_top``, ``lam2_bottom``, ``lam2_equator``: λ2 at S = 0, L and L/2, linear in u (``hoop_row``);
- ``lam2_max``: the largest hoop stretch, λ2 at the crest S* (IntervalDiscretisation.crest); its gradient is the row
  of λ2(S*) (at an interior maximum ∂λ2/∂S = 0, at an end S* is fixed: S*'s motion does not enter to first order);
- ``axial_stretch``: λ̄ = u[axial_index], the ends' distance over L.

A landing that fails keeps the stored point of the interval nearer the value (smaller |q − v|), status NEAREST. The
points are merged into the branch's located points in order along it (``with_events``).
"""
from dataclasses import replace

import numpy as np

from .control import gradient, value
from .results import IntervalSpecial
from .stability import smallest_stress
from ..analysis.branches.events import crossings
from ..analysis.results import Kind
from ..numerics.continuation import RootStatus
from ..scene.events import Quantity
from ..scene.loading import Control

HOOP_AT = {Quantity.LAM2_TOP: 0.0, Quantity.LAM2_BOTTOM: 1.0, Quantity.LAM2_EQUATOR: 0.5}  # S/L of each
CONTROLS = {Quantity.VOLUME: Control.VOLUME, Quantity.VOLUME_RATIO: Control.VOLUME, Quantity.AMOUNT: Control.GAS}


def hoop_row(disc, s: float) -> tuple:
    """(ℓ, c): λ2(s) = ℓ·u + c at the reference arclength s (c = 1 on plugged ends, else 0)."""
    zero = disc.profile(np.zeros(disc.size), np.array([s]))[0][0]
    rows = np.eye(disc.size)
    ell = np.array([disc.profile(row, np.array([s]))[0][0] - zero for row in rows])
    return ell, float(zero)


def tube_quantity(system, quantity: Quantity) -> tuple:
    """(q(X), ∇q(X)) of ``quantity`` in the coordinates X of ``system`` (a tube/primary.TubeSystem; module
    docstring)."""
    disc, columns = system.system.eq.disc, system.columns
    if quantity in CONTROLS:
        scale = 1 / (np.pi * disc.length) if quantity == Quantity.VOLUME_RATIO else 1.0
        q, dq = value(system, CONTROLS[quantity]), gradient(system, CONTROLS[quantity])
        return (lambda X: scale * q(X)), (lambda X: scale * dq(X))
    if quantity == Quantity.LAM2_MAX:
        def crest_row(X):
            return hoop_row(disc, disc.crest(system.full(X)[:-1])[0])

        def largest(X):
            u = system.full(X)[:-1]
            return float(disc.profile(u, np.array([disc.crest(u)[0]]))[0][0])

        return largest, (lambda X: np.append(crest_row(X)[0], 0.0)[columns])
    if quantity == Quantity.PRESSURE:
        ell, c = np.zeros(disc.size + 1), 0.0
        ell[-1] = 1.0
    elif quantity == Quantity.AXIAL_STRETCH:
        ell, c = np.zeros(disc.size + 1), 0.0
        ell[disc.axial_index] = 1.0
    else:
        ell, c = hoop_row(disc, HOOP_AT[quantity] * disc.length)
        ell = np.append(ell, 0.0)
    row = ell[columns]
    return (lambda X: float(row @ X) + c), (lambda X: row)


def event_points(scene, system, states: np.ndarray, pressure: np.ndarray, settings) -> list[IntervalSpecial]:
    """The UZ points, in the order of the scene's events, of the branch with points (``states``, ``pressure``)
    traced on ``system`` (module docstring)."""
    X = np.column_stack([states, pressure])[:, system.columns]
    found = []
    for event in scene.events:
        quantity = tube_quantity(system, event.quantity)
        offset = np.array([quantity[0](x) for x in X]) - event.value
        note = f"{event.quantity.value} = {event.value:g}"
        if offset[0] == 0:
            found.append(IntervalSpecial(Kind.UZ, states[0], float(pressure[0]), 0, RootStatus.LOCATED, note=note))
        for i, point, _ in crossings(system, X, offset, quantity, event.value, settings):
            if point is not None:
                Y = system.full(point.X)
                found.append(IntervalSpecial(Kind.UZ, Y[:-1], float(Y[-1]), i, RootStatus.LOCATED, note=note))
                continue
            nearer = i if abs(offset[i]) <= abs(offset[i + 1]) else i + 1
            found.append(IntervalSpecial(Kind.UZ, states[nearer], float(pressure[nearer]), i, RootStatus.NEAREST,
                                         note=note))
    return found


def with_events(scene, system, branch, settings):
    """``branch`` (an IntervalBranch traced on ``system``) with the UZ points of ``scene``'s events among its located
    points: each inserted before the first located point that lies after it (``along``), the others' order kept."""
    if not scene.events:
        return branch
    eq = system.system.eq
    special = list(branch.special)
    for point in sorted(event_points(scene, system, branch.states, branch.pressure, settings),
                        key=lambda s: along(branch, s)):
        here = along(branch, point)
        at = next((k for k, s in enumerate(special) if along(branch, s) > here), len(special))
        special.insert(at, replace(point, smallest_stress=smallest_stress(eq, point.u)))
    return replace(branch, special=tuple(special))


def along(branch, point: IntervalSpecial) -> float:
    """Where a located point lies along ``branch``: its index plus its projection on the chord of its interval
    (Y = (u, P)), over the chord's length² (0..1 between the points); its index alone in the last interval, whose end
    is not stored."""
    i = point.index
    if i + 1 >= len(branch.pressure):
        return float(i)
    before, after = (np.append(branch.states[k], branch.pressure[k]) for k in (i, i + 1))
    chord = after - before
    return i + float(chord @ (np.append(point.u, point.pressure) - before)) / float(chord @ chord)
