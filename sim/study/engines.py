"""Engines that run study cells: separate local processes, or Ray tasks (``ray_engine``), or, for the
benchmarks, this process.

Every engine calls the same :func:`swarmnav.study.cell.run_cell` and yields
each cell's ``(row, progress)`` as it finishes (in finishing order).  Workers run
with one thread for NumPy's BLAS and OpenMP and ``MUJOCO_GL`` set (no rendering
happens in workers), set in the environment the workers start with, so it holds
before anything in them imports NumPy or MuJoCo.

The local driver is linear in the number of cells: it takes cells from a lazy
iterator, keeps at most a couple of batches per worker in flight, and waits on
one pipe and one process sentinel per worker (``multiprocessing.connection.wait``),
so each completion costs the same whatever the size of the study.  Short cells
travel in batches sized from the measured cell time (:class:`BatchSizer`); every
cell's result comes back on its own, so the driver always knows which cell a
worker is running.  A worker that does not know a component a cell names (a plugin
the driver has and the worker cannot find) answers :class:`ComponentMissing`
instead of a row, and the driver ends the study with it (exit 2), no error rows.  A worker that dies (killed, a segfault, ``os._exit``) turns
that cell into an ``error`` row naming the signal or exit code; the rest of its
queue goes to a fresh worker.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import queue
import signal
import threading
import time
from collections import deque
from multiprocessing.connection import wait as wait_any
from typing import Any, Iterable, Iterator

from swarmnav.sim.defaults import SINGLE_THREAD_ENVIRONMENT
from swarmnav.study.cell import ComponentMissing, _versions_json, base_row, run_cell
from swarmnav.study.grid import Cell

PARENT_POLL_S = 0.5
BATCH_TARGET_S = 0.25  # a batch of short cells takes about this long on a worker
MAX_BATCH = 256  # cells per batch at most
BATCHES_IN_FLIGHT = 2  # per worker: one running, one waiting, so a worker never idles for the driver
STOP_WAIT_S = 5.0  # a finished worker's time to exit before it is terminated

Result = tuple[dict[str, Any], list[dict[str, Any]]]


def worker_environment() -> dict[str, str]:
    return {**SINGLE_THREAD_ENVIRONMENT, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}


@contextlib.contextmanager
def _environment(values: dict[str, str]):
    saved = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


class BatchSizer:
    """Cells per batch: as many as take about ``target_s`` at the mean measured cell time (an exponential
    mean of the rows' ``cell_wall_s``); one cell until the first is measured, and for every long cell."""

    def __init__(self, target_s: float = BATCH_TARGET_S, limit: int = MAX_BATCH):
        self.target_s, self.limit = target_s, limit
        self.mean_s: float | None = None

    def observe(self, row: dict[str, Any]) -> None:
        seconds = row.get("cell_wall_s")
        if seconds is not None:
            self.mean_s = seconds if self.mean_s is None else 0.8 * self.mean_s + 0.2 * seconds

    def size(self) -> int:
        if self.mean_s is None:
            return 1
        return max(1, min(self.limit, int(self.target_s / max(self.mean_s, 1e-6))))


def died_row(cell: Cell, how: str) -> Result:
    """The ``error`` row of a cell whose worker died while running it."""
    row = base_row(cell)
    row.update(versions=_versions_json(), outcome="error", success=False,
               error=f"the worker running this cell died ({how})")
    return row, []


def exit_description(exitcode: int | None) -> str:
    if exitcode is not None and exitcode < 0:
        try:
            return f"killed by signal {signal.Signals(-exitcode).name}"
        except ValueError:
            return f"killed by signal {-exitcode}"
    return f"exit code {exitcode}"


def _exit_with_parent(parent_pid: int) -> None:
    """End this worker when the study's process is gone (killed, not just stopped)."""
    def watch() -> None:
        while os.getppid() == parent_pid:
            time.sleep(PARENT_POLL_S)
        os._exit(1)
    threading.Thread(target=watch, daemon=True).start()


def _worker_main(conn, parent_pid: int, logs_dir: str | None, log_format: str = "swarmnav") -> None:
    """A local worker: batches arrive on ``conn`` (read by a thread, so the driver's sends never wait on a
    running cell), each cell runs on this process's main thread (where the wall limit's timer works) and its
    result goes back at once.  Ctrl-C is the driver's to handle: it terminates its workers."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _exit_with_parent(parent_pid)
    inbox: queue.SimpleQueue = queue.SimpleQueue()

    def receive() -> None:
        try:
            while True:
                inbox.put(conn.recv())
        except (EOFError, OSError):
            inbox.put(None)
    threading.Thread(target=receive, daemon=True).start()
    while (batch := inbox.get()) is not None:
        for cell in batch:
            try:
                result: Result | ComponentMissing = run_cell(cell, logs_dir, log_format)
            except ComponentMissing as exc:
                result = exc
            conn.send(result)


class _LocalWorker:
    def __init__(self, context, logs_dir: str | None, log_format: str = "swarmnav"):
        self.conn, child = context.Pipe()
        self.process = context.Process(target=_worker_main, args=(child, os.getpid(), logs_dir, log_format),
                                       daemon=True)
        self.process.start()
        child.close()
        self.queued: deque[Cell] = deque()  # sent, not yet returned, in the order the worker runs them

    def send(self, batch: list[Cell]) -> None:
        """Queue ``batch`` on this worker.  A worker that died since the last wait (its pipe is broken) keeps
        the batch in its queue: the driver's next wait sees its sentinel, makes the cell it was running an
        ``error`` row and hands the rest, this batch included, to a fresh worker."""
        self.queued.extend(batch)
        try:
            self.conn.send(batch)
        except (BrokenPipeError, ConnectionResetError):
            pass

    def receive(self) -> tuple[list[Result], bool]:
        """The results waiting on the pipe, and whether the worker is gone (its pipe closed)."""
        results = []
        try:
            while self.conn.poll():
                results.append(self.conn.recv())
        except (EOFError, OSError):
            return results, True
        return results, False

    def stop(self, terminate: bool) -> None:
        if terminate:
            self.process.kill()
        else:
            with contextlib.suppress(OSError):
                self.conn.send(None)
        self.process.join(0.0 if terminate else STOP_WAIT_S)
        if self.process.is_alive():
            self.process.kill()
            self.process.join()
        self.conn.close()


def run_local(cells: Iterable[Cell], workers: int, logs_dir: str | None = None,
              log_format: str = "swarmnav") -> Iterator[Result]:
    """Run the cells on ``workers`` spawned processes; on an early exit (Ctrl-C, SIGTERM) the workers
    this engine started are terminated."""
    source = iter(cells)
    retry: deque[Cell] = deque()  # the queue of a worker that died, for the next workers
    sizer = BatchSizer()
    context = multiprocessing.get_context("spawn")
    pool: list[_LocalWorker | None] = [None] * workers
    finished = False

    try:
        exhausted = False
        while True:
            for slot, worker in enumerate(pool):
                while not exhausted or retry:
                    size = sizer.size()
                    if worker is not None and len(worker.queued) >= BATCHES_IN_FLIGHT * size:
                        break
                    batch = []
                    while retry and len(batch) < size:
                        batch.append(retry.popleft())
                    while len(batch) < size and not exhausted:
                        cell = next(source, None)
                        if cell is None:
                            exhausted = True
                        else:
                            batch.append(cell)
                    if not batch:
                        break
                    if worker is None:
                        with _environment(worker_environment()):
                            worker = pool[slot] = _LocalWorker(context, logs_dir, log_format)
                    worker.send(batch)
            busy = [w for w in pool if w is not None and w.queued]
            if not busy:
                break
            ready = set(wait_any([w.conn for w in busy] + [w.process.sentinel for w in busy]))
            for worker in busy:
                if worker.conn not in ready and worker.process.sentinel not in ready:
                    continue
                results, gone = worker.receive()
                for result in results:
                    if isinstance(result, ComponentMissing):
                        raise result
                    row, progress = result
                    worker.queued.popleft()
                    sizer.observe(row)
                    yield row, progress
                if gone or not worker.process.is_alive():
                    worker.process.join()
                    for result in worker.receive()[0]:  # what it sent before it died
                        if isinstance(result, ComponentMissing):
                            raise result
                        worker.queued.popleft()
                        yield result
                    if worker.queued:
                        yield died_row(worker.queued.popleft(), exit_description(worker.process.exitcode))
                        retry.extendleft(reversed(worker.queued))
                    worker.queued.clear()
                    worker.conn.close()
                    pool[pool.index(worker)] = None
        finished = True
    finally:
        for worker in pool:
            if worker is not None:
                worker.stop(terminate=not finished)


def run_inline(cells: Iterable[Cell], logs_dir: str | None = None, log_format: str = "swarmnav") -> Iterator[Result]:
    """Run the cells one after another in this process (the benchmarks' engine: plan times are measured
    alone and warm, as their own timing loops measure them; no worker start-up)."""
    for cell in cells:
        yield run_cell(cell, logs_dir, log_format)
