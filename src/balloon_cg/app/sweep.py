"""Parameter sweeps: one scene, varied over the cartesian product of ``--vary`` specs, members run in parallel.

``balloon-cg sweep SCENE.toml --vary M=0:0.005:21 -o SWEEP.h5`` expands the specs into members (each a Scene
made by ``Scene.with_overrides``), computes them in worker processes (a local ProcessPoolExecutor, or an
existing dask.distributed cluster with ``--scheduler``) and appends each member to one sweep file as it
finishes, each to its own file (``io.sweep_file``: a store folder beside the sweep file, and the sweep file a
view rebuilt from it). The output is owned (``io.lock.claim``) from before the expansion until the view is
written. Workers return their results as plain data (``MemberResult``); only the parent process writes, and the
pool's workers die with it (``worker_hygiene``). dask workers need one setting (``DASK_WORKER_CONFIG``; a
sweep warns, ``SlowWorkersWarning``, when a worker lacks it). Re-running the same sweep skips the members whose
file holds the same scene_hash; a different sweep into an existing file needs --force, which replaces the old
sweep only once every member of the new one is written.
"""
import contextlib
import hashlib
import itertools
import os
import re
import sys
from fractions import Fraction
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


from ..analysis.picture import analyse
from ..analysis.branches.primary import trace_primary
from ..analysis.verdict import incomplete
from ..dynamics.frequencies import attach
from ..io.lock import claim
from ..io.output import check_output
from ..io.sweep_file import (SweepError, commit_replacement, open_store, read_store, rebuilding, root_attrs,
                             store_path)
from ..numerics import interrupt, workers
from ..numerics.hygiene import worker_hygiene
from .progress import auto_tqdm, tqdm_disable
from ..scene import Scene, SceneError, parse_scene
from ..scene.tables import Shape

MODES = ("analysis", "no-pear", "primary-only")
MAX_MEMBERS = 10_000  # docs/scenes.md, Bounds: a sweep's member count (the product of the --vary counts)


# --- specs and members -------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Member:
    index: int
    overrides: dict  # canonical dotted key -> value (as given to Scene.with_overrides)
    scene: Scene

    @property
    def scene_hash(self) -> str:
        return scene_hash(self.scene)

    @property
    def label(self) -> str:
        return ", ".join(f"{k}={_fmt(v)}" for k, v in self.overrides.items())


def scene_hash(scene: Scene) -> str:
    """sha256 of the scene's normalised TOML (independent of comments and formatting of the source file)."""
    return hashlib.sha256(scene.to_toml().encode("utf-8")).hexdigest()


_INDEXED = re.compile(r"(\w+)\.(\w+)\[(\d+)\]")


def parse_vary(spec: str, scene: Scene) -> tuple[str, list]:
    """``KEY=START:STOP:num=COUNT``, ``KEY=linspace(START, STOP, COUNT)`` or the short ``KEY=START:STOP:COUNT``
    (COUNT evenly spaced values, ends included: never MATLAB's START:STEP:STOP), or ``KEY=v1,v2,...`` -> (key,
    values).

    KEY is a dotted scene key (``field.M``, ``continuation.stop_stretch``, ``field.coils[0].radius``,
    ``material.alpha[0]``) or a bare name found in exactly one table (``M`` -> ``field.M``).
    """
    key, sep, text = spec.partition("=")
    key, text = key.strip(), text.strip()
    if not sep or not key or not text:
        raise SweepError(f"--vary {spec!r}: expected KEY=START:STOP:num=COUNT, KEY=linspace(START, STOP, COUNT) or "
                         "KEY=v1,v2,...")
    try:
        key = scene.canonical_key(key)
    except SceneError as e:
        raise SweepError(f"--vary {e}") from None
    parts = _range_fields(text)
    if parts is None:
        values = [_value(v.strip()) for v in text.split(",")]
        if any(v == "" for v in values):
            raise SweepError(f"--vary {spec!r}: empty value in the list")
        return key, values
    if len(parts) != 3:
        raise SweepError(f"--vary {spec!r}: a range is START:STOP:num=COUNT or linspace(START, STOP, COUNT) (three "
                         "fields)")
    try:
        start, stop = (_number(p) for p in parts[:2])
        count = int(parts[2])
    except ValueError:
        raise SweepError(f"--vary {spec!r}: START and STOP must be numbers and COUNT an integer (the number of "
                         "values, not a step)") from None
    if not (np.isfinite(start) and np.isfinite(stop)):
        raise SweepError(f"--vary {spec!r}: START and STOP must be finite numbers")
    if count < 1 or (count == 1 and start != stop):
        raise SweepError(f"--vary {spec!r}: COUNT must be >= 2 (or 1 with START = STOP)")
    if count > MAX_MEMBERS:
        raise SweepError(f"--vary {spec!r}: COUNT = {count}: at most {MAX_MEMBERS} members per sweep")
    values = grid(*(Fraction(p.strip()) for p in parts[:2]), count)  # finite numbers: exact fractions
    if isinstance(start, int) and isinstance(stop, int) and all(float(v).is_integer() for v in values):
        values = [int(v) for v in values]
    return key, values


def grid(start: Fraction, stop: Fraction, count: int) -> list[float]:
    """``count`` evenly spaced values from ``start`` to ``stop`` (ends included), each computed exactly from the
    decimals written and then rounded once: start + (stop − start)·i/(count − 1), so that 1.2:1.4:3 gives 1.3 (where
    numpy's linspace gives 1.2999999999999998) and every value is the float nearest the exact one."""
    if count == 1:
        return [float(start)]
    return [float(start + (stop - start) * i / (count - 1)) for i in range(count)]


def _range_fields(text: str) -> list[str] | None:
    """[START, STOP, COUNT] of a range spec (``linspace(a, b, n)``, ``a:b:num=n`` or ``a:b:n``; a wrong field count
    is kept for the caller to name), None for a list of values."""
    if text.startswith("linspace(") and text.endswith(")"):
        return [p.strip() for p in text[len("linspace("):-1].split(",")]
    if ":" not in text:
        return None
    parts = [p.strip() for p in text.split(":")]
    if len(parts) == 3 and parts[2].startswith("num="):
        parts[2] = parts[2][len("num="):].strip()
    return parts


def expand(scene: Scene, specs: list[str]) -> list[Member]:
    """The members of a sweep: the cartesian product of the specs (first spec outermost), each validated.

    Raises SweepError (a bad spec) or SceneError: one message for every invalid member, before any work.
    """
    if not specs:
        raise SweepError("give at least one --vary KEY=...")
    axes = [parse_vary(s, scene) for s in specs]
    keys = [k for k, _ in axes]
    if len(set(keys)) != len(keys):
        raise SweepError(f"--vary: the same key is varied twice ({', '.join(keys)})")
    total = int(np.prod([len(v) for _, v in axes], dtype=object))
    if total > MAX_MEMBERS:
        raise SweepError(f"--vary {' '.join(specs)}: {total} members; at most {MAX_MEMBERS} per sweep")
    members, errors = [], {}
    for index, values in enumerate(itertools.product(*(v for _, v in axes))):
        overrides = dict(zip(keys, values))
        try:
            member_scene = overridden(scene, overrides)
        except SceneError as e:
            errors.setdefault(str(e), []).append(index)
            continue
        members.append(Member(index, overrides, member_scene))
    if errors:
        total = sum(map(len, errors.values()))
        lines = [f"{msg} (member{'s' if len(idx) > 1 else ''} {_ranges(idx)})" for msg, idx in errors.items()]
        raise SceneError(f"{total} of {total + len(members)} sweep members are invalid: " + "; ".join(lines))
    return members


def overridden(scene: Scene, overrides: dict) -> Scene:
    """``scene`` with ``overrides`` (canonical keys, indexed ones included) applied and validated."""
    return scene.with_overrides(_expand_indexed(overrides, scene))


def _expand_indexed(overrides: dict, scene: Scene) -> dict:
    """``material.alpha[0] = x`` as a whole-list override ``material.alpha = [..., x, ...]`` (what
    Scene.with_overrides accepts); other keys unchanged."""
    out, data = {}, scene.to_dict()
    for key, value in overrides.items():
        match = _INDEXED.fullmatch(key)
        if match is None:
            out[key] = value
            continue
        tab, k, i = match.group(1), match.group(2), int(match.group(3))
        current = out.get(f"{tab}.{k}", data.get(tab, {}).get(k))
        if not isinstance(current, list) or any(isinstance(x, dict) for x in current):
            raise SceneError(f"{key} = {_fmt(value)}: {tab}.{k} is not a list of numbers")
        if i >= len(current):
            raise SceneError(f"{key} = {_fmt(value)}: {tab}.{k} has {len(current)} entries")
        current = list(current)
        current[i] = value
        out[f"{tab}.{k}"] = current
    return out


def _number(text: str):
    text = text.strip()
    try:
        return int(text)
    except ValueError:
        return float(text)


def _value(text: str):
    for parse in (int, float):
        try:
            return parse(text)
        except ValueError:
            pass
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    return text.strip("\"'")


def _fmt(v) -> str:
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def _ranges(indices: list[int]) -> str:
    return ", ".join(map(str, indices[:6])) + (", …" if len(indices) > 6 else "")


# --- the worker --------------------------------------------------------------------------------------------

@dataclass
class MemberResult:
    """What a worker returns (plain data, pickled back to the parent): the branches, snap-throughs, branch
    points and what is incomplete (analysis.verdict) of one member."""

    index: int
    branches: list
    snaps: list | None
    branch_points: list
    incomplete: list
    wall_time: float
    pid: int


@dataclass
class TubeMemberResult:
    """What a worker returns for one member of a tube scene: tube/picture.tube_picture's TubePicture (the primary
    branch and, unless the mode is primary-only, the bulge branch; ``no-pear`` is the whole picture: a tube has
    no pear branches), its wall time and process id."""

    index: int
    picture: object
    wall_time: float
    pid: int


def compute_member(index: int, scene_toml: str, scene_name: str, mode: str) -> MemberResult | TubeMemberResult:
    """Worker side: compute one member (local pool or dask worker); picklable in and out."""
    # BLAS runs single-threaded in every member: importing balloon_cg limits it (balloon_cg/__init__); with
    # 2 BLAS threads per member on busy cores a member ran 35x slower (benchmarks/sweep.py).
    # the members are the parallel unit: a member's points are not spread over more processes (numerics.workers)
    scene = parse_scene(scene_toml, scene_name)
    start = time.perf_counter()
    if scene.geometry.shape == Shape.TUBE:
        from ..dynamics.tube import with_frequencies
        from ..tube.picture import tube_picture

        picture = with_frequencies(scene, tube_picture(scene, primary_only=mode == "primary-only"))
        return TubeMemberResult(index, picture, time.perf_counter() - start, os.getpid())
    with workers.serial():
        if mode == "primary-only":
            branches, snaps, points = [trace_primary(scene)], None, []
            found = incomplete(branches)
        else:
            picture = analyse(scene, pear=(mode == "analysis"))
            branches, snaps, points, found = (picture.branches + picture.surface_branches, picture.snaps,
                                              picture.branch_points, picture.incomplete)
        if scene.dynamics.frequencies:  # [dynamics]: each member's natural frequencies (docs/dynamics.md)
            attach(branches, scene.dynamics.count, scene.dynamics.m_max, scene.dynamics.modes)
    return MemberResult(index, branches, snaps, points, found, time.perf_counter() - start, os.getpid())


# --- the writer (parent process only) ----------------------------------------------------------------------

@dataclass
class SweepResult:
    path: Path
    members: list
    mode: str = "analysis"
    store: Path = None  # the folder of the member files (io.sweep_file.store_path, or staging_path for --force)
    computed: list = field(default_factory=list)  # indices computed by this call
    skipped: list = field(default_factory=list)  # indices already in the store (same scene_hash)
    failed: dict = field(default_factory=dict)  # index -> error message
    replaced: bool = True  # False: a --force sweep left incomplete; the old sweep file is kept
    wall_time: float = 0.0


def run_sweep(scene: Scene, specs: list[str], out_path, *, mode: str = "analysis", workers: int | None = None,
              scheduler: str | None = None, force: bool = False, progress: bool = False,
              command: str | None = None, members: list[Member] | None = None) -> SweepResult:
    """Expand ``specs`` over ``scene``, compute the members not yet stored for ``out_path`` and write them.

    ``workers``: local processes (default: all cores; 1 computes in this process); ``scheduler``: address of a
    dask.distributed scheduler to send the members to instead. Failed members are reported in the result (the
    others are written); an interrupted sweep keeps the members written so far. The sweep file is rebuilt from
    the store when the call ends; with ``force`` only once every member is written (else ``replaced`` is
    False and the old file is untouched; the same --force call resumes the replacement).
    Raises io.lock.OutputInUse at once if another process owns ``out_path``.
    """
    if mode not in MODES:
        raise SweepError(f"mode {mode!r}: must be one of {', '.join(MODES)}")
    start = time.perf_counter()
    path = Path(out_path)
    with claim(path, "sweep"):
        check_output(path, force, sweep=True)  # another kind of file there only with --force (io.output)
        members = expand(scene, specs) if members is None else members
        axes = [list(parse_vary(s, scene)) for s in specs]
        with interrupt.Held() as held:  # a signal meanwhile only sets the flag: raised once the store is open,
            held.start()  #                 never inside h5py (an import copies members)
            store = open_store(path, root_attrs(scene, axes, mode, len(members), command), members, force)
        result = SweepResult(path, members, mode, store.directory, skipped=sorted(store.done))
        todo = [m for m in members if m.index not in store.done]
        by_index = {m.index: m for m in members}
        with rebuilding(path, store.directory, trusted=store.done, kept=not force) as view:
            try:
                with auto_tqdm()(total=len(members), initial=len(store.done), desc="sweep", unit=" members",
                                 disable=tqdm_disable(progress), file=sys.stderr) as bar:
                    with contextlib.closing(_compute(todo, mode, workers, scheduler)) as outcomes:
                        for index, outcome in outcomes:
                            if isinstance(outcome, BaseException):
                                result.failed[index] = f"{type(outcome).__name__}: {outcome}"
                            else:  # a signal meanwhile only sets the flag: raised after them (``interrupt.Held``),
                                #    never inside h5py (a KeyboardInterrupt there can surface as a SystemError)
                                with interrupt.Held() as held:
                                    held.start()
                                    store.write_member(by_index[index], outcome)
                                    view.add(index)
                                    result.computed.append(index)
                            bar.update()
                            _check_interrupt()  # a signal swallowed while the member was stored or copied
            finally:
                if force and len(store.done) == len(members):  # the new sweep complete: it replaces the old
                    view.finish()
                    commit_replacement(path)
                    view.kept, result.store = True, store_path(path)
                elif force:
                    result.replaced = False
    result.wall_time = time.perf_counter() - start
    return result


# bytes one local sweep worker holds at least: a worker computing a SPOM1 member (degree 40) peaks at 154 MiB resident
# (measured, issue 42; the 49 workers were ~140 MB each; a wire-refined member needs more): --oversubscribe
# starts no more than the available memory holds at this floor
WORKER_MEMORY = 160 * 2**20


def available_memory() -> int | None:
    """Bytes of memory available to new processes (Linux: MemAvailable of /proc/meminfo; elsewhere the free physical
    pages), None where the system does not say."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None


def memory_workers() -> int:
    """The local sweep workers the available memory holds (``available_memory`` / WORKER_MEMORY, at least 1; no bound,
    a very large number, where the system does not say)."""
    available = available_memory()
    return 2**31 if available is None else max(1, available // WORKER_MEMORY)


def cpu_count() -> int:
    """The CPUs this process may run on (its affinity mask where the system has one): the default and the cap of
    --workers."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _compute(todo: list[Member], mode: str, workers: int | None, scheduler: str | None):
    """Yield (index, result dict or exception) as members finish."""
    if not todo:
        return
    jobs = [(m.index, m.scene.to_toml(), m.scene.name, mode) for m in todo]
    if scheduler is not None:
        yield from _compute_dask(jobs, scheduler)
        return
    workers = cpu_count() if workers is None else workers
    if workers <= 1 or len(jobs) == 1:
        for job in jobs:
            try:
                yield job[0], compute_member(*job)
            except Exception as e:  # noqa: BLE001 - reported per member
                yield job[0], e
        return
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    pool = ProcessPoolExecutor(max_workers=min(workers, len(jobs)), initializer=worker_hygiene,
                               initargs=(os.getpid(),))
    try:
        futures = {pool.submit(compute_member, *job): job[0] for job in jobs}
        pending = set(futures)
        while pending:
            done, pending = wait(pending, timeout=INTERRUPT_POLL, return_when=FIRST_COMPLETED)
            _check_interrupt()
            for future in done:
                error = future.exception()
                yield futures[future], error if error is not None else future.result()
    except BaseException:  # an interrupt (or the caller closing early): the running members are abandoned
        _terminate(pool)
        raise
    pool.shutdown(wait=True)


INTERRUPT_POLL = 0.2  # s: how often the pool loop looks at the interrupt flag


def _check_interrupt() -> None:
    """Raise KeyboardInterrupt if a signal asked to stop (``interrupt.sigterm_raises`` sets the flag too: its
    exception can be swallowed when the signal lands in a callback, as once in CI, e.g. an h5py finalizer while a
    member is copied into the view): ``run_sweep`` checks after every member it stores (whichever way it was
    computed), the pool's loop also between its waits."""
    if interrupt.requested():
        raise KeyboardInterrupt


def _terminate(pool) -> None:
    """Stop a process pool now: its workers are terminated (their members are recomputed on resume).

    The order of Python 3.14's ``terminate_workers`` (no public API before): shut the pool without waiting (no
    queued member starts), terminate, then wait for each worker itself; waiting on the pool's manager thread
    after killing its workers can hang when a worker died holding the call queue's lock."""
    processes, results = list((pool._processes or {}).values()), pool._result_queue
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.terminate()
    for process in processes:
        process.join(timeout=5)
        if process.exitcode is None:
            process.kill()
            process.join()
    # a worker killed while it sent its result (a member's is megabytes) leaves the pool's manager thread reading the
    # rest of the message for ever (this process holds the pipe's write end too), and Python's exit joins that thread:
    # the sweep hung after its line (seen once in 10 interrupts of two-coil members); with the last write end closed
    # the read ends (EOFError) and the thread with it
    if results is not None:
        results._writer.close()


# The dask config of a sweep's workers: dask's nanny starts every worker with MALLOC_TRIM_THRESHOLD_=65536, and
# any such glibc setting freezes its dynamic mmap threshold at 128 KiB (mallopt(3)), so each larger array (the
# Galerkin matrices) is a fresh mmap, page-faulted in and unmapped again: ten times the page faults, a member
# 1.4x slower (benchmarks/dask_worker.py). Set it around creating a LocalCluster (dask.config.set), or in the
# dask YAML config of `dask worker` (README, a sweep); None makes the nanny leave the variable unset.
DASK_WORKER_CONFIG = {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}


class SlowWorkersWarning(UserWarning):
    """Some dask workers of a sweep run with glibc's mmap threshold frozen (``frozen_mmap_threshold``)."""


def frozen_mmap_threshold() -> bool:
    """Whether this process's glibc malloc has a fixed mmap threshold of 128 KiB: MALLOC_TRIM_THRESHOLD_ set
    (dask's nanny default) and MALLOC_MMAP_THRESHOLD_ not (which would set the threshold itself); Linux only."""
    return (sys.platform.startswith("linux") and "MALLOC_TRIM_THRESHOLD_" in os.environ
            and "MALLOC_MMAP_THRESHOLD_" not in os.environ)


def _warn_slow_workers(client) -> None:
    """SlowWorkersWarning if a worker connected now has a frozen mmap threshold (``DASK_WORKER_CONFIG``)."""
    frozen = [w for w, answer in client.run(frozen_mmap_threshold, on_error="return").items() if answer is True]
    if frozen:
        warnings.warn(f"{len(frozen)} dask worker(s) run with MALLOC_TRIM_THRESHOLD_ set (dask's nanny default), "
                      "which makes each member about 1.4x slower; start the workers with the dask config "
                      "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_ = null "
                      "(balloon_cg.app.sweep.DASK_WORKER_CONFIG; README)", SlowWorkersWarning, stacklevel=2)


def _compute_dask(jobs, scheduler: str):
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise SweepError("--scheduler needs the 'distributed' package (pip install 'balloon-cg[sweep]')") from None
    try:
        client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError, ValueError, TypeError) as e:
        raise SweepError(f"--scheduler {scheduler}: cannot connect ({e})") from None
    try:
        _warn_slow_workers(client)
        futures = {client.submit(compute_member, *job, pure=False): job[0] for job in jobs}
        for future in as_completed(futures):
            index = futures[future]
            if future.status == "error":
                yield index, future.exception()
            else:
                yield index, future.result()
            future.release()
    finally:
        client.close()


# --- reading and summary -----------------------------------------------------------------------------------

def format_summary(result: SweepResult) -> str:
    """Members, time, and per member the pear branch points (pressures) read back from the store."""
    stored_members = read_store(result.store)
    mode = result.mode
    lines = [
        f"sweep file     {result.path}",
        f"members        {len(result.members)}: {len(result.computed)} computed, {len(result.skipped)} already in "
        f"the file, {len(result.failed)} failed",
        f"time           {result.wall_time:.2f} s",
        f"mode           {mode}",
        "",
    ]
    w = max([len("overrides")] + [len(m.label) for m in result.members])
    if result.members and result.members[0].scene.geometry.shape == Shape.TUBE:
        return "\n".join(lines + _tube_rows(result, stored_members, w))
    header = (f"{'member':>6}  {'overrides':<{w}}  {'result':<10}  {'points':>6}  {'pear BPs':>8}  "
              "pear branch point pressures (voltages on a voltage continuation)")
    lines.append(header)
    for m in result.members:
        if m.index in result.failed:
            lines.append(f"{m.index:>6}  {m.label:<{w}}  failed: {result.failed[m.index]}")
            continue
        stored = stored_members.get(m.index)
        if stored is None:
            lines.append(f"{m.index:>6}  {m.label:<{w}}  not computed")
            continue
        a = stored["attrs"]
        n_points = len(stored["branches"]["primary"]["pressure"])
        values = a.get("branch_point_voltages", a.get("branch_point_pressures", []))
        pears = [p for p, block in zip(values, a.get("branch_point_blocks", [])) if block == "odd_held"]
        count = "n/a" if mode == "primary-only" else str(len(pears))
        pressures = ", ".join(f"{p:.6g}" for p in pears) if pears else ("-" if mode != "primary-only" else "")
        verdict = "complete" if a.get("complete") else "incomplete"
        lines.append(f"{m.index:>6}  {m.label:<{w}}  {verdict:<10}  {n_points:>6}  {count:>8}  {pressures}")
    return "\n".join(lines)


def _tube_rows(result: SweepResult, stored_members: dict, w: int) -> list[str]:
    """format_summary's member lines of a tube sweep: per member its pressure maximum, the onset of bulging (P,
    V/V0), the bulge's volume fold and Maxwell's pressure (io.tube_file.tube_row)."""
    from ..io.tube_file import tube_row

    lines = [f"{'member':>6}  {'overrides':<{w}}  {'result':<10}  {'points':>6}  {'P_max':>10}  {'P_onset':>10}  "
             f"{'V_onset':>10}  {'P_LV':>10}  {'P_M':>10}"]
    for m in result.members:
        stored = stored_members.get(m.index)
        if m.index in result.failed or stored is None:
            what = f"failed: {result.failed[m.index]}" if m.index in result.failed else "not computed"
            lines.append(f"{m.index:>6}  {m.label:<{w}}  {what}")
            continue
        row = tube_row(stored)
        verdict = "complete" if stored["attrs"].get("complete") else "incomplete"
        points = len(stored["branches"]["primary"]["pressure"])
        values = "  ".join(f"{row[k]:>10.6g}" for k in ("P_max", "P_onset", "V_onset", "P_LV", "P_M"))
        lines.append(f"{m.index:>6}  {m.label:<{w}}  {verdict:<10}  {points:>6}  {values}")
    return lines
