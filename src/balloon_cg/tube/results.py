"""A tube's branch as plain data: its points, the located points (LP, LV, BP) and why the trace stopped (a signal:
``signalled``, StopCode.INTERRUPTED)."""
import enum
from dataclasses import dataclass

import numpy as np

from ..analysis.results import Kind, StopCode
from ..galerkin.equilibrium import Parameters
from ..galerkin.interval import IntervalDiscretisation, Mirror
from ..numerics import interrupt
from ..numerics.continuation import RootStatus, Stop


class IntervalStop(enum.StrEnum):
    """Why an interval branch stopped (beside the tracer's TraceStop)."""

    HOOP_STRETCH = "hoop_stretch"  # the largest hoop stretch passed continuation.stop_stretch
    REJOINED = "rejoined"  # a bulge branch met the mirror-symmetric states again (tube/bulge.py)
    COMPRESSED = "compressed"  # in a coil field, the membrane turned compressed after being taut (tube/stability.py)
    UNRESOLVED = "unresolved"  # a point's Legendre tail passed solver.max_error (tube/resolution.py); not stored
    HELD_RANGE = "held_range"  # continued in the held distance (tube/stretch.py), λ left [1, 5]; not stored


def signalled() -> Stop | None:
    """The stop of a trace at its next point once SIGINT or SIGTERM asked for one (numerics.interrupt), else None."""
    if interrupt.requested():
        return Stop(StopCode.INTERRUPTED, "interrupted (SIGINT or SIGTERM): stopped at this point")
    return None


@dataclass(frozen=True)
class IntervalSpecial:
    """A located point: LP (fold in P), LV (fold in V), BP (``block`` the mirror block whose lowest eigenvalue
    vanishes) or UZ (where an event's quantity reaches its value: ``note``, tube/events.py), its state ``u`` and
    pressure, between points ``index`` and ``index + 1`` (the last index: in the step that passed the stop, whose end
    is not stored); ``status`` of its location; ``smallest_stress`` of its state (negative: the membrane is compressed
    there and the point is not to be trusted: tube/stability.py)."""

    kind: Kind
    u: np.ndarray
    pressure: float
    index: int
    status: RootStatus
    block: Mirror | None = None
    smallest_stress: float = np.nan  # tube/stability.smallest_stress of the state: compressed below COMPRESSED
    note: str = ""  # a UZ point's event: "volume_ratio = 3" (tube/events.py)
    voltage: float = np.nan  # on a voltage continuation (tube/voltage.py) the point's Φ̄; NaN on one in P


@dataclass(frozen=True)
class IntervalBranch:
    """The points (``states`` rows u, ``pressure``), the enclosed volume over the reference one (V/V0, V0 = πL), the
    lowest eigenvalue of each mirror block at every point (``lowest``: Mirror -> array; empty on a branch without mirror
    symmetry), the number of unstable directions at every point under each control (``unstable``: Control -> int array;
    files before gas control have no Control.GAS), the located points, why the trace stopped and the smallest principal
    stress at every point (negative: compressed, tube/stability.py); ``params``: the branch's parameters (the field's M
    and χ; P is each point's); ``tail`` and ``first_integral``: per point, the spectral error estimate and the
    spread of H = λ1Φ_1 − Φ along the tube (tube/accuracy.py; None where not computed: the primary branch, a
    branch read from a file); ``voltage``: on a voltage continuation each point's Φ̄ (P fixed, tube/voltage.py);
    ``parent``: (branch name, label) of the branch point a switched branch was born at (tube/picture.py; None: the
    primary branch), ``rejoins``: the label of the parent branch's point where it rejoined it (None: it did not)."""

    disc: IntervalDiscretisation
    states: np.ndarray
    pressure: np.ndarray
    volume: np.ndarray
    lowest: dict
    unstable: dict
    special: tuple
    stop: Stop
    smallest_stress: np.ndarray  # per point: tube/stability.smallest_stress
    params: Parameters
    tail: np.ndarray | None = None  # per point: galerkin/interval.IntervalDiscretisation.tail
    first_integral: np.ndarray | None = None  # per point: tube/accuracy.first_integral_spread
    voltage: np.ndarray | None = None  # per point Φ̄ on a voltage continuation (tube/voltage.py); None: in P
    stretched: bool = False  # continued in λ at a fixed P (tube/stretch.py); False: in P or Φ̄
    parent: tuple | None = None  # (branch name, label) of the branch point it was switched at
    rejoins: int | None = None  # the label on the parent branch where it rejoined it

    def held_stretch(self) -> np.ndarray:
        """λ of each point: its λ̄, the held distance of the ends over L (where they are held)."""
        return self.states[:, self.disc.axial_index]

    def branch_points(self, block: Mirror | None = None) -> list:
        return [s for s in self.special if s.kind == Kind.BP and (block is None or s.block == block)]
