"""The committed tree is whole: no text file carries a merge's conflict markers (one did, in README.md, for a
whole session)."""
import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MARKER = re.compile(rb"^(<{7}|>{7})( |$)|^={7}$", re.MULTILINE)
TEXT = (".py", ".md", ".toml", ".txt", ".cfg", ".ini", ".yml", ".yaml", ".json", "")


def conflicted(root: Path, names) -> list[str]:
    """The names (relative to ``root``) of text files holding a conflict marker line."""
    return [name for name in names
            if Path(name).suffix in TEXT and (root / name).is_file() and MARKER.search((root / name).read_bytes())]


def test_no_conflict_markers_in_tracked_files():
    try:
        listed = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout")
    assert conflicted(ROOT, [name for name in listed.decode().split("\0") if name]) == []


def test_the_marker_check_finds_markers(tmp_path):
    (tmp_path / "a.md").write_text("x\n<<<<<<< HEAD\nours\n=======\ntheirs\n>>>>>>> main\n")
    (tmp_path / "b.md").write_text("a table row\n| ===== |\n======= is not alone on its line\n")
    (tmp_path / "c.png").write_bytes(b"\n=======\n")  # not text
    assert conflicted(tmp_path, ["a.md", "b.md", "c.png"]) == ["a.md"]
