"""Is a result complete? The contract of docs/numerics.md: every stored result is verified or flagged.

A result is *complete* when every leg of every branch ended where the scene asked (a requested stop: the pole
stretch limits, stop_pressure, stop_volume, stop_amount, stop_voltage, zero voltage, the wire gap, a dielectric
membrane's compression (the end of the membrane model: tension-field theory is not modelled), a pear branch
rejoining the primary branch), every special point is LOCATED (and every axisymmetric branch point classified),
every bifurcating branch asked for could be started, and the stability flags of every assessed point are settled
between the stability degree and the check degree. A non-axisymmetric branch (``surface.branches``) may end at the
caps of its whole-sphere basis or at its ``[surface] max_points``: a stated limitation (Gap.LIMITED), since every
point it stores is resolved; a point whose tail on the branch's final basis exceeds max_error (points are traced
on the bases of their segment and stored on the last) is flagged (Gap.UNRESOLVED). Any branch that ends at
solver.max_degree on its way to the balloon folded flat about a wire at P = 0 (``flattening``: no degree reaches
that end) is a stated limitation too (Gap.LIMITED). Everything else is an ``Incomplete`` entry: typed, named,
explained. A limitation of the method
that is not a failure of the computation (branch points not searched on a scene without equator symmetry) is
an entry too, but does not make the result incomplete (``Gap.fails``). The CLI turns failing entries into exit
status 1 (unless ``--allow-partial``); the run file stores every entry (``io.run_file``: root attributes
complete, incomplete_*).
"""
import enum
from dataclasses import dataclass

import numpy as np

from .results import Classification, Kind, Status, StopCode, SurfaceBranch, TraceStop

REQUESTED_STOPS = frozenset({StopCode.STOP_STRETCH, StopCode.MIN_STRETCH, StopCode.STOP_PRESSURE,
                             StopCode.STOP_VOLUME, StopCode.STOP_AMOUNT, StopCode.STOP_VOLTAGE, StopCode.ZERO_VOLTAGE,
                             StopCode.STOP_FIELD, StopCode.ZERO_FIELD,
                             StopCode.COMPRESSED, StopCode.WIRE_GAP,
                             StopCode.BOTTOM_STOP_STRETCH, StopCode.REJOINED, StopCode.CLOSED})


# where a non-axisymmetric branch may end short without failing: the caps of the whole-sphere basis (its points up to
# there are resolved) and the [surface] max_points budget
SURFACE_LIMITS = frozenset({StopCode.RESOLUTION_LIMIT, TraceStop.MAX_POINTS})
# where any branch may end short without failing: on its way to an end no degree resolves (the balloon folded flat
# about a wire at P = 0: ``flattening``), every point up to solver.max_degree resolved
METHOD_LIMITS = frozenset({StopCode.FLATTENING})


class Gap(enum.StrEnum):
    STOPPED_SHORT = "stopped_short"  # a leg stopped before what the scene asked (budget, resolution, Newton)
    APPROXIMATE = "approximate"  # a special point is known only to a bracket
    UNSETTLED = "unsettled"  # stability flags change between the stability and the check degree at some points
    UNCLASSIFIED = "unclassified"  # an axisymmetric branch point whose reduced energy could not be fitted
    NOT_STARTED = "not_started"  # a bifurcating branch the analysis asked for could not be started
    NOT_SEARCHED = "not_searched"  # branch points were not searched (a limitation, stated; not a failure)
    NOT_SWITCHED = "not_switched"  # a branch point of a whole-sphere primary branch in its own symmetry sector: not
    #                                a pitchfork of a kept reflection, no branch switched there (a limitation, stated)
    NOT_ASKED = "not_asked"  # branch points whose branches the scene did not ask for ([surface] branches = "first")
    LIMITED = "limited"  # a non-axisymmetric branch ended at the whole-sphere basis' cap or its [surface] max_points,
    #                      or a branch on its way to the balloon folded flat about a wire (METHOD_LIMITS): a
    #                      limitation of the method or the budget asked for, stated; every stored point resolved
    INTERRUPTED = "interrupted"  # a signal stopped the computation: what follows the stored points is missing
    UNRESOLVED = "unresolved"  # stored points of a non-axisymmetric branch whose spectral tail on the branch's final
    #                            basis (they were traced on earlier ones) exceeds solver.max_error

    @property
    def fails(self) -> bool:
        """Whether an entry of this kind makes the result incomplete."""
        return self not in (Gap.NOT_SEARCHED, Gap.NOT_SWITCHED, Gap.NOT_ASKED, Gap.LIMITED)


@dataclass(frozen=True)
class Incomplete:
    gap: Gap
    branch: str
    message: str  # for people


def incomplete(branches: list, not_searched: str = "", not_started: tuple = (),
               not_switched: tuple = (), not_asked: tuple = ()) -> list[Incomplete]:
    """What the traced ``branches`` lack against the contract (module docstring); ``not_searched``: why branch
    points were not searched on the primary branch, if they were asked for and not searched; ``not_started``:
    (name, reason) of the bifurcating branches that could not be started; ``not_switched``: (name, reason) of the
    branch points of a whole-sphere primary branch that are not pitchforks; ``not_asked``: (names, reason) of the
    branches the scene chose not to trace."""
    found = [Incomplete(Gap.NOT_STARTED, name, reason) for name, reason in not_started]
    found += [Incomplete(Gap.NOT_SWITCHED, name, reason) for name, reason in not_switched]
    found += [Incomplete(Gap.NOT_ASKED, names, reason) for names, reason in not_asked]
    for branch in branches:
        for leg in branch.legs:
            if leg.stop.code in METHOD_LIMITS or (isinstance(branch, SurfaceBranch) and leg.stop.code in SURFACE_LIMITS):
                found.append(Incomplete(Gap.LIMITED, branch.name, f"{leg.label} leg: {leg.stop.message}"))
            elif leg.stop.code == StopCode.INTERRUPTED:
                found.append(Incomplete(Gap.INTERRUPTED, branch.name, f"{leg.label} leg: {leg.stop.message}"))
            elif leg.stop.code not in REQUESTED_STOPS:
                found.append(Incomplete(Gap.STOPPED_SHORT, branch.name, f"{leg.label} leg: {leg.stop.message}"))
        for s in branch.special:
            if s.status != Status.LOCATED:
                found.append(Incomplete(Gap.APPROXIMATE, branch.name,
                                        f"{s.kind.value} near point {s.index} (±{s.uncertainty:.1g}): {s.reason}"))
            if s.kind == Kind.BP and s.m == 0 and s.classification == Classification.NONE:
                found.append(Incomplete(Gap.UNCLASSIFIED, branch.name, f"BP near point {s.index}: fewer than three "
                                        "constrained minimisations along its mode converged"))
        if isinstance(branch, SurfaceBranch):
            above = [int(i) for i in np.flatnonzero(branch.error_estimate > branch.scene.solver.max_error)]
            if above:
                found.append(Incomplete(Gap.UNRESOLVED, branch.name, f"points {above} exceed solver.max_error "
                                        f"{branch.scene.solver.max_error:g} on the final basis (tail up to "
                                        f"{branch.error_estimate.max():.2g})"))
        if branch.unsettled:
            found.append(Incomplete(Gap.UNSETTLED, branch.name,
                                    f"stability flags change at the check degree at points {branch.unsettled}"))
    if not_searched:
        found.append(Incomplete(Gap.NOT_SEARCHED, branches[0].name, not_searched))
    return found


def failing(found: list[Incomplete]) -> list[Incomplete]:
    """The entries that make a result incomplete."""
    return [item for item in found if item.gap.fails]


def summary_line(found: list[Incomplete]) -> str:
    """One line: 'complete' or what is incomplete, counted by kind."""
    if not failing(found):
        return "complete: every branch reached its requested end and every special point is located"
    found = failing(found)
    counts = {}
    for item in found:
        counts[item.gap] = counts.get(item.gap, 0) + 1
    return "incomplete: " + ", ".join(f"{n} {gap.value}" for gap, n in counts.items()) + \
        " (" + "; ".join(f"{item.branch}: {item.message}" for item in found[:3]) + \
        ("; …" if len(found) > 3 else "") + ")"
