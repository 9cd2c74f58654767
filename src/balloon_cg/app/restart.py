"""``balloon-cg continue RUN.h5 LABEL``: restart from a labelled special point of a run file (AUTO's IRS = LAB).

Every special point of a run file has a label, unique in the file (``io.run_file.labelled``: 1, 2, … through the
branches in their order; ``inspect`` shows them). From the point with ``label``:

- in the branch's own parameter (P, or Φ̄ of a voltage continuation; ``parameter`` None or that name): the
  branch through the point is traced again in both directions from it, with the scene's stop rules and
  ``[[events]]``, on the stored discretisation (``restart_branch``: a Branch named ``continued``);
- a fold (LP, LV, LN) in a second parameter q (any key of ``analysis.second_parameter``): the fold curve through it
  (``analysis.fold_curve.continue_fold``);
- a pear branch point (BP of block odd_held, on an equator-symmetric branch) in q: the curve of pitchforks through
  it (``analysis.codim2.continue_branch_point``; its mode recomputed, ``pear_point``), as ``critical`` traces it.

The branch is rebuilt from the file (``stored_branch``): its scene (the stored scene text), discretisation,
parameters and points. Not yet: the other branch points (even, m ≥ 1) in a second parameter, surface
branches, an ordinary point in a second parameter, switching branches at a BP.
"""
import time
from dataclasses import dataclass

import numpy as np

from ..analysis.assembly import assemble
from ..analysis.events import with_events
from ..analysis.fold_curve import CONTROL_OF_FOLD, continue_fold
from ..analysis.primary import landing_targets, range_limits, stop_rule
from ..analysis.branch_point import WernerSpence
from ..analysis.codim2 import continue_branch_point, plain_branch
from ..analysis.problem import equilibrium_of
from ..analysis.results import Block, Branch, Kind, SpecialPoint
from ..analysis.tracer import Tracer
from ..galerkin.equilibrium import Parameters
from ..numerics import continuation
from ..post.quantities import branch_discretisation, stored_scene


class RestartError(ValueError):
    """A label or parameter ``continue`` cannot start from; the one-line message says which and what is allowed."""


@dataclass(frozen=True)
class Labelled:
    """The special point with ``label`` of a run file: its branch (rebuilt) and the point."""

    label: int
    branch: Branch
    point: SpecialPoint


def stored_branch(run: dict, name: str) -> Branch:
    """The axisymmetric branch ``name`` of a read run file (``io.run_file.read_run``) as a Branch: scene,
    discretisation, parameters and points (no stability, no special points)."""
    data = run["branches"][name]
    attrs = data["attrs"]
    parameter = attrs.get("parameter", "P")
    X = np.asarray(data["unknowns"], dtype=float)
    params = Parameters(float(X[0, -1]) if parameter == "P" else float(data["pressure"][0]), float(attrs["M"]),
                        float(attrs["chi"]), float(attrs.get("voltage", 0.0)))
    disc = branch_discretisation(data)
    return Branch(name, stored_scene(run), disc, attrs["kernel_class"], attrs["kernel_signature"], params, X,
                  data["newton_iterations"], data["residual"], data["error_estimate"],
                  np.full(len(X), disc.degree), parameter=parameter)


def find_label(run: dict, label: int) -> Labelled:
    """The special point ``label`` of a read run file; RestartError naming the labels the file has if none is."""
    labels = []
    for name, data in run["branches"].items():
        for row, point in enumerate(data["special_points"]):
            labels.append(point["label"])
            if point["label"] != label:
                continue
            if data["attrs"].get("m", 0):
                raise RestartError(f"label {label}: a point of the surface branch {name}; continue starts from "
                                   "axisymmetric branches only")
            special = SpecialPoint(Kind(point["kind"]), int(point["index"]), np.asarray(data["special_unknowns"][row]),
                                   block=Block(point["block"]), note=point["note"])
            return Labelled(label, stored_branch(run, name), special)
    listed = f"{min(labels)}..{max(labels)}" if labels else "none"
    raise RestartError(f"label {label}: no special point has it in {run['path']} (its labels: {listed}; "
                       "balloon-cg inspect shows them)")


def restart_branch(start: Labelled, progress=None) -> Branch:
    """The branch through the labelled point, traced again from it in both directions in the branch's parameter
    (module docstring), on the stored degree and basis map."""
    t0 = time.perf_counter()
    branch, scene = start.branch, start.branch.scene
    disc = branch.disc
    held = disc.pin_translation and bool(scene.field.coils) and scene.field.M != 0
    tracer = Tracer(scene, disc.symmetric, held)
    params = branch.params
    system = tracer.system(disc.degree, params, disc.mapping)
    north = np.append(system.eq.disc.pole_rows()["lam2_north"], 0.0)
    X = start.point.X
    tangent = continuation.tangent(system, X, north)
    upper = scene.continuation.stop_stretch
    stop, limits = stop_rule(scene, upper), range_limits(scene, upper)
    residual = float(np.abs(system.residual(X)).max())
    legs = [tracer.leg(continuation.Point(X, sign * tangent, 0, residual), params, stop, progress,
                       degree=disc.degree, mapping=disc.mapping, limits=limits) for sign in (1.0, -1.0)]
    return with_events(assemble(tracer, params, "primary", legs[0], legs[1], t0,
                                land_on=landing_targets(scene, upper), labels=("up", "down")))


def pear_point(branch: Branch, start: Labelled) -> SpecialPoint:
    """The pear branch point of ``start`` on the plain symmetric ``branch`` (``codim2.plain_branch``) with its
    critical mode, which run files do not store: the null vector of the pear block H_odd at the point (its
    smallest right singular vector; ``codim2.continue_branch_point`` converges the extended system from it)."""
    X = start.branch.disc.transfer(start.point.X, branch.disc)
    pear = WernerSpence(equilibrium_of(branch), branch.params, np.zeros(0))
    phi = np.linalg.svd(pear.odd_hessian(X[:-1], branch.params.with_value("P", X[-1])))[2][-1]
    mode = np.zeros(pear.embed.shape[0])
    mode[pear.odd] = phi
    return SpecialPoint(Kind.BP, start.point.index, X, block=Block.ODD_HELD, mode=mode, note=start.point.note)


def restart(start: Labelled, parameter: str | None, direction: float = 1.0, progress=None):
    """What ``continue`` computes from ``start`` (module docstring): a Branch (in the branch's own parameter) or
    a FoldCurve (a fold in a second parameter); RestartError for what is not built."""
    own = start.branch.parameter
    if parameter in (None, own):
        return restart_branch(start, progress)
    kind = start.point.kind
    if kind in CONTROL_OF_FOLD:
        return continue_fold(start.branch, start.point, parameter, direction, progress=progress)
    if kind == Kind.BP and start.point.block == Block.ODD_HELD and start.branch.disc.symmetric:
        branch = plain_branch(start.branch, start.point.X)
        return continue_branch_point(branch, pear_point(branch, start), parameter, direction, progress=progress)
    if kind == Kind.BP:
        raise RestartError(f"--parameter {parameter}: label {start.label} is a BP of block "
                           f"{start.point.block.value or 'none'}; only pear (odd_held) points of an equator-symmetric "
                           "branch are continued in a second parameter")
    raise RestartError(f"--parameter {parameter}: label {start.label} is a {kind.value}; from it only the branch's "
                       f"own parameter {own} (a fold, LP, LV or LN, also continues in a second parameter)")
