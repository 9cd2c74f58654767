"""What docs/hdf5.md says a reader gets, parsed from the page for the tests that hold the code to it."""
import re
from pathlib import Path

HDF5_MD = Path(__file__).resolve().parents[1] / "docs" / "hdf5.md"


def inspect_json_keys(kind: str) -> set:
    """The top-level keys of ``inspect --json`` of a file of ``kind`` (``run file``, ``tube run file``, ...): the
    row of the table under "What `inspect --json` prints", its backquoted names that are not in parentheses
    (nested ones too)."""
    text = HDF5_MD.read_text()
    section = text[text.index("## What `inspect --json` prints"):]
    row = next(line for line in section.splitlines() if line.startswith(f"| {kind} |"))
    keys = row.split("|")[2]
    while re.search(r"\([^()]*\)", keys):  # the innermost parentheses first: they nest
        keys = re.sub(r"\([^()]*\)", "", keys)
    return set(re.findall(r"`([a-z_]+)`", keys))
