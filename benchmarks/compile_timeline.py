"""Benchmark: where a cold default run's numba compiles go, per process (issue 37's `make run` floor).

Runs ``python -m balloon_cg.app.default_run OUT --quiet`` of this install with a fresh numba cache folder
(NUMBA_CACHE_DIR in a temporary folder) and a probe loaded by every process it starts (a sitecustomize.py on
PYTHONPATH that wraps numba's ``Dispatcher.compile``): each process's top-level compiles (a kernel and the
kernels it calls, numba's compile or its cache load, the CPU of this process) and its CPU in all. A kernel
listed by two processes was compiled twice; a load is a cache hit (its time is counted after any wait for
another process's compile lock: model/compile_lock.py wraps outside the probe).

    python benchmarks/compile_timeline.py [--keep DIR] [--quick]
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PROBE = '''
import atexit, os, sys, time, importlib.abc, importlib.machinery
_log, _rows, _depth = os.environ["COMPILE_TIMELINE_LOG"], [], [0]
def _cpu():
    t = os.times()
    return t.user + t.system
def _wrap(module):
    original = module.Dispatcher.compile
    def compile(self, sig):
        _depth[0] += 1
        cpu, misses = _cpu(), sum(self._cache_misses.values())
        try:
            return original(self, sig)
        finally:
            _depth[0] -= 1
            if _depth[0] == 0:
                kind = "compile" if sum(self._cache_misses.values()) > misses else "load"
                _rows.append((kind, self.py_func.__module__ + "." + self.py_func.__qualname__, _cpu() - cpu))
    module.Dispatcher.compile = compile
class _Hook(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name != "numba.core.dispatcher":
            return None
        sys.meta_path.remove(self)
        spec = importlib.machinery.PathFinder.find_spec(name, path)
        run = spec.loader.exec_module
        def exec_module(module):
            run(module)
            _wrap(module)
        spec.loader.exec_module = exec_module
        return spec
sys.meta_path.insert(0, _Hook())
@atexit.register
def _dump():
    with open(f"{_log}.{os.getpid()}", "w") as f:
        f.write(f"process {_cpu():.2f} {' '.join(sys.argv[1:])}\\n")
        for kind, name, cpu in _rows:
            f.write(f"{kind} {name} {cpu:.2f}\\n")
'''


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--keep", help="write the run files, figures and logs here instead of a temporary folder")
    parser.add_argument("--quick", action="store_true", help="the default run's --quick (a check of this script)")
    options = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="compile_timeline_") as tmp:
        folder = Path(options.keep or tmp)
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "probe").mkdir(exist_ok=True)
        (folder / "probe" / "sitecustomize.py").write_text(PROBE)
        env = {**os.environ, "PYTHONPATH": str(folder / "probe"), "NUMBA_CACHE_DIR": str(folder / "numba"),
               "COMPILE_TIMELINE_LOG": str(folder / "log")}
        load = os.getloadavg()
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "balloon_cg.app.default_run", folder / "out", "--quiet"]
                       + ["--quick"] * options.quick, env=env, check=True, capture_output=True)
        wall = time.perf_counter() - start
        print(f"cold default run {wall:.1f} s wall; load {load[0]:.1f} before, {os.getloadavg()[0]:.1f} after")
        for log in sorted(folder.glob("log.*")):
            head, *rows = log.read_text().splitlines()
            _, cpu, *argv = head.split()
            rows = [row.split() for row in rows]
            compiled = [(name, float(c)) for kind, name, c in rows if kind == "compile"]
            print(f"\nprocess {' '.join(argv)[-60:]}: {float(cpu):.1f} s CPU, {len(compiled)} kernels compiled "
                  f"({sum(c for _, c in compiled):.1f} s CPU), {len(rows) - len(compiled)} loaded from the cache")
            for name, c in sorted(compiled, key=lambda x: -x[1]):
                print(f"  {c:6.2f}  {name}")


if __name__ == "__main__":
    main()
