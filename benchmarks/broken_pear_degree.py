"""Benchmark (issue 37): the off-equator coil's disconnected pear branch traced as stored against its legs started
on the wire map at a low degree, the lever that would meet the off-equator floor and that changes the stored branch.

As stored (``broken_symmetry``), the legs in P start at the continued seed on its plain basis: degree 320, where the
symmetric relative's pear branch was traced, and they never go down. Here the same continued point is also moved
onto the wire map of its own state (``wires.wire_map``) at DEGREE, corrected there at its pressure, and traced both
ways with the same stop rules (the tracer refines as it needs). Printed per way, serially (one process, one BLAS
thread): the CPU of the two legs and of the branch's assessment (``assess_branch`` with its checks, as ``analyse``
does), its points, the degrees they were solved at, its storage degree, its largest error estimate and its fold(s)
in P (located both ways: they should agree to the solver's tolerance), and the ratio of the CPU to the stored way's.

    BALLOON_CG_WORKERS=1 python benchmarks/broken_pear_degree.py [--degrees 40 60 90]
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

from balloon_cg.analysis.branches.assembly import assemble
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.wires import wire_map
from balloon_cg.analysis.results import Kind
from balloon_cg.analysis.stability.axisymmetric import assess_branch
from balloon_cg.analysis.switching import broken_symmetry
from balloon_cg.analysis.switching.pear import pear_landing, pear_stop_rule
from balloon_cg.numerics import continuation
from balloon_cg.numerics.newton import newton
from balloon_cg.numerics.threads import blas_threads
from balloon_cg.scene import load_scene

SCENE = Path(__file__).resolve().parents[1] / "tests" / "data" / "off_equator.toml"


def continued_seed(scene):
    """(X, parameters) of the disconnected half's continued seed (``broken_symmetry.broken_pear`` before its legs)."""
    primary = trace_primary(scene)
    relative, bp = broken_symmetry.pitchfork(scene)
    for sign in broken_symmetry.SIGNS:
        X, params, joins = broken_symmetry.half(scene, relative, bp, primary, sign)
        if not joins:
            return X, params
    raise RuntimeError("no disconnected half")


def mapped_start(scene, X, params, degree: int):
    """The legs of the disconnected branch from X moved onto its own wire map at ``degree`` (module docstring)."""
    tracer = broken_symmetry.held_tracer(scene)
    plain = tracer.system((X.size - 1) // 2, params).eq.disc  # N + 1 a's and N b's (b_0 held), and P
    system = tracer.system(degree, params, wire_map(plain, X[:-1], scene.field.coils, False))
    pressure = np.eye(system.eq.disc.size + 1)[-1]
    Y = plain.transfer(X, system.eq.disc)
    Y = newton(system.residual, system.jacobian, Y, pressure, Y[-1], scene.solver.tol, scene.solver.max_newton).x
    legs = [tracer.leg(continuation.Point(Y, sign * continuation.tangent(system, Y, pressure), 0, 0.0), params,
                       pear_stop_rule(scene), degree=degree, mapping=system.eq.disc.mapping)
            for sign in broken_symmetry.SIGNS]
    return assemble(tracer, params, "mapped", legs[0], legs[1], land_on=pear_landing(scene), labels=("up", "down"))


def row(name: str, scene, trace) -> dict:
    start = time.process_time()
    branch = trace()
    traced = time.process_time() - start
    start = time.process_time()
    assess_branch(branch, scene.stability.degree, False, check=True, m_max=scene.stability.m_max)
    return {"way": name, "legs": traced, "assessment": time.process_time() - start, "points": len(branch.X),
            "degrees": sorted({int(d) for d in branch.degree}), "storage": branch.disc.degree,
            "error": float(branch.error_estimate.max()),
            "folds": [float(s.X[-1]) for s in branch.special if s.kind == Kind.LP]}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--degrees", type=int, nargs="+", default=[40, 60, 90])
    args = parser.parse_args(argv)
    scene = load_scene(SCENE)
    with blas_threads():
        X, params = continued_seed(scene)
        rows = [row("as stored (plain seed basis)", scene,
                    lambda: broken_symmetry.trace_disconnected(scene, X, params, "stored", None, 0.0))]
        rows += [row(f"wire map from degree {N}", scene, lambda N=N: mapped_start(scene, X, params, N))
                 for N in args.degrees]
    base = rows[0]["legs"] + rows[0]["assessment"]
    print(f"{'way':<30}{'legs s':>8}{'assess s':>10}{'ratio':>7}{'points':>8}{'storage':>9}{'max error':>11}  "
          "degrees; LP folds (P)")
    for r in rows:
        print(f"{r['way']:<30}{r['legs']:8.2f}{r['assessment']:10.2f}{(r['legs'] + r['assessment']) / base:7.2f}"
              f"{r['points']:8d}{r['storage']:9d}{r['error']:11.2e}  {r['degrees']}; "
              + ", ".join(f"{p:.12f}" for p in r["folds"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
