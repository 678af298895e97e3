"""Engines that run study cells: separate local processes, or Ray tasks (or, for the benchmarks, this process).

Both call the same :func:`swarmnav.sim.study.cell.run_cell` and yield each
cell's ``(row, progress)`` as it finishes (in finishing order).  Workers run with
one thread for NumPy's BLAS and OpenMP and ``MUJOCO_GL`` set (no rendering
happens in workers), set in the environment the workers start with, so it holds
before anything in them imports NumPy or MuJoCo.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import os
import socket
import threading
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from typing import Any, Iterator, Sequence

from swarmnav.models.errors import ConfigError
from swarmnav.sim.commands import SINGLE_THREAD_ENVIRONMENT
from swarmnav.sim.study.cell import run_cell
from swarmnav.sim.study.grid import Cell

PARENT_POLL_S = 0.5
RAY_AUTH_LOGGER = "ray._private.authentication.authentication_token_setup"

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


def _exit_with_parent(parent_pid: int) -> None:
    """Worker initializer: end this worker when the study's process is gone (killed, not just stopped)."""
    def watch() -> None:
        import time
        while os.getppid() == parent_pid:
            time.sleep(PARENT_POLL_S)
        os._exit(1)
    threading.Thread(target=watch, daemon=True).start()


def run_local(cells: Sequence[Cell], workers: int, logs_dir: str | None = None) -> Iterator[Result]:
    """Run the cells on ``workers`` spawned processes; on an early exit (Ctrl-C, SIGTERM) the workers
    this engine started are terminated."""
    if not cells:
        return
    before = set(multiprocessing.active_children())
    context = multiprocessing.get_context("spawn")
    with _environment(worker_environment()):
        executor = ProcessPoolExecutor(max_workers=workers, mp_context=context,
                                       initializer=_exit_with_parent, initargs=(os.getpid(),))
        pending = {executor.submit(run_cell, cell, logs_dir) for cell in cells}
    finished = False
    try:
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                yield future.result()
        finished = True
    finally:
        if finished:
            executor.shutdown(wait=True)
        else:
            executor.shutdown(wait=False, cancel_futures=True)
            for process in set(multiprocessing.active_children()) - before:
                process.terminate()


def run_inline(cells: Sequence[Cell], logs_dir: str | None = None) -> Iterator[Result]:
    """Run the cells one after another in this process (the benchmarks' engine: plan times are measured
    alone and warm, as their own timing loops measure them; no worker start-up)."""
    for cell in cells:
        yield run_cell(cell, logs_dir)


def _drop_token_notice(record: logging.LogRecord) -> bool:
    """Logging filter: drop Ray's notice that a new local instance enabled token authentication."""
    return not record.getMessage().startswith("Token authentication is enabled")


def check_reachable(address: str, timeout_s: float = 5.0) -> None:
    """Fail at once, naming ``--address``, when a ``host:port`` (or ``ray://host:port``) cluster address does not
    answer a TCP connection (Ray itself would retry for minutes); other forms (``auto``) go to Ray as given."""
    host, sep, port = address.removeprefix("ray://").rpartition(":")
    if not sep or not port.isdigit():
        return
    try:
        socket.create_connection((host, int(port)), timeout=timeout_s).close()
    except OSError as exc:
        raise ConfigError("--address", f"cannot reach {address} ({exc.strerror or exc})") from None


def start_ray(address: str | None, workers: int | None) -> None:
    """Connect to the cluster at ``address``, or start a local instance with ``workers`` CPUs."""
    import ray
    if ray.is_initialized():
        return
    runtime_env = {"env_vars": worker_environment()}
    if address:
        check_reachable(address)
        ray.init(address=address, runtime_env=runtime_env, log_to_driver=False)
    else:
        # A new local instance turns token authentication on by default and logs a warning that it did;
        # the default stays (setting RAY_AUTH_MODE after Ray's import would break its client), the notice goes.
        logging.getLogger(RAY_AUTH_LOGGER).addFilter(_drop_token_notice)
        ray.init(num_cpus=workers, runtime_env=runtime_env, include_dashboard=False, log_to_driver=False)


def run_ray(cells: Sequence[Cell], address: str | None = None, workers: int | None = None,
            logs_dir: str | None = None) -> Iterator[Result]:
    """Run the cells as Ray tasks (one CPU each) on a local instance or the cluster at ``address``."""
    if not cells:
        return
    import ray
    start_ray(address, workers)
    task = ray.remote(num_cpus=1, max_retries=0)(run_cell)
    pending = [task.remote(cell, logs_dir) for cell in cells]
    try:
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            for ref in done:
                yield ray.get(ref)
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)
