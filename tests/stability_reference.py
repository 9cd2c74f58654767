"""The reference table of issue 28: every stored eigenvalue, flag and located point of the whole picture of the
shipped scenes, as computed by the code this table was made with (main at 86f8543, before the stability work of
issue 28; rewritten twice since: when a surface branch's critical mode moved to the perturbation degree its point
was located at: the two-coil m = 1 branch's points moved by ~2e-8, nothing else; and again from main at 5271428,
whose two-coil table no longer matched it: the merges of issue 27a/27b added the free balloon's pitchfork (a BP of
odd_free on the primary, the later special points renumbered; branches pear_free_1 and its mirror) and moved
pear_0_mirror's m = 1 crossing by 1.8e-10, every other common entry within 1e-10).
tests/test_stability_reference.py computes the same table with the code under test and compares it to 1e-10;
``python tests/stability_reference.py`` rewrites tests/data/stability_reference.npz (only to record a
deliberate change of the numbers).

A picture's table (``table``): per branch, the lowest eigenvalues of every block (axisymmetric branches) or reading
(surface branches), the six flags, the unsettled points, and per special point its kind, block, m, status and
classification (one text row) and its X (the located point).
"""
import sys
from pathlib import Path

import numpy as np

SCENES = ("spom1", "spom1_two_coils_M0.002")
ROOT = Path(__file__).resolve().parents[1]
REFERENCE = Path(__file__).resolve().parent / "data" / "stability_reference.npz"


def table(picture, prefix: str) -> dict[str, np.ndarray]:
    """{key: array} of a picture's stored stability and special points (module docstring)."""
    out = {}
    for branch in picture.branches + picture.surface_branches:
        key = f"{prefix}/{branch.name}"
        if isinstance(branch.stability, dict):  # a surface branch: lowest eigenvalues per reading
            for reading, values in branch.stability.items():
                out[f"{key}/lowest_{reading}"] = np.asarray(values, dtype=float)
        else:
            for block in branch.stability[0].blocks:
                out[f"{key}/lowest_{block}"] = np.array([a.blocks[block] for a in branch.stability])
            out[f"{key}/flags"] = np.array([list(a.flags().values()) for a in branch.stability], dtype=bool)
            out[f"{key}/degrees"] = np.array([a.degree for a in branch.stability])
            out[f"{key}/unsettled"] = np.asarray(branch.unsettled, dtype=np.int64)
        for n, s in enumerate(branch.special):
            out[f"{key}/special_{n}/label"] = np.array(
                f"{s.kind.value} {s.block.value} m={s.m} {s.status.value} {s.classification.value} index={s.index}")
            out[f"{key}/special_{n}/X"] = np.asarray(s.X, dtype=float)
    return out


def scene_table(name: str) -> dict[str, np.ndarray]:
    """``table`` of the whole picture of the shipped scene ``name``."""
    from balloon_cg.analysis.picture import analyse
    from balloon_cg.scene import load_scene

    return table(analyse(load_scene(ROOT / "scenes" / f"{name}.toml")), name)


def main() -> int:
    tables = {}
    for name in SCENES:
        tables |= scene_table(name)
    REFERENCE.parent.mkdir(exist_ok=True)
    np.savez_compressed(REFERENCE, **tables)
    print(f"{REFERENCE}: {len(tables)} arrays")
    return 0


if __name__ == "__main__":
    sys.exit(main())
