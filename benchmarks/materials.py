"""Strain-energy classes: codegen and first-JIT time per new class, and the solve speed of a user formula's
cached class against the committed class of the same material (one run, classes interleaved).

(1) Per class, in a fresh subprocess with an empty kernel cache and an empty numba cache: ``balloon-cg kernels``
    (codegen stages for a user formula; first call of every kernel, i.e. numba compilation); a committed
    family's codegen time is measured in this process (what ``make regenerate`` spends on it).
(2) trace_primary at M = 0 to λ = 5, warm (compiled), best of REPEAT process-CPU times, preset and user formula
    alternating; the pressures must agree to 1e-12.
(3) The cost of the domain check (Equilibrium: every log argument > 0 at every node of every Newton iterate) on
    the Gent preset's trace: with and without it, alternating, best of REPEAT.

Run: python benchmarks/materials.py   (writes benchmarks/results/materials.txt)
"""
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.codegen import build, classes
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.scene import parse_scene

REPEAT = 5
OGDEN = " + ".join(f"mu{i}/a{i}*(lambda1**a{i} + lambda2**a{i} + lambda3**a{i} - 3)" for i in (1, 2, 3))
SPOM1 = f'energy = "{OGDEN}"\n[material.parameters]\n' \
        "mu1 = 3.00508\na1 = 1.3\nmu2 = 0.0145\na2 = 4.0\nmu3 = -0.0177\na3 = -2.0"
GENT = 'energy = "-(mu*Jm/2)*log(1 - (I1 - 3)/Jm)"\n[material.parameters]\nmu = 2.0\nJm = 97.2'
CLASSES = {"Mooney-Rivlin-I": 'preset = "Mooney-Rivlin-I"', "Gent": 'preset = "Gent"',
           "Gent-Gent": 'preset = "Gent-Gent"', "Arruda-Boyce": 'preset = "Arruda-Boyce"',
           "user SPOM1": SPOM1, "user Gent": GENT}
PAIRS = {"SPOM1": ('preset = "SPOM1"', SPOM1), "Gent": ('preset = "Gent"', GENT)}


def scene_text(material: str) -> str:
    return f"[material]\n{material}\n[continuation]\nstop_stretch = 5.0\n"


def first_use(material: str) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.toml"
        path.write_text(scene_text(material))
        env = {**os.environ, "BALLOON_CG_KERNEL_CACHE": f"{tmp}/kernels", "NUMBA_CACHE_DIR": f"{tmp}/numba"}
        command = "from balloon_cg.app.cli import main; raise SystemExit(main())"
        out = subprocess.run([sys.executable, "-c", command, "kernels", str(path), "--json"], env=env,
                             check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def best_cpu_times(scenes, repeat: int = REPEAT) -> list:
    """Per scene the best of ``repeat`` process-CPU times of trace_primary, the scenes alternating."""
    best = [float("inf")] * len(scenes)
    for _ in range(repeat):
        for k, s in enumerate(scenes):
            start = time.process_time()
            trace_primary(s)
            best[k] = min(best[k], time.process_time() - start)
    return best


def solve_times(pair) -> tuple:
    scenes = [parse_scene(scene_text(m)) for m in pair]
    branches = [trace_primary(s) for s in scenes]  # compile
    assert abs(branches[1].pressure / branches[0].pressure - 1).max() < 1e-12
    return *best_cpu_times(scenes), len(branches[0].pressure)


def domain_check_times() -> tuple:
    scene = parse_scene(scene_text('preset = "Gent"'))
    trace_primary(scene)
    original = Equilibrium.__init__

    def unchecked(self, *args, **kwargs):
        original(self, *args, **kwargs)
        self._domain_check = False

    best = {True: float("inf"), False: float("inf")}
    try:
        for _ in range(REPEAT):
            for check in (True, False):
                Equilibrium.__init__ = original if check else unchecked
                start = time.process_time()
                trace_primary(scene)
                best[check] = min(best[check], time.process_time() - start)
    finally:
        Equilibrium.__init__ = original
    return best[True], best[False]


def main():
    lines = ["(1) first use (fresh caches)", f"{'class':<18}{'codegen s':>10}{'first JIT s':>12}  kernel class"]
    for name, material in CLASSES.items():
        r = first_use(material)
        stages = r["stages"]
        if r["source"] == "committed":  # what make regenerate spends on it
            build.class_module(next(c for c in classes.energy_classes() if c.name == r["class"]), stages)
        codegen = sum(stages[k] for k in ("derive", "lower", "print"))
        jit = sum(seconds for seconds, _ in r["jit"].values())
        lines.append(f"{name:<18}{codegen:>10.2f}{jit:>12.2f}  {r['class']} ({r['source']})")
    lines += ["", "(2) trace_primary to λ = 5, warm, best of %d CPU s" % REPEAT,
              f"{'material':<10}{'points':>7}{'committed':>11}{'user formula':>14}{'ratio':>8}"]
    for name, pair in PAIRS.items():
        committed, user, points = solve_times(pair)
        lines.append(f"{name:<10}{points:>7}{committed:>11.3f}{user:>14.3f}{user / committed:>8.2f}")
    with_check, without_check = domain_check_times()
    lines += ["", "(3) Gent trace_primary, domain check on/off, best of %d CPU s" % REPEAT,
              f"{'on':>8}{'off':>8}{'ratio':>8}", f"{with_check:>8.3f}{without_check:>8.3f}"
                                                  f"{with_check / without_check:>8.2f}"]
    text = "\n".join(lines)
    print(text)
    out = Path(__file__).parent / "results" / "materials.txt"
    out.write_text(text + "\n")


if __name__ == "__main__":
    main()
