"""Study behind analysis/stability/axisymmetric.NEAR_ZERO: how far the lowest eigenvalue of each block at a point's stability
degree N is from its value at the check degree (``check_degree``: 2N, or N/1.5 at solver.max_degree), at every point
whose lowest eigenvalue is below the old threshold 0.1 (the points the flag check read before), on the defaults
(|δx|² norm, wire-mapped basis). Prints per scene, by |μ_N| range, the blocks counted, the largest |μ_N − μ_check|
and the largest relative difference, and how many blocks changed sign.

    python benchmarks/near_zero.py [SCENE ...]      (default: the two-coil scene and the paper coil; serial)
"""
import os
import sys

os.environ.setdefault("BALLOON_CG_WORKERS", "1")

import numpy as np  # noqa: E402

from balloon_cg.analysis.stability import axisymmetric as stability
from balloon_cg.analysis import picture
from balloon_cg.scene import load_scene  # noqa: E402

OLD_NEAR_ZERO = 0.1
RANGES = ((0.0, 1e-8), (1e-8, 1e-6), (1e-6, 1e-4), (1e-4, 1e-2), (1e-2, OLD_NEAR_ZERO))


def study(scene) -> np.ndarray:
    """(μ_N, μ_check) of every block at the points the old rule checked, over the scene's assessed branches."""
    rows, assess = [], stability.assess_branch

    def spy(branch, degree, symmetric=None, check=False, near_zero=None, m_max=0, on_point=None):
        results, unsettled = assess(branch, degree, symmetric, check, near_zero, m_max, on_point)
        if check:
            symmetric = branch.disc.symmetric if symmetric is None else symmetric
            variations = stability.Variations(stability.equilibrium_of(branch))
            for n, a in enumerate(results):
                if min(abs(v[0]) for v in a.blocks.values()) >= OLD_NEAR_ZERO:
                    continue
                finer = variations[stability.check_degree(branch, a.degree)].assess(
                    branch.X[n][:-1], branch.params_at(branch.X[n]), symmetric, m_max)
                rows.extend((values[0], finer.blocks[name][0]) for name, values in a.blocks.items())
        return results, unsettled

    picture.assess_branch = spy
    try:
        picture.analyse(scene)
    finally:
        picture.assess_branch = assess
    return np.array(rows).reshape(-1, 2)


def main(names):
    print("scene, |mu_N| range: blocks, max |mu_N - mu_check|, max relative")
    for name in names:
        rows = study(load_scene(name))
        mu, error = rows[:, 0], np.abs(rows[:, 0] - rows[:, 1])
        print(f"{name}: {len(rows)} blocks at {OLD_NEAR_ZERO}-checked points, sign changes "
              f"{int((np.sign(rows[:, 0]) != np.sign(rows[:, 1])).sum())}")
        for lo, hi in RANGES:
            inside = (np.abs(mu) >= lo) & (np.abs(mu) < hi)
            if inside.any():
                print(f"  [{lo:g}, {hi:g}): {inside.sum():5d}  {error[inside].max():.2e}  "
                      f"{(error[inside] / np.abs(mu[inside])).max():.2e}")
        print(f"  all: {len(rows):5d}  {error.max():.2e}")


if __name__ == "__main__":
    main(sys.argv[1:] or ["spom1_two_coils_M0.002", "spom1_paper_coil"])
