"""Benchmark: the perturbation degree that follows the mode, on the run that needed it.

TPOM1 with the paper's inferred coil (a = 1.961 at h = 0), M = 0.001, pear branches to λ2(0) = 6 on an unmapped
basis (post.paper's single-coil case): the whole picture at stability degree 20 and 40. Per run: CPU time
(process time, BLAS single-threaded), whether the result is complete, the m = 1 branch points stored on the pear
branches (located / approximate) and the assessment degrees on the first pear branch (how many points at each).
Run it with the installed package of each tree (old and new side by side): python benchmarks/mode_following.py
"""
import time
from collections import Counter

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Status
from balloon_cg.analysis.verdict import failing
from balloon_cg.post.paper import SINGLE_COIL, SINGLE_COIL_REACH, Case

CASE = Case(SINGLE_COIL, (("material.preset", "TPOM1"), ("field.M", 0.001)) + SINGLE_COIL_REACH)


def main():
    scene = CASE.load()
    analyse(scene.with_overrides({"continuation.stop_stretch": 1.2}), pear=False)  # load the kernels
    print("TPOM1, one coil a = 1.961, M = 0.001, stop_stretch 6 (CPU seconds of analyse)")
    print(f"{'stability.degree':>16} {'CPU s':>7} {'complete':>8} {'pear m=1 BP located/approx':>27}  "
          "pear_0 points per assessment degree")
    for degree in (20, 40):
        c0 = time.process_time()
        picture = analyse(scene.with_overrides({"stability.degree": degree}))
        cpu = time.process_time() - c0
        pears = [s for b in picture.branches[1:] for s in b.special if s.m >= 1]
        located = sum(s.status == Status.LOCATED for s in pears)
        degrees = Counter(a.degree for a in picture.branches[1].stability)
        print(f"{degree:16d} {cpu:7.1f} {str(not failing(picture.incomplete)):>8} "
              f"{f'{located}/{len(pears) - located}':>27}  {dict(sorted(degrees.items()))}", flush=True)


if __name__ == "__main__":
    main()
