"""``balloon-cg continue RUN.h5 LABEL``: restart from a labelled special point of a run file (AUTO's IRS = LAB).

Every special point of a run file has a label, unique in the file (``io.run_file.labelled``: 1, 2, … through the
branches in their order; ``inspect`` shows them). From the point with ``label``:

- in the branch's own parameter (P, or Φ̄ of a voltage continuation; ``parameter`` None or that name): from a
  point that is no branch point, the branch through it is traced again in both directions from it, with the
  scene's stop rules and ``[[events]]``, on the stored discretisation, and, if the stored branch was assessed
  (a run without --primary-only), assessed with its branch points and m ≥ 1 points located as ``run`` gives them
  (``restart_branch``: a Picture of one branch, primary); from a branch point of an equator-symmetric branch,
  the branches bifurcating there (``switch``): at a pear point (odd_held, or odd_free: the free balloon) the
  pear branch and its mirror image, as ``run`` traces them (``picture.pear_pair``, its critical mode recomputed:
  ``pear_point``), assessed and with their m ≥ 1 points as ``run`` gives them, at an m ≥ 1 point of a reading
  the branch's states are equilibria of (``Branch.reads``: held or free on an equator-symmetric branch, the held
  reading's on a held branch without it, the free one's on the free balloon's ``primary_free``) the
  non-axisymmetric branch and its other direction on the whole sphere (``picture.surface_pair``, assessed as
  ``run`` assesses it), on a capsule over (θ, φ) with its image under the rotation by π/m
  (``picture.trace_capsule``, its mirror sector's stability read); the branch of the point is written as read (its
  stored stability is not read back);
- a fold (LP, LV, LN) in a second parameter q (any key of ``analysis.critical.second_parameter``): the fold curve through it
  (``analysis.critical.fold_curve.continue_fold``);
- any other point (UZ, EP, TP) in M or Φ̄ (TUNED): the branch through it in that parameter at its fixed P
  (``restart_in``: a Picture of one branch, primary, assessed as the stored branch was; with [dynamics] its
  frequencies, the tuning curves Ω²(M) or Ω²(Φ̄) at fixed P);
- a pear branch point (BP of block odd_held, or odd_free: the free balloon's, on an equator-symmetric branch) in q:
  the curve of pitchforks through it (``analysis.critical.pitchfork_curve.continue_branch_point``; its mode recomputed,
  ``pear_point``), as ``critical`` traces the held one.

A restarted leg stops where it crosses its known parent away from its own pitchfork (``rejoin_rule``) or comes
back to where it started (``closing_rule``: a closed loop, traced once); a restarted pear branch whose parent is
known is written under its own name after that parent as read, so that a restart from that file knows it too. The branch is rebuilt from the file
(``stored_branch``): its scene (the stored scene text), discretisation,
parameters, points and special points; ``with_settings`` sets keys of the scene that do not change the equations
(stops, tolerances, readings, events: ``continue --set``). Not yet (RestartError, one line): the other branch
points (even, m ≥ 1) in a second parameter, switching at an even point, at an m ≥ 1 point of the other reading
or at an m = 0 point of a branch without equator symmetry, points of surface branches, an ordinary point in a
second parameter other than M or Φ̄.
"""
import time
from dataclasses import dataclass, replace

import numpy as np

from ..analysis.branches.assembly import assemble
from ..analysis.branches.events import with_events
from ..analysis.critical.fold_curve import CONTROL_OF_FOLD, continue_fold
from ..analysis.branches.primary import landing_targets, range_limits, stop_rule
from ..analysis.points.extended_systems import WernerSpence
from ..analysis.critical.pitchfork_curve import continue_branch_point, plain_branch
from ..analysis.picture import (FREE_PRIMARY, PEAR_NAMES, Picture, Progress, azimuthal_crossings, examine,
                                label_readings, pear_pair, stopped, surface_name, surface_pair, trace_capsule,
                                unsearched_events)
from ..analysis.branches.problem import equilibrium_of
from ..analysis.results import Block, Branch, Classification, Gauge, Kind, Leg, SpecialPoint, Status, StopCode
from ..analysis.critical.second_parameter import resolve
from ..analysis.surface.branches import SurfaceStartError
from ..analysis.switching.pear import mark_rejoin, pear_landing, pear_stop_rule
from ..analysis.branches.tracer import Tracer
from ..analysis.timing import Clock, Step
from ..dynamics.frequencies import attach_to
from ..galerkin.equilibrium import Parameters
from ..numerics import continuation, interrupt
from ..numerics.continuation import Stop, TraceStop
from ..io.run_file import stored_scene
from ..scene import SceneError
from ..scene.tables import Shape, startable
from ..post.quantities import branch_discretisation


class RestartError(ValueError):
    """A label or parameter ``continue`` cannot start from; the one-line message says which and what is allowed."""


@dataclass(frozen=True)
class Labelled:
    """The special point with ``label`` of a run file: its branch (rebuilt) and the point."""

    label: int
    branch: Branch
    point: SpecialPoint
    assessed: bool = False  # the stored branch has its stability (a run without --primary-only)
    parent: Branch | None = None  # a pear branch's parent (the primary branch, as read) ...
    parent_point: int = -1  # ... and the number of its pitchfork there (``numbered_branch_points``)


def stored_branch(run: dict, name: str) -> Branch:
    """The axisymmetric branch ``name`` of a read run file (``io.run_file.read_run``) as a Branch: scene,
    discretisation, parameters, points and special points (``stored_special``; no stability)."""
    data = run["branches"][name]
    attrs = data["attrs"]
    parameter = attrs.get("parameter", "P")
    X = np.asarray(data["unknowns"], dtype=float)
    params = Parameters(float(X[0, -1]) if parameter == "P" else float(data["pressure"][0]), float(attrs["M"]),
                        float(attrs["chi"]), float(attrs.get("voltage", 0.0)))
    disc = branch_discretisation(data)
    return Branch(name, stored_scene(run), disc, attrs["kernel_class"], attrs["kernel_signature"], params, X,
                  data["newton_iterations"], data["residual"], data["error_estimate"],
                  np.full(len(X), disc.degree), special=stored_special(data), legs=stored_legs(attrs),
                  parameter=parameter)


def stored_stop(code: str, message: str) -> Stop:
    """A stored stop code (a StopCode or TraceStop value) and its message as a Stop."""
    try:
        return Stop(StopCode(code), message)
    except ValueError:
        return Stop(TraceStop(code), message)


def stored_legs(attrs: dict) -> tuple:
    """The legs of a stored branch: its leg_labels and leg_stop_codes, each message read back from stop_reason
    ('label: message; …'; the code where it cannot be)."""
    parts = dict(part.split(": ", 1) for part in attrs.get("stop_reason", "").split("; ") if ": " in part)
    return tuple(Leg(label, stored_stop(code, parts.get(label, code)))
                 for label, code in zip(attrs.get("leg_labels", []), attrs.get("leg_stop_codes", [])))


def stored_special(data: dict) -> list[SpecialPoint]:
    """The special points of a read branch (``io.run_file.read_run``) as SpecialPoints: kind, interval, X, block,
    m, classification and E, status, reading, note and an end point's stop (no mode: run files do not store
    it)."""
    return [SpecialPoint(Kind(s["kind"]), int(s["index"]), np.asarray(data["special_unknowns"][row], dtype=float),
                         classification=Classification(s["classification"]), block=Block(s["block"]),
                         m=int(s.get("m", 0)), status=Status(s["status"]), uncertainty=float(s["uncertainty"]),
                         reason=s["reason"], E=(s["E2"], s["E3"], s["E4"]), note=s["note"], gauge=Gauge(s["gauge"]),
                         stop=stored_stop(s["stop_code"], s["note"]) if s["stop_code"] else None)
            for row, s in enumerate(data["special_points"])]


def find_label(run: dict, label: int) -> Labelled:
    """The special point ``label`` of a read run file; RestartError naming the labels the file has if none is."""
    labels = []
    for name, data in run["branches"].items():
        for row, point in enumerate(data["special_points"]):
            labels.append(point["label"])
            if point["label"] != label:
                continue
            if data["attrs"].get("m", 0) or "surface_degree" in data["attrs"]:
                raise RestartError(f"label {label}: a point of the surface branch {name}; continue starts from "
                                   "axisymmetric branches only")
            branch, parent = stored_branch(run, name), data["attrs"].get("parent_branch", "")
            return Labelled(label, branch, branch.special[row], "stability" in data,
                            stored_branch(run, parent) if parent in run["branches"] else None,
                            int(data["attrs"].get("parent_branch_point", -1)))
    if not run["branches"]:
        raise RestartError(f"label {label}: {run['path']} has no branches (a curve file: continue starts from a "
                           "point of a run file; critical or continue --parameter traced this curve)")
    listed = f"{min(labels)}..{max(labels)}" if labels else "none"
    raise RestartError(f"label {label}: no special point has it in {run['path']} (its labels: {listed}; "
                       "balloon-cg inspect shows them)")


SETTABLE = ("continuation", "solver", "stability", "surface", "loading", "events")  # what ``with_settings`` changes


def with_settings(start: Labelled, overrides: dict) -> Labelled:
    """``start`` with its scene's keys set (``Scene.with_overrides``: dotted keys, None restores the default), for
    what is traced from it: the stops, the tolerances, the readings, the [[events]]. A key that changes the
    equations (material, field, electric) would leave the stored point off its equilibrium: RestartError naming
    it (run a new scene with it, or continue in it as a second parameter)."""
    if not overrides:
        return start
    scene = start.branch.scene
    for key in overrides:
        section = scene.canonical_key(key).split(".")[0].split("[")[0]
        if section not in SETTABLE:
            raise RestartError(f"--set {key}: continue keeps the stored point's equations, so only "
                               f"{', '.join(s + '.*' for s in SETTABLE)} can change (for {section}.*: a new "
                               f"run with --set, or continue --parameter {key} to follow the point in it)")
    scene = scene.with_overrides(overrides, name=scene.name)
    return replace(start, branch=replace(start.branch, scene=scene),
                   parent=None if start.parent is None else replace(start.parent, scene=scene))


def restart_branch(start: Labelled, progress=None) -> Picture:
    """The branch through the labelled point, traced again from it in both directions in the branch's parameter
    (P, Φ̄, or M on a branch ``restart_in`` traced; module docstring), on the stored degree and basis map, with the
    stops of its kind (a pear branch's: either pole stretch at stop_stretch, ``switching.pear_stop_rule``); if the stored branch was assessed, assessed and its
    branch points and m ≥ 1 points located (``picture.examine``, no branch switched), as ``run`` gives them."""
    t0 = time.perf_counter()
    branch, scene = start.branch, start.branch.scene
    disc = branch.disc
    tracer = Tracer(scene, disc.symmetric, held_layout(branch), parameter=branch.parameter)
    params = branch.params
    system = tracer.system(disc.degree, params, disc.mapping)
    point = step_away(system, start, tracer.settings)
    upper = scene.continuation.stop_stretch
    pear = is_pear(branch)  # stopped as run stops pear branches
    rejoined = []  # the parent's branch points where a leg stopped (``rejoin_rule``)

    def stop():  # a leg's own rule (a pear leg remembers its crossings of the parent; each leg its way round)
        if not pear:
            return closing_rule(disc, point.X, stop_rule(scene, upper, branch.parameter, params))
        base = pear_stop_rule(scene) if start.parent is None else rejoin_rule(start, pear_stop_rule(scene), rejoined)
        return closing_rule(disc, point.X, base)

    def leg(sign):
        return tracer.leg(replace(point, tangent=sign * point.tangent), params, stop(), progress, degree=disc.degree,
                          mapping=disc.mapping, limits=range_limits(scene, upper, branch.parameter, params))

    clock = Clock()
    up, down = both_ways(leg, clock)
    child = pear and start.parent is not None  # stored with its parent, under its own name
    name = branch.name if child or branch.name == FREE_PRIMARY else "primary"
    traced = with_events(assemble(tracer, params, name, up, down, t0, labels=("up", "down"),
                                  land_on=pear_landing(scene) if pear else landing_targets(scene, upper)))
    if child:  # through its pitchfork on the parent into the mirror image: the fold of P there is that pitchfork
        #        (P is even in the pear amplitude), as run marks a rejoin
        points = numbered_branch_points(start.parent)
        block = points[start.parent_point].block  # its reading's pitchforks (held or free)
        for bp in points:
            if bp.block == block:
                mark_rejoin(traced, start.parent, bp)
        traced.parent, traced.rejoins = (start.parent.name, start.parent_point), next(iter(rejoined), None)
    picture = (examine(scene, traced, Ticks(progress), pear=False, clock=clock, control=not pear) if start.assessed
               else Picture([traced], clock=clock))
    return replace(picture, branches=[start.parent, *picture.branches]) if child else picture


def is_pear(branch: Branch) -> bool:
    """Whether a stored branch is a pear branch (pear_<n>, its mirror image, broken_pear; or one of them restarted
    and written as ``primary`` by ``continue``): another name than the primary branch's, or states without the
    equator symmetry the scene's primary branch has."""
    return branch.name not in ("primary", FREE_PRIMARY) or (
        not branch.disc.symmetric and Tracer(branch.scene).symmetric)


CLOSING_SHARE = 0.25  # the start lies within this share of a step's chord of it: the leg came back to it
AWAY_STEPS = 3  # ... after having been farther from it than this many such chords


def closing_rule(disc, X0, base):
    """stop(disc, point) of a restarted leg that comes back to where it started (``X0`` on ``disc``): a closed
    branch, the loop of an isola whose crossings of its parent are not known (a pear branch restarted from a file
    that ``continue`` wrote) or an isolated loop, stops there with StopCode.CLOSED instead of going round to
    max_points. Points compare by (λ2(0), λ2(π), η(0), η(π), p), the same on any discretisation the leg refines to:
    the leg closes on the step whose chord passes within CLOSING_SHARE of its length of the start, once it has been
    more than AWAY_STEPS chords away. Elsewhere ``base``."""
    def signature(disc, X):
        rows = disc.pole_rows()
        return np.array([rows[name] @ X[:-1] for name in ("lam2_top", "lam2_bottom", "eta_top", "eta_bottom")]
                        + [X[-1]])

    origin = signature(disc, X0)
    state = {"previous": None, "away": 0.0}

    def stop(disc, point):
        here = signature(disc, point.X)
        previous, state["previous"] = state["previous"], here
        if previous is not None:
            chord = here - previous
            length = float(np.linalg.norm(chord))
            t = float(np.clip((origin - previous) @ chord / length ** 2, 0.0, 1.0)) if length > 0 else 0.0
            gap = float(np.linalg.norm(previous + t * chord - origin))
            if state["away"] > AWAY_STEPS * length and gap <= CLOSING_SHARE * length:
                return Stop(StopCode.CLOSED, f"closed on itself: back at the point it was restarted from (P = "
                                             f"{point.X[-1]:.6g})")
        state["away"] = max(state["away"], float(np.linalg.norm(here - origin)))
        return base(disc, point)

    return stop


def rejoin_rule(start: Labelled, base, rejoined: list):
    """stop(disc, point) of one leg of a restarted pear branch whose parent is known: where the pear amplitude
    A = λ2(0) − λ2(π) changes sign the leg crosses the equator-symmetric parent; it passes the pitchfork it was
    born at once (into its mirror image: P is even in A there, ``mark_rejoin``) and stops at any other crossing
    (StopCode.REJOINED, at the parent's pitchfork of its reading nearest in the branch parameter, whose number
    in ``numbered_branch_points`` it appends to ``rejoined``), as ``run``'s pear branches stop: so a restart on an
    isola ends where the closed loop does instead of going round it. Elsewhere ``base``
    (``switching.pear_stop_rule``)."""
    points = numbered_branch_points(start.parent)
    block = points[start.parent_point].block
    pitchforks = [(n, bp.X[-1]) for n, bp in enumerate(points) if bp.block == block]
    state = {"amplitude": None, "passed": False}

    def stop(disc, point):
        rows = disc.pole_rows()
        amplitude = float((rows["lam2_top"] - rows["lam2_bottom"]) @ point.X[:-1])
        before, state["amplitude"] = state["amplitude"], amplitude
        if before is not None and before * amplitude < 0:
            n = min(pitchforks, key=lambda item: abs(item[1] - point.X[-1]))[0]
            if n != start.parent_point or state["passed"]:
                rejoined.append(n)
                return Stop(StopCode.REJOINED, f"rejoined the primary branch at its pitchfork at P = {point.X[-1]:.6g}")
            state["passed"] = True
        return base(disc, point)

    return stop


def step_away(system, start: Labelled, settings: continuation.Settings) -> continuation.Point:
    """The start of a restart: the labelled point moved one continuation step (``settings.step``, else a tenth,
    a hundredth of it) along the branch toward its interior (Keller's corrector), with its tangent along the
    stored order of the points. Not the point itself: there the test function that located it (P′, V′, λ2′, the
    event's quantity − value, …) is zero, so its sign at the first point of a leg would be rounding, and at a
    turning point of λ2(0) a tangent oriented by it is undefined."""
    X, rows, i = start.point.X, start.branch.X, start.point.index
    along = rows[i + 1] - rows[i] if i + 1 < len(rows) else rows[i] - rows[i - 1]
    tangent = continuation.tangent(system, X, along)
    side = 1.0 if i == 0 else -1.0
    for h in settings.step * np.array([1.0, 0.1, 0.01]):
        result = continuation.correct(system, X + side * h * tangent, tangent, settings)
        if result.converged:
            return continuation.Point(result.x, continuation.tangent(system, result.x, tangent), result.iterations,
                                      float(np.abs(system.residual(result.x)).max()))
    raise RestartError(f"label {start.label}: the corrector did not converge one step (down to "
                       f"{0.01 * settings.step:g}) from the point along its branch")


def pear_point(branch: Branch, start: Labelled) -> SpecialPoint:
    """The pear branch point of ``start`` (odd_held, or odd_free: the free balloon's) on the plain symmetric
    ``branch`` (``codim2.plain_branch``) with its critical mode, which run files do not store: the null vector of
    its block of the Hessian at the point (its smallest right singular vector, its largest entry positive so that
    +φ is reproducible; ``codim2.continue_branch_point`` converges the extended system from it). A signal raises
    ``Interrupted`` before the decomposition."""
    X = start.branch.disc.transfer(start.point.X, branch.disc)
    pear = WernerSpence(equilibrium_of(branch), branch.params, np.zeros(0), block=start.point.block)
    interrupt.check()
    phi = np.linalg.svd(pear.odd_hessian(X[:-1], branch.params.with_value("P", X[-1])))[2][-1]
    mode = np.zeros(pear.embed.shape[0])
    mode[pear.odd] = phi * np.sign(phi[np.argmax(np.abs(phi))])
    return SpecialPoint(Kind.BP, start.point.index, X, block=start.point.block, mode=mode, note=start.point.note)


def numbered_branch_points(branch: Branch) -> list[SpecialPoint]:
    """The m = 0 branch points of an equator-symmetric branch in the numbering of ``run`` (its
    ``picture.branch_points``: along the branch, the free balloon's after the others)."""
    return sorted((s for s in branch.branch_points() if s.m == 0), key=lambda s: s.block == Block.ODD_FREE)


class Ticks(Progress):
    """The per-point callable ``progress`` of ``restart`` (None: nothing) as a ``picture.Progress``."""

    def __init__(self, progress=None):
        self.progress = progress

    def tick(self, phase) -> None:
        if self.progress is not None:
            self.progress(phase)


def switch(start: Labelled, progress=None) -> Picture:
    """The branches bifurcating at the branch point ``start`` (module docstring) in a Picture: ``branches`` the
    stored branch of the point (as read: not assessed) and the pear branches (assessed), ``surface.branches`` the
    non-axisymmetric ones, ``not_started`` those that could not start; RestartError for a point this does not
    switch at."""
    branch, point, label = start.branch, start.point, start.label
    if point.kind != Kind.BP:
        raise RestartError(f"label {label} is a {point.kind.value}, not a branch point: nothing to switch at")
    what = f"label {label} is a BP of block {point.block.value or 'none'}"
    if not branch.disc.symmetric and not (point.m >= 1 and branch.reads(point.block)):
        raise RestartError(f"{what} on {branch.name}, a branch without equator symmetry: switching there is built "
                           f"at the m ≥ 1 points of its own reading ({branch.gauge.value}) only (the other reading's "
                           "states are no equilibria of it)")
    if branch.parameter != "P":
        raise RestartError(f"{what} on {branch.name}, continued in {branch.parameter}: switching is built for "
                           "branches continued in P only")
    progress = Ticks(progress)
    if point.block in PEAR_NAMES:
        points = numbered_branch_points(branch)
        n = next(i for i, s in enumerate(points) if s is point)
        picture = Picture([branch], branch_points=points)
        clock = picture.clock  # the pear branches' time, and the phase a signal stops them in, as run records them
        try:
            with clock.step(Step.PEAR_BRANCHES):
                plain = plain_branch(branch, point.X)
                interrupt.check()  # each of the two costs ~1 s near a wire, and neither polls inside
                points[n] = replace(point, mode=pear_point(plain, start).mode)
                traced = pear_pair(branch.scene, branch, picture, n, progress)
            if traced:
                with clock.step(Step.CROSSINGS):
                    azimuthal_crossings(picture, picture.branches[1:], branch.scene)
            else:  # a signal stopped them
                stopped(picture)
        except interrupt.Interrupted:  # in a unit that polls inside (a plain degree's search): abandoned
            stopped(picture)
        label_readings(picture.branches[1:])
        return Picture(picture.branches, not_started=picture.not_started, interrupted=picture.interrupted,
                       interrupted_in=picture.interrupted_in, clock=clock)
    if point.m >= 1 and branch.scene.geometry.shape == Shape.CAPSULE:  # over (θ, φ), as run traces it
        k = next(i for i, s in enumerate(branch.branch_points()) if s is point)
        picture = Picture([branch])
        trace_capsule(branch.scene, branch, k, point, picture, progress)
        stopped(picture)  # a signal in its trace: flagged
        unsearched_events(picture, branch.scene)
        return picture
    if point.m >= 1:  # held, or free on an equator-symmetric branch (its held states are free equilibria)
        k = next(i for i, s in enumerate(branch.branch_points()) if s is point)
        try:
            pair = surface_pair(branch, k, point, branch.scene.surface.max_points, progress)
        except SurfaceStartError as error:
            return Picture([branch], not_started=[(surface_name(branch, k, point), str(error))])
        label_readings(pair)
        picture = Picture([branch], surface_branches=pair)
        stopped(picture)  # a signal in the surface branches (their trace, their assessment): flagged
        unsearched_events(picture, branch.scene)
        return picture
    raise RestartError(f"{what}: switching there is not built (only at pear points, odd_held or odd_free, and "
                       "m ≥ 1 points; run traces no branches at the others either)")


def restart(start: Labelled, parameter: str | None, direction: float = 1.0, progress=None):
    """What ``continue`` computes from ``start`` (module docstring): a Picture (in the branch's own parameter: of
    the branch through it, or at a branch point of the branch of the point and the branches switched to) or a
    two-parameter curve (a fold or a pear point in a second parameter); RestartError for what is not built, and for
    a stored scene a new run may not start (``scene.tables.startable``: a file written before one of its checks is
    read, not continued). The Picture's branches get their natural frequencies when the scene asks for them
    ([dynamics]: not after a signal; a signal during them interrupts the picture there, ``attach_to``)."""
    try:
        startable(start.branch.scene)
    except SceneError as e:
        raise RestartError(f"label {start.label}: the file's scene cannot start a new run: {e}") from None
    own = start.branch.parameter
    kind = start.point.kind
    if parameter in (None, own):
        picture = switch(start, progress) if kind == Kind.BP else restart_branch(start, progress)
        attach_to(picture, start.branch.scene.dynamics)
        return picture
    if kind in CONTROL_OF_FOLD:
        return continue_fold(start.branch, start.point, parameter, direction, progress=progress)
    if kind == Kind.BP and start.point.block in PEAR_NAMES and start.branch.disc.symmetric:
        branch = plain_branch(start.branch, start.point.X)
        return continue_branch_point(branch, pear_point(branch, start), parameter, direction, progress=progress)
    if kind == Kind.BP:
        raise RestartError(f"--parameter {parameter}: label {start.label} is a BP of block "
                           f"{start.point.block.value or 'none'}; only pear points (odd_held, odd_free) of an "
                           "equator-symmetric branch are continued in a second parameter")
    picture = restart_in(start, tuned(start, parameter), progress)
    attach_to(picture, start.branch.scene.dynamics)
    return picture


TUNED = ("M", "voltage")  # the runtime scalars a point is followed in at fixed P (``restart_in``)


def tuned(start: Labelled, key: str) -> str:
    """The Parameters field of ``key`` (a scene key or bare name: ``analysis.critical.second_parameter.resolve``) when it is
    one a point can be followed in at fixed P (TUNED); RestartError otherwise (UnknownParameter for a key the
    scene's kernels do not take)."""
    name = resolve(start.branch.scene, key).split(".")[-1]
    if name not in TUNED or name == start.branch.parameter:
        raise RestartError(f"--parameter {key}: label {start.label} is a {start.point.kind.value}; from it the "
                           f"branch's own parameter {start.branch.parameter}, or {' or '.join(TUNED)} at fixed P "
                           "(a fold, LP, LV or LN, also continues in a second parameter)")
    return name


def restart_in(start: Labelled, name: str, progress=None) -> Picture:
    """The branch through the labelled point in the runtime scalar ``name`` (M or Φ̄) at the point's fixed P (and
    the other parameters): from the point, on the stored degree and basis map, traced both ways with the scene's
    stops (the pole stretches, the wire gap, M in [0, continuation.stop_field] or Φ̄ in [0, stop_voltage], the
    control's), M's ends landed on; assessed, with its branch points and m ≥ 1 points located, as ``run`` gives
    them, if the stored branch was (``picture.examine``, no branch switched). A Picture of one branch, primary,
    whose parameter is ``name``: with [dynamics] frequencies, the tuning curves Ω²(M) or Ω²(Φ̄) at fixed P.
    Its folds in ``name`` are LP points; the point itself is a regular point of the new branch (a fold of P or a
    branch point is continued as a curve instead: ``restart``)."""
    t0 = time.perf_counter()
    branch, scene = start.branch, start.branch.scene
    disc = branch.disc
    params = branch.params_at(start.point.X)
    tracer = Tracer(scene, disc.symmetric, held_layout(branch), parameter=name)
    system = tracer.system(disc.degree, params, disc.mapping)
    X = np.append(start.point.X[:-1], getattr(params, name))
    tangent = continuation.tangent(system, X, np.eye(X.size)[-1])  # oriented with the parameter increasing
    point = continuation.Point(X, tangent, 0, float(np.abs(system.residual(X)).max()))
    upper = scene.continuation.stop_stretch

    def leg(sign):
        return tracer.leg(replace(point, tangent=sign * tangent), params,
                          closing_rule(disc, X, stop_rule(scene, upper, name, params)), progress, degree=disc.degree,
                          mapping=disc.mapping, limits=range_limits(scene, upper, name, params))

    clock = Clock()
    up, down = both_ways(leg, clock)
    primary = with_events(assemble(tracer, params, "primary", up, down, t0, labels=("up", "down"),
                                   land_on=landing_targets(scene, upper)))
    return (examine(scene, primary, Ticks(progress), pear=False, clock=clock) if start.assessed else
            Picture([primary], clock=clock))


def both_ways(leg, clock: Clock) -> tuple:
    """(up, down): ``leg(1.0)`` and, unless it closed (the loop is whole, traced once), ``leg(-1.0)``, charged to
    Step.TRACE on ``clock`` (the restarted picture's: a signal during them is recorded in the trace)."""
    with clock.step(Step.TRACE):
        up = leg(1.0)
        return up, None if up.stop.code == StopCode.CLOSED else leg(-1.0)


def held_layout(branch: Branch) -> bool:
    """Whether a stored branch's layout holds the balloon's centre (b_0 = 0 pinned with a field acting), as its
    Tracer was built."""
    scene = branch.scene
    return branch.disc.pin_translation and bool(scene.field.coils) and scene.field.M != 0
