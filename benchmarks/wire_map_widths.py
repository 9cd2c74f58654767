"""Wire-map widths against the membrane–wire gap: the cheapest degree per width, from the wire to far from it.

For points of three equator-symmetric coil scenes whose gaps span 0.05 (the paper's single coil at M = 0.003 past
its turning point, near the end of its primary branch) to ~2 (the a = 4 coil at λ = 2), and for the map
``analysis.branches.wires.centred_map`` at the membrane's closest approach to each wire with widths

    ε_j = f · gap_j                  (x units per unit gap: main's rule is f = 0.4 below gap 0.5), and
    ε_j = f · gap_j · |dx/ds|_j      (the gap measured along the membrane: s the meridian's arclength),

plus the plain basis (Legendre in x) and the rule ``wires.wire_map`` ships, each point is solved by the
pole-stretch-constrained Newton (``work_precision.PointSolver``, tol 1e-13) at the degrees of DEGREES, started
from the fine solution transferred to that basis. Per basis the table gives two degrees: the cheapest that meets
|P/P_ref − 1| ≤ LEVEL, and the cheapest whose tail estimate ``Discretisation.tail`` (what the tracer grows its
degree by) is ≤ MAX_ERROR (the default solver.max_error); '-' where DEGREES end first.

Points before the turning point are ``work_precision.prepare``'s targets (fine solve at λ*, shooting reference);
points past it (pole stretch falling again) are taken at the traced branch's own points, referenced the same way:
``shooting.shoot_symmetric`` (Taylor start, rtol 1e-12), cross-checked against shooting started at the pole and
the Galerkin solution on the tracer's own (mapped) basis; the largest cross-check difference is printed.

Run: python benchmarks/wire_map_widths.py   (writes benchmarks/results/wire_map_widths.txt; ~17 min, loaded)
"""
import sys
import time
from dataclasses import dataclass

import numpy as np

import work_precision as wp
from baselines import OUR_DEGREES

LEVEL = 1e-8
MAX_ERROR = 1e-9
DEGREES = OUR_DEGREES + (320,)
GAP_FACTORS = (0.1, 0.15, 0.2, 0.3, 0.4, 0.6, 0.8, 1.0, 1.5, 2.0, 3.0)  # ε = f · gap
ARC_FACTORS = (0.2, 0.3, 0.4, 0.6, 0.8, 1.2, 1.6, 2.4, 3.2)  # ε = f · gap · |dx/ds|


@dataclass
class StudyCase:
    label: str
    case: wp.Case
    past_turn_gaps: tuple  # past the turning point: the branch points nearest these gaps


def study_cases():
    from balloon_cg.post.paper import SINGLE_COIL, SINGLE_COIL_REACH, Case

    two, single = wp.cases()[1:]
    paper = Case(SINGLE_COIL, (("field.M", 0.003),) + SINGLE_COIL_REACH).load()
    return [
        StudyCase(two.label, wp.Case(two.label, two.scene, (1.1, 1.3, 1.5, 1.7, 1.8), "shooting"), (0.0,)),
        StudyCase(single.label, wp.Case(single.label, single.scene, (2.0, 2.5, 3.0, 3.5, 3.8), "shooting"), (0.0,)),
        StudyCase("SPOM1, paper coil a = 1.961, M = 0.003",
                  wp.Case("paper coil M = 0.003", paper, (1.3, 1.5, 1.7), "shooting"), (0.1, 0.075, 0.06, 0.0)),
    ]


def past_turn_targets(study: StudyCase, solver):
    """Targets at the full primary branch's points past its turning point nearest ``past_turn_gaps`` (0: the
    last point); X_neighbour_fine is not used here."""
    from balloon_cg.analysis.branches.primary import trace_primary
    from balloon_cg.analysis.branches.wires import wire_gap
    from balloon_cg.model.shooting import shoot_symmetric

    scene = study.case.scene
    branch = trace_primary(scene, down=False)
    disc = branch.disc
    lam = branch.pole_values()["lam2_top"]
    turn = int(np.argmax(lam))
    gaps = np.array([wire_gap(disc, X[:-1], scene.field.coils)[0] for X in branch.X])
    targets = []
    for goal in study.past_turn_gaps:
        i = turn + 1 + int(np.argmin(np.abs(gaps[turn + 1:] - goal)))
        X = branch.X[i]
        eta0 = float(disc.pole_rows()["eta_top"] @ X[:-1])
        shot = shoot_symmetric(scene, lam[i], X[-1], eta0)
        pole = shoot_symmetric(scene, lam[i], X[-1], eta0, start="pole")
        if not (shot.converged and pole.converged):
            raise RuntimeError(f"{study.label}: shooting at branch point {i} failed: {shot.message} / {pole.message}")
        checks = {f"Galerkin degree {disc.degree} (mapped)": X[-1], "shooting from the pole": pole.P}
        targets.append(wp.Target(float(lam[i]), disc.degree, X, None, shot.P, eta0,
                                 "shooting (Taylor start), past the turning point", checks))
    return branch, targets


def bases(approach_list, symmetric, coils, disc, u):
    """(label, WireMap or None) per basis of the study (module docstring)."""
    from balloon_cg.analysis.branches.wires import centred_map, wire_map

    out = [("plain", None), ("shipped", wire_map(disc, u, coils, symmetric))]
    out += [(f"{f:g}·gap", centred_map(approach_list, [f * a.gap for a in approach_list], symmetric))
            for f in GAP_FACTORS]
    out += [(f"{f:g}·gap·|dx/ds|", centred_map(approach_list, [f * a.gap * a.dx_ds for a in approach_list], symmetric))
            for f in ARC_FACTORS]
    return out


def ladder(solver, target, source_disc, mapping):
    """(cheapest degree with error ≤ LEVEL, cheapest with tail ≤ MAX_ERROR), None where DEGREES end first."""
    by_error = by_tail = None
    for d in DEGREES:
        X0 = solver.convert(target.X_fine, source_disc, d, mapping)
        result, _ = solver.solve(d, X0, target.stretch, 1e-13, mapping=mapping)
        if result.converged:
            if by_error is None and abs(result.x[-1] / target.P_ref - 1) <= LEVEL:
                by_error = d
            if by_tail is None and solver.equilibrium(d, mapping).disc.tail(result.x[:-1]) <= MAX_ERROR:
                by_tail = d
        if by_error is not None and by_tail is not None:
            break
    return by_error, by_tail


def study(sc: StudyCase):
    from balloon_cg.analysis.branches.wires import approaches

    branch, solver, targets = wp.prepare(sc.case)
    points = [(t, branch.disc) for t in targets if t is not None]
    full, late = past_turn_targets(sc, solver)
    points += [(t, full.disc) for t in late]
    coils = sc.case.scene.field.coils
    rows = []
    for t, disc in points:
        found = approaches(disc, t.X_fine[:-1], coils)
        near = min(found, key=lambda a: a.gap)
        cells = {}
        for label, mapping in bases(found, solver.symmetric, coils, disc, t.X_fine[:-1]):
            cells[label] = ladder(solver, t, disc, mapping) if (mapping is not None or label == "plain") else None
        check = max(abs(v / t.P_ref - 1) for v in t.checks.values())
        rows.append((t, near, check, cells))
        print(f"  {sc.label} λ = {t.stretch:.4f} gap {near.gap:.4f}: " +
              ", ".join(f"{k} {v}" for k, v in cells.items()), flush=True)
    return rows


def format_rows(label, rows):
    labels = list(rows[0][3])
    width = max(len(k) for k in labels) + 1
    lines = [f"== {label}", "  " + f"{'λ':>7} {'gap':>7} {'|dx/ds|':>7} {'x':>6} {'check':>7}"
             + "".join(f"{k:>{max(width, 9)}}" for k in labels)]
    for t, near, check, cells in rows:
        def cell(v):
            if v is None:
                return "n/a"
            return "/".join("-" if d is None else str(d) for d in v)
        lines.append("  " + f"{t.stretch:7.4f} {near.gap:7.4f} {near.dx_ds:7.3f} {near.x:6.3f} {check:7.1e}"
                     + "".join(f"{cell(cells[k]):>{max(width, 9)}}" for k in labels))
    return lines


def main():
    t0 = time.perf_counter()
    chosen = [int(a) for a in sys.argv[1:]] or None
    lines = [
        "Wire-map widths: per point and basis, the cheapest degree with |P/P_ref − 1| ≤ "
        f"{LEVEL:g} / the cheapest with tail estimate ≤ {MAX_ERROR:g} ('-': beyond degree {DEGREES[-1]}; n/a: no map).",
        "gap: the membrane–wire distance at the closest approach, x = cos θ there, |dx/ds| = sin θ/λ1 there;",
        "check: the largest relative difference of the cross-checks (shooting from the pole, the fine Galerkin",
        "solution) from the reference. 'shipped': analysis.branches.wires.wire_map. See the module docstring.",
        "",
    ]
    for k, sc in enumerate(study_cases()):
        if chosen is not None and k not in chosen:
            continue
        lines += format_rows(sc.label, study(sc)) + [""]
    lines.append(f"total wall time {time.perf_counter() - t0:.0f} s")
    text = "\n".join(lines) + "\n"
    print(text)
    if chosen is None:
        wp.RESULTS.mkdir(parents=True, exist_ok=True)
        (wp.RESULTS / "wire_map_widths.txt").write_text(text)


if __name__ == "__main__":
    main()
