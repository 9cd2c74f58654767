"""Independent pieces of one computation on every core: ``spread(work, items, costs)``.

The points of a branch are independent for stability (each is one set of dense Hessian blocks and eigensolves), so
``[work(i) for i in items]`` is handed to forked worker processes: a forked child inherits the jitted kernels and
the data ``work`` reads (nothing is pickled but item numbers and results), and each child runs the same code on the
same numbers with single-threaded BLAS, so the results are those of the serial loop, bit for bit. The items go out
costliest first (the near-wire points of a branch cost N³ at degrees up to 320) and come back in their order.

The work stays in this process where forking does not pay or is not allowed: one core, a total cost below
``MIN_COST`` (starting the workers costs ~50–100 ms), inside ``serial()`` (a sweep's member: the members are the
parallel unit there), or BALLOON_CG_WORKERS=1 (the number of worker processes; default: the cores this process may
run on). The workers leave SIGINT and SIGTERM to this process and die with it (``hygiene.worker_hygiene``); a
signal here (``numerics.interrupt``) raises ``Interrupted`` within a second, and the workers are killed as
``spread`` returns or raises; a worker killed from outside (the OOM killer) raises ``BrokenProcessPool``.
"""
import multiprocessing
import os
import threading
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager

from . import interrupt
from .hygiene import worker_hygiene

# Σ cost below which the work stays here: ~0.2 s of assessments (degree³ per block; a point at N = 20 with m = 1,
# cost 1.6e4, is ~0.3 ms), against ~50–100 ms to start two workers and collect 50 results
MIN_COST = 1e7
_state = threading.local()
_job = None  # (work, items) of the running ``spread``, inherited by the forked workers


def count() -> int:
    """Worker processes ``spread`` may use: BALLOON_CG_WORKERS, else the cores this process may run on; 1 inside
    ``serial()``."""
    if getattr(_state, "serial", 0):
        return 1
    setting = os.environ.get("BALLOON_CG_WORKERS", "").strip()
    if setting:
        return max(1, int(setting))
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


@contextmanager
def serial():
    """``spread`` runs in this process for the duration (a sweep member: its siblings use the other cores)."""
    _state.serial = getattr(_state, "serial", 0) + 1
    try:
        yield
    finally:
        _state.serial -= 1


def sharing(items: int, cost: float) -> int:
    """The worker processes ``spread`` uses for ``items`` items of total ``cost``: 1 (this process) where forking does
    not pay or is not allowed (module docstring; inside a worker too), else ``count()`` at most ``items``."""
    forking = "fork" in multiprocessing.get_all_start_methods()
    if cost < MIN_COST or _job is not None or not forking:  # _job: inside a worker
        return 1
    return min(count(), items)


def spread(work, items, costs=None, on_result=None, interruptible: bool = True, here=()) -> list:
    """``[work(item) for item in items]``, on ``count()`` forked workers where it pays (module docstring).
    ``costs``: a relative cost per item (default 1 each); ``on_result()`` is called here as each result arrives.
    ``here``: positions of items computed in this process before the workers start, so that what they build and
    cache (a second variation per degree) is inherited, not built again in every worker.
    ``work``'s exceptions are raised here; a signal raises ``interrupt.Interrupted`` (not ``interruptible``: the
    work is finished first, as a serial loop without checks would)."""
    global _job
    items = list(items)
    costs = [1.0] * len(items) if costs is None else [float(c) for c in costs]
    workers = sharing(len(items), sum(costs))
    if workers < 2:
        return [_counted(work(item), on_result) for item in items]
    results = [None] * len(items)
    for i in sorted(set(here)):
        results[i] = _counted(work(items[i]), on_result)
    order = sorted(set(range(len(items))) - set(here), key=lambda i: (-costs[i], i))
    _job = (work, items)
    pool = ProcessPoolExecutor(workers, multiprocessing.get_context("fork"), worker_hygiene, (os.getpid(), False))
    try:
        futures = [(i, pool.submit(_run, i)) for i in order]
        for i, future in futures:
            results[i] = _counted(_result(future) if interruptible else future.result(), on_result)
    finally:
        _stop(pool)
        _job = None
    return results


def _result(future):
    """The future's result, waiting in steps so that a signal here is seen within a second (``Interrupted``)."""
    while True:
        interrupt.check()
        try:
            return future.result(timeout=1.0)
        except TimeoutError:
            continue


def _stop(pool: ProcessPoolExecutor) -> None:
    """Cancel what is queued and kill the workers (they ignore SIGTERM; an item still running is not waited for):
    the executor has no public way to stop its workers before Python 3.14's ``kill_workers``."""
    processes = list((pool._processes or {}).values())
    for process in processes:
        if process.is_alive():
            process.kill()
    pool.shutdown(wait=True, cancel_futures=True)  # its manager thread sees the killed workers and ends
    for process in processes:
        process.join()


def _counted(result, on_result):
    if on_result is not None:
        on_result()
    return result


def _run(i: int):
    work, items = _job
    return work(items[i])


class Stream:
    """``[consumer(item) for item in items]`` per group, the items fed while they are made: one forked worker per
    group (``sharing(len(groups), cost)`` of them, else here, in ``results``) builds its consumer as
    ``make(group)`` (a closure that may keep state from item to item: a reading that follows its previous values)
    and applies it to every item ``feed`` hands it, in order, beside this process's own work (a branch's points
    read as they are traced). Items go through a ``multiprocessing.Queue`` (its feeder thread: ``feed`` never
    waits for a busy worker); ``results`` returns the lists per group, raises a worker's exception here, and
    raises ``interrupt.Interrupted`` within a second of a signal; ``close`` kills the workers (``results`` and
    the ``with`` block call it). Each consumer runs the code a serial loop runs on the same items: the same
    numbers, bit for bit."""

    def __init__(self, make, groups, cost: float):
        self.make, self.groups = make, list(groups)
        self.items, self.workers = [], []
        if sharing(len(self.groups), cost) < 2:
            return
        context = multiprocessing.get_context("fork")
        parent = os.getpid()
        for group in self.groups:
            inbox, (receive, send) = context.Queue(), context.Pipe(duplex=False)
            process = context.Process(target=_consume, args=(parent, make, group, inbox, send), daemon=True)
            process.start()
            send.close()
            self.workers.append((process, inbox, receive))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def feed(self, item) -> None:
        """Hand ``item`` to every group's consumer (here: kept for ``results``)."""
        if not self.workers:
            self.items.append(item)
        for _, inbox, _ in self.workers:
            inbox.put(item)

    def results(self) -> list:
        """Per group, its consumer's results over every item fed, in order."""
        if not self.workers:
            out = []
            for group in self.groups:
                consume = self.make(group)
                out.append([consume(item) for item in self.items])
            return out
        try:
            interrupt.check()  # a signal during the feeding: no results (a serial reading would stop at its check)
            for _, inbox, _ in self.workers:
                inbox.put(None)
            out = []
            for process, _, receive in self.workers:
                while not receive.poll(1.0):
                    interrupt.check()
                    if not process.is_alive() and not receive.poll(0):
                        raise RuntimeError(f"a stream worker (pid {process.pid}) died (exit code {process.exitcode})")
                kind, value = receive.recv()
                if kind == "error":
                    raise value
                out.append(value)
            return out
        finally:
            self.close()

    def close(self) -> None:
        """Kill the workers (idempotent)."""
        for process, inbox, receive in self.workers:
            if process.is_alive():
                process.kill()
            process.join()
            inbox.cancel_join_thread()
            inbox.close()
            receive.close()
        self.workers = []


def _consume(parent: int, make, group, inbox, send) -> None:
    """A stream worker: ``make(group)`` applied to each item of ``inbox`` until None, the list sent back (or the
    exception raised)."""
    worker_hygiene(parent, False)
    _state.serial = 1  # a spread inside the consumer stays in this worker
    try:
        consume = make(group)
        out = []
        while (item := inbox.get()) is not None:
            out.append(consume(item))
        send.send(("done", out))
    except BaseException as error:  # noqa: BLE001 - raised again in the parent
        send.send(("error", error))
