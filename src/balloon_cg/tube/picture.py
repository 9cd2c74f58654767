"""Everything a tube scene asks for (``balloon-cg run`` on a tube): the primary branch with its folds and branch
points (tube/primary.py), the branches switched at its branch points (tube/bulge.py; sliding ends only: on plugged
ones the branch points are not trusted, docs/tubes.md): at every odd one, and at every even one where the primary
branch is uniform (no coil field), in order along the primary branch, a branch point where an earlier branch rejoined
the primary one not switched again (that branch is its branch, traced from its other end); where
solver.tube_resolution = "refine" the first odd one alone, its branch held to the resolution policy
(tube/resolution.py: the primary branch retraced with it, so the other labels would be a coarser branch's). Each is
traced until it rejoins the mirror-symmetric (odd) or uniform (even) states, its largest hoop stretch passes
``continuation.stop_stretch``, its V reaches ``continuation.stop_volume`` (V/R0³, landed on; the primary branch ends
there too) or after ``continuation.max_points``. The branch born at the first odd branch point (the onset of
bulging) is named "bulge", the others "bulge_<label>", <label> their branch point's label (``inspect``: the primary
branch's located points are numbered first); each knows its parent label and where it rejoined
(IntervalBranch.parent, .rejoins). With [surface] branches "first" (the default where built) or "all" the
non-axisymmetric branches traced from the located m ≥ 1 zeros (``with_surface``, tube/surface/branch.py). And
Maxwell's pressure of the uniform closed tube (model/tube.maxwell_pressure; closed ends without a field only: ends
held apart have no single one, a coil field no uniform state: ``maxwell``), computed first. A signal (numerics.interrupt) ends the stage it comes in at its next point, or before
the next stage starts (one during Maxwell's pressure, which does not poll, at the primary branch's first point): what
is finished is kept, and the picture names the stage (``Stage``). A whole picture's branches are assessed for m = 1..
``stability.m_max`` (tube/azimuthal.py: ``modes``). On a voltage continuation (``continuation.parameter =
"voltage"``) the picture is the tube continued in Φ̄ at its fixed P alone (tube/voltage.py: ``charged_picture``); from a
stored point of a held tube, the tube continued in the held distance λ at its P alone (tube/stretch.py:
``stretched_picture``)."""
import enum
from dataclasses import dataclass, replace

import numpy as np

from .azimuthal import branch_modes
from .azimuthal_crossings import crossings
from .bulge import BranchStartError
from .onset import OnsetCurve, onset_curve
from .primary import in_field, primary_branch
from .resolution import REFINE, traced_bulge
from .surface.branch import traced_branch
from .results import IntervalBranch
from .stretch import stretch_branch
from .voltage import voltage_branch
from ..analysis.results import IntervalStop, Kind, StopCode
from ..analysis.surface.meridian.trace import SurfaceBranchStartError
from ..analysis.verdict import Gap, Incomplete
from ..galerkin.equilibrium import Equilibrium
from ..galerkin.interval import Mirror
from ..galerkin.interval_elements import ElementInterval, collocated
from ..model.membrane import scene_energy
from ..model.tube import maxwell_pressure
from ..numerics import interrupt
from ..numerics.threads import limited_blas
from ..scene.tables import ContinuationParameter, Ends


BULGE = "bulge"  # the name of the branch switched at the first odd branch point, the prefix of the others'


class Stage(enum.StrEnum):
    """A stage of a tube's work, named where a signal stopped it (the file's ``interrupted`` attribute)."""

    PRIMARY = "primary"  # the primary branch (tube/primary.py)
    BULGE = "bulge"  # the bulge branch (tube/bulge.py)
    ONSET = "onset"  # the onset curve of ``critical`` (tube/onset.py)
    MODES = "modes"  # the branches' m ≥ 1 blocks and their zeros (``with_modes``): the branches are whole
    SURFACE = "surface"  # the non-axisymmetric branches ([surface] branches: tube/surface/branch.py)
    FREQUENCIES = "frequencies"  # the branches' natural frequencies (dynamics/tube.py): the branches are whole


@dataclass(frozen=True)
class TubePicture:
    """The branches by name ("primary", "bulge" and "bulge_<label>" where they were switched: ``branch_name``),
    Maxwell's pressure (None where the uniform closed path has no maximum and minimum, the ends are held, or coils
    act: ``maxwell``), for ``critical`` the onset of bulging followed in a second parameter (tube/onset.py), and the
    stage a signal stopped (None: the work is whole; the stage's branch or curve ends ``interrupted`` where it had
    started, and is absent where it had not); ``frequencies``: with [dynamics] frequencies, each branch's
    (dynamics/tube.py: TubeFrequencies by branch name); ``modes``: each branch's m = 1..``stability.m_max`` blocks
    (tube/azimuthal.TubeModes by branch name; None: not assessed, m_max = 0 or a signal); ``surface``: the
    non-axisymmetric branches traced from the m ≥ 1 zeros (``with_surface``: tube/surface/branch.MeridianSurfaceBranch
    by name; None: none asked); ``not_started``: (name, why) of the switched branches that could not start (the run
    is then incomplete: exit 1)."""

    branches: dict
    maxwell: float | None
    onset: OnsetCurve | None = None
    interrupted: Stage | None = None
    frequencies: dict | None = None
    modes: dict | None = None
    not_started: tuple = ()  # (name, why) of each branch whose first step off its branch point did not converge
    surface: dict | None = None  # name -> tube/surface/branch.MeridianSurfaceBranch ([surface] branches; None: none)


def gaps(picture: TubePicture) -> list[Incomplete]:
    """What a tube run lacks (its file's verdict, io/tube_file.py; ``run`` exits 130 for a signal, 1 for the others; a
    sweep member is stored incomplete): the stage a signal stopped, each switched branch that did not start, each
    branch stopped unresolved (IntervalStop.UNRESOLVED: at its layout's cap) after its resolved points. Not assessed
    here: a ``critical`` run's onset curve (its command's exit says whether it turned back, resolved) and the [surface]
    branches (their stops stored with them)."""
    stopped = picture.interrupted
    return ([Incomplete(Gap.INTERRUPTED, stopped.value, f"interrupted by a signal during {stopped.value}")]
            if stopped else []) + [Incomplete(Gap.NOT_STARTED, name, why) for name, why in picture.not_started] + [
        Incomplete(Gap.STOPPED_SHORT, name, f"{b.stop.message}, after {len(b.pressure)} resolved points (its stop code "
                                            f"{IntervalStop.UNRESOLVED.value})")
        for name, b in picture.branches.items() if b.stop.code == IntervalStop.UNRESOLVED]


def tube_picture(scene, primary_only: bool = False) -> TubePicture:
    """The primary branch and, unless ``primary_only``, the branches switched at its branch points (module
    docstring); on a
    voltage continuation the tube continued in Φ̄ at its fixed P alone (tube/voltage.py: ``charged_picture``)."""
    if scene.continuation.parameter == ContinuationParameter.VOLTAGE:
        return charged_picture(scene)
    pm = maxwell(scene)  # first: it does not poll for a signal (~0.16 s for SPOM1), the traces after it do
    primary = primary_branch(scene)
    branches: dict[str, IntervalBranch] = {"primary": primary}
    if primary.stop.code == StopCode.INTERRUPTED:
        return TubePicture(branches, pm, interrupted=Stage.PRIMARY)
    labels = switchable(scene, primary)
    if primary_only:
        return with_modes(scene, TubePicture(branches, pm))
    picture = bulge_picture(scene, primary, labels, pm) if labels else with_modes(scene, TubePicture(branches, pm))
    return with_surface(scene, picture)


def switchable(scene, primary: IntervalBranch) -> list:
    """The labels of the branch points of ``primary`` a branch is switched at (module docstring): none on plugged
    ends, the first odd one where solver.tube_resolution = "refine", the odd ones in a coil field, else the odd and
    the even ones."""
    if scene.geometry.ends != Ends.SLIDING:
        return []
    blocks = (Mirror.ODD,) if in_field(scene) or scene.solver.tube_resolution == REFINE else (Mirror.ODD, Mirror.EVEN)
    labels = [k for k, s in enumerate(primary.special) if s.kind == Kind.BP and s.block in blocks]
    return labels[:1] if scene.solver.tube_resolution == REFINE else labels


def branch_name(primary: IntervalBranch, label: int) -> str:
    """The name of the branch switched at the located point ``label`` of ``primary``: "bulge" at its first odd branch
    point, else "bulge_<label>"."""
    first = next((k for k, s in enumerate(primary.special) if s.kind == Kind.BP and s.block == Mirror.ODD), None)
    return BULGE if label == first else f"{BULGE}_{label}"


def charged_picture(scene, start: tuple | None = None, direction: float = 1.0) -> TubePicture:
    """The tube continued in Φ̄ at fixed P (tube/voltage.voltage_branch from ``start``, ``direction``) as the picture's
    primary branch: no bulge branch is switched, no Maxwell pressure, the m ≥ 1 blocks not read."""
    branch = voltage_branch(scene, start, direction)
    return TubePicture({"primary": branch}, None,
                       interrupted=Stage.PRIMARY if branch.stop.code == StopCode.INTERRUPTED else None)


def stretched_picture(scene, point, disc, direction: float = 1.0) -> TubePicture:
    """The held tube continued in λ at fixed P from the stored located point ``point`` on ``disc``
    (tube/stretch.stretch_branch, ``direction``) as the picture's primary branch, as ``charged_picture``'s."""
    branch = stretch_branch(scene, disc, point.u, point.pressure, direction)
    return TubePicture({"primary": branch}, None,
                       interrupted=Stage.PRIMARY if branch.stop.code == StopCode.INTERRUPTED else None)


def bulge_picture(scene, primary: IntervalBranch, labels, pm: float | None) -> TubePicture:
    """``primary`` and the branches switched at its branch points ``labels`` (tube/bulge.py; named by ``branch_name``),
    in order, a label where an earlier one rejoined skipped, each stopped as ``tube_picture``'s (one whose first step
    does not converge listed in ``not_started``), traced as solver.tube_resolution asks (tube/resolution.traced_bulge:
    "refine" retraces the primary branch with it, which then replaces ``primary``: ``switchable`` gives one label
    there); ``pm``: Maxwell's pressure. Also ``continue`` from a tube file's label."""
    branches, reached, stopped, not_started = {"primary": primary}, set(), None, ()
    for label in labels:
        if label in reached:
            continue
        if interrupt.requested():  # in the primary branch's assessment or the branch before: this one not started
            return TubePicture(branches, pm, interrupted=Stage.BULGE, not_started=not_started)
        name = branch_name(primary, label)
        try:
            primary, point, branch = traced_bulge(scene, primary, primary.special[label],
                                                  stop_stretch=scene.continuation.stop_stretch)
        except BranchStartError as e:
            not_started += ((name, str(e)),)
            continue
        branches["primary"] = primary
        label = next(k for k, s in enumerate(primary.special) if s is point)  # its label on a retraced primary
        rejoins = rejoined_at(scene, primary, branch, label)
        branches[name] = replace(branch, parent=("primary", label), rejoins=rejoins)
        reached.add(rejoins)
        if branch.stop.code == StopCode.INTERRUPTED:
            stopped = Stage.BULGE
            break
    return with_modes(scene, TubePicture(branches, pm, interrupted=stopped, not_started=not_started))


def rejoined_at(scene, primary: IntervalBranch, branch: IntervalBranch, label: int) -> int | None:
    """The label of the branch point of ``primary`` where ``branch`` (switched at ``label``) rejoined it: of the same
    block, the nearest in (u, P) to its last point and within two of the scene's largest steps of it (the step that
    crossed the primary branch's states ends beyond it); None where it did not rejoin or the point lies beyond the
    traced primary branch (a branch on other unknowns than the primary's, spectral elements, compared with the
    branch points collocated onto them)."""
    if branch.stop.code != IntervalStop.REJOINED:
        return None
    block = primary.special[label].block
    last = np.append(branch.states[-1], branch.pressure[-1])
    on = ((lambda u: u) if branch.disc == primary.disc else
          (lambda u: collocated(primary.disc, u, branch.disc)))  # a branch on spectral elements: tube/front.py
    near = [(float(np.linalg.norm(np.append(on(s.u), s.pressure) - last)), k) for k, s in enumerate(primary.special)
            if s.kind == Kind.BP and s.block == block and k != label]
    distance, found = min(near, default=(np.inf, None))
    return found if distance <= 2 * scene.continuation.step_max else None


@limited_blas
def with_modes(scene, picture: TubePicture) -> TubePicture:
    """``picture`` with its branches' m = 1..``stability.m_max`` blocks (tube/azimuthal.py) and the zeros of their
    eigenvalues located (tube/azimuthal_crossings.py) where m_max ≥ 1 and no signal stopped the picture. A signal
    (after the last check of the stage before, or while the blocks are read: at each point and each eigenvalue of a
    zero's search) ends the work there: none are kept, the picture is interrupted in Stage.MODES. One BLAS thread, as the
    traces."""
    m_max = scene.stability.m_max
    if m_max < 1 or picture.interrupted is not None:
        return picture
    modes = {}
    try:
        for name, branch in picture.branches.items():
            interrupt.check()
            found = branch_modes(Equilibrium(scene, branch.disc), np.column_stack([branch.states, branch.pressure]),
                                 branch.params, m_max)
            modes[name] = replace(found, crossings=tuple(crossings(scene, branch, found)))
    except interrupt.Interrupted:
        return replace(picture, interrupted=Stage.MODES)
    return replace(picture, modes=modes)


def surface_name(parent: str, m: int, k: int) -> str:
    """The name of the non-axisymmetric branch born at the k-th located zero of ``parent``'s m-th block (its order
    in ``inspect``'s list of that block's zeros): "m<m>_bp<k>" on the primary branch, "<parent>_m<m>_bp<k>" else."""
    return f"m{m}_bp{k}" if parent == "primary" else f"{parent}_m{m}_bp{k}"


def with_surface(scene, picture: TubePicture) -> TubePicture:
    """``picture`` with the non-axisymmetric branches of [surface] branches (tube/surface/branch.py, along +φ: the
    −φ half is its image under the rotation by π/m): "first" at the primary branch's first located m ≥ 1 zero along
    it, "all" at every located zero of every branch (the free tube's: without a field the held reading is the same);
    "none", m ≥ 1 not assessed or a signal before: none. One whose switched point does not converge is listed in
    ``not_started``; a signal during a trace ends the stage (Stage.SURFACE)."""
    asked = scene.surface.branches
    if asked == "none" or picture.modes is None or picture.interrupted is not None:
        return picture
    zeros = []  # (parent, the zero's order among its block's, the zero)
    for parent, modes in picture.modes.items():
        counted = {}  # m -> the free zeros of block m so far
        for zero in (c for c in modes.crossings if not c.held):
            k = counted[zero.m] = counted.get(zero.m, -1) + 1
            if zero.mode is not None:
                zeros.append((parent, k, zero))
    if asked == "first":
        zeros = sorted((z for z in zeros if z[0] == "primary"), key=lambda z: z[2].index)[:1]
    traced, not_started, stopped = {}, picture.not_started, None
    for parent, k, zero in zeros:
        name = surface_name(parent, zero.m, k)
        if interrupt.requested():
            stopped = Stage.SURFACE
            break
        branch = picture.branches[parent]
        if isinstance(branch.disc, ElementInterval):  # the basis over (S, φ) reads one Legendre series in S
            not_started += ((name, f"{parent} is on spectral elements (solver.tube_resolution = \"elements\"): its "
                                   "non-axisymmetric branches are traced on the Legendre series only"),)
            continue
        try:
            traced[name] = traced_branch(scene, branch.disc, zero, branch.params, parent=(parent, k))
        except SurfaceBranchStartError as e:
            not_started += ((name, str(e)),)
            continue
        if traced[name].stop.code == StopCode.INTERRUPTED:
            stopped = Stage.SURFACE
            break
    return replace(picture, surface=traced, not_started=not_started, interrupted=stopped)


def onset_picture(scene, name: str = "M", direction: float = 1.0) -> TubePicture:
    """``critical`` on a tube: the primary branch and the curve of its first odd branch point (the onset of bulging)
    followed in ``name`` (tube/onset.py); no curve where the primary branch has no odd branch point."""
    pm = maxwell(scene)  # first, as in tube_picture
    primary = primary_branch(scene)
    branches = {"primary": primary}
    if primary.stop.code == StopCode.INTERRUPTED:
        return TubePicture(branches, pm, interrupted=Stage.PRIMARY)
    onsets = primary.branch_points(Mirror.ODD)
    if not onsets:
        return TubePicture(branches, pm)
    return onset_from(scene, primary, onsets[0], name, direction, pm)


def onset_from(scene, primary: IntervalBranch, point, name: str, direction: float, pm: float | None) -> TubePicture:
    """``primary`` and the curve of its odd branch point ``point`` followed in ``name`` (tube/onset.py), as
    ``onset_picture``'s; also ``continue --parameter M`` from a tube file's label."""
    branches = {"primary": primary}
    if interrupt.requested():  # in the primary branch's stability and branch points: the curve not started
        return TubePicture(branches, pm, interrupted=Stage.ONSET)
    curve = onset_curve(scene, primary, point, name, direction)
    return TubePicture(branches, pm, curve, Stage.ONSET if curve.stop.code == StopCode.INTERRUPTED else None)


def maxwell(scene) -> float | None:
    """Maxwell's pressure of the scene's uniform closed tube (under a voltage, of its effective energy:
    model/membrane.Charged); None where there is none: ends held apart, no maximum and minimum on the uniform path,
    or coils acting on the tube (M > 0): the field varies along the tube, so there is neither a uniform state nor the
    first integral of axial translation that the equal-area rule rests on (docs/tubes.md), and the field-free value
    is not the field's."""
    if scene.geometry.axial_stretch is not None or in_field(scene):
        return None
    found = maxwell_pressure(scene_energy(scene))
    return None if found is None else float(found[0])

