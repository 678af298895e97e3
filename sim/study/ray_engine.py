"""The Ray engine: study cells as Ray tasks on a local instance or a cluster.

Linear like the local driver: a bounded number of batches in flight (a couple per
CPU of the cluster), ``ray.wait`` over those references only, cells taken from a
lazy iterator, batches sized from the measured cell time.

On a cluster (``--address``) every node must have the driver's swarmnav (and its
MuJoCo, NumPy, SciPy and Python) installed, and the driver's plugins (entry-point
distributions, :mod:`swarmnav.sim.plugins`) at the driver's versions: each task
answers with the node's address, versions and plugin distributions, and a node
whose versions differ, or that lacks a plugin or a component a cell names, fails
the study at once, naming the node and the distribution (its rows are not kept).  Logs (``--logs``) are written by the
task to a temporary folder on its node and travel back with the row; the driver
writes them under its own ``--out``, so no log depends on a worker's disk.

Ray's own retries are off (``max_retries=0``): a task whose worker dies (killed,
a segfault, ``os._exit``) fails once; a batch that failed runs again one cell per
task, and a single cell whose task fails is an ``error`` row saying so.
"""

from __future__ import annotations

import json
import logging
import os
import signal
import socket
import tempfile
from collections import deque
from itertools import islice
from pathlib import Path as FilePath
from typing import Any, Iterable, Iterator

from swarmnav.models.contained_files import check_no_link, folder as contained_folder, open_in_folder
from swarmnav.models.errors import ConfigError
from swarmnav.sim.plugins import distributions
from swarmnav.study.cell import ComponentMissing, _versions_json, run_cell
from swarmnav.study.engines import BATCHES_IN_FLIGHT, BatchSizer, Result, died_row, worker_environment
from swarmnav.study.grid import Cell

RAY_AUTH_LOGGER = "ray._private.authentication.authentication_token_setup"
TRIES = 1  # Ray's max_retries = 0: one try per task


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
    """Connect to the cluster at ``address``, or start a local instance with ``workers`` CPUs.

    Ray's core worker installs a native handler for SIGTERM that prints a stack trace and dies by the signal;
    the handler this process had before (the CLI's: exit with one line, the rows kept) is put back."""
    import ray
    if ray.is_initialized():
        return
    runtime_env = {"env_vars": worker_environment()}
    previous = signal.getsignal(signal.SIGTERM)
    if address:
        check_reachable(address)
        ray.init(address=address, runtime_env=runtime_env, log_to_driver=False)
    else:
        # A new local instance turns token authentication on by default and logs a warning that it did;
        # the default stays (setting RAY_AUTH_MODE after Ray's import would break its client), the notice goes.
        logging.getLogger(RAY_AUTH_LOGGER).addFilter(_drop_token_notice)
        ray.init(num_cpus=workers, runtime_env=runtime_env, include_dashboard=False, log_to_driver=False)
    if previous is not None:
        signal.signal(signal.SIGTERM, previous)


def run_batch(cells: list[Cell], keep_logs: str | None) -> dict[str, Any]:
    """A task: run the cells in order; return the node, its versions, and each cell's row, progress and log
    bytes (``None`` without ``--logs`` or in plan-only mode); ``keep_logs``: the logs' format, None for none."""
    import ray
    context = ray.get_runtime_context()
    answer: dict[str, Any] = {"node": ray.util.get_node_ip_address(), "node_id": context.get_node_id(),
                              "versions": _versions_json(), "plugins": distributions(), "missing": None}
    results = []
    for cell in cells:
        try:
            results.append(_run_one(cell, keep_logs))
        except ComponentMissing as exc:
            answer["missing"] = exc.problem
            break
    return {**answer, "results": results}


def _run_one(cell: Cell, keep_logs: str | None) -> tuple[dict[str, Any], list[dict[str, Any]], bytes | None]:
    """One cell's row, progress and log bytes (see :func:`run_batch`)."""
    if not (keep_logs and cell.physics):
        row, progress = run_cell(cell)
        return row, progress, None
    with tempfile.TemporaryDirectory(prefix="swarmnav-log-") as folder:
        row, progress = run_cell(cell, folder, keep_logs)
        log = FilePath(folder) / f"{cell.config_hash}.mcap"
        return row, progress, log.read_bytes() if log.exists() else None


def _node(answer: dict[str, Any]) -> str:
    return f"node {answer['node']} (id {answer.get('node_id', '?')[:12]})"


def _check_plugins(answer: dict[str, Any], driver: dict[str, str]) -> None:
    """Every plugin distribution the driver loaded is on the node at the driver's version."""
    theirs = answer.get("plugins", {})
    differ = [f"{name} {theirs[name] if name in theirs else 'not installed'} (driver {version})"
              for name, version in driver.items() if theirs.get(name) != version]
    if differ:
        raise ConfigError("--address", f"{_node(answer)} differs from the driver in its plugins: {', '.join(differ)}; "
                                       "install the driver's plugins on every node of the cluster")
    if answer.get("missing"):
        raise ConfigError("--address", f"{_node(answer)}: {answer['missing']}")


def _check_versions(answer: dict[str, Any], driver: str) -> None:
    if answer["versions"] == driver:
        return
    theirs, ours = json.loads(answer["versions"]), json.loads(driver)
    differ = ", ".join(f"{k} {theirs.get(k)} (driver {ours.get(k)})" for k in sorted(set(theirs) | set(ours))
                       if theirs.get(k) != ours.get(k))
    raise ConfigError("--address", f"{_node(answer)} runs {differ}; install the driver's versions on "
                                   "every node of the cluster")


def _save_log(logs_dir: str, config_hash: str, data: bytes) -> str:
    final = FilePath(logs_dir) / f"{config_hash}.mcap"
    contained_folder(final.parent, "--out")
    temporary = final.with_name(f".{final.name}.tmp")
    with os.fdopen(open_in_folder(temporary, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, "--out"), "wb") as out:
        out.write(data)
    check_no_link(final, "--out")
    os.replace(temporary, final)
    return str(final)


def _failure(exc: Exception) -> str:
    first = (str(exc).strip().splitlines() or [""])[0][:200]
    what = f"{type(exc).__name__}: {first}" if first else type(exc).__name__
    return f"{what}; {TRIES} try, Ray's own retries are off"


def run_ray(cells: Iterable[Cell], address: str | None = None, workers: int | None = None,
            logs_dir: str | None = None, nodes: set[str] | None = None, log_format: str = "swarmnav") -> Iterator[Result]:
    """Run the cells as Ray tasks (one CPU each) on a local instance or the cluster at ``address``; the ids of
    the nodes that ran them are added to ``nodes``."""
    import ray
    start_ray(address, workers)
    task = ray.remote(num_cpus=1, max_retries=0)(run_batch)
    slots = BATCHES_IN_FLIGHT * max(1, int(ray.cluster_resources().get("CPU", 1)))
    driver_versions, driver_plugins = _versions_json(), distributions()
    source, solo, sizer = iter(cells), deque(), BatchSizer()
    inflight: dict[Any, list[Cell]] = {}
    try:
        while True:
            while len(inflight) < slots:
                batch = [solo.popleft()] if solo else list(islice(source, sizer.size()))
                if not batch:
                    break
                inflight[task.remote(batch, log_format if logs_dir is not None else None)] = batch
            if not inflight:
                break
            done, _ = ray.wait(list(inflight), num_returns=1)
            for ref in done:
                batch = inflight.pop(ref)
                try:
                    answer = ray.get(ref)
                except ray.exceptions.RayError as exc:  # the task's worker or node died
                    if len(batch) == 1:
                        yield died_row(batch[0], _failure(exc))
                    else:
                        solo.extend(batch)  # again one cell per task: only the cell that fails is an error row
                    continue
                _check_versions(answer, driver_versions)
                _check_plugins(answer, driver_plugins)
                if nodes is not None:
                    nodes.add(answer["node_id"])
                for row, progress, log in answer["results"]:
                    if log is not None:
                        row["log"] = _save_log(logs_dir, row["config_hash"], log)
                    sizer.observe(row)
                    yield row, progress
    finally:
        # The tasks still in flight are not cancelled: in Ray 2.60 ``ray.cancel`` races with a task's reply
        # and can abort the driver ("Tried to complete task that was not pending", exit 1) after its rows
        # were kept.  A stopped driver exits, and Ray ends the tasks of a job whose driver is gone; in a
        # Python session the in-flight batches (a few seconds each, ``BatchSizer``) finish and are dropped.
        inflight.clear()
