"""How many Gauss nodes the Ritz–Galerkin system needs: node rules n_q(N) against accuracy and cost.

The integrands (Ogden powers, the coil field) are not polynomials, so Gauss exactness is no criterion; a rule
is judged by what it changes:
(a) P at the work-precision points (benchmarks/work_precision.py: cases, references, warm starts from the
    neighbour at λ* − 0.02 solved on the same rule and degree), tolerance 1e-12, in x and, with coils, on the
    tracer's wire-mapped basis; with the tail estimate (``Discretisation.tail``) the degree choice reads;
(b) the lowest eigenvalues of every stability block (``SecondVariation.assess``, perturbation degree 20 and
    the equilibrium's own degree, the one ``bifurcation.locate`` uses) at those solutions;
(c) located branch points with the rule as the default of every discretisation (equilibria, stability bases,
    extended systems): SPOM1 at M = 0 against the closed-form pear stretches (``sphere_modes``), the two-coil
    (M = 0.001) first pear pitchfork and both pear pitchforks of one coil of radius 2 (M = 0.001, the near-wire
    scene of tests/test_branch_points.py) against the rule 2N + 16;
(d) the CPU time of one constrained Newton solve, best of REPEAT, the rules interleaved in every repeat, as a
    ratio to the default rule (BLAS single-threaded, as in work_precision).

Run: python benchmarks/quadrature.py   (writes benchmarks/results/quadrature.txt)
"""
import os
import time
from contextlib import contextmanager

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # single-threaded BLAS/LAPACK (set before numpy loads)

import numpy as np  # noqa: E402

import work_precision as wp  # noqa: E402
from balloon_cg.galerkin import discretisation  # noqa: E402

DEFAULT = "3N/2 + 8"
REFERENCE = "reference"
RULES = {
    "N + 4": lambda n: n + 4,
    "N + 8": lambda n: n + 8,
    "5N/4 + 8": lambda n: (5 * n) // 4 + 8,
    DEFAULT: discretisation.gauss_nodes,
}
FINE = "2N + 16"  # a rule converged in the node count at the branch points (3N + 16 agrees to 1e-10): their reference
FINE_NODES = lambda n: 2 * n + 16  # noqa: E731
DEGREES = (8, 12, 16, 20, 24, 28, 32, 40, 48, 64, 96)
STABILITY_AT = (16, 28, 48)  # equilibrium degrees whose solutions are assessed
STABILITY_DEGREE = 20
TOL = 1e-12
REPEAT = 5


@contextmanager
def default_rule(nodes):
    """Every Discretisation with quadrature = 0 (and the stability basis) on ``nodes(N)`` inside the block."""
    from balloon_cg.analysis.stability import axisymmetric as stability

    saved = discretisation.gauss_nodes
    discretisation.gauss_nodes = stability.gauss_nodes = nodes
    discretisation._tables.cache_clear()
    try:
        yield
    finally:
        discretisation.gauss_nodes = stability.gauss_nodes = saved
        discretisation._tables.cache_clear()


def point_rows(case, branch, targets):
    """(a), (d): per (λ*, degree, basis) and rule: error, tail, iterations, best CPU time; with the solvers, the
    settings and the wire maps per λ*."""
    solvers = {name: wp.PointSolver(case.scene, branch.params, nodes) for name, nodes in RULES.items()}
    maps = wp.wire_maps(case, branch, targets) if case.scene.field.coils else {}
    settings = [(t, d, basis) for t in targets if t is not None for d in DEGREES
                for basis in ((None, "mapped") if maps.get(t.stretch) is not None else (None,))]
    starts = {}
    for t, d, basis in settings:
        mapping = maps[t.stretch] if basis else None
        for name, solver in solvers.items():
            starts[name, t.stretch, d, basis] = wp.neighbour(solver, t, d, branch.disc, mapping)
    rows = {}
    for _ in range(REPEAT):
        for t, d, basis in settings:
            mapping = maps[t.stretch] if basis else None
            for name, solver in solvers.items():
                X0 = starts[name, t.stretch, d, basis]
                if X0 is None:
                    continue
                result, seconds = solver.solve(d, X0, t.stretch, TOL, mapping=mapping)
                row = rows.setdefault((name, t.stretch, d, basis), dict(time=np.inf))
                row["time"] = min(row["time"], seconds)
                row.update(converged=result.converged, its=result.iterations, X=result.x,
                           error=abs(result.x[-1] / t.P_ref - 1) if result.converged else np.nan,
                           tail=solver.equilibrium(d, mapping).disc.tail(result.x[:-1]))
    return solvers, settings, rows, maps


def spectra(solvers, targets, rows, maps):
    """(b): {(rule, λ*, degree, N_s): {block: lowest eigenvalues}} at the plain-basis solutions, and the same
    under key (REFERENCE, λ*, degree, N_s) at the best-resolved solution (default rule, the largest degree, on
    the wire-mapped basis where there is one): the converged spectrum on the same perturbation basis."""
    from balloon_cg.analysis.stability.axisymmetric import SecondVariation

    out = {}
    top = max(DEGREES)
    for t in targets:
        if t is None:
            continue
        reference = next((basis, rows[DEFAULT, t.stretch, top, basis]) for basis in ("mapped", None)
                         if (DEFAULT, t.stretch, top, basis) in rows)
        for d in STABILITY_AT:
            for name, solver in solvers.items():
                row = rows.get((name, t.stretch, d, None))
                if row is None or not row["converged"]:
                    continue
                eq, X = solver.equilibrium(d), row["X"]
                for n_s in sorted({STABILITY_DEGREE, d}):
                    out[name, t.stretch, d, n_s] = assess(SecondVariation(eq, n_s), X, solver.params)
                    if (REFERENCE, t.stretch, d, n_s) not in out:
                        basis, ref = reference
                        ref_eq = solvers[DEFAULT].equilibrium(top, maps[t.stretch] if basis else None)
                        out[REFERENCE, t.stretch, d, n_s] = assess(SecondVariation(ref_eq, n_s), ref["X"],
                                                                   solver.params)
    return out


def assess(variation, X, params) -> dict:
    """{block: lowest eigenvalues} of one equilibrium X = (u, P)."""
    blocks = variation.assess(X[:-1], params.with_value("P", X[-1]), variation.eq.disc.symmetric).blocks
    return {name: np.asarray(values) for name, values in blocks.items()}


def spectrum_error(blocks, reference) -> float:
    """max over blocks and their lowest eigenvalues of |μ − μ_ref| / max(|μ_ref|, 1e-3) (eigenvalues O(1))."""
    return max(float(np.max(np.abs(blocks[b] - reference[b]) / np.maximum(np.abs(reference[b]), 1e-3)))
               for b in reference)


def format_points(case, targets, settings, rows):
    names = list(RULES)
    lines = [f"== {case.label}: P error |P/P_ref − 1| (tail estimate), Newton iterations (n_q) per node rule, "
             f"tol {TOL:g}; CPU time as a ratio to {DEFAULT} (t0)"]
    lines.append(f"  {'λ*':>5} {'N':>4} {'basis':>6} " + " ".join(f"{n:>30}" for n in names)
                 + " " + " ".join(f"{'t/t0 ' + n:>14}" for n in names[:-1]) + f" {'t0 ms':>7}")
    for t, d, basis in settings:
        cells, ratios = [], []
        ref = rows.get((DEFAULT, t.stretch, d, basis))
        for name in names:
            r = rows.get((name, t.stretch, d, basis))
            n_q = RULES[name](d)
            if r is None or not r["converged"]:
                cells.append(f"{'failed (' + str(n_q) + ')':>30}")
                ratios.append(np.nan)
                continue
            cells.append(f"{r['error']:9.1e} ({r['tail']:7.1e}) {r['its']:2d} its ({n_q:3d})")
            ratios.append(r["time"] / ref["time"] if ref and ref["converged"] else np.nan)
        lines.append(f"  {t.stretch:5.2f} {d:4d} {basis or 'x':>6} " + " ".join(f"{c:>30}" for c in cells) + " "
                     + " ".join(f"{q:14.2f}" for q in ratios[:-1])
                     + f" {ref['time'] * 1e3 if ref else np.nan:7.3f}")
    return lines


def summary(settings, rows) -> list:
    """Per rule: the CPU time ratio to the default at degrees 20–48 (median, range) and the largest ratio of its
    P error to the default's where the default's lies in (1e-11, 1e-6] (above the rounding floor, at degrees a
    tolerance of the order of solver.max_error would choose)."""
    lines = []
    for name in list(RULES)[:-1]:
        ratios, worse = [], []
        for t, d, basis in settings:
            r, r0 = rows.get((name, t.stretch, d, basis)), rows.get((DEFAULT, t.stretch, d, basis))
            if not (r and r0 and r["converged"] and r0["converged"]):
                continue
            if 20 <= d <= 48:
                ratios.append(r["time"] / r0["time"])
            if 1e-11 < r0["error"] <= 1e-6:
                worse.append((r["error"] / r0["error"], t.stretch, d, basis or "x"))
        top = max(worse) if worse else (np.nan, np.nan, 0, "-")
        lines.append(f"  {name:>9}: CPU time / default at N = 20–48: median {np.median(ratios):.2f} "
                     f"(range {min(ratios):.2f}–{max(ratios):.2f}); largest P error / default's error (default's "
                     f"in (1e-11, 1e-6]): {top[0]:.2f} (λ* = {top[1]}, N = {top[2]}, {top[3]})")
    return lines


def format_spectra(found):
    names = list(RULES)
    lines = [f"  stability (b): the {3} lowest eigenvalues of every block (perturbation degree N_s) at the degree-N "
             "solution of each rule, against the same at the best-resolved solution (default rule, degree "
             f"{max(DEGREES)}, wire-mapped where there is one): max relative error per rule; the reference's lowest "
             "even and odd_held eigenvalues"]
    lines.append(f"  {'λ*':>5} {'N':>4} {'N_s':>4} {'even':>12} {'odd_held':>12} "
                 + " ".join(f"{n:>10}" for n in names))
    for key in sorted(k for k in found if k[0] == REFERENCE):
        _, stretch, d, n_s = key
        ref = found[key]
        errors = [spectrum_error(found[(n, stretch, d, n_s)], ref) if (n, stretch, d, n_s) in found else np.nan
                  for n in names]
        lines.append(f"  {stretch:5.2f} {d:4d} {n_s:4d} {ref['even'][0]:12.6f} {ref['odd_held'][0]:12.6f} "
                     + " ".join(f"{e:10.1e}" for e in errors))
    return lines


def _pear_points(scene, first_only=False):
    """The located odd-held (pear) branch points of the primary branch of ``scene`` (all, or the first):
    (λ at the north pole, P, status) each."""
    from balloon_cg.analysis.points import branch_points as bifurcation
    from balloon_cg.analysis.branches.primary import trace_primary
    from balloon_cg.analysis.stability.axisymmetric import assess_branch

    primary = trace_primary(scene)
    primary.stability, _ = assess_branch(primary, scene.stability.degree, True)
    events = [e for e in bifurcation.detect(primary, primary.stability) if e[1] == "odd_held"]
    points = [bifurcation.locate(primary, *e) for e in events[:1 if first_only else None]]
    return [(primary.pole_values(bp.X)["lam2_top"][0], bp.X[-1], bp.status.value) for bp in points]


def sphere_pear_points():
    """SPOM1, M = 0: the located pear points of the primary branch."""
    return _pear_points(wp.cases()[0].scene.with_overrides({"continuation.stop_stretch": 8.0}))


def two_coil_pear_point():
    """Two coils, M = 0.001 (tests/test_pear_points.py's scene, stop_stretch 1.75): the first pear pitchfork."""
    from balloon_cg.scene import load_scene

    return _pear_points(load_scene(wp.ROOT / "scenes" / "spom1_two_coils_M0.001.toml").with_overrides(
        {"continuation.stop_stretch": 1.75, "stability.m_max": 0}), first_only=True)


def near_wire_pitchforks():
    """One coil of radius 2, M = 0.001 (tests/test_branch_points.py's near-wire scene, wire gap 0.02): both pear
    pitchforks; the second (P ≈ 1.92839) was once mislocated by an under-resolved stability basis."""
    from balloon_cg.scene import parse_scene

    return _pear_points(parse_scene('[material]\npreset = "SPOM1"\n[field]\nM = 0.001\n[[field.coils]]\n'
                                    'radius = 2.0\nheight = 0.0\ncurrent = 1.0\n[continuation]\n'
                                    'stop_stretch = 6.0\nwire_gap = 0.02\n', name="SPOM1-coil"))


def branch_points():
    """(c): per rule (as the default of every discretisation), the located points of both scenes."""
    from balloon_cg.model.sphere_modes import bifurcation_stretches
    from balloon_cg.scene.materials import get_preset

    lines = ["== (c) located branch points with the rule as the default everywhere (equilibria, stability bases, "
             "extended systems)"]
    exact = bifurcation_stretches(get_preset("SPOM1"), 1, lam_max=8.0)
    found = {}
    for name, nodes in {**RULES, FINE: FINE_NODES}.items():
        with default_rule(nodes):
            found[name] = {}
            for label, locate in (("sphere", sphere_pear_points), ("two coils", two_coil_pear_point),
                                  ("near wire", near_wire_pitchforks)):
                t0 = time.perf_counter()
                found[name][label] = (locate(), time.perf_counter() - t0)
    reference = found[FINE]
    lines.append(f"  SPOM1, M = 0, pear points: closed-form λ = {', '.join(f'{x:.12f}' for x in exact)}; two coils "
                 f"M = 0.001, first pear pitchfork, and one coil of radius 2 at M = 0.001, both pear pitchforks: "
                 f"P − P({FINE}); wall time of trace + assessment + location")
    for name, points in found.items():
        sphere, t_sphere = points["sphere"]
        lam = np.array([s[0] for s in sphere])
        err = np.abs(lam[:, None] - exact[None, :]).min(axis=0).max() if lam.size else np.nan
        cells = [f"sphere {lam.size} points, max |λ − λ_exact| = {err:.1e} ({t_sphere:.1f} s)"]
        for label in ("two coils", "near wire"):
            found_here, seconds = points[label]
            ref = reference[label][0]
            if len(found_here) != len(ref):
                cells.append(f"{label}: {len(found_here)} points against {len(ref)}")
                continue
            cells.append(f"{label}: " + ", ".join(f"P = {p[1]:.9f} ({p[1] - r[1]:+.1e}, {p[2]})"
                                                  for p, r in zip(found_here, ref)) + f" ({seconds:.1f} s)")
        lines.append(f"  {name:>9}: " + "; ".join(cells))
    return lines


def main():
    t_start = time.perf_counter()
    lines = [__doc__.split("\n\n")[0], ""]
    for case in wp.cases():
        branch, _, targets = wp.prepare(case)
        solvers, settings, rows, maps = point_rows(case, branch, targets)
        block = (format_points(case, targets, settings, rows) + summary(settings, rows)
                 + format_spectra(spectra(solvers, targets, rows, maps)))
        print("\n".join(block), flush=True)
        lines += block + [""]
    block = branch_points()
    print("\n".join(block), flush=True)
    lines += block + ["", f"total wall time {time.perf_counter() - t_start:.0f} s"]
    wp.RESULTS.mkdir(parents=True, exist_ok=True)
    (wp.RESULTS / "quadrature.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
