"""The natural frequencies of a tube's branch in its run file (dynamics/tube.py; docs/hdf5.md "Tube run files"):
/branches/<name>/frequencies/ with the attribute ``count``, per block ``omega2_<block>`` (point, frequency) and
``special_omega2_<block>`` (located point, frequency), Ω² = ω² R0² ρ/μ described as the sphere's (io/schema.py)."""
import numpy as np

from .hdf5 import checksummed
from .schema import OMEGA2, SPECIAL_OMEGA2, describe

GROUP = "frequencies"


def write_tube_frequencies(branch_group, frequencies) -> None:
    """``frequencies`` (dynamics.tube.TubeFrequencies) under ``branch_group``/frequencies."""
    group = branch_group.create_group(GROUP)
    group.attrs["count"] = frequencies.count
    for block, values in frequencies.omega2.items():
        describe(checksummed(group, f"{OMEGA2}{block}", values))
        describe(checksummed(group, f"{SPECIAL_OMEGA2}{block}", frequencies.special[block]))


def read_tube_frequencies(path, branch_group, points: int, located: int, error) -> dict | None:
    """{'count', 'omega2': {block: (points, count)}, 'special': {block: (located, count)}} of a branch group, None
    where it has no frequencies; ``error`` (the file kind's FileError) naming a dataset whose shape is not its
    branch's."""
    if GROUP not in branch_group:
        return None
    group = branch_group[GROUP]
    count = int(group.attrs["count"])
    out = {"count": count, "omega2": {}, "special": {}}
    for name, dataset in group.items():
        key, rows = ("special", located) if name.startswith(SPECIAL_OMEGA2) else ("omega2", points)
        values = np.asarray(dataset[()], dtype=float)
        if values.shape != (rows, count):
            raise error(path, f"{dataset.name}: shape {values.shape}, expected ({rows}, {count})")
        out[key][name.removeprefix(SPECIAL_OMEGA2 if key == "special" else OMEGA2)] = values
    return out
