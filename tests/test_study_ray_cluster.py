"""A study on a real two-node Ray cluster on this machine (``ray start --head``, then a second ``ray start
--address`` node with its own temporary folder): a physics study with ``--logs`` leaves every log readable under
the driver's ``--out``, whichever node ran it; a node with other versions is refused naming it."""

import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
import pytest

from swarmnav.models.errors import ConfigError
from swarmnav.cli.main import main

pytest.importorskip("ray", reason="the ray extra is not installed (pip install 'swarmnav[ray]')")

STUDY = ('name = "cluster"\nscenarios = ["gwo-scenario-1", "restaurant-table-2"]\nmode = "physics"\n'
         'time_limit_s = 2.0\nseeds = 2\n[[planners]]\nname = "astar"\n')
# Token authentication off for this private cluster: its token would otherwise have to be written where every
# Ray process of this user looks for it (~/.ray), shared with anything else running here.
ENVIRONMENT = {**os.environ, "RAY_AUTH_MODE": "disabled"}


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _descendants(pid: int) -> list[int]:
    try:
        children = [int(c) for c in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except OSError:
        return []
    return children + [d for c in children for d in _descendants(c)]


def _processes_of(folder: Path) -> list[int]:
    """The processes of the cluster whose temporary folder is ``folder``, with their children (from /proc)."""
    roots = []
    for entry in Path("/proc").iterdir():
        try:
            if entry.name.isdigit() and str(folder).encode() in (entry / "cmdline").read_bytes():
                roots.append(int(entry.name))
        except OSError:
            continue
    return sorted({p for r in roots for p in [r, *_descendants(r)]})


def _stop(pids: list[int]) -> None:
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for pid in pids:
            try:
                os.kill(pid, sig)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + 10
        while any(Path(f"/proc/{p}").exists() for p in pids) and time.monotonic() < deadline:
            time.sleep(0.2)


@pytest.fixture(scope="module")
def cluster():
    """Two Ray nodes of one CPU each, each with its own temporary folder (short paths: Ray's sockets live
    there); stopped by the PIDs of their processes (``ray stop`` would stop every Ray instance on the machine)."""
    base = Path(tempfile.mkdtemp(prefix="snray-", dir="/tmp"))
    head, node = base / "head", base / "node"
    port = _free_port()
    ray = str(Path(sys.executable).parent / "ray")
    try:
        subprocess.run([ray, "start", "--head", f"--port={port}", "--num-cpus=1", f"--temp-dir={head}",
                        "--include-dashboard=false", "--disable-usage-stats"],
                       env=ENVIRONMENT, check=True, capture_output=True, timeout=180)
        subprocess.run([ray, "start", f"--address=127.0.0.1:{port}", "--num-cpus=1", f"--temp-dir={node}",
                        "--disable-usage-stats"], env=ENVIRONMENT, check=True, capture_output=True, timeout=180)
        yield f"127.0.0.1:{port}", head, node
    finally:
        _stop(_processes_of(base))


def test_a_physics_study_on_two_nodes_keeps_every_log_under_out(cluster, tmp_path):
    address, head, node = cluster
    path = tmp_path / "study.toml"
    path.write_text(STUDY)
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "swarmnav.cli", "study", str(path), "--out", str(out),
                           "--engine", "ray", "--address", address, "--logs", "--json"],
                          env=ENVIRONMENT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout)
    assert summary["ran"] == 4 and summary["ray_nodes"] == 2  # both nodes ran cells
    rows = pd.read_parquet(out / "runs.parquet")
    assert len(rows) == 4 and (rows.outcome == "ok").all()
    for log in rows.log:
        assert Path(log).parent == (out / "logs").resolve() and Path(log).stat().st_size > 0
        assert main(["log", "info", log, "--json"]) == 0
    for folder in (head, node):  # nothing of a log stayed in a node's folder
        assert not list(folder.rglob("*.mcap"))


def test_a_node_with_other_versions_fails_the_study_naming_it():
    from swarmnav.study.cell import _versions_json
    from swarmnav.study.ray_engine import _check_versions
    driver = _versions_json()
    other = json.loads(driver)
    other["swarmnav"] = "0.0.1"
    _check_versions({"node": "10.1.2.3", "versions": driver}, driver)  # the same versions pass
    with pytest.raises(ConfigError) as info:
        _check_versions({"node": "10.1.2.3", "versions": json.dumps(other, sort_keys=True)}, driver)
    assert info.value.field == "--address"
    assert "node 10.1.2.3 (id ?) runs swarmnav 0.0.1 (driver " in info.value.problem
