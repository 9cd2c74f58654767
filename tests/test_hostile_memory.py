"""Issue 30 acceptance, memory: the inputs that once allocated without bound or hung are refused by a process whose
peak resident memory stays under 2 GiB — a scene whose keys multiply into 42 GiB, a 200 KB run file declaring a
1e11-element dataset (745 GiB) read by `inspect`, `inspect --json` and `plot`, a formula SymPy would evaluate as
(1/3)**(10**9), ten thousand coils. Each command runs in its own process under a wrapper that reports the peak
resident set of its child (getrusage RUSAGE_CHILDREN: the child's own, not this test process')."""
import json
import shutil
import subprocess
import sys

import h5py
import pytest

from test_damaged_fuzz import _huge
from test_hostile_inputs import BAD, SPOM1

PEAK = 2 * 1024**3  # bytes
WRAPPER = ("import json, resource, subprocess, sys; r = subprocess.run(sys.argv[1:], capture_output=True, text=True); "
           "print(json.dumps({'code': r.returncode, 'stderr': r.stderr, "
           "'peak': resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024}))")


def measured(*argv) -> dict:
    """{'code', 'stderr', 'peak' (bytes)} of ``balloon-cg ARGV`` in a child process."""
    out = subprocess.run([sys.executable, "-c", WRAPPER, sys.executable, "-m", "balloon_cg", *argv],
                         capture_output=True, text=True, timeout=600, check=True)
    return json.loads(out.stdout)


def refused(result: dict, words: str) -> None:
    lines = result["stderr"].strip().splitlines()
    assert result["code"] == 2 and len(lines) == 1 and words in lines[0], result["stderr"]
    assert result["peak"] < PEAK, result["peak"]


@pytest.mark.parametrize("case", ["product of keys", "many coils"])
def test_scenes_that_multiply_into_gigabytes_are_refused_within_2_GiB(case, tmp_path):
    text, words = BAD[case]
    scene = tmp_path / "s.toml"
    scene.write_text(text)
    refused(measured("run", str(scene), "-o", str(tmp_path / "x.h5"), "--quiet"), words)
    assert not (tmp_path / "x.h5").exists()


def test_a_formula_sympy_would_evaluate_for_ever_is_refused_within_2_GiB(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text('[material]\nenergy = "I1 - 3 + 0*(1/3)**(10**9)"\n')
    refused(measured("run", str(scene), "-o", str(tmp_path / "x.h5"), "--quiet"), "material.energy")


def test_a_file_declaring_745_GiB_is_refused_within_2_GiB(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(SPOM1 + "[continuation]\nstop_stretch = 1.3\n")
    good = tmp_path / "good.h5"
    assert measured("run", str(scene), "-o", str(good), "--quiet", "--primary-only")["code"] == 0
    bad = tmp_path / "bad.h5"
    shutil.copy(good, bad)
    with h5py.File(bad, "r+") as f:
        _huge(f["branches/primary"], "pressure")
    assert bad.stat().st_size < 10 * good.stat().st_size
    for argv in (["inspect", str(bad)], ["inspect", "--json", str(bad)],
                 ["plot", str(bad), "--what", "pressure-pole", "-o", str(tmp_path / "p.png")]):
        refused(measured(*argv), "pressure")
