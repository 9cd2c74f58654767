"""The stability of a branch on the whole sphere (``surface.branches``) and its secondary branch points: every point
read held and free under pressure, volume and gas control (``surface.stability``) on the basis it was traced on; a
change of the number of negative held eigenvalues of a sector under pressure control between two points is a
secondary branch point, located by Brent's method on that eigenvalue. The symmetry sectors are read in groups,
one per core (``numerics.workers``), each along the whole branch: while it is traced (``readers``, fed by the trace) or
after it. A signal (``numerics.interrupt``) stops the assessment at the next point or root search: the branch is left
as traced, not assessed (no half-assessed surface branch is kept).
"""
from dataclasses import replace

import numpy as np

from ...numerics import continuation, eigen, interrupt, workers
from ...numerics.newton import newton
from ...surface import stability as surface_stability
from ...surface.embedding import transfer
from ...surface.equilibrium import SurfaceEquilibrium
from ..results import Kind, SpecialPoint, Status, SurfaceBranch

STABILITY_COUNT = 4  # lowest eigenvalues stored per point and reading


def assess(sb: SurfaceBranch, traced: list, readings=surface_stability.READINGS, stream=None) -> bool:
    """``assessed``; False when a signal stopped it (``sb`` then left as traced: no stability, no secondary
    points)."""
    special = list(sb.special)
    try:
        assessed(sb, traced, readings, stream)
    except interrupt.Interrupted:
        sb.stability, sb.sectors, sb.special = {}, None, special
        return False
    return True


def assessed(sb: SurfaceBranch, traced: list, readings=surface_stability.READINGS, stream=None) -> None:
    """The stability readings of every point (held and free, under pressure, volume and gas control:
    ``surface.stability.READINGS``: ``sb.stability`` the lowest over every sector, ``sb.sectors`` each sector's
    ``spectrum_count`` lowest) and the secondary branch points: where the number of negative held eigenvalues
    of a sector under pressure control changes between points i and i + 1 (i ≥ 1: point 0 is the parent point),
    the zero of the crossing eigenvalue, located by Brent's method along the chord with the corrector on its
    hyperplane (as azimuthal_points.locate); APPROXIMATE with the bracket when the search fails. ``traced``: per
    point, (the SurfaceTrace it was traced on, its coefficients there): a point is read on its own basis (resolved
    there; the final basis of a branch that refined is several times larger than its first points need).
    ``readings``: the Readings made (default all; a field that is not axisymmetric: held only). ``stream``: the
    ``workers.Stream`` of ``readers`` fed every traced point as it was traced (the readings read beside the trace:
    the same numbers); None: read here, the sector groups on every core. A fold (LP) of the branch changes the
    count of the state's own sector between its points: not a branch point."""
    held = surface_stability.Reading(True)
    sizes = _sector_sizes(traced)
    if stream is None:
        groups = _sector_groups(sizes, workers.sharing(len(sizes), sum(float(c.size) ** 3 for _, c in traced)))
        make = _reader(sb.scene, sb.params, sb.parameter, readings, {trace.basis: trace.eq for trace, _ in traced})
        items = [(trace.basis, c, value) for (trace, c), value in zip(traced, sb.values)]
        read = workers.spread(lambda keys: _read_all(make(keys), items), groups,
                              [sum(sizes[key] ** 3 for key in keys) for keys in groups])
    else:
        read = stream.results()
        if any(len(part) != len(traced) for part in read):
            raise RuntimeError(f"the readers were fed {[len(part) for part in read]} points of the {len(traced)} "
                               "traced")
    spectra = [{r: _in_order([part[i][0][r] for part in read], sizes) for r in readings} for i in range(len(traced))]
    counts = [_in_order([part[i][1] for part in read], sizes) for i in range(len(traced))]
    held_spectra = [s[held] for s in spectra]
    sb.stability = {r.name: np.array([surface_stability.lowest_over(s[r], STABILITY_COUNT) for s in spectra])
                    for r in readings}
    sb.sectors = {r.name: {key: _padded([s[r].get(key, ()) for s in spectra]) for key in spectra[0][r]}
                  for r in readings}
    folds = {s.index for s in sb.special if s.kind == Kind.LP}
    for i in range(1, len(counts) - 1):
        for key in counts[i]:
            if counts[i][key] != counts[i + 1][key] and not (i in folds and key == sb.basis.characters):
                interrupt.check()
                sb.special.append(_secondary(sb, traced, i, key, min(counts[i][key], counts[i + 1][key]),
                                             (held_spectra[i][key], held_spectra[i + 1][key])))
    sb.special.sort(key=lambda s: s.index)


def spectrum_count(scene) -> int:
    """The lowest eigenvalues read per sector: STABILITY_COUNT, or [dynamics] count where the scene asks for natural
    frequencies and more (they are these eigenvalues over 2: dynamics.surface)."""
    return max(STABILITY_COUNT, scene.dynamics.count if scene.dynamics.frequencies else 0)


def _padded(rows: list) -> np.ndarray:
    """(points × the longest row) of per-point eigenvalue rows, NaN where a row is shorter (a sector with fewer
    modes)."""
    out = np.full((len(rows), max(len(r) for r in rows)), np.nan)
    for n, row in enumerate(rows):
        out[n, :len(row)] = row
    return out


def _sector_sizes(traced: list) -> dict:
    """{characters: the sector's size on the last point's basis (the largest: a branch refines as it goes)} over the
    sectors of every basis the branch was traced on."""
    sizes = {}
    for trace, _ in traced:
        for sector in trace.basis.sectors():
            if sector.size:
                sizes[sector.characters] = float(sector.size)
    return sizes


def _sector_groups(sizes: dict, parts: int) -> list:
    """The sectors in ``parts`` groups of about equal cost (size³: a factorisation per point), largest first into
    the group with the least so far; one group of all, in their order, when ``parts`` is 1."""
    if parts < 2:
        return [tuple(sizes)]
    groups, loads = [[] for _ in range(parts)], [0.0] * parts
    for key in sorted(sizes, key=lambda k: -sizes[k]):
        lightest = loads.index(min(loads))
        groups[lightest].append(key)
        loads[lightest] += sizes[key] ** 3
    return [tuple(g) for g in groups if g]


def _in_order(parts: list, order) -> dict:
    """The groups' {characters: value} dicts as one, in the sectors' ``order`` (a serial reading's)."""
    merged = {k: v for part in parts for k, v in part.items()}
    return {k: merged[k] for k in order if k in merged}


def readers(trace, params, parameter: str, readings=surface_stability.READINGS) -> workers.Stream:
    """The sectors of ``trace``'s basis read beside the trace, in groups of about equal cost, one forked worker
    each (``workers.Stream``; where forking does not pay, read at the end, here): ``follow(..., final=fed(stream))``
    hands them each traced point in order once it is kept, and ``assess(..., stream=)`` takes their readings. Each group
    reads as ``assessed`` reads it, so the numbers are the same; a basis the trace refines to is built again in
    the workers (the first one they inherit). The cost that decides the forking: the first point's Σ size³ over
    two points (a branch has at least two)."""
    sizes = {sector.characters: float(sector.size) for sector in trace.basis.sectors() if sector.size}
    cost = 2.0 * sum(size ** 3 for size in sizes.values())
    groups = _sector_groups(sizes, workers.sharing(len(sizes), cost))
    return workers.Stream(_reader(trace.scene, params, parameter, readings, {trace.basis: trace.eq}), groups, cost)


def fed(stream: workers.Stream):
    """final(trace, point) for ``surface.branches.follow``: the point handed to the ``readers`` as (its basis without
    the cached tables: a few hundred bytes to send, equal to it; its coefficients; its parameter's value)."""
    return lambda trace, p: stream.feed((replace(trace.basis), trace.system.coefficients(p.X), float(p.X[-1])))


def _reader(scene, params, parameter: str, readings, equilibria: dict):
    """make(keys) -> read((basis, c, value)) -> (spectra, negative held counts) of the sectors ``keys`` at one
    point, the points given in the branch's order, each sector following its own spectra at the previous point
    (``surface.stability.sector_spectra``; at the first point it solves dense). ``equilibria``: {basis:
    SurfaceEquilibrium} known (others are built once). The groups of sectors go to every core
    (``numerics.workers``): a sector's numbers are those of a serial reading of all of them."""
    held = surface_stability.Reading(True)

    def make(keys: tuple):
        spectra = None

        def read(item):
            nonlocal spectra
            interrupt.check()
            basis, c, value = item
            if basis not in equilibria:
                equilibria[basis] = SurfaceEquilibrium(scene, basis)
            eq, at = equilibria[basis], params.with_value(parameter, value)
            spectra = surface_stability.sector_spectra(eq, c, at, spectrum_count(scene), readings, guesses=spectra,
                                                       only=keys)
            return spectra, _negative_counts(eq, c, at, spectra[held])
        return read
    return make


def _read_all(read, items: list) -> list:
    """``read`` (one group's reader: it follows its spectra from point to point) over the items in order."""
    return [read(item) for item in items]


def _negative_counts(eq, c, params, lowest: dict) -> dict:
    """{characters: the number of negative held eigenvalues of the sector}: from its lowest STABILITY_COUNT, or,
    when they are all negative, from the inertia of its matrix (numerics.eigen.negative_count)."""
    counts = {}
    for key, values in lowest.items():
        counts[key] = int((values < 0).sum())
        if counts[key] == values.size:
            interrupt.check()
            held = surface_stability.Reading(True)
            A = surface_stability.restricted_sectors(eq, c, params, (held,), (key,))[held][key]
            counts[key] = eigen.negative_count(A)
    return counts


def _secondary(sb: SurfaceBranch, traced: list, i: int, sector: tuple, k: int, ends: tuple) -> SpecialPoint:
    """The secondary branch point between points i and i + 1 where eigenvalue k of ``sector`` crosses zero, searched
    on the basis of point i + 1 (``ends``: the sector's lowest held eigenvalues at points i and i + 1; the spectra
    follow the lowest at i, and where eigenvalue k is among them the search starts from their values at the ends
    it read on that basis instead of solving there again)."""
    (before, c0), (trace, c1) = traced[i], traced[i + 1]
    if before is not trace:
        c0 = transfer(before.basis, c0, trace.basis)
    system, solver = trace.system, trace.scene.solver
    X0, X1 = system.point(c0, sb.values[i]), system.point(c1, sb.values[i + 1])
    chord = X1 - X0
    d = chord / np.linalg.norm(chord)
    held = surface_stability.Reading(True)

    def on_final(c, value):
        return np.append(c if trace.basis == sb.basis else transfer(trace.basis, c, sb.basis), value)

    last = {}  # the factors of the last evaluation's Newton matrix: the next one starts from them (same rows d)

    def value_at(s):
        interrupt.check()  # each evaluation is a Newton solve and a sector's eigenvalues (~0.5 s on two coils)
        result = newton(system.residual, system.jacobian, X0 + s * d, d, d @ X0 + s, solver.tol, solver.max_newton,
                        last.get("factors"))
        if not result.converged:
            raise ArithmeticError(result.message)
        last["factors"] = result.factors
        c, params = system.coefficients(result.x), system.params_at(result.x)
        A = surface_stability.restricted_sectors(trace.eq, c, params, (held,), (sector,))[held][sector]
        return float(eigen.lowest_following(A, k + 1, float(ends[0][0]))[k]), on_final(c, result.x[-1])

    length = float(np.linalg.norm(chord))
    known = {}
    if k < len(ends[1]):
        known[length] = float(ends[1][k]), on_final(c1, sb.values[i + 1])
    if k < len(ends[0]) and before is trace:
        known[0.0] = float(ends[0][k]), on_final(c0, sb.values[i])
    found = continuation.locate_root(value_at, length, known=known)
    note = f"secondary branch point: held eigenvalue {k} of the symmetry sector {sector} crosses zero"
    if found is not None and found.status == continuation.RootStatus.LOCATED:
        return SpecialPoint(Kind.BP, i, found.payload, m=sb.m, note=note, sector=sector)
    X = np.append(sb.coefficients[i], sb.values[i]) if found is None else found.payload
    return SpecialPoint(Kind.BP, i, X, m=sb.m, status=Status.APPROXIMATE,
                        uncertainty=0.5 * float(abs(sb.values[i + 1] - sb.values[i])),
                        reason="the root search along the chord failed; the nearest evaluated point is stored",
                        note=note, sector=sector)
