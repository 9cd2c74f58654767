"""Per-solve cost of the constrained Newton (benchmarks/work_precision.py PointSolver.solve) at the baseline points,
for one or several installs of balloon-cg timed in alternating rounds of one run (issue 14: the Python-level cost
of a Newton iteration).

The points are the 12 of benchmarks/baselines.py at the setting it chose for ours (degree, plain or wire-mapped
basis; results/baselines.txt of 2026-12-02: two coils λ* 1.3 and 1.5 on the wire map, degrees 20 and 28), warm-started from the converged neighbour at λ* − 0.02 exactly as
there. They are prepared once by this interpreter (traces, neighbours, wire maps) and handed to one worker
process per install; each round asks every worker in turn for the best of REPEAT solves of every point (wall
clock, single-threaded BLAS), and a point's time is its best over the rounds. Printed per point: the time of each
install, its ratio to the first, and whether the solves agree (same iteration count, |ΔP/P| ≤ 1e-13).

    python benchmarks/newton_overhead.py --python OLD/bin/python --python NEW/bin/python [--rounds 7]
"""
import argparse
import json
import os
import pickle
import subprocess
import sys
import tempfile
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
ROUNDS = 7
REPEAT = 200
TOL = 1e-10  # the tightest of baselines.OUR_TOLS
# (case index in work_precision.cases(), λ*, degree, wire-mapped basis): the settings baselines.py chose for ours
POINTS = [(0, 1.3, 8, False), (0, 1.5, 8, False), (0, 2.0, 8, False), (0, 3.0, 8, False),
          (1, 1.3, 20, True), (1, 1.5, 28, True), (1, 1.7, 40, True), (1, 1.8, 56, True),
          (2, 1.3, 8, False), (2, 1.5, 10, False), (2, 2.0, 16, False), (2, 3.0, 40, False)]


def prepare(path):
    """The start of every point (X0 on its degree and basis, the branch parameters, the mapping) into ``path``."""
    sys.path.insert(0, str(HERE))
    import work_precision as wp
    from balloon_cg.analysis.branches.wires import wire_map

    points = []
    for index, case in enumerate(wp.cases()):
        mine = [p for p in POINTS if p[0] == index]
        case.stretches = tuple(p[1] for p in mine)
        branch, solver, targets = wp.prepare(case)
        for (_, stretch, degree, mapped), target in zip(mine, targets):
            mapping = None
            if mapped:
                mapping = wire_map(branch.disc, target.X_neighbour_fine[:-1], case.scene.field.coils,
                                   solver.symmetric)
            X0 = wp.neighbour(solver, target, degree, branch.disc, mapping)
            points.append(dict(case=index, label=case.label, stretch=stretch, degree=degree, mapping=mapping,
                               X0=X0, params=branch.params))
    with open(path, "wb") as f:
        pickle.dump(points, f)
    return points


def worker(path):
    """Serve rounds on stdin: per line, one JSON list of (best seconds, iterations, P) per point."""
    sys.path.insert(0, str(HERE))
    import work_precision as wp
    from balloon_cg.numerics.newton import newton

    with open(path, "rb") as f:
        points = pickle.load(f)
    cases = wp.cases()
    calls = []
    for p in points:
        solver = wp.PointSolver(cases[p["case"]].scene, p["params"])
        residual, jacobian, row = solver.system(p["degree"], p["mapping"])
        calls.append((residual, jacobian, p["X0"], row, p["stretch"]))
    for residual, jacobian, X0, row, stretch in calls:
        newton(residual, jacobian, X0, row, stretch, TOL, 30)  # load the kernels outside the timings
    print("ready", flush=True)
    for _ in sys.stdin:
        out = []
        for residual, jacobian, X0, row, stretch in calls:
            best = np.inf
            for _ in range(REPEAT):
                t0 = time.perf_counter()
                result = newton(residual, jacobian, X0, row, stretch, TOL, 30)
                best = min(best, time.perf_counter() - t0)
            out.append((best, result.iterations, float(result.x[-1]), result.converged))
        print(json.dumps(out), flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--python", action="append", help="an interpreter with balloon-cg installed (repeat)")
    parser.add_argument("--rounds", type=int, default=ROUNDS)
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        return worker(args.worker)
    pythons = args.python or [sys.executable]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "points.pkl"
        points = prepare(path)
        workers = [subprocess.Popen([python, __file__, "--worker", str(path)], stdin=subprocess.PIPE,
                                    stdout=subprocess.PIPE, text=True) for python in pythons]
        for w in workers:
            if w.stdout.readline().strip() != "ready":
                raise RuntimeError("a worker failed to start")
        best = [[np.inf] * len(points) for _ in pythons]
        last = [None] * len(pythons)
        load = os.getloadavg()[0]
        for _ in range(args.rounds):
            for k, w in enumerate(workers):
                w.stdin.write("round\n")
                w.stdin.flush()
                last[k] = json.loads(w.stdout.readline())
                best[k] = [min(b, r[0]) for b, r in zip(best[k], last[k])]
        for w in workers:
            w.stdin.close()
            w.wait()
    head = f"  {'point':<40} {'deg':>7}" + "".join(f" {f'[{k}] µs':>9}" for k in range(len(pythons)))
    head += "".join(f" {f'[{k}]/[0]':>8}" for k in range(1, len(pythons))) + "  agree (its, |ΔP/P| ≤ 1e-13)"
    lines = [f"Constrained Newton per solve (best of {REPEAT} × {args.rounds} alternating rounds, wall, "
             f"single-threaded BLAS; load average {load:.1f} -> {os.getloadavg()[0]:.1f})"]
    lines += [f"  [{k}] {python}" for k, python in enumerate(pythons)] + [head]
    ratios = []
    for i, p in enumerate(points):
        times = [best[k][i] for k in range(len(pythons))]
        its = [last[k][i][1] for k in range(len(pythons))]
        P = [last[k][i][2] for k in range(len(pythons))]
        agree = all(it == its[0] for it in its) and all(abs(q / P[0] - 1) <= 1e-13 for q in P)
        agree = agree and all(last[k][i][3] for k in range(len(pythons)))
        ratios.append([t / times[0] for t in times[1:]])
        basis = "mapped " if p["mapping"] else ""
        lines.append(f"  {p['label'] + ', λ* ' + format(p['stretch'], '.1f'):<40} {basis + str(p['degree']):>7}"
                     + "".join(f" {t * 1e6:9.1f}" for t in times) + "".join(f" {r:8.3f}" for r in ratios[-1])
                     + f"  {'yes' if agree else 'NO'} ({its[0]} its; "
                     + ", ".join(f"{abs(q / P[0] - 1):.0e}" for q in P[1:]) + ")")
    if len(pythons) > 1:
        r = np.array(ratios)
        lines.append("  ratio [k]/[0]: " + "; ".join(
            f"[{k + 1}] min {r[:, k].min():.3f}, median {np.median(r[:, k]):.3f}, max {r[:, k].max():.3f}"
            for k in range(r.shape[1])))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
