"""The mirror image of a pear branch as the reflection z → −z of the branch, not a second continuation.

In a scene invariant under z → −z (material and loading always are; the coils when ``Field.is_equator_symmetric``)
the branch leaving a pear branch point along −φ is the reflection of the one leaving it along +φ: θ → π − θ,
λ2̃(x) = λ2(−x), η̃(x) = −η(−x) (x = cos θ; ``Discretisation.reflect``, a sign per coefficient, on the mirrored
wire map for a mapped basis). Every step of the trace is equivariant: predictor, Keller's corrector and the step
control (norms and dot products of sign-flipped vectors), the refinement and the wire maps (re-centred on the
reflected wires), the rejoin test φ·(u − u*) (φ odd, u* even). The energy is invariant, so every block of the
second variation (m = 0 and m ≥ 1, held and free, under pressure, volume and gas control) has the same spectrum:
the assessments are copied.

Only the bookkeeping of the pole stretches is not symmetric, and is reflected as the trace would have done it:
the tracer locates the turning points of the north pole stretch (TP) only, and stops at min_stretch at the north
pole only. So the pear branch is traced with its south pole turning points located too (``switching.Turn.BOTTOM``):
they become the mirror's TP, while the pear's own TP (the mirror's south turning points) are not carried over; the
stops STOP_STRETCH and BOTTOM_STOP_STRETCH swap; LP, LV, LN and EP keep their kind with X reflected; a rejoin (the
BP of an equator-symmetric primary point) is its own reflection as a state, its coefficients reflected onto the
mirrored wire map like every other point's (on a map an equator-symmetric state's coefficients are not their own
reflection). A pear branch that stopped on min_stretch, or whose
south pole stretch reached it (where the mirror's trace would have stopped), is not reflected: the mirror is traced
(``Origin.TRACED_NOT_REFLECTABLE``).

Check (every stored result is verified or flagged): the residual (max-norm) of each reflected point on the
mirror's own system exceeds that of the pear branch's point on its system by at most solver.tol
(``reflection_excess``: zero to rounding for an exact reflection); if one does not, the mirror is traced
(``Origin.TRACED_REFLECTION_FAILED``). The stored residuals are the pear branch's (Newton's, at the solved degree).
"""
import time
from dataclasses import replace

import numpy as np

from ..branches.events import event_points
from ..branches.primary import top_stop_stretch
from ..branches.problem import branch_system
from ..results import Branch, Kind, Leg, Origin, SpecialPoint, Stop, StopCode
from .pear import Turn, bottom_stop_stretch

MIRROR = "_mirror"  # the suffix of a branch's mirror image (a pear branch's, a whole-sphere pitchfork branch's)


def reflectable(scene) -> bool:
    """Whether the scene is invariant under z → −z (its coils are: ``Field.is_equator_symmetric``)."""
    return scene.field.is_equator_symmetric


def take_bottom_turns(branch: Branch) -> list[SpecialPoint]:
    """Remove the south pole turning points (``Turn.BOTTOM``, traced for the reflection) from ``branch.special``
    and return them."""
    turns = [s for s in branch.special if s.kind == Turn.BOTTOM]
    branch.special = [s for s in branch.special if s.kind != Turn.BOTTOM]
    return turns


def reflection(pear: Branch, bottom_turns: list[SpecialPoint], name: str) -> Branch | Origin:
    """The mirror image ``name`` of the traced pear branch ``pear`` and of its assessments, if any (module
    docstring), its residuals checked; or, where it is not the mirror the trace would give or a reflected point
    fails the check, the Origin to record on the traced mirror instead."""
    t0 = time.perf_counter()
    cont = pear.scene.continuation
    if pear.stopped(StopCode.MIN_STRETCH) or pear.pole_values()["lam2_bottom"].min() <= cont.min_stretch:
        return Origin.TRACED_NOT_REFLECTABLE
    disc = pear.disc.reflected()
    mirror = replace(pear, name=name, disc=disc, X=pear.disc.reflect(pear.X), origin=Origin.REFLECTED,
                     reflection_of=pear.name)
    if not reflection_excess(pear, mirror).max() <= pear.scene.solver.tol:
        return Origin.TRACED_REFLECTION_FAILED
    swapped = {StopCode.STOP_STRETCH: bottom_stop_stretch(cont.stop_stretch),
               StopCode.BOTTOM_STOP_STRETCH: top_stop_stretch(cont.stop_stretch)}

    def stop(s: Stop) -> Stop:  # the stops that name a pole or a coil are reflected; the others are the same
        if s.code == StopCode.WIRE_GAP:
            return Stop(s.code, f"{s.message} on {pear.name}; here the mirror image of that coil")
        return swapped.get(s.code, s)

    # the user points are located again on the image (an event of one pole is not one of the other)
    special = [_reflected(s, pear.disc, stop) for s in pear.special + bottom_turns if s.kind not in (Kind.TP, Kind.UZ)]
    special += event_points(mirror)
    return replace(mirror, special=sorted(special, key=lambda s: s.index),
                   legs=tuple(Leg(leg.label, stop(leg.stop)) for leg in pear.legs),
                   stability=None if pear.stability is None else  # not assessed: ``continue`` at a BP
                   [replace(a, blocks={k: v.copy() for k, v in a.blocks.items()}) for a in pear.stability],
                   unsettled=list(pear.unsettled), wall_time=time.perf_counter() - t0)


def reflection_excess(branch: Branch, mirror: Branch) -> np.ndarray:
    """Per point, by how much the residual (max-norm) of the reflected point on ``mirror``'s own system exceeds that
    of the point on ``branch``'s: zero to rounding when the reflection is exact. (Not the residual itself: a point
    solved at a lower degree and stored on the finer final basis has a residual there of its truncation error,
    ~1e-13 and above; its own Newton residual is ``Branch.residual``.)"""
    own, reflected = branch_system(branch), branch_system(mirror)
    return np.array([np.abs(reflected.residual(Y)).max() - np.abs(own.residual(X)).max()
                     for X, Y in zip(branch.X, mirror.X)])


def _reflected(s: SpecialPoint, disc, stop) -> SpecialPoint:
    """A special point of the pear branch (on ``disc``) as one of its mirror image, X reflected onto the mirror's
    basis: a south turning point becomes a TP. A rejoin (BP, a primary branch point) is its own reflection as a
    state, but not as coefficients on a wire map: there ``disc.reflect`` gives the same state on the mirrored map
    (its critical mode, in x, is the primary's and stays)."""
    kind = Kind.TP if s.kind == Turn.BOTTOM else s.kind
    return replace(s, kind=kind, X=disc.reflect(s.X), stop=None if s.stop is None else stop(s.stop))
