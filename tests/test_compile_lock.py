"""A kernel compiled once across processes (model/compile_lock.py): a process that needs a kernel another one is
compiling waits for its lock and loads the result from numba's on-disk cache; a process that dies holding the lock
releases it. Each process here has a fresh cache folder of its own test (NUMBA_CACHE_DIR); the order of events is
fixed by the lock and by lines on the processes' pipes, never by sleeping."""
import os
import signal
import subprocess
import sys

from numba.core.dispatcher import Dispatcher

import balloon_cg.model.kernels  # noqa: F401  (installs the lock)
from balloon_cg.model import compile_lock

KERNEL = "from balloon_cg.numerics.newton import max_abs as kernel\nfrom numba import float64\nSIG = (float64[:],)\n"
# holds the kernel's lock, says so, compiles the kernel once told to (the lock it holds is not taken again), then
# ends (releasing it)
HOLDER = KERNEL + """import sys
import balloon_cg.model.kernels
from balloon_cg.model import compile_lock
with compile_lock.held(compile_lock.lock_path(kernel)):
    print("held", flush=True)
    if sys.stdin.readline().strip() == "compile":
        kernel.compile(SIG)
        print(sum(kernel._cache_misses.values()), flush=True)
        sys.stdin.readline()
"""
# says it is about to compile the kernel (through the lock), compiles it and prints how many signatures it compiled
# and how many it loaded from the cache
WAITER = KERNEL + """import balloon_cg.model.kernels
print("ready", flush=True)
kernel.compile(SIG)
print(sum(kernel._cache_misses.values()), sum(kernel._cache_hits.values()))
"""


def _started(code: str, cache) -> subprocess.Popen:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    return subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)


def test_importing_the_kernels_installs_the_lock_once():
    assert Dispatcher.compile.locked
    compile_lock.install()
    assert not getattr(Dispatcher.compile.unlocked, "locked", False)


def test_a_kernel_another_process_compiles_is_waited_for_and_loaded(tmp_path):
    holder = _started(HOLDER, tmp_path)
    try:
        assert holder.stdout.readline().strip() == "held", holder.stderr.read()
        waiter = _started(WAITER, tmp_path)
        assert waiter.stdout.readline().strip() == "ready", waiter.stderr.read()  # at the lock, or about to be
        holder.stdin.write("compile\n")
        holder.stdin.flush()
        assert holder.stdout.readline().strip() == "1"  # compiled, saved to the cache, the lock still held
        assert waiter.poll() is None
        holder.stdin.write("done\n")
        holder.stdin.flush()
        out, err = waiter.communicate(timeout=600)
        assert waiter.returncode == 0, err
        assert out.split() == ["0", "1"]  # nothing compiled: loaded from the holder's cache entry
    finally:
        holder.kill()
        holder.communicate()


def test_a_process_killed_holding_the_lock_releases_it(tmp_path):
    holder = _started(HOLDER, tmp_path)
    try:
        assert holder.stdout.readline().strip() == "held", holder.stderr.read()
        waiter = _started(WAITER, tmp_path)
        assert waiter.stdout.readline().strip() == "ready", waiter.stderr.read()
        holder.send_signal(signal.SIGKILL)
        holder.wait()
        out, err = waiter.communicate(timeout=600)
        assert waiter.returncode == 0, err
        assert out.split() == ["1", "0"]  # the holder compiled nothing: the waiter compiles it itself
    finally:
        holder.kill()
        holder.communicate()
