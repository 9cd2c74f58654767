"""The whole picture of a scene: primary branch, stability, branch points, pear branches, snap-through.

``analyse(scene)`` traces the primary branch, assesses every point (``stability``), locates and classifies its
branch points (``bifurcation``; in a field those of the held and of the free balloon, each point and branch
labelled with its reading, ``results.Gauge``), follows each pear-shaped branch (``switching``) until it rejoins the primary
branch (a fold candidate there is the rejoin's branch point: ``switching.mark_rejoin``) or stops, assesses it,
and adds its mirror image (north and south poles swapped: the reflection z → −z of the branch and its
assessments in a scene invariant under it, ``mirror``; traced and assessed where it cannot be reflected),
locates the branch points of the non-axisymmetric blocks on every branch (``azimuthal_points``: stored with the
branch, not in ``Picture.branch_points``), follows the non-axisymmetric branches born at the m ≥ 1 points on the
whole sphere (``surface.branches``: ``Picture.surface_branches``, as ``[surface] branches`` asks; a capsule's over
(θ, φ), along +φ with its image under the rotation by π/m: ``surface.meridian.capsule``, ``rotation``,
``Picture.meridian_surface``) and lists the snap-throughs under the
scene's loading control (pressure, volume or gas: its held stability flag, on the branches of the held reading). A voltage continuation (at fixed P) gets the same, with
Φ̄ as the parameter of every branch and of its branch points. A primary branch without equator symmetry (a field
that breaks it) gets its stability changes under every control mode located instead (``control_points``: LP, LV,
LN or BP) and its m ≥ 1 points, and the pear branch the broken symmetry disconnects from it is found by
continuation in the coil heights (``broken_symmetry``); its held states carry the field's net axial force (the
hold's reaction), so the free balloon gets its own primary branch (``FREE_PRIMARY``, the axial translation an
unknown: ``_trace_free``) with ``[surface] branches = "all"``, and the branches at the m ≥ 1 points of each branch's
own reading are traced on the whole sphere (``Branch.reads``; the other reading's in ``Picture.not_switched``). A field that is not axisymmetric gets its primary branch traced on the whole
sphere (``surface.primary``) and the branches born at its pitchforks with their mirror images
(``surface.pitchforks``; its other branch points in ``Picture.not_switched``). Every branch carries its assessments
in ``branch.stability`` and the points whose flags change at the check degree in ``branch.unsettled``.
"""
import enum
import itertools
from contextlib import contextmanager
from dataclasses import dataclass, field, replace

import numpy as np

from .branches import events
from .points import azimuthal_points, branch_points as bifurcation, control_points, free_pitchforks
from .surface import branches as surface_branches, pitchforks as surface_pitchforks, primary as surface_primary
from .surface.meridian import capsule, events as meridian_events, rotation
from .surface.meridian.trace import SurfaceBranchStartError
from .switching import broken_symmetry, mirror
from ..scene import Control, Geometry
from ..scene.tables import Shape
from .branches.control import FOLD_KIND, control_value, control_values, minimised_energy
from .switching.mirror import MIRROR
from .branches.primary import trace_primary
from .branches.problem import equilibrium_of
from .results import Block, Branch, Gauge, IntervalStop, Kind, Origin, Status, StopCode
from .stability.axisymmetric import assess_branch, assessed_degrees
from .switching.pear import mark_rejoin, trace_pear
from .timing import Clock, Step
from .branches.tracer import ContinuationError
from .verdict import Gap, Incomplete, incomplete
from ..numerics import interrupt, workers
from ..numerics.continuation import TraceStop
from ..numerics.threads import limited_blas


BROKEN = "broken_pear"  # the pear branch a broken equator symmetry disconnects (``broken_symmetry``)
FREE_PRIMARY = "primary_free"  # the free balloon's primary branch in a field without equator symmetry
FREE_NOT_ASKED = ('not traced: [surface] branches = "first" (the free balloon\'s primary branch, with the axial '
                  'translation free, and the branches at its m ≥ 1 points); set "all"')
PEAR_NAMES = {Block.ODD_HELD: "pear", Block.ODD_FREE: "pear_free"}  # a pear branch's name: <prefix>_<BP number>
MODES = {Block.ODD_HELD: "pear (odd)", Block.ODD_FREE: "free pear (odd, translation free)",
         Block.EVEN: "equator-symmetric (even)"}
ROTATED = "_rotated"  # the suffix of a non-axisymmetric branch's image under the rotation by π (a capsule's: π/m)
OPPOSITE = "_opposite"  # the suffix of the branch traced along −φ (even m: the rotation by π maps the mode to itself)


class Phase(enum.StrEnum):
    """The phases of ``analyse``, for progress reports."""

    PRIMARY = "primary branch"
    STABILITY = "stability"
    PEAR = "pear branches"
    FREE = "free balloon"
    SURFACE = "non-axisymmetric branches"


class Progress:
    """What ``analyse`` reports: ``tick(phase)`` per traced or assessed point, ``finish(phase, count)`` with the
    number of points the phase stored (the tracer may compute a few points it does not keep). This base class
    reports nothing; the CLI draws one bar per phase."""

    def tick(self, phase: Phase) -> None:
        pass

    def finish(self, phase: Phase, count: int) -> None:
        pass

    def expect(self, phase: Phase, count: int) -> None:
        """``count`` more points are to come in ``phase`` (known ahead for the stability of a traced branch)."""

    def ticker(self, phase: Phase):
        """A per-point callable for the tracers."""
        return lambda point: self.tick(phase)

    @contextmanager
    def budget(self, phase: Phase, count: int):
        """``ticker`` for a trace of at most ``count`` points (a branch's max_points): they are expected ahead, so
        the phase shows a total and a time left (an upper bound: the branch may stop sooner), and the part not
        used is taken back when the trace ends."""
        done = [0]

        def tick(point):
            done[0] += 1
            self.tick(phase)

        self.expect(phase, count)
        try:
            yield tick
        finally:
            self.expect(phase, min(done[0] - count, 0))



@dataclass
class SnapThrough:
    """Under the scene's loading control: a stable stretch of ``from_branch`` ends at point ``from_index`` (its
    last stable point) at ``pressure`` (the control value there: P, V or n); the lowest-energy stable point at
    that control value is on ``to_branch`` near ``to_index`` ("" and −1: none) (``find_snaps``)."""

    from_branch: str
    from_index: int
    pressure: float
    to_branch: str = ""
    to_index: int = -1


@dataclass
class Picture:
    branches: list
    branch_points: list = field(default_factory=list)  # the primary branch's m = 0 BP special points, in order
    #                                                    (the free balloon's odd_free points after the others)
    snaps: list = field(default_factory=list)  # SnapThrough
    not_searched: str = ""  # why branch points were not searched, if they were not
    not_started: list = field(default_factory=list)  # (name, reason) of bifurcating branches that could not start
    not_switched: list = field(default_factory=list)  # (name, reason) of a whole-sphere primary's branch points that
    #                                                   are not pitchforks (``surface.pitchforks``)
    not_asked: list = field(default_factory=list)  # (names, reason) of branch points whose branches the scene did
    #                                                not ask for (``[surface] branches = "first"``)
    surface_branches: list = field(default_factory=list)  # SurfaceBranch from the m ≥ 1 points (surface_branches)
    meridian_surface: dict = field(default_factory=dict)  # a capsule's: name -> MeridianSurfaceBranch (``capsule``)
    interrupted: bool = False  # a signal stopped the analysis (numerics.interrupt): later phases not computed
    interrupted_in: str = ""  # the phase it stopped (a timing.Step value; "" where none had started)
    clock: Clock = field(default_factory=Clock)  # seconds per phase (``timing``)

    @property
    def primary(self):
        """The primary branch: a Branch, or a SurfaceBranch for a field that is not axisymmetric."""
        return self.branches[0] if self.branches else self.surface_branches[0]

    def __repr__(self):
        n, surface = len(self.branches), len(self.surface_branches)
        return (f"Picture({n} branch{'es' * (n != 1)} ({sum(len(b.X) for b in self.branches)} points), {surface} "
                f"surface, {len(self.branch_points)} branch points, {len(self.snaps)} snap-throughs, "
                f"{'complete' if not self.incomplete else f'{len(self.incomplete)} incomplete parts'})")

    @property
    def incomplete(self) -> list[Incomplete]:
        """What the picture lacks against the contract (``verdict``); empty when it is complete."""
        found = incomplete(self.branches + self.surface_branches, self.not_searched, tuple(self.not_started),
                           tuple(self.not_switched), tuple(self.not_asked)) + meridian_gaps(self.meridian_surface)
        if self.interrupted:
            during = f" during {self.interrupted_in}" if self.interrupted_in else ""
            found.append(Incomplete(Gap.INTERRUPTED, self.primary.name, f"interrupted by a signal{during}: the "
                                    "branches and phases after the stored points were not computed"))
        return found


MERIDIAN_ENDS = (IntervalStop.REJOINED, IntervalStop.HOOP_STRETCH, StopCode.INTERRUPTED)  # stops that end it whole


def meridian_gaps(branches: dict) -> list[Incomplete]:
    """What a capsule's non-axisymmetric branches (name -> MeridianSurfaceBranch) lack: LIMITED where one ended at
    [surface] max_points or its basis' cap (stated), STOPPED_SHORT where it stopped otherwise before its ends
    (MERIDIAN_ENDS: back through the axisymmetric states, stop_stretch, or a signal, which the picture states),
    APPROXIMATE for each [[events]] UZ point Newton did not land on (as a sphere's surface branch's; listed once, on
    the traced branch: an image's events are its source's, rotated)."""
    found = []
    for name, branch in branches.items():
        if branch.stop.code == TraceStop.MAX_POINTS or branch.limited:
            found.append(Incomplete(Gap.LIMITED, name, branch.stop.message))
        elif branch.stop.code not in MERIDIAN_ENDS:
            found.append(Incomplete(Gap.STOPPED_SHORT, name, branch.stop.message))
        found += [Incomplete(Gap.APPROXIMATE, name, f"UZ after point {event.index}: {event.note}")
                  for event in branch.events if not event.located and not branch.image_of]
    return found


def _assess(branch: Branch, scene, symmetric: bool, progress: Progress, clock: Clock) -> bool:
    """Assess ``branch`` (one STABILITY tick per point); False when a signal stopped it (the branch is kept as
    traced, not assessed)."""
    progress.expect(Phase.STABILITY, len(branch.X))
    try:
        with clock.step(Step.STABILITY):
            branch.stability, branch.unsettled = assess_branch(
                branch, scene.stability.degree, symmetric, check=True, m_max=scene.stability.m_max,
                on_point=lambda: progress.tick(Phase.STABILITY))
    except interrupt.Interrupted:
        return False
    return True


@limited_blas
def analyse(scene, progress: Progress | None = None, pear: bool = True, clock: Clock | None = None) -> Picture:
    """The picture of a scene (module docstring); ``pear=False`` skips the pear and the non-axisymmetric branches
    (those follow ``[surface] branches``). ``progress``: a
    ``Progress`` told of every point. A signal (``numerics.interrupt``) stops it at the next point: the picture
    then holds what is finished (``interrupted``; the branches after it are not traced, nor assessed).
    ``clock``: the Clock its phases are charged to (``Picture.clock``; default: one started here)."""
    progress, clock = progress or Progress(), clock or Clock()
    if not scene.field.is_axisymmetric:
        return _whole_sphere(scene, progress, clock, pear)
    with clock.step(Step.TRACE):
        primary = trace_primary(scene, progress=progress.ticker(Phase.PRIMARY))
    progress.finish(Phase.PRIMARY, len(primary.X))
    return examine(scene, primary, progress, pear, clock)


def examine(scene, primary: Branch, progress: Progress | None = None, pear: bool = True,
            clock: Clock | None = None, control: bool = True) -> Picture:
    """The picture of an axisymmetric scene from its traced primary branch (``analyse`` after the trace; also
    ``continue``'s restarted branch): assessed, its branch points located, the branches born there followed as
    ``pear`` and ``[surface] branches`` ask, the m ≥ 1 points of every branch, the snap-throughs. ``control``: a
    branch without equator symmetry gets its stability changes under every control (LV, LN: ``control_points``),
    as a broken-symmetry primary does; a restarted pear branch does not, as ``run`` marks none on pear branches."""
    picture = Picture([primary], clock=clock or Clock())
    try:
        _examine(scene, picture, progress or Progress(), pear, control)
    except interrupt.Interrupted:  # raised in a unit of work that polls inside (a plain degree's search): abandoned
        stopped(picture)
    return picture


def _examine(scene, picture: Picture, progress: Progress, pear: bool, control: bool) -> None:
    """``examine`` into ``picture`` (its primary branch traced)."""
    primary, clock = picture.primary, picture.clock
    surface = pear and scene.surface.branches != "none"
    if stopped(picture):
        return
    if not _assess(primary, scene, primary.disc.symmetric, progress, clock):
        stopped(picture)
        return
    if primary.disc.symmetric:
        _branch_points(primary, picture)
    else:
        with clock.step(Step.BRANCH_POINTS):
            primary.special += control_points.find(primary) if control else []
        primary.special.sort(key=_along)
        search = pear and not scene.field.is_equator_symmetric  # continuation.symmetry = "none": none broken
        if search and not stopped(picture):
            with clock.step(Step.PEAR_BRANCHES):
                _trace_broken(scene, primary, picture, progress)
        if surface and primary.gauge == Gauge.HELD and scene.surface.branches == "first":
            picture.not_asked.append((FREE_PRIMARY, FREE_NOT_ASKED))
        elif surface and primary.gauge == Gauge.HELD and not stopped(picture):
            _trace_free(scene, picture, progress)
        picture.not_searched = _unsearched(primary, search, surface)
        pear = False  # no equator-symmetric pitchforks to switch at
    if stopped(picture):
        return
    if pear:
        with clock.step(Step.PEAR_BRANCHES):
            _trace_pears(scene, primary, picture, progress)
        progress.finish(Phase.PEAR, sum(len(b.X) for b in picture.branches[1:]))
    progress.finish(Phase.STABILITY, sum(len(b.stability or ()) for b in picture.branches))
    if not azimuthal_crossings(picture, picture.branches, scene):
        return
    if surface:
        with clock.step(Step.SURFACE_BRANCHES):
            for branch in [b for b in picture.branches if b.name in (primary.name, FREE_PRIMARY)]:
                _trace_surface(scene, branch, picture, progress)
                if stopped(picture):
                    return
            unsearched_events(picture, scene)
        progress.finish(Phase.SURFACE, sum(len(b.values) for b in picture.surface_branches)
                        + sum(len(b.pressure) for b in picture.meridian_surface.values() if not b.image_of))
    label_readings(picture.branches + picture.surface_branches)
    with clock.step(Step.SNAP_THROUGHS):
        picture.snaps = snap_throughs([b for b in picture.branches if b.gauge != Gauge.FREE], scene.loading.control)


def azimuthal_crossings(picture: Picture, branches: list, scene) -> bool:
    """The m ≥ 1 branch points of each of ``branches`` (``azimuthal_points``: on the branches, not in
    ``picture.branch_points``), in their order along it; False when a signal stopped the search."""
    for branch in branches:
        if stopped(picture):
            return False
        with picture.clock.step(Step.CROSSINGS):
            branch.special += azimuthal_points.find(branch, assessed_degrees(branch), scene.stability.m_max)
        branch.special.sort(key=_along)
    return True


def _along(s) -> tuple:
    """The order of special points along a branch: by interval, the free reading's after the others in one (so
    the numbering of the held reading's branch points does not depend on the free ones before them there)."""
    return s.index, Gauge.of_block(s.block, True) == Gauge.FREE


def label_readings(branches: list) -> None:
    """Each special point's reading (``results.Gauge``): a branch point's from its block, the others' (folds, end
    points, a surface branch's secondary points) from their branch."""
    for branch in branches:
        for s in branch.special:
            s.gauge = Gauge.of_block(s.block, branch.field_acts) if s.kind == Kind.BP and s.block else branch.gauge


def _branch_points(primary: Branch, picture: Picture) -> None:
    """The located and classified m = 0 branch points of an equator-symmetric primary branch (``bifurcation``),
    in ``picture.branch_points`` and among the branch's special points."""
    with picture.clock.step(Step.BRANCH_POINTS):
        # the free balloon's pear points (odd_free) after the others: the held numbering does not depend on them
        crossings = sorted(bifurcation.detect(primary, primary.stability), key=lambda c: c[1] == Block.ODD_FREE)
        located = workers.spread(lambda crossing: _located(primary, *crossing), crossings,
                                 [bifurcation.location_cost(primary, index) for index, _, _ in crossings])
        for bp in itertools.takewhile(lambda bp: bp is not None, located):
            picture.branch_points.append(bp)
            primary.special.append(bp)
    primary.special.sort(key=_along)


def _located(primary: Branch, index: int, block: Block, k: int):
    """The m = 0 branch point detected between points index and index + 1 of ``primary``, located and classified
    (``bifurcation``); each on its own (``_branch_points`` spreads them over the cores: the numbers of the serial
    loop). None once a signal asked to stop: in this process the points located before it are kept, as the serial
    loop kept them; on workers the signal raises ``interrupt.Interrupted`` here within a second (``workers.spread``)
    and the points in the workers are abandoned, as a branch's assessments are."""
    if interrupt.requested():
        return None
    bp = bifurcation.classify(primary, bifurcation.locate(primary, index, block, k))
    bp.note = f"{MODES[block]} mode"  # its name: its label in the file
    return bp


def _trace_broken(scene, primary: Branch, picture: Picture, progress: Progress) -> None:
    """The pear branch the broken equator symmetry disconnects (``broken_symmetry``), assessed; a failure to find
    it is a branch not started."""
    try:
        branch = broken_symmetry.broken_pear(scene, primary, BROKEN, progress.ticker(Phase.PEAR))
    except broken_symmetry.HomotopyError as error:
        picture.not_started.append((BROKEN, str(error)))
        return
    if branch is not None:
        picture.branches.append(branch)
        _assess(branch, scene, False, progress, picture.clock)


def _unsearched(primary: Branch, searched: bool, surface: bool) -> str:
    """What is not searched on a primary branch without equator symmetry (``Picture.not_searched``); ``searched``:
    the disconnected pear branch was searched for (``_trace_broken``); ``surface``: the branches at its m ≥ 1
    points are traced (``_trace_surface``). A scene whose coils are equator-symmetric breaks no pitchfork (a pear
    branch restarted by ``continue``, ``continuation.symmetry = "none"``). Without ``surface`` the free balloon's
    primary branch is not traced either (``_trace_free``; with it, "first" names it in ``Picture.not_asked``)."""
    missing = []
    if not searched and not primary.scene.field.is_equator_symmetric:
        missing.append("the pear branch of the broken pitchfork (disconnected from this branch) is not traced")
    if not surface:
        missing.append("the branches at its branch points are not traced")
    if not surface and primary.gauge == Gauge.HELD:
        missing.append("nor is the free balloon's branch (its held states carry the field's net axial force: a "
                       "free balloon moves along the axis until it vanishes)")
    return "; ".join(missing)


def _trace_free(scene, picture: Picture, progress: Progress) -> None:
    """The free balloon's primary branch (FREE_PRIMARY) of a field without equator symmetry: the held primary
    branch's states carry the field's net axial force (the hold's reaction), so the free balloon needs its own
    branch, traced with the axial translation b_0 an unknown and the net axial force zero (``primary.released``:
    it starts where that force vanishes), assessed, its stability changes under every control located
    (``control_points``); its m ≥ 1 points are switched with the primary branch's (``_trace_surface``). A start
    that fails is a branch not started (the result is then incomplete). Its m = 0 branch points (the pitchforks
    of a symmetry about the plane where the free balloon centres: one coil's own plane) are classified and the
    pear branches born at them traced both ways, <FREE_PRIMARY>_pear_<n> and its _mirror (``free_pitchforks``),
    assessed."""
    with picture.clock.step(Step.FREE_BALLOON):
        try:
            free = trace_primary(scene, symmetric=False, held=False, name=FREE_PRIMARY,
                                 progress=progress.ticker(Phase.FREE))
        except ContinuationError as error:
            picture.not_started.append((FREE_PRIMARY, str(error)))
            return
    progress.finish(Phase.FREE, len(free.X))
    picture.branches.append(free)
    if not _assess(free, scene, False, progress, picture.clock):
        return
    with picture.clock.step(Step.BRANCH_POINTS):
        free.special += control_points.find(free)
        free.special.sort(key=_along)
        pitchforks = free_pitchforks.classified(free)
    m0 = [s for s in free.branch_points() if s.m == 0]
    with picture.clock.step(Step.PEAR_BRANCHES):
        for n, _ in pitchforks:
            if stopped(picture) or not pear_pair(scene, free, picture, n, progress, points=m0,
                                                 prefix=f"{FREE_PRIMARY}_pear"):
                return


WHOLE_SPHERE_EVENTS = "the [[events]] are not located on branches traced on the whole sphere"


def _whole_sphere(scene, progress: Progress, clock: Clock, pear: bool) -> Picture:
    """The picture of a field that is not axisymmetric: its primary branch traced on the whole sphere, assessed
    held under every control, its secondary branch points located (``surface.primary``), and the branches born at
    its pitchforks (the first one, or all: ``[surface] branches``; none with ``pear=False``) followed with their
    mirror images (``surface.pitchforks``); a branch point that is not a pitchfork is listed in
    ``Picture.not_switched``."""
    primary = surface_primary.trace_surface_primary(scene, progress.ticker(Phase.PRIMARY), clock)
    progress.finish(Phase.PRIMARY, len(primary.values))
    picture = Picture([], surface_branches=[primary], clock=clock)
    if scene.events:
        picture.not_searched = WHOLE_SPHERE_EVENTS
    if not (stopped(picture) or not pear or scene.surface.branches == "none"):
        _switch_pitchforks(scene, primary, picture, progress)
    label_readings(picture.surface_branches)  # folds, end points and secondary points: held, as their branches
    return picture


def _switch_pitchforks(scene, primary, picture: Picture, progress: Progress) -> None:
    """The branches born at the pitchforks of a whole-sphere primary branch (the first one, or all: ``[surface]
    branches``) with their mirror images; the branch points that are not pitchforks in ``Picture.not_switched``."""
    search = surface_pitchforks.pitchforks(primary)
    picture.not_switched = search.unswitched
    with picture.clock.step(Step.SURFACE_BRANCHES):
        for number, bp, broken in search.pitchforks[:1] if scene.surface.branches == "first" else search.pitchforks:
            if stopped(picture):
                break
            _switch_pitchfork(scene, primary, number, bp, broken, picture, progress)
    progress.finish(Phase.SURFACE, sum(len(b.values) for b in picture.surface_branches[1:]))


def _switch_pitchfork(scene, primary, number: int, bp, broken: tuple, picture: Picture, progress: Progress) -> None:
    """The branch born at one pitchfork of a whole-sphere primary branch and its mirror image (reflected, else
    traced along −φ), the classification written back to the parent point; a start that fails is a branch not
    started."""
    name, budget = surface_pitchforks.branch_name(number), scene.surface.max_points

    def traced(sign: float):
        with progress.budget(Phase.SURFACE, budget) as tick:
            return surface_pitchforks.trace_pitchfork(primary, number, bp, broken, budget, sign, tick)

    try:
        branch = traced(1.0)
        other = surface_pitchforks.mirror_image(branch, broken) or (
            None if interrupt.requested() else traced(-1.0))  # a signal: the other direction is not started
    except surface_branches.SurfaceStartError as error:
        picture.not_started.append((name, str(error)))
        return
    picture.surface_branches += [b for b in (branch, other) if b is not None]
    _classified(primary, bp, branch)


def _classified(primary, bp, branch) -> None:
    """The classification of ``branch``'s origin (the reduced energy on the whole sphere) written back to its
    parent point ``bp`` of ``primary``."""
    origin = branch.special[0]
    primary.special = [replace(s, classification=origin.classification, E=origin.E) if s is bp else s
                       for s in primary.special]


def stopped(picture: Picture) -> bool:
    """Whether a signal asked the analysis to stop (``numerics.interrupt``); the picture is then ``interrupted``,
    in the phase its clock is in (or left last: the phases poll the flag at every point and step)."""
    if interrupt.requested() and not picture.interrupted:
        picture.interrupted = True
        current = picture.clock.current
        picture.interrupted_in = current.value if current is not None else ""
    return picture.interrupted


def _trace_pears(scene, primary: Branch, picture: Picture, progress: Progress):
    """Pear branches from the pear branch points of both readings (``pear_pair``), a branch that rejoins at an
    already traced point not repeated. An interrupt ends the search after the branch being traced (which is kept;
    assessed unless the signal came before or during its assessment)."""
    reached = set()
    for n, bp in enumerate(picture.branch_points):
        if bp.block not in PEAR_NAMES or n in reached:
            continue
        if not pear_pair(scene, primary, picture, n, progress, reached):
            return


def pear_pair(scene, primary: Branch, picture: Picture, n: int, progress: Progress,
              reached: set | None = None, points: list | None = None, prefix: str | None = None) -> bool:
    """The pear branch from the pear branch point ``n`` of ``points`` (default ``picture.branch_points``, the
    primary branch's) named <prefix>_<n> (default by its block, held: pear_<n>; free, in a field: pear_free_<n>,
    traced with the translation free) and its mirror image: the reflection of the pear branch in a scene invariant
    under z → −z (``mirror``: its Origin says how it was obtained), else traced; appended to ``picture.branches``
    (a branch that cannot start to ``picture.not_started``), each assessed. The branch points where they rejoin
    are added to ``reached``. False when a signal (``numerics.interrupt``) stopped the work."""
    points = picture.branch_points if points is None else points
    bp, reflect = points[n], mirror.reflectable(scene)
    prefix = PEAR_NAMES[bp.block] if prefix is None else prefix
    pear, bottom_turns = None, []
    for sign, suffix in ((1.0, ""), (-1.0, MIRROR)):
        if interrupt.requested():
            return False
        name = f"{prefix}_{n}{suffix}"
        origin = Origin.TRACED
        if sign < 0 and pear is not None:
            reflected = mirror.reflection(pear, bottom_turns, name)
            if isinstance(reflected, Branch):  # parent, rejoin and assessments are the pear's, reflected
                picture.branches.append(reflected)
                continue
            origin = reflected
        branch = trace_pear(primary, bp, sign, name, progress.ticker(Phase.PEAR), bottom_turns=reflect)
        if branch is None:
            picture.not_started.append((name, f"the first correction from branch point {n} of {primary.name} "
                                              "along its mode did not converge"))
            continue
        bottom_turns = mirror.take_bottom_turns(branch)
        branch.origin = origin
        branch.parent = (primary.name, n)
        branch.rejoins = _rejoin_point(branch, points, n)
        if branch.rejoins is not None:
            if reached is not None:
                reached.add(branch.rejoins)
            mark_rejoin(branch, primary, points[branch.rejoins])
        picture.branches.append(branch)
        if interrupt.requested() or not _assess(branch, scene, False, progress, picture.clock):
            return False  # kept as traced, not assessed
        pear = branch if sign > 0 and reflect else None
    return True


def _trace_surface(scene, branch: Branch, picture: Picture, progress: Progress):
    """The non-axisymmetric branches born at the located m ≥ 1 branch points of an axisymmetric ``branch`` (the
    primary branch, the free balloon's: ``FREE_PRIMARY``), as ``[surface] branches`` asks (the held reading's
    first one, or all; on a branch without equator symmetry "first" traces none: their basis keeps one reflection,
    and costs); ``surface_pair``; the parent point gets the classification from the reduced energy on the whole
    sphere. Only the points of the reading the branch's states are equilibria of are switched (``Branch.reads``):
    the others are listed in ``Picture.not_switched`` with why, those the scene leaves out in
    ``Picture.not_asked``."""
    points = [(k, bp) for k, bp in enumerate(branch.branch_points()) if bp.m >= 1 and bp.status == Status.LOCATED]
    other = [(k, bp) for k, bp in points if not branch.reads(bp.block)]
    if other:
        picture.not_switched.append((", ".join(surface_name(branch, k, bp) for k, bp in other),
                                     _other_reading(branch)))
        points = [(k, bp) for k, bp in points if branch.reads(bp.block)]
    first = scene.surface.branches == "first"
    chosen = points if not first else [] if not branch.disc.symmetric else [p for p in points if p[1].block.held][:1]
    if len(chosen) < len(points):
        traced = {k for k, _ in chosen}
        reason = ('not traced: [surface] branches = "first" (set "all" to trace them)' if branch.disc.symmetric else
                  'not traced: [surface] branches = "first" traces none on a branch without equator symmetry (its '
                  'whole-sphere basis keeps the mirror y → −y alone: near a wire minutes to hours a branch); set "all"')
        picture.not_asked.append((", ".join(surface_name(branch, k, bp) for k, bp in points if k not in traced),
                                  reason))
    for k, bp in chosen:
        if stopped(picture):
            return
        name = surface_name(branch, k, bp)
        if scene.geometry.shape == Shape.CAPSULE:
            trace_capsule(scene, branch, k, bp, picture, progress)
            continue
        try:
            pair = surface_pair(branch, k, bp, scene.surface.max_points, progress)
        except surface_branches.SurfaceStartError as error:
            picture.not_started.append((name, str(error)))
            continue
        picture.surface_branches += pair
        _classified(branch, bp, pair[0])


def trace_capsule(scene, branch: Branch, k: int, bp, picture: Picture, progress: Progress) -> None:
    """The capsule's branch born at the m ≥ 1 point ``bp`` (number ``k`` in ``branch.branch_points()``), along +φ
    over (θ, φ) (``capsule.traced_branch``: refined by its error estimate, its mirror sector's stability at every
    point), and its −φ half, the image under the rotation by π/m about the axis (meridian/rotation.py, named
    <name>_rotated), with their UZ points (meridian/events.py), into ``Picture.meridian_surface``; listed in ``not_started`` where its switched point does not
    converge. A signal stops its trace at the next point, the points traced kept (StopCode.INTERRUPTED; its image
    too), and the analysis. ``continue`` at a capsule's m ≥ 1 label calls it too."""
    name = surface_name(branch, k, bp)
    with progress.budget(Phase.SURFACE, scene.surface.max_points) as tick:
        try:
            traced = capsule.traced_branch(scene, branch, bp, parent=(branch.name, k), progress=tick)
        except SurfaceBranchStartError as error:
            picture.not_started.append((name, str(error)))
            return
    if traced.stop.code != StopCode.INTERRUPTED:  # its UZ points (a signal: the points traced kept, no more work)
        traced = meridian_events.with_events(scene, traced, branch.params_at(bp.X))
    picture.meridian_surface[name] = traced
    picture.meridian_surface[f"{name}{ROTATED}"] = rotation.rotated(traced, name)  # its UZ points the same P, V
    if traced.stop.code == StopCode.INTERRUPTED:
        stopped(picture)


def surface_name(branch: Branch, k: int, bp) -> str:
    """The name of the branch born at the m ≥ 1 point ``bp`` (number ``k`` in ``branch.branch_points()``):
    m<m>_bp<k>, prefixed by the parent's name on the free balloon's primary branch."""
    return f"{FREE_PRIMARY}_m{bp.m}_bp{k}" if branch.name == FREE_PRIMARY else f"m{bp.m}_bp{k}"


def _other_reading(branch: Branch) -> str:
    """Why the points of the other reading on a held or free ``branch`` are not switched (``Branch.reads``)."""
    if branch.gauge == Gauge.HELD:
        return ("not switched: free-reading points of held states, which carry the field's net axial force (the "
                "hold's reaction) and are no free equilibria; the free balloon's m ≥ 1 points are on "
                f"{FREE_PRIMARY} (traced with [surface] branches = \"all\")")
    return ("not switched: held-reading points of free states, whose centre is where the net force vanishes, not "
            "where the scene holds the balloon; the held balloon's are on the primary branch")


def surface_pair(primary: Branch, k: int, bp, max_points: int, progress: Progress) -> list:
    """The two directions of the pitchfork at the m ≥ 1 branch point ``bp`` (number ``k`` in
    ``primary.branch_points()``), named m<m>_bp<k>: along +φ, and for an odd m its image under the rotation by π
    about the axis (``surface_branches.rotated``), for an even m (which that rotation maps to itself) traced along
    −φ. SurfaceStartError when it cannot start."""
    name = surface_name(primary, k, bp)

    def traced(sign: float, called: str):
        with progress.budget(Phase.SURFACE, max_points) as tick:
            return _with_events(surface_branches.trace_surface(primary, k, bp, sign, called, max_points, tick))

    branch = traced(1.0, name)
    if interrupt.requested():  # the other direction is not started
        return [branch]
    other = (surface_branches.rotated(branch, f"{name}{ROTATED}") if bp.m % 2 else  # its UZ points turned with it
             traced(-1.0, f"{name}{OPPOSITE}"))
    return [branch, other]


def _with_events(branch):
    """A traced surface branch with the UZ points of its scene's ``[[events]]`` (``events.with_surface_events``,
    on its stored basis)."""
    trace = surface_branches.SurfaceTrace(branch.scene, branch.basis, branch.params, branch.held)
    return events.with_surface_events(branch, trace.system)


def unsearched_events(picture: Picture, scene) -> None:
    """Add to ``picture.not_searched`` the events not located on its surface branches, if it has any
    (``events.unlocated_on_surface``)."""
    missing = events.unlocated_on_surface(scene) if picture.surface_branches or picture.meridian_surface else ""
    if missing:
        picture.not_searched = "; ".join(filter(None, (picture.not_searched, missing)))


def _rejoin_point(branch: Branch, branch_points: list, origin: int) -> int | None:
    """The pear branch point of the reading of ``origin`` (the same block) where ``branch`` rejoined the primary
    branch (nearest in the continuation parameter, P or Φ̄), if any."""
    if not branch.stopped(StopCode.REJOINED):
        return None
    p_end = branch.X[-1, -1]
    block = branch_points[origin].block
    candidates = [(abs(bp.X[-1] - p_end), n) for n, bp in enumerate(branch_points)
                  if n != origin and bp.block == block]
    return min(candidates)[1] if candidates else None


HELD_FLAG = {Control.PRESSURE: "stable_pressure", Control.VOLUME: "stable_volume", Control.GAS: "stable_gas"}


def snap_throughs(branches: list, control: Control = Control.PRESSURE) -> list:
    """The snap-throughs under the loading ``control`` (``find_snaps``): its held flag (HELD_FLAG), its control
    value q (P, V or n) and the energy it minimises ranking the targets (``control.minimised_energy``)."""
    curves = []
    for b in branches:
        eq = equilibrium_of(b)
        energy = np.array([eq.energy(x[:-1], b.params_at(x)) for x in b.X])
        P, volume = b.pressure, 2 * np.pi * np.array([eq.volume(x[:-1]) for x in b.X])
        # a voltage branch (pressure control only): q = Φ̄ at fixed P
        q = b.X[:, -1] if b.parameter != "P" else control_values(P, volume, control)
        energy = minimised_energy(energy, P, volume, control)
        stable = np.array([a.flags()[HELD_FLAG[control]] for a in b.stability], dtype=bool)
        folds = located_folds(b.disc, [(s.kind, s.status, s.index, s.X) for s in b.special], control,
                              b.scene.geometry)
        curves.append(Curve(b.name, q, stable, energy, folds))
    return find_snaps(curves)


def located_folds(disc, special, control: Control, geometry: Geometry = Geometry()) -> dict:
    """{interval i: q at the fold} of the located folds of the control q (``control.FOLD_KIND``: LP, LV, LN; on a
    voltage branch LP is the fold in Φ̄ = X[-1], q there) among ``special`` ((kind, status, index, X) on ``disc``
    of a scene of reference ``geometry``)."""
    return {int(index): control_value(disc, X, control, geometry) for kind, status, index, X in special
            if kind == FOLD_KIND[control] and status == Status.LOCATED}


@dataclass(frozen=True)
class Curve:
    """A branch as ``find_snaps`` sees it, per point: the control value (P under pressure control, the volume
    under volume control), whether it is stable under that control, and the energy that control minimises."""

    name: str
    control: np.ndarray
    stable: np.ndarray
    energy: np.ndarray
    folds: dict = field(default_factory=dict)  # interval i -> q at the located fold of q there (located_folds)


def find_snaps(curves: list[Curve]) -> list[SnapThrough]:
    """Where a stable stretch of a branch ends next to an unstable point (a fold or a loss of stability, reached
    by raising or lowering the control along the stretch: both ends of every stretch), the jump at that control
    value to the stable point of lowest energy on any branch (an interval of two stable points strictly bracketing
    it, not within one point of the start on its branch or on the branch's mirror image: the same state
    reflected; none: to_branch ""). ``pressure`` of the result is the control value: the located fold's where the
    stretch ends at one (``Curve.folds``), else the last stable point's."""
    snaps = []
    for curve in curves:
        stable = curve.stable
        for i in range(len(stable) - 1):
            if stable[i] != stable[i + 1]:
                end = i if stable[i] else i + 1
                value = float(curve.folds.get(i, curve.control[end]))
                target = _stable_at(curves, value, exclude=(curve.name, end))
                snaps.append(SnapThrough(curve.name, end, value, *(target or ())))
    return snaps


def _family(name: str) -> str:
    """A pear branch and its mirror image (``_trace_pears`` names it <name>_mirror) share a family."""
    return name.removesuffix(MIRROR)


def _stable_at(curves: list[Curve], value: float, exclude):
    best = None
    for curve in curves:
        stable, c = curve.stable, curve.control
        for i in range(len(c) - 1):
            if _family(curve.name) == _family(exclude[0]) and abs(i - exclude[1]) <= 1:
                continue
            if stable[i] and stable[i + 1] and (c[i] - value) * (c[i + 1] - value) < 0:
                if best is None or curve.energy[i] < best[0]:
                    best = (curve.energy[i], curve.name, i)
    return best[1:] if best else None
