"""A tube continued in the voltage Φ̄ at a fixed pressure (``continuation.parameter = "voltage"``, P =
``continuation.pressure``; docs/tubes.md): the sphere's voltage continuation on a tube's mirror-symmetric states.

Start (``charged_start``): the tube at P and Φ̄ = 0, from tube/primary's start at P = 0 (the unstressed tube; held
ends stretched to their distance) by natural continuation in P (``continuation.natural``, Newton on the even rows
with P prescribed); ContinuationError where it does not get there (P beyond the pressure maximum of the tube's
lower path). ``continue --parameter voltage`` from a label starts at that stored point instead (its P and Φ̄).

Trace: pseudo-arclength continuation in X = (u[even block], Φ̄) (tube/primary.TubeSystem on the ParameterSystem in
"voltage": ∂R/∂Φ̄ from the generated voltage gradient), Φ̄ rising first (``direction`` −1: falling); its folds in
Φ̄ (LP, the pull-in: the largest voltage the tube holds at P) located by the tracer's fold monitor on Φ̄. It stops
where Φ̄ passes ``continuation.stop_voltage`` (STOP_VOLTAGE), falls below 0 (ZERO_VOLTAGE: a voltage-free state at
P again; not landed on Φ̄ = 0), the largest hoop stretch passes ``stop_stretch`` (HOOP_STRETCH), after
``max_points``, or at the next point after SIGINT/SIGTERM. At every point, with its Φ̄: the number of unstable
directions under each control (tube/stability.unstable_counts: at fixed Φ̄ and P, ∂R/∂u, on δV = 0 and with the
gas term), the mirror blocks' spectra (their lowest eigenvalues stored) and the smallest principal stress (the
dielectric stress at its Φ̄). Where a block's count of negative eigenvalues changes between points, the eigenvalue
that crossed is followed to its zero by Brent in the arclength (``_branch_point``), a branch point (BP) where its
null vector is orthogonal to ∂R/∂Φ̄ (the odd block's always: the onset of bulging in Φ̄), the fold otherwise (not
kept: the LP is the monitor's); near an even branch point the Keller corrector may fail, and the point is then the
nearest evaluated (status NEAREST). Not read on it (scene/tables.py refuses what would ask for them): user events,
the m ≥ 1 blocks, frequencies, coils.
"""
from dataclasses import replace

import numpy as np

from .events import along
from .zeros import corrected_zero, is_fold
from .primary import (TubeSystem, _start, discretisation, held, scene_parameters,
                      volume_ratio)
from .results import IntervalBranch, IntervalSpecial, IntervalStop, signalled
from .stability import smallest_stress, spectrum, unstable_counts
from ..analysis.branches.problem import ParameterSystem, continuation_settings
from ..analysis.branches.tracer import ContinuationError
from ..analysis.stability.crossings import count_changes
from ..analysis.results import Kind, StopCode
from ..galerkin.equilibrium import Equilibrium
from ..galerkin.interval import Mirror
from ..numerics import continuation
from ..numerics.continuation import Stop
from ..numerics.newton import newton
from ..numerics.threads import limited_blas


def charged_start(scene, disc, pressure: float) -> np.ndarray:
    """Y = (u, P) of the tube at ``pressure`` and Φ̄ = 0 (module docstring)."""
    eq = Equilibrium(scene, disc)
    params = scene_parameters(scene).with_value("voltage", 0.0)
    system = TubeSystem(ParameterSystem(eq, params, "P"), disc.block(Mirror.EVEN), held(disc))
    X = _start(system.system, disc, scene.solver)

    def solve(X, P):
        return newton(system.residual, system.jacobian, X, np.eye(X.size)[-1], P, scene.solver.tol,
                      scene.solver.max_newton)

    X, reached, message = continuation.natural(solve, X, 0.0, pressure)
    if reached < pressure:
        raise ContinuationError(f"could not inflate the tube to continuation.pressure = {pressure:g} at zero voltage "
                                f"beyond P = {reached:.6g} ({message}): past its pressure maximum")
    return system.full(X)


@limited_blas
def voltage_branch(scene, start: tuple | None = None, direction: float = 1.0) -> IntervalBranch:
    """The tube continued in Φ̄ at fixed P (module docstring): from ``start`` = (u, P, Φ̄) of a stored point (None:
    ``charged_start`` at continuation.pressure), Φ̄ rising (``direction`` 1) or falling (−1) first."""
    disc = discretisation(scene)
    eq = Equilibrium(scene, disc)
    if start is None:
        Y = charged_start(scene, disc, scene.continuation.pressure)
        u, pressure, charge = Y[:-1], float(Y[-1]), 0.0
    else:
        u, pressure, charge = start
    params = scene_parameters(scene, pressure).with_value("voltage", charge)
    system = TubeSystem(ParameterSystem(eq, params, "voltage"), disc.block(Mirror.EVEN), held(disc))
    settings = continuation_settings(scene)
    X = np.append(u, charge)[system.columns]
    t = continuation.tangent(system, X, direction * np.eye(X.size)[-1])
    first = continuation.Point(X, t, 0, float(np.abs(system.residual(X)).max()))
    limit, top = scene.continuation.stop_stretch, scene.continuation.stop_voltage

    def stop(point):
        if (interrupted := signalled()) is not None:
            return interrupted
        voltage = float(point.X[-1])
        if voltage < 0:
            return Stop(StopCode.ZERO_VOLTAGE, f"the voltage fell below 0 ({voltage:.3g}): a voltage-free state at "
                                               f"P = {pressure:g}")
        if top is not None and voltage > top:
            return Stop(StopCode.STOP_VOLTAGE, f"the voltage {voltage:.6g} passed stop_voltage {top:g}")
        hoop = disc.node_state(system.full(point.X)[:-1])[0].max()
        if hoop > limit:
            return Stop(IntervalStop.HOOP_STRETCH, f"the largest hoop stretch {hoop:.6g} passed stop_stretch {limit:g}")
        return None

    path = continuation.trace(system, first, settings, stop, {Kind.LP: np.eye(X.size)[-1]})
    states = np.array([system.full(p.X)[:-1] for p in path.points])
    voltage = np.array([float(p.X[-1]) for p in path.points])
    at = [params.with_value("voltage", v) for v in voltage]
    full = [np.append(s, pressure) for s in states]
    counts = [unstable_counts(eq, [Y], p) for Y, p in zip(full, at)]
    unstable = {control: np.array([c[control][0] for c in counts]) for control in counts[0]}
    spectra = {block: np.array([spectrum(eq, Y, disc.block(block), p) for Y, p in zip(full, at)]) for block in Mirror}
    found = [(Kind(f.label), system.full(f.point.X), f.index, f.status, None) for f in path.folds]
    for block in Mirror:
        for i, order in count_changes((spectra[block] < 0).sum(axis=1)):
            zero = _branch_point(system, eq, path.points[i], path.points[i + 1], block, order, settings, params)
            if zero is not None:
                found.append((Kind.BP, zero[0], i, zero[1], block))
    special = [IntervalSpecial(kind, Y[:-1], pressure, i, status, block,
                               smallest_stress(eq, Y[:-1], float(Y[-1])), voltage=float(Y[-1]))
               for kind, Y, i, status, block in found]
    branch = IntervalBranch(disc, states, np.full(len(states), pressure),
                            np.array([volume_ratio(eq, Y) for Y in full]),
                            {block: values[:, 0] for block, values in spectra.items()}, unstable, (), path.stop,
                            np.array([smallest_stress(eq, s, v) for s, v in zip(states, voltage)]), params,
                            voltage=voltage)
    return replace(branch, special=tuple(sorted(special, key=lambda s: along(branch, s))))


def _branch_point(system, eq, before, after, block: Mirror, order: int, settings, params) -> tuple | None:
    """(Y = (u, Φ̄), status) where the eigenvalue number ``order`` of ``block`` vanishes between two points of the
    voltage trace ``system``, by Brent in the arclength from ``before`` (each value a Keller corrector; one that
    fails ends the search NEAREST); None where it is the fold in Φ̄ (the null vector not orthogonal to ∂R/∂Φ̄, as
    tube/primary's branch points in P)."""
    index, pressure = eq.disc.block(block), params.P
    root = corrected_zero(system, settings, before.X, before.tangent, float(before.tangent @ (after.X - before.X)),
                          lambda Y: spectrum(eq, np.append(Y[:-1], pressure), index,
                                             params.with_value("voltage", Y[-1]))[order])
    if root is None:
        return None
    Y = root.payload
    at = params.with_value("voltage", Y[-1])
    if is_fold(eq, Y[:-1], at, eq.parameter_derivative(Y[:-1], at, "voltage"), index, order):
        return None
    return Y, root.status
