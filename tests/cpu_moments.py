"""Signals at chosen moments of a command's own work, for the interrupt studies (issue 42): a moment is an amount of
CPU time spent by the command (``setitimer(ITIMER_PROF)``: the process's CPU, all threads; in a sweep, the CPU of
one member in its worker), so it lands anywhere in the work (inside a LAPACK call, a write, a pool wait) and at the
same place of the work on an idle or a loaded machine, where a wall-clock sleep would not. The timer is armed at a
mark of the work: a phase of the run's clock entered or a point done (``anchored``: the last mark before the
moment in a reference run), a sweep member started (``in_members``), a function called (``handled``: the command's
handler, or the n-th call of a unit of the work).
The latency is measured in the same clock: the command's CPU time from the moment (the timer's expiry; in a
sweep, the signal's receipt) to Python's last atexit handler; its wall time is recorded beside it (a loaded
machine stretches it, so it is no pass criterion).

``command(folder, argv, sig, moment)`` runs `balloon-cg argv` through the entry point (``balloon_cg.__main__.run``)
in a fresh interpreter and returns a ``Moment``: exit code, stderr, and the driver's record (the marks of the run
with their CPU times, each sweep member's CPU, the CPU at the moment and at exit), from which a reference run (no
signal) places the moments of a study (``evenly``).
"""
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

DRIVER = r'''
import atexit, contextlib, functools, importlib, json, os, signal, sys, time
sig, where, offset, report, argv = (getattr(signal, sys.argv[1]), sys.argv[2], float(sys.argv[3]), sys.argv[4],
                                    sys.argv[5:])
record = {"start_cpu": time.process_time(), "armed_cpu": None, "expiry_cpu": None, "sent_wall": None, "received_wall": None,
          "received_cpu": None, "clock_cpu": None, "call_cpu": None, "events": [], "marks": 0, "member_cpu": {},
          "compiled": 0}
DRIVER = os.getpid()
install = signal.signal


def noting(signum, handler):
    # every handler the command installs for SIGINT/SIGTERM, wrapped to note its first call in this process
    if signum in (signal.SIGINT, signal.SIGTERM) and callable(handler):
        inner = handler

        def handler(s, frame):
            if record["received_wall"] is None and os.getpid() == DRIVER:
                record["received_wall"], record["received_cpu"] = time.monotonic(), time.process_time()
            return inner(s, frame)
    return install(signum, handler)


signal.signal = noting


def expired(signum, frame):  # the timer: the signal goes to the command's process (a sweep's parent)
    if os.getpid() == DRIVER:
        record["expiry_cpu"], record["sent_wall"] = record["armed_cpu"] + offset, time.monotonic()
    os.kill(DRIVER, sig)


def arm():
    if offset == float("inf"):  # a reference: never
        return
    if os.getpid() == DRIVER:
        record["armed_cpu"] = time.process_time()
    signal.setitimer(signal.ITIMER_PROF, offset)


install(signal.SIGPROF, expired)


def exiting():
    signal.setitimer(signal.ITIMER_PROF, 0)  # a moment after the work: not in Python's finalization (SIGPROF kills)
    record["exit_cpu"], record["exit_wall"] = time.process_time(), time.monotonic()
    with open(report, "w") as f:
        json.dump(record, f)


atexit.register(exiting)  # the first registered: Python calls it last
from balloon_cg.__main__ import run
from numba.core import event


class Compiling(event.Listener):  # a kernel compiled here (not found in numba's cache), kept in the cache
    def on_start(self, found):
        record["compiled"] += type(found.data["dispatcher"]._cache).__name__ != "NullCache"

    def on_end(self, found):
        pass


event.register("numba:compile", Compiling())
from balloon_cg.analysis import timing
from balloon_cg.app import progress, sweep

clock_init, clock_step, tick = timing.Clock.__init__, timing.Clock.step, progress.PhaseBars.tick


def mark(kind, name):
    # an event of the run: a phase entered or left, a point done; the timer armed at the chosen entry or point
    record["events"].append([time.process_time(), kind, name])
    if kind != "exit":
        record["marks"] += 1
        if where == f"mark {record['marks']}":
            arm()


def started(self, *args, **kwargs):  # the run's clock: its phases are timed from here
    clock_init(self, *args, **kwargs)
    if record["clock_cpu"] is None and os.getpid() == DRIVER:
        record["clock_cpu"] = time.process_time()
        if where == "mark 0":
            arm()


@contextlib.contextmanager
def step(self, phase):
    mark("enter", phase.value)
    try:
        with clock_step(self, phase):
            yield
    finally:
        mark("exit", phase.value)


def ticked(self, phase):
    tick(self, phase)
    mark("point", phase.value)


timing.Clock.__init__, timing.Clock.step, progress.PhaseBars.tick = started, step, ticked
compute = sweep.compute_member


@functools.wraps(compute)
def timed_member(index, *args):
    # a member's computation, timed (the reference), or with the timer set in its worker (forked: this wrapper is
    # the module's attribute there too)
    armed = where == f"member {index}"
    if armed:
        arm()
    start = time.process_time()
    try:
        return compute(index, *args)
    finally:
        if armed:
            signal.setitimer(signal.ITIMER_PROF, 0)
        record["member_cpu"][index] = time.process_time() - start


sweep.compute_member = timed_member
if where.startswith("call "):  # the timer armed as the n-th call of a function begins (after the imports)
    target, _, nth = where.removeprefix("call ").partition("@")
    module, _, name = target.partition(":")
    owner, _, attribute = name.rpartition(".")
    holder = importlib.import_module(module)
    holder = getattr(holder, owner) if owner else holder
    handler, calls = getattr(holder, attribute), [0]

    @functools.wraps(handler)
    def called(*args, **kwargs):
        calls[0] += 1
        if calls[0] == int(nth or 1):
            record["call_cpu"] = time.process_time()
            arm()
        return handler(*args, **kwargs)

    setattr(holder, attribute, called)
sys.argv = ["balloon-cg", *argv]
sys.exit(run())
'''


@dataclass
class Moment:
    code: int
    stderr: str
    record: dict

    @property
    def fired(self) -> bool:
        """Whether the signal was sent (the moment came before the command ended): by this process's timer, or
        received from a sweep member's worker."""
        return self.record["expiry_cpu"] is not None or self.record["received_wall"] is not None

    @property
    def cpu_after(self) -> float:
        """CPU seconds of the command from the moment (the run's timer expiry, else the signal's receipt) to exit."""
        start = self.record["expiry_cpu"] if self.record["expiry_cpu"] is not None else self.record["received_cpu"]
        return self.record["exit_cpu"] - start

    @property
    def wall_after(self) -> float:
        """Wall seconds from the signal (sent by this process's timer, else received) to exit (not a pass criterion:
        load stretches it)."""
        return self.record["exit_wall"] - (self.record["sent_wall"] or self.record["received_wall"])

    @property
    def handler_cpu(self) -> float:
        """The CPU seconds from the call of the command's handler (``handled``) to exit."""
        return self.record["exit_cpu"] - self.record["call_cpu"]

    @property
    def run_cpu(self) -> float:
        """The CPU seconds from the run's clock's start to exit."""
        return self.record["exit_cpu"] - self.record["clock_cpu"]


NEVER = ("never", 0.0)


def foreground() -> None:
    """In the child before it starts: SIGINT as in a foreground process (a shell starts a background job, and so
    its children, with SIGINT ignored, and Python then leaves it ignored)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def command(folder: Path, argv: list, sig: str = "SIGTERM", moment: tuple = NEVER, workers: int = 1,
            timeout: float = 1800) -> Moment:
    """`balloon-cg argv` in ``folder``, ``sig`` sent to it at ``moment`` (``anchored``, ``in_members``; NEVER: no
    signal). ``workers``: BALLOON_CG_WORKERS (1: every point in this process, so that its CPU time is the run's
    work). ``timeout``: a hang guard only."""
    report = folder / f".moment_{os.getpid()}.json"
    env = os.environ | {"BALLOON_CG_WORKERS": str(workers)}
    where, offset = moment
    done = subprocess.run([sys.executable, "-c", DRIVER, sig, where, repr(offset), str(report), *argv],
                          capture_output=True, text=True, timeout=timeout, cwd=folder, env=env,
                          preexec_fn=foreground)
    record = json.loads(report.read_text())
    report.unlink()
    record["member_cpu"] = {int(k): v for k, v in record["member_cpu"].items()}
    return Moment(done.returncode, done.stderr, record)


def warm_reference(folder: Path, argv: list, moment: tuple = NEVER, outputs: tuple = ()) -> Moment:
    """`balloon-cg argv` in ``folder`` without a signal, to place moments on (``moment``: where its clock starts,
    ``handled``), run again (``outputs``: files and folders it wrote, removed first) when the first run compiled
    kernels for numba's cache (in its own process: the cache is shared with other processes): a replay loads them,
    so on a fresh clone a moment placed on the compiling run's CPU could come after the replay's whole work, and no
    signal was sent (10 of test_interrupt_moments' 17 in a fresh worktree, session 30)."""
    done = command(folder, argv, moment=moment)
    if not done.record["compiled"]:
        return done
    for name in outputs:
        path = folder / name
        shutil.rmtree(path) if path.is_dir() else path.unlink(missing_ok=True)
    return command(folder, argv, moment=moment)


def evenly(total: float, count: int) -> list[float]:
    """``count`` moments evenly spaced in (0, total): total·k/(count + 1)."""
    return [total * k / (count + 1) for k in range(1, count + 1)]


def anchored(reference: Moment, t: float) -> tuple[tuple, str]:
    """The moment ``t`` CPU seconds after the run's clock started in the ``reference`` run (no signal), as the last
    mark before it (a phase entered or a point done: the n-th) and the CPU seconds after that mark: replayed, the
    timer is armed at that mark, so that the moment lands at the same place of the work however the CPU time of the
    earlier work varies; and the phase the reference was in then (the innermost open one)."""
    at = reference.record["clock_cpu"] + t
    marks, since, open_phases = 0, reference.record["clock_cpu"], []
    for cpu, kind, name in reference.record["events"]:
        if cpu > at:
            break
        if kind == "exit":
            open_phases.pop()
            continue
        marks, since = marks + 1, cpu
        if kind == "enter":
            open_phases.append(name)
    return (f"mark {marks}", at - since), (open_phases[-1] if open_phases else "")


def handled(handler: str, t: float = float("inf"), call: int = 1) -> tuple:
    """The moment ``t`` CPU seconds after the ``call``-th call of ``handler`` (``module:function`` or
    ``module:Class.method``, e.g. ``balloon_cg.app.cli:continue_run``) begins: for commands without a run's clock
    (the default: never, the call's CPU noted for a reference), or a moment in a given unit of the work."""
    return f"call {handler}@{call}", t


def in_members(reference: Moment, t: float) -> tuple:
    """The moment ``t`` CPU seconds into a sweep's work, its members' CPU in the ``reference`` sweep (serial, no
    signal) laid end to end in the order of their indices (the order the pool starts them): (member, CPU seconds into
    it), the timer armed in the member's worker as it starts the member."""
    member_cpu = reference.record["member_cpu"]
    for index in sorted(member_cpu):
        if t < member_cpu[index]:
            return f"member {index}", t
        t -= member_cpu[index]
    raise ValueError("the moment lies after the last member")


VARYING = ("created", "command", "history", "total_seconds", "phase_seconds", "wall_time", "trace_time",
           "worker_pid")  # attributes that say when, how long, by which command or process: not the result


def digests(path: Path) -> dict:
    """{object path: sha256} of every dataset (dtype, shape, bytes) and of every group's and dataset's attributes
    other than VARYING: two files with equal digests hold the same results bit for bit."""
    out = {}

    def attrs(item) -> str:
        return repr(sorted((k, np.asarray(v).tolist()) for k, v in item.attrs.items()
                           if k not in VARYING and k not in ("DIMENSION_LIST", "REFERENCE_LIST")))

    with h5py.File(path, "r") as f:
        out["/"] = hashlib.sha256(attrs(f).encode()).hexdigest()

        def visit(name, item):
            h = hashlib.sha256(attrs(item).encode())
            if isinstance(item, h5py.Dataset):
                data = item[()]
                h.update(f"{item.dtype} {item.shape}".encode())
                h.update(repr(np.asarray(data).tolist()).encode() if item.dtype.kind == "O" else
                         np.asarray(data).tobytes())
            out[name] = h.hexdigest()

        f.visititems(visit)
    return out
