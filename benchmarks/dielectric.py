"""Dielectric classes: codegen and first-JIT time of a new class with the term −Φ̄² λ1² λ2², and the solve speed
against the same material's class without it (one run, the two alternating).

(1) Per material, in a fresh subprocess with an empty kernel cache and an empty numba cache: ``balloon-cg kernels``
    of the scene with [electric] (codegen stages of the on-demand class; first call of every kernel, i.e. numba
    compilation), and the same for the scene without it (committed classes: JIT only).
(2) trace_primary at M = 0 to λ = 5, warm (compiled), best of REPEAT process-CPU times, without [electric] and
    with [electric] voltage = 0 (the same equations through the dielectric class; the pressures must agree to
    1e-12) alternating; the dielectric scene also pays the compression check of every point.

Run: python benchmarks/dielectric.py   (writes benchmarks/results/dielectric.txt)
"""
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.scene import parse_scene
from materials import best_cpu_times  # benchmarks/materials.py (this folder is on sys.path when run as a script)

REPEAT = 5
TWO_COILS = ("[field]\nM = 0.002\n[[field.coils]]\nradius = 1.7321\nheight = 1.0\ncurrent = 1.0\n"
             "[[field.coils]]\nradius = 1.7321\nheight = -1.0\ncurrent = -1.0\n")
MATERIALS = {
    "neo-Hookean": '[material]\npreset = "neo-Hookean"\n',
    "SPOM1": '[material]\npreset = "SPOM1"\n',
    "SPOM1 two coils": '[material]\npreset = "SPOM1"\n' + TWO_COILS,
    "Gent": '[material]\npreset = "Gent"\n',
    "user Gent": '[material]\nenergy = "-(mu*Jm/2)*log(1 - (I1 - 3)/Jm)"\n[material.parameters]\nmu = 2.0\n'
                 "Jm = 97.2\n",
}
SOLVE = ("neo-Hookean", "SPOM1", "Gent")
CONTINUATION = "[continuation]\nstop_stretch = 5.0\n"


def first_use(text: str) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.toml"
        path.write_text(text)
        env = {**os.environ, "BALLOON_CG_KERNEL_CACHE": f"{tmp}/kernels", "NUMBA_CACHE_DIR": f"{tmp}/numba"}
        command = "from balloon_cg.app.cli import main; raise SystemExit(main())"
        out = subprocess.run([sys.executable, "-c", command, "kernels", str(path), "--json"], env=env,
                             check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def codegen_and_jit(report: dict) -> tuple:
    codegen = sum(report["stages"].get(k, 0.0) for k in ("derive", "lower", "print"))
    return codegen, sum(seconds for seconds, _ in report["jit"].values())


def solve_times(material: str) -> tuple:
    scenes = [parse_scene(material + CONTINUATION), parse_scene(material + CONTINUATION + "[electric]\n")]
    branches = [trace_primary(s) for s in scenes]  # compile
    assert len(branches[0].X) == len(branches[1].X)
    assert np.abs(branches[1].pressure / branches[0].pressure - 1).max() < 1e-12
    return *best_cpu_times(scenes, REPEAT), len(branches[0].X)


def main():
    lines = ["(1) first use (fresh kernel and numba caches), seconds",
             f"{'material':<17}{'codegen':>9}{'first JIT':>11}{'JIT plain':>11}  dielectric kernel class"]
    for name, material in MATERIALS.items():
        electric = first_use(material + "[electric]\nvoltage = 0.2\n")
        plain = first_use(material)
        codegen, jit = codegen_and_jit(electric)
        lines.append(f"{name:<17}{codegen:>9.2f}{jit:>11.2f}{codegen_and_jit(plain)[1]:>11.2f}  "
                     f"{electric['class']} ({electric['source']})")
    lines += ["", f"(2) trace_primary to λ = 5, warm, best of {REPEAT} CPU s (voltage 0: same branch)",
              f"{'material':<12}{'points':>7}{'plain':>8}{'dielectric':>12}{'ratio':>8}"]
    for name in SOLVE:
        plain, electric, points = solve_times(MATERIALS[name])
        lines.append(f"{name:<12}{points:>7}{plain:>8.3f}{electric:>12.3f}{electric / plain:>8.2f}")
    text = "\n".join(lines)
    print(text)
    (Path(__file__).parent / "results" / "dielectric.txt").write_text(text + "\n")


if __name__ == "__main__":
    main()
