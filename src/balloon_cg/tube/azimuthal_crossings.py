"""Where an m ≥ 1 eigenvalue of a tube's branch vanishes (tube/azimuthal.py): the m ≥ 1 branch points.

Between two stored points Y_i, Y_{i+1} of a branch whose m-th block's unstable count changes, the eigenvalue
number k (ascending, from 0: analysis/stability/crossings.count_changes) of the free tube's block (and of the held
tube's m = 1 block where it has one: tube/azimuthal.readings) is followed along the secant: at arclength
s the state is Keller's corrector from Y_i + s t (t the unit secant, on every free unknown and P), and Brent's method
in s finds its zero (numerics/continuation.locate_root: ``located``, or ``nearest`` where a corrector failed), and
the eigenvector there is the critical mode (tube/azimuthal.critical_mode) a non-axisymmetric branch would leave along.
"""
from dataclasses import dataclass

import numpy as np

from .azimuthal import block, critical_mode
from .primary import TubeSystem, held, volume_ratio
from .zeros import corrected_zero
from ..analysis.branches.problem import ParameterSystem, continuation_settings
from ..analysis.stability.crossings import count_changes
from ..galerkin.equilibrium import Equilibrium
from ..numerics import interrupt
from ..numerics.continuation import RootStatus



@dataclass(frozen=True)
class AzimuthalCrossing:
    """The m-th block's eigenvalue ``order`` vanishes at the state u, ``pressure``, ``volume`` (V/V0), between
    points ``index`` and ``index + 1``; ``status`` of its location; ``value`` the eigenvalue there; ``held``: of the
    held tube's block (tube/azimuthal.readings), else the free one's; ``mode``: its eigenvector there, the critical
    mode the non-axisymmetric branch is born along (tube/azimuthal.critical_mode: coefficients of (R, T, Z), G-unit;
    None where not computed: files before it)."""

    m: int
    order: int
    index: int
    u: np.ndarray
    pressure: float
    volume: float
    status: RootStatus
    value: float
    held: bool = False
    mode: np.ndarray | None = None


def crossings(scene, branch, modes) -> list[AzimuthalCrossing]:
    """The zeros of the m ≥ 1 eigenvalues of ``branch`` (tube/results.IntervalBranch) where ``modes``
    (tube/azimuthal.TubeModes) says its unstable counts change, ordered by m then along the branch; a signal stops
    it at its next eigenvalue (numerics/interrupt.Interrupted)."""
    disc = branch.disc
    eq = Equilibrium(scene, disc)
    params = branch.params
    system = TubeSystem(ParameterSystem(eq, params, "P"), disc.free, held(disc))
    settings = continuation_settings(scene)
    points = [np.append(u, P)[system.columns] for u, P in zip(branch.states, branch.pressure)]
    blocks = [(m, False, counts) for m, counts in modes.unstable.items()]
    blocks += [] if modes.held is None else [(1, True, modes.held["unstable"])]
    found = []
    for m, held_block, counts in blocks:
        for i, order in count_changes(counts):
            located = _zero(system, eq, params, settings, points[i], points[i + 1], m, order, held_block)
            if located is not None:
                Y, status, value = located
                mode = critical_mode(eq, Y[:-1], params.with_value("P", Y[-1]), m, order, held_block)
                found.append(AzimuthalCrossing(m, order, i, Y[:-1], float(Y[-1]), volume_ratio(eq, Y), status, value,
                                               held_block, mode))
    return found


def _zero(system, eq, params, settings, before, after, m: int, order: int, held_block: bool):
    """(Y, status, eigenvalue) where the eigenvalue ``order`` of the m-th block (the held tube's if ``held_block``)
    vanishes on the secant from ``before`` to ``after`` (X coordinates of ``system``); None where nothing could be
    evaluated."""
    length = float(np.linalg.norm(after - before))

    def eigenvalue(Y):
        interrupt.check()  # not an ArithmeticError: a signal ends the search, not this evaluation
        return float(np.linalg.eigvalsh(block(eq, Y[:-1], params.with_value("P", Y[-1]), m, held_block))[order])

    end = system.full(after)
    root = corrected_zero(system, settings, before, (after - before) / length, length, eigenvalue,
                          {length: (eigenvalue(end), end)})
    return None if root is None else (root.payload, root.status, root.value)
