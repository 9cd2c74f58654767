"""A capsule's convergence in the degree: the enclosed volume and the hoop stretch at the middle of an inflated SPOM1
capsule against the degree N, each column the change from the previous degree, and the tail estimate
(``Discretisation.tail``: what the tracer's max_error reads).

The state is tests/test_capsule.py's ``inflated`` (the start at pole stretch 1.005, natural continuation in P, Newton
at each degree); on the piecewise basis split at the joins (galerkin/elements.py) the changes fall geometrically, on
one Legendre series in x (the code before it: run this file with PYTHONPATH pointing at that tree's src) as N⁻³.

    python benchmarks/capsule_convergence.py [--length 4] [--pressure 0.5] [--degrees 16 24 32 48 64 96]
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_capsule import capsule_scene, inflated  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=4.0)
    parser.add_argument("--pressure", type=float, default=0.5)
    parser.add_argument("--degrees", type=int, nargs="+", default=[16, 24, 32, 48, 64, 96])
    args = parser.parse_args()
    import balloon_cg
    print(f"SPOM1 capsule, length {args.length:g}, P = {args.pressure:g} ({Path(balloon_cg.__file__).parent})")
    print(f"{'N':>4} {'V':>20} {'|dV|':>9} {'lam2(pi/2)':>18} {'|dlam2|':>9} {'tail':>8} {'s':>6}")
    previous = None
    for degree in args.degrees:
        start = time.perf_counter()
        eq, u = inflated(capsule_scene(args.length), degree, args.pressure)
        volume = 2 * np.pi * eq.volume(u)
        hoop = float(eq.state_at(u, np.array([0.5 * np.pi]))[0][0])
        changes = ("", "") if previous is None else tuple(f"{abs(now - before):.2e}" for now, before
                                                          in zip((volume, hoop), previous))
        print(f"{degree:4d} {volume:20.15f} {changes[0]:>9} {hoop:18.15f} {changes[1]:>9} {eq.disc.tail(u):8.1e} "
              f"{time.perf_counter() - start:6.2f}")
        previous = (volume, hoop)


if __name__ == "__main__":
    main()
