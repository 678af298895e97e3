"""``swarmnav bench log``: write a long run log and read it back, time and peak memory of each reader.

A robot stuck against a disc until its time limit (``straight`` drives into it):
every control step logs its messages for the whole run, so the log's length is
set by ``--duration`` (3,000 s by default: about 750,000 messages).  Each step
runs as its own process, the command a user would type, and is measured from
outside: wall time and the process's peak resident memory (``ru_maxrss`` from
``os.wait4``), so the figures include the interpreter and the libraries each
command loads.  Beside swarmnav's readers, the ``mcap`` library's own summary read
and message stream (``StreamReader``: front to back, one chunk at a time; the seeking
reader's ``iter_messages`` holds far more) of the same file give the yardstick.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from swarmnav.benchmarks.figures import print_figures

STUCK_SCENARIO = """
name = "bench-log-stuck"
description = "The robot drives straight into a disc and stays against it until the time limit"
seed = 0
time_limit_s = {duration_s}
arena = {{ width_m = 4.0, height_m = 4.0, walls = false }}
robot = {{ radius_m = 0.15, max_speed_m_s = 0.2 }}
start = {{ x = 0.5, y = 2.0, heading_deg = 0.0 }}
goal = {{ x = 3.5, y = 2.0, tolerance_m = 0.1 }}
sensors = {{ count = 12, range_m = 0.4 }}
planner = {{ name = "straight", params = {{}} }}

[[obstacles]]
x = 2.0
y = 2.0
radius_m = 0.4
height_m = 0.5

[[obstacles]]
x = 3.0
y = 0.8
radius_m = 0.2
motion = {{ kind = "linear", speed_m_s = 0.05, heading_deg = 90.0, at_edge = "reflect" }}
"""

MCAP_SUMMARY = """
import sys
from mcap.reader import make_reader
with open(sys.argv[1], "rb") as f:
    s = make_reader(f).get_summary()
print(s.statistics.message_count)
"""

MCAP_STREAM = """
import sys
from mcap.records import Message
from mcap.stream_reader import StreamReader
n = 0
with open(sys.argv[1], "rb") as f:
    for record in StreamReader(f, skip_magic=False).records:
        n += isinstance(record, Message)
print(n)
"""


# Each command is started by this small launcher, not by the benchmark's own process: Linux carries a
# process's peak memory across fork and exec, so a child of a large parent would report the parent's size.
LAUNCHER = """
import json, os, subprocess, sys, time
argv = json.loads(sys.argv[1])
started = time.perf_counter()
process = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
error = process.stderr.read().decode(errors="replace").strip().splitlines()
_, status, usage = os.wait4(process.pid, 0)
code = os.waitstatus_to_exitcode(status)
print(json.dumps({"s": time.perf_counter() - started, "cpu_s": usage.ru_utime + usage.ru_stime,
                  "peak_mb": usage.ru_maxrss / 1024.0, "exit": code, "error": error[-1] if code and error else ""}))
"""


def measure(argv: list[str]) -> dict[str, Any]:
    """Run one command; its wall time (s), CPU time (s: user + system, what a loaded machine does not
    inflate), peak resident memory (MB, ``ru_maxrss``) and exit status, measured by :data:`LAUNCHER`."""
    out = subprocess.run([sys.executable, "-S", "-c", LAUNCHER, json.dumps(argv)], capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout)


def benchmark_log(duration_s: float, video: bool = True) -> dict[str, Any]:
    """Write a ``duration_s`` run log, then time every reader of it (one process each)."""
    swarmnav = [sys.executable, "-m", "swarmnav.cli"]
    python = [sys.executable, "-c"]
    figures: dict[str, Any] = {"simulated_s": duration_s}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        scenario, log = folder / "stuck.toml", folder / "stuck.mcap"
        scenario.write_text(STUCK_SCENARIO.format(duration_s=duration_s))
        steps = {
            "write (swarmnav run)": swarmnav + ["run", str(scenario), "--out", str(log)],
            "mcap summary read": python + [MCAP_SUMMARY, str(log)],
            "mcap message stream": python + [MCAP_STREAM, str(log)],
            "swarmnav log info": swarmnav + ["log", "info", str(log)],
            "swarmnav plot": swarmnav + ["plot", str(log), "-o", str(folder / "plot.png")],
            "swarmnav log recover": swarmnav + ["log", "recover", str(log), str(folder / "recovered.mcap")],
            "swarmnav replay --verify": swarmnav + ["replay", str(log), "--verify"],
        }
        if video:  # one frame every 10 simulated seconds, small: the reading, not the rendering
            steps["swarmnav replay --video"] = swarmnav + ["replay", str(log), "--video", str(folder / "v.mp4"),
                                                          "--fps", "0.1", "--width", "160", "--height", "120"]
        for name, argv in steps.items():
            result = measure(argv)
            if name.startswith("write"):
                figures["log_mb"] = log.stat().st_size / 1e6 if log.exists() else 0.0
            figures[f"{name}: s"] = result["s"]
            figures[f"{name}: cpu s"] = result["cpu_s"]
            figures[f"{name}: peak MB"] = result["peak_mb"]
            if result["exit"] != 0 and name.startswith("write"):  # nothing to measure: one line, exit 2
                from swarmnav.models.errors import ConfigError
                raise ConfigError("--duration", f"the {duration_s:g} s logged run failed (exit {result['exit']}: "
                                                f"{result['error'] or 'no message'})")
            if result["exit"] != 0:
                figures[f"{name}: exit"] = f"{result['exit']} ({result['error']})"
    return figures


def run(args: argparse.Namespace) -> int:
    duration_s = 300.0 if args.quick else args.duration
    print_figures(benchmark_log(duration_s, video=not args.no_video), args.json)
    return 0
