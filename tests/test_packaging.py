"""`pip install .` (a regular, non-editable install) ships the generated kernels and the default scenes."""
import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_wheel_contains_generated_kernels_and_default_scenes(tmp_path):
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps",
                    "-w", str(tmp_path), str(ROOT)], check=True, capture_output=True)
    wheel = next(tmp_path.glob("balloon_cg-*.whl"))
    names = set(zipfile.ZipFile(wheel).namelist())
    generated = {p.name for p in (ROOT / "generated").glob("*.py")}
    assert {f"balloon_cg/generated/{name}" for name in generated} <= names
    assert "balloon_cg/default_scenes/spom1.toml" in names
