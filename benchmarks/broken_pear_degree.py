"""Benchmark (issue 37): the off-equator coil's disconnected pear branch traced as the package does it (its legs
started on the wire map of the continued point at the scene's degree: ``broken_symmetry.trace_disconnected``) against
the way it was stored before session 23 (the legs from the continued seed on its plain basis: degree 320, where the
symmetric relative's pear branch was traced, never going down).

Printed per way, serially (one process, one BLAS thread): the CPU of the two legs and of the branch's assessment
(``assess_branch`` with its checks, as ``analyse`` does), its points, the degrees they were solved at, its storage
degree, its largest error estimate and its fold(s) in P (located both ways: they should agree to the solver's
tolerance), and the ratio of the CPU to the plain way's.

    BALLOON_CG_WORKERS=1 python benchmarks/broken_pear_degree.py
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

from balloon_cg.analysis.branches.assembly import assemble
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.results import Kind
from balloon_cg.analysis.stability.axisymmetric import assess_branch
from balloon_cg.analysis.switching import broken_symmetry
from balloon_cg.analysis.switching.pear import pear_landing, pear_stop_rule
from balloon_cg.numerics import continuation
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


def plain_start(scene, X, params):
    """The legs of the disconnected branch from X on its plain seed basis (the stored way before session 23)."""
    tracer = broken_symmetry.held_tracer(scene)
    degree = (X.size - 1) // 2  # N + 1 a's and N b's (b_0 held), and P
    system, pressure = tracer.system(degree, params), np.eye(X.size)[-1]
    legs = [tracer.leg(continuation.Point(X, sign * continuation.tangent(system, X, pressure), 0, 0.0), params,
                       pear_stop_rule(scene), degree=degree) for sign in broken_symmetry.SIGNS]
    return assemble(tracer, params, "plain", legs[0], legs[1], land_on=pear_landing(scene), labels=("up", "down"))


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
    argparse.ArgumentParser(description=__doc__.split("\n")[0]).parse_args(argv)
    scene = load_scene(SCENE)
    with blas_threads():
        X, params = continued_seed(scene)
        rows = [row("plain seed basis (before)", scene, lambda: plain_start(scene, X, params)),
                row("wire map (the package's)", scene,
                    lambda: broken_symmetry.trace_disconnected(scene, X, params, "broken_pear", None, 0.0))]
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
