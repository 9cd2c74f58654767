"""The reference tables of issue 37's "unchanged": every stored eigenvalue, flag and located point of the whole
picture of every shipped scene and of the off-equator scene (tests/data/off_equator.toml), as computed by main at
94ce54e (before the speed work of issue 37), and of a Gent balloon (tests/data/gent.toml), as computed by main at
a7f2a88 (before issue 38 made the reference meridian data: its "sphere scenes unchanged").
tests/test_stability_reference.py computes the same tables with the
code under test and compares them (``compare``); ``python tests/stability_reference.py [SCENE ...]`` rewrites
tests/data/reference/SCENE.npz (only to record a deliberate change of the numbers).

A picture's table (``table``): per branch, the lowest eigenvalues of every block (axisymmetric branches) or reading
(surface branches), the six flags, the perturbation degree of each assessment, the unsettled points, and per
special point its kind, block, m, status, classification and index (one text row) and its X (the located point);
on a surface branch also ``x``, its state x = X + u at SAMPLES (41 Gauss–Legendre cos θ × 12 φ: off the poles), which
no basis enters (X's coefficients are of the branch's final basis, whose wire map the trace's chain of refinements
chooses).
Where an assessment's degree N was raised above stability.degree (near a wire), ``error_<block>`` holds its own error
estimate, |μ(N) − μ(⌊N/1.5⌋)| per eigenvalue (the coarser degree: an over-estimate of the error at N, where the
eigenvalues converge spectrally); zero elsewhere. A special point's ``uncertainty`` is the one it was stored with (an
approximate point's bracket).
"""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).resolve().parent / "data"
OFF_EQUATOR = DATA / "off_equator.toml"
GENT = DATA / "gent.toml"  # issue 38's Gent scene: its table computed by main before the meridian (a7f2a88)
EXTRA = {path.stem: path for path in (OFF_EQUATOR, GENT)}  # scenes of tests/data/
SCENES = tuple(sorted(p.stem for p in (ROOT / "scenes").glob("*.toml")
                     if not p.stem.startswith("tube_"))) + tuple(EXTRA)  # a tube's run is not a picture


SAMPLES = (np.polynomial.legendre.leggauss(41)[0], np.linspace(0.0, 2 * np.pi, 12, endpoint=False))  # (cos θ, φ)


def reference_path(scene: str) -> Path:
    return DATA / "reference" / f"{scene}.npz"


def table(picture, errors: bool = False) -> dict[str, np.ndarray]:
    """{key: array} of a picture's stored stability and special points (module docstring); ``errors``: with the
    eigenvalues' error estimates (``eigenvalue_errors``)."""
    out = {}
    for branch in picture.branches + picture.surface_branches:
        key = branch.name
        if isinstance(branch.stability, dict):  # a surface branch: lowest eigenvalues per reading
            for reading, values in branch.stability.items():
                out[f"{key}/lowest_{reading}"] = np.asarray(values, dtype=float)
        elif branch.stability:
            for block in branch.stability[0].blocks:
                out[f"{key}/lowest_{block}"] = np.array([a.blocks[block] for a in branch.stability])
            out[f"{key}/flags"] = np.array([list(a.flags().values()) for a in branch.stability], dtype=bool)
            out[f"{key}/degrees"] = np.array([a.degree for a in branch.stability])
            out[f"{key}/unsettled"] = np.asarray(branch.unsettled, dtype=np.int64)
            if errors:
                out |= {f"{key}/error_{block}": e for block, e in eigenvalue_errors(branch).items()}
        for n, s in enumerate(branch.special):
            out[f"{key}/special_{n}/label"] = np.array(
                f"{s.kind.value} {s.block.value} m={s.m} {s.status.value} {s.classification.value} index={s.index}")
            out[f"{key}/special_{n}/X"] = np.asarray(s.X, dtype=float)
            if isinstance(branch.stability, dict):  # the state itself: its coefficients are of the branch's basis
                out[f"{key}/special_{n}/x"] = branch.basis.grid_values(s.X[:-1], *SAMPLES)
            out[f"{key}/special_{n}/uncertainty"] = np.asarray(s.uncertainty, dtype=float)
    return out


def eigenvalue_errors(branch) -> dict[str, np.ndarray]:
    """Per block, |μ(N) − μ(⌊N/1.5⌋)| of every stored eigenvalue whose degree N exceeds stability.degree (module
    docstring), zero elsewhere."""
    from balloon_cg.analysis.branches.problem import equilibrium_of
    from balloon_cg.analysis.stability.axisymmetric import Variations
    from balloon_cg.numerics.threads import blas_threads

    variations, base = Variations(equilibrium_of(branch)), branch.scene.stability.degree
    symmetric, m_max = branch.disc.symmetric, branch.scene.stability.m_max
    out = {block: np.zeros_like(np.array([a.blocks[block] for a in branch.stability]))
           for block in branch.stability[0].blocks}
    for n, a in enumerate(branch.stability):
        if a.degree <= base:
            continue
        X = branch.X[n]
        with blas_threads():
            coarse = variations[int(a.degree / 1.5)].assess(X[:-1], branch.params_at(X), symmetric, m_max)
        for block, values in a.blocks.items():
            out[block][n] = np.abs(values - coarse.blocks[block])
    return out


def scene_path(scene: str) -> Path:
    return EXTRA.get(scene, ROOT / "scenes" / f"{scene}.toml")


def scene_table(scene: str, errors: bool = False) -> dict[str, np.ndarray]:
    """``table`` of the whole picture of ``scene`` (a shipped scene's name, or one of tests/data/: EXTRA)."""
    from balloon_cg.analysis.picture import analyse
    from balloon_cg.scene import load_scene

    return table(analyse(load_scene(scene_path(scene))), errors)


def main(argv: list[str]) -> int:
    for scene in argv or SCENES:
        tables = scene_table(scene, errors=True)
        path = reference_path(scene)
        path.parent.mkdir(exist_ok=True)
        np.savez_compressed(path, **tables)
        print(f"{path}: {len(tables)} arrays", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
