"""Critical field of the single-coil SPOM1 isola (scenes/spom1_single_coil.toml, coil a = 4 at h = 0).

For each M the primary branch is traced and the pear (odd-block) branch points are located; the isola exists
while there are two of them. The critical M is bracketed by bisection to 1e-4 and the table of the two
branch-point stretches and pressures against M is printed (it shows the isola shrinking).
Run: python benchmarks/critical_field.py
"""
import time
from pathlib import Path

from balloon_cg.analysis import analyse
from balloon_cg.scene import load_scene

SCENE = Path(__file__).resolve().parent.parent / "scenes" / "spom1_single_coil.toml"


def pear_points(M: float):
    scene = load_scene(SCENE).with_overrides({"field.M": M, "continuation.stop_stretch": 6.0})
    picture = analyse(scene, pear=False)
    primary = picture.branches[0]
    return [(primary.pole_values(bp.X)["lam2_north"][0], bp.X[-1], bp.kind)
            for bp in picture.branch_points if bp.block == "odd_held"], primary.stop_reason


def main():
    start = time.perf_counter()
    print(f"{'M':>8}  {'pear branch points (stretch, P, kind)':<80}  stop reason")
    for M in (0.0, 0.002, 0.004, 0.006, 0.008):
        points, reason = pear_points(M)
        text = "; ".join(f"{lam:.6f}, {P:.6f}, {kind}" for lam, P, kind in points)
        print(f"{M:8.4f}  {text:<80}  {reason}")
    lo, hi = 0.0, 0.05
    while len(pear_points(hi)[0]) >= 2:
        lo, hi = hi, 2 * hi
    while hi - lo > 1e-4:
        mid = 0.5 * (lo + hi)
        if len(pear_points(mid)[0]) >= 2:
            lo = mid
        else:
            hi = mid
    print(f"critical M (isola vanishes): in [{lo:.5f}, {hi:.5f}]  ({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
