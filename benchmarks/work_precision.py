"""Work–precision: error of P at fixed north pole stretches against the wall time of one point solve.

For each scene and each target pole stretch λ*, and for a range of Legendre degrees (fixed: no adaptivity) and
Newton tolerances, one point is solved by the pole-stretch-constrained Newton (R(u; P) = 0, λ2(0) = λ*, the
same bordered Newton ``branch._land`` uses), warm-started from the converged neighbour at λ* − H on the same
discretisation: what one continuation step costs, without the step control. Only that Newton call is timed
(best of REPEAT, repeats interleaved over all settings so that load from other processes hits them alike);
building the discretisation (once per degree on a branch) is not. Two clocks: process CPU time (the plotted
and compared one) and wall time. BLAS/LAPACK run single-threaded (OPENBLAS_NUM_THREADS=1, set here) for every
method: on a shared 2-core machine with a load average of ~7, a solve of a few ms is preempted in most
repeats, so wall times of ms-scale solves mostly measure the scheduler; the CPU time of a single-threaded
process does not.

References: SPOM1 M = 0: the exact sphere pressure. Two coils and the single equatorial coil (both
equator-symmetric): ``shooting.shoot_symmetric`` at rtol = atol = 1e-13 (DOP853 on the first-order system, an
independent discretisation), cross-checked against shooting started at the pole and against the Galerkin
solution at the finest degree the adaptive trace used.

Run: python benchmarks/work_precision.py   (writes benchmarks/results/work_precision.{txt,png})
"""
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # single-threaded BLAS/LAPACK for every method (set before numpy loads)

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"

SPOM1_M0 = """
[material]
preset = "SPOM1"
[continuation]
stop_stretch = 5.0
"""
DEGREES = (8, 12, 16, 24, 32, 48, 64, 96, 128, 192)
TOLS = (1e-6, 1e-9, 1e-12)
H = 0.02  # pole stretch distance of the warm-start neighbour
MAPPED = "mapped"  # the 'tol' key of rows on the wire-mapped basis (coil scenes; tolerance TOLS[-1])
REPEAT = 5


@dataclass
class Case:
    label: str
    scene: object
    stretches: tuple
    reference: str  # "sphere" or "shooting"


def cases():
    from balloon_cg.scene import load_scene, parse_scene

    return [
        Case("SPOM1, M = 0", parse_scene(SPOM1_M0, name="spom1"), (1.3, 1.5, 2.0, 3.0), "sphere"),
        Case("SPOM1, two coils, M = 0.002", load_scene(ROOT / "scenes" / "spom1_two_coils_M0.002.toml"),
             (1.3, 1.5, 1.7, 1.8), "shooting"),
        Case("SPOM1, single coil, M = 0.002", load_scene(ROOT / "scenes" / "spom1_single_coil.toml"),
             (1.3, 1.5, 2.0, 3.0), "shooting"),
    ]


class PointSolver:
    """The pole-stretch-constrained Newton of one scene on fixed-degree discretisations (as PrimaryTracer);
    ``nodes(degree)``: the Gauss nodes of its quadrature (None: the default rule)."""

    def __init__(self, scene, params, nodes=None):
        self.scene, self.params, self.nodes = scene, params, nodes
        self.symmetric = scene.continuation.symmetry != "none" and scene.field.is_equator_symmetric
        held = bool(scene.field.coils) and not scene.field.is_equator_symmetric
        self.pin = (not scene.field.coils) or held
        self._eq, self._system = {}, {}

    def equilibrium(self, degree, mapping=None):
        from balloon_cg.galerkin.discretisation import Discretisation
        from balloon_cg.galerkin.equilibrium import Equilibrium

        if (degree, mapping) not in self._eq:
            disc = Discretisation(degree, self.symmetric, self.pin, self.nodes(degree) if self.nodes else 0, mapping)
            self._eq[degree, mapping] = Equilibrium(self.scene, disc)
        return self._eq[degree, mapping]

    def system(self, degree, mapping=None):
        """(R, its Jacobian, the pole row) of the constrained system at ``degree`` and ``mapping``, built once (as
        a tracer holds them along a branch: building them is no part of a solve's time)."""
        from balloon_cg.analysis.branches.problem import ParameterSystem

        if (degree, mapping) not in self._system:
            eq = self.equilibrium(degree, mapping)
            system = ParameterSystem(eq, self.params, "P")
            self._system[degree, mapping] = (system.residual, system.jacobian,
                                             np.append(eq.disc.pole_rows()["lam2_top"], 0.0))
        return self._system[degree, mapping]

    def convert(self, X, source, degree, mapping=None):
        """X (u, P) from discretisation ``source`` to ``degree`` and ``mapping`` (Discretisation.transfer)."""
        return source.transfer(X, self.equilibrium(degree, mapping).disc)

    def solve(self, degree, X0, stretch, tol, max_newton=None, mapping=None):
        """Constrained Newton at ``degree`` from X0 (already on that degree): (NewtonResult, CPU seconds);
        the wall time of the same call is left in ``self.last_wall``."""
        from balloon_cg.numerics.newton import newton

        residual, jacobian, row = self.system(degree, mapping)
        t0, c0 = time.perf_counter(), time.process_time()
        result = newton(residual, jacobian, X0, row, stretch, tol, max_newton or self.scene.solver.max_newton)
        self.last_wall = time.perf_counter() - t0
        return result, time.process_time() - c0


@dataclass
class Target:
    """One target pole stretch: fine solutions there and at λ* − H, the reference P and how it was obtained."""

    stretch: float
    fine_degree: int
    X_fine: np.ndarray
    X_neighbour_fine: np.ndarray
    P_ref: float
    eta0: float
    note: str = ""
    checks: dict = field(default_factory=dict)


def prepare(case: Case):
    """Trace the primary branch (adaptive degree) to the largest target; fine solutions at every λ* and λ* − H."""
    from balloon_cg.analysis.branches.primary import trace_primary
    from balloon_cg.model.shooting import shoot_symmetric
    from balloon_cg.model.sphere import sphere_pressure

    top = max(case.stretches)
    branch = trace_primary(case.scene, stop_stretch=top, down=False)
    solver = PointSolver(case.scene, branch.params)
    disc = branch.disc
    lam = branch.pole_values()["lam2_top"]
    eta_row = disc.pole_rows()["eta_top"]
    targets = []
    for s in case.stretches:
        if s > lam.max() + 1e-12:
            targets.append(None)
            continue
        out = []
        for goal in (s - H, s):
            i = max(int(np.searchsorted(lam, goal)) - 1, 0)  # last branch point below the goal (first crossing)
            X = solver.convert(branch.X[i], disc, disc.degree, disc.mapping)
            result, _ = solver.solve(disc.degree, X, goal, 1e-13, mapping=disc.mapping)
            if not result.converged:
                raise RuntimeError(f"{case.label}: fine solve at λ = {goal} failed: {result.message}")
            out.append(result.x)
        X_nb, X_fine = out
        P_gal, eta0 = X_fine[-1], float(eta_row @ X_fine[:-1])
        checks = {f"Galerkin degree {disc.degree}": P_gal}
        if case.reference == "sphere":
            P_ref, note = sphere_pressure(case.scene.material, s), "exact sphere"
        else:
            shot = shoot_symmetric(case.scene, s, P_gal, eta0)
            pole = shoot_symmetric(case.scene, s, P_gal, eta0, start="pole")
            if not (shot.converged and pole.converged):
                raise RuntimeError(f"{case.label}: shooting at λ = {s} failed: {shot.message} / {pole.message}")
            P_ref, note = shot.P, "shooting (Taylor start, rtol 1e-13)"
            checks["shooting from the pole"] = pole.P
        targets.append(Target(s, disc.degree, X_fine, X_nb, P_ref, eta0, note, checks))
    return branch, solver, targets


def neighbour(solver, target: Target, degree: int, source_disc, mapping=None):
    """The converged point at λ* − H on ``degree`` and ``mapping`` (untimed), or None."""
    X = solver.convert(target.X_neighbour_fine, source_disc, degree, mapping)
    result, _ = solver.solve(degree, X, target.stretch - H, 1e-13, mapping=mapping)
    return result.x if result.converged else None


def wire_maps(case, branch, targets):
    """Per target stretch: the tracer's wire-mapped basis centred from the neighbour's profile (coil scenes)."""
    from balloon_cg.analysis.branches.wires import wire_map

    return {t.stretch: wire_map(branch.disc, t.X_neighbour_fine[:-1], case.scene.field.coils, branch.disc.symmetric)
            for t in targets if t is not None}


def sweep(case, branch, solver, targets, degrees=DEGREES, tols=TOLS, repeat=REPEAT):
    """rows: dict per (stretch, degree, tol) with error, best time, iterations, residual, tail; with coils also
    (stretch, degree, MAPPED) on the wire-mapped basis at the tightest tolerance."""
    maps = wire_maps(case, branch, targets)
    settings = [(tol, None) for tol in tols]
    if any(m is not None for m in maps.values()):
        settings.append((MAPPED, "mapped"))
    starts = {}
    for t in targets:
        if t is None:
            continue
        for d in degrees:
            starts[(t.stretch, d, None)] = neighbour(solver, t, d, branch.disc)
            if len(settings) > len(tols) and maps[t.stretch] is not None:
                starts[(t.stretch, d, "mapped")] = neighbour(solver, t, d, branch.disc, maps[t.stretch])
    rows = {}
    for _ in range(repeat):
        for t in targets:
            if t is None:
                continue
            for d in degrees:
                for tol, basis in settings:
                    key = (t.stretch, d, tol)
                    X0 = starts.get((t.stretch, d, basis))
                    if X0 is None:
                        rows[key] = dict(converged=False, message="no neighbour at λ* − H", time=np.nan)
                        continue
                    mapping = maps[t.stretch] if basis else None
                    result, seconds = solver.solve(d, X0, t.stretch, tols[-1] if basis else tol, mapping=mapping)
                    row = rows.setdefault(key, dict(time=np.inf, wall=np.inf))
                    row["time"] = min(row["time"], seconds)
                    row["wall"] = min(row["wall"], solver.last_wall)
                    row.update(converged=result.converged, message=result.message, iterations=result.iterations,
                               residual=result.residual, P=result.x[-1],
                               error=abs(result.x[-1] / t.P_ref - 1) if result.converged else np.nan,
                               tail=solver.equilibrium(d, mapping).disc.tail(result.x[:-1]))
    return rows


def bifurcation_hook(case: Case):
    """(b) the bifurcation pressure: uses balloon_cg.analysis.stability.axisymmetric / balloon_cg.analysis.points.branch_points when they exist.

    Returns a line for the report. The error of the bifurcation pressure against degree is the natural
    extension of this table once the detection is in place (a located branch point per degree).
    """
    try:
        from balloon_cg.analysis.points import branch_points as bifurcation
        from balloon_cg.analysis.stability import axisymmetric as stability
    except ImportError as error:
        return f"(b) bifurcation pressure: not available ({error})"
    return bifurcation_rows(case, stability, bifurcation)


def bifurcation_rows(case, stability, bifurcation):
    """First detected branch point of the primary branch traced at fixed Legendre degrees (adaptivity off):
    its pressure per degree, against the finest, and the wall time of trace + detection + location.

    ``bifurcation.locate`` takes the eigenvalue with the branch's own discretisation, so the primary branch
    degree is the resolution parameter here; the stability basis degree N = 20 only serves detection.
    """
    from balloon_cg.analysis.branches.primary import trace_primary

    try:
        found_P = {}
        lines = []
        for degree in (16, 24, 40, 64):
            scene = case.scene.with_overrides({"solver.degree": degree, "solver.max_degree": degree,
                                               "solver.max_error": 1e-2})
            t0 = time.perf_counter()
            branch = trace_primary(scene, stop_stretch=min(max(case.stretches), 3.0), down=False)
            assessments, _ = stability.assess_branch(branch, 20)
            events = bifurcation.detect(branch, assessments)
            if not events:
                lines.append(f"degree {degree}: none detected")
                continue
            bp = bifurcation.locate(branch, *events[0])
            found_P[degree] = bp.X[-1]
            lines.append(f"degree {degree}: P_b = {bp.X[-1]:.12f} ({events[0][1]}, {time.perf_counter() - t0:.1f} s)")
        if len(found_P) > 1:
            best = found_P[max(found_P)]
            lines.append("relative to degree {}: {}".format(max(found_P), ", ".join(
                f"{d}: {abs(P / best - 1):.1e}" for d, P in found_P.items() if d != max(found_P))))
        return "(b) bifurcation pressure (balloon_cg.analysis.points.branch_points, first branch point, N = 20): " + "; ".join(lines)
    except Exception as error:  # the API is someone else's work in progress: report, don't fail
        return f"(b) bifurcation pressure: hook failed ({type(error).__name__}: {error})"


def format_case(case, branch, targets, rows, degrees=DEGREES, tols=TOLS):
    lines = [f"== {case.label}: reference {targets[0].note if targets[0] else '-'}; branch traced to "
             f"λ = {branch.pole_values()['lam2_top'].max():.4g} (adaptive degree up to {branch.disc.degree})"]
    for t in targets:
        if t is None:
            continue
        checks = ", ".join(f"{k}: {v / t.P_ref - 1:+.1e}" for k, v in t.checks.items())
        lines.append(f"  λ* = {t.stretch}: P_ref = {t.P_ref:.15g}   cross-checks (relative): {checks}")
    tols = tuple(tols) + ((MAPPED,) if any(key[2] == MAPPED for key in rows) else ())
    header = f"  {'λ*':>5} {'degree':>6} " + " ".join(f"{setting_label(tol):>31}" for tol in tols)
    lines += [header, f"  {'':>5} {'':>6} " + " ".join(f"{'rel. error  cpu ms wall ms its':>31}" for _ in tols)]
    for t in targets:
        if t is None:
            continue
        for d in degrees:
            cells = []
            for tol in tols:
                r = rows[(t.stretch, d, tol)]
                if not r.get("converged"):
                    cells.append(f"{'failed: ' + r['message'][:22]:>31}")
                else:
                    cells.append(f"{r['error']:10.1e} {r['time'] * 1e3:7.2f} {r['wall'] * 1e3:7.2f} "
                                 f"{r['iterations']:3d}")
            lines.append(f"  {t.stretch:5.2f} {d:6d} " + " ".join(f"{c:>31}" for c in cells))
    return lines


def setting_label(tol) -> str:
    return f"wire-mapped basis, tol {TOLS[-1]:.0e}" if tol == MAPPED else f"tol {tol:.0e}"


def cheapest(rows, stretch, level, degrees=DEGREES, tols=TOLS):
    """The fastest (degree, tol, time, error) with error ≤ level at ``stretch``, or None."""
    good = [(r["time"], d, setting_label(tol), r["error"]) for (s, d, tol), r in rows.items()
            if s == stretch and r.get("converged") and r["error"] <= level]
    if not good:
        return None
    t, d, tol, e = min(good)
    return d, tol, t, e


def plot(results, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(results), figsize=(5.2 * len(results), 4.4), sharey=True)
    markers = {TOLS[0]: "s", TOLS[1]: "^", TOLS[2]: "o"}
    for ax, (case, branch, targets, rows) in zip(np.atleast_1d(axes), results):
        for k, t in enumerate(x for x in targets if x is not None):
            color = f"C{k}"
            for tol in TOLS:
                pts = [(rows[(t.stretch, d, tol)]["time"] * 1e3, max(rows[(t.stretch, d, tol)]["error"], 1e-16))
                       for d in DEGREES if rows[(t.stretch, d, tol)].get("converged")]
                if not pts:
                    continue
                x, y = zip(*pts)
                ax.loglog(x, y, marker=markers[tol], color=color, ls="-" if tol == TOLS[-1] else "none",
                          mfc="none" if tol != TOLS[-1] else color, ms=5, lw=1,
                          label=f"λ* = {t.stretch}" if tol == TOLS[-1] else None)
            mapped = [(rows[key]["time"] * 1e3, max(rows[key]["error"], 1e-16)) for key in
                      ((t.stretch, d, MAPPED) for d in DEGREES) if key in rows and rows[key].get("converged")]
            if mapped:
                x, y = zip(*mapped)
                ax.loglog(x, y, marker="D", color=color, ls="--", ms=4, lw=1, mfc="none",
                          label=f"λ* = {t.stretch}, wire-mapped basis")
        ax.axhline(1e-8, color="0.6", lw=0.8, ls="--")
        ax.set_title(case.label, fontsize=10)
        ax.set_xlabel("CPU time per point solve [ms] (single-threaded)")
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    np.atleast_1d(axes)[0].set_ylabel("|P / P_ref − 1|  (floored at 1e-16)")
    fig.suptitle("Work–precision: constrained Newton from the neighbour at λ* − 0.02, degrees "
                 f"{DEGREES[0]}–{DEGREES[-1]}; ● tol 1e-12 (lines, by degree), ▲ 1e-9, ■ 1e-6; "
                 "◇ dashed: wire-mapped basis",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=130)


def main():
    results, lines = [], []
    t_start = time.perf_counter()
    for case in cases():
        t0 = time.perf_counter()
        branch, solver, targets = prepare(case)
        rows = sweep(case, branch, solver, targets)
        results.append((case, branch, targets, rows))
        block = format_case(case, branch, targets, rows)
        block.append("  cheapest setting per λ* with error ≤ 1e-8 / ≤ 1e-11:")
        for t in targets:
            if t is None:
                continue
            parts = []
            for level in (1e-8, 1e-11):
                best = cheapest(rows, t.stretch, level)
                parts.append("none" if best is None else
                             f"degree {best[0]}, {best[1]}: {best[2] * 1e3:.2f} ms CPU (error {best[3]:.1e})")
            lines_ = f"    λ* = {t.stretch}: {parts[0]}  |  {parts[1]}"
            block.append(lines_)
        missing = [s for s, t in zip(case.stretches, targets) if t is None]
        if missing:
            block.append(f"  not reached by the branch: λ* = {missing} ({branch.stop_reason})")
        block.append("  " + bifurcation_hook(case))
        block.append(f"  (case wall time {time.perf_counter() - t0:.0f} s)")
        print("\n".join(block), flush=True)
        lines += block + [""]
    head = [
        "Work–precision of the primary branch solver: P at fixed north pole stretch λ*",
        "time = one pole-stretch-constrained Newton solve from the converged neighbour at λ* − 0.02 on the same",
        f"fixed-degree discretisation (best of {REPEAT}, interleaved): process CPU time and wall time, BLAS single-",
        "threaded (shared 2-core machine under load: the CPU time is the reliable one, see the module docstring);",
        "error = |P/P_ref − 1|; its = Newton iterations.",
        "Symmetric (equator) subspace in all three scenes: about degree + 1 unknowns. With coils, a last column:",
        "the same solve on the wire-mapped basis the tracer uses near a wire (balloon_cg.analysis.branches.wires.wire_map, centred",
        "from the neighbour's profile), tol 1e-12.",
        "",
    ]
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "work_precision.txt").write_text("\n".join(head + lines) +
                                                f"\ntotal wall time {time.perf_counter() - t_start:.0f} s\n")
    plot(results, RESULTS / "work_precision.png")
    print(f"wrote {RESULTS / 'work_precision.txt'} and work_precision.png")
    return results


if __name__ == "__main__":
    main()
