"""`swarmnav bench odometry`: wheel odometry's pose error against distance driven, per robot of the catalogue.

Each robot (:data:`models.robots.ROBOTS`) drives the same waypoints (three sides of a 3 m square, ``follow``,
the pose from odometry, :mod:`controllers.odometry`) twice: on the empty floor (``clean``), and with a
fixed box across the loop's first side (``contact``), which the robot drives into and pushes against (the
path is given, not planned: the navigator sees only its odometry, so it keeps driving into the box).  Each row
is one run: ``pose_error_m`` (final), ``max_pose_error_m``, ``distance_m`` (the true path driven), their
ratio ``error_per_m``, ``collisions`` and ``outcome``.  Every robot runs at the lower of its top speed and
0.5 m/s, for ``time_limit_s`` simulated seconds at most.

The table of docs/sensing.md between the ``odometry-table`` markers is :func:`block` of the committed
:data:`RESULTS` (``tests/test_odometry_table.py`` fails when they drift).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from swarmnav.models.marked_block import MarkedBlock

RESULTS = Path(__file__).resolve().parents[2] / "models" / "suites" / "results" / "odometry.json"
PAGE = Path(__file__).resolve().parents[2] / "docs" / "sensing.md"  # the page that holds the table
BEGIN = "<!-- odometry-table: generated from models/suites/results/odometry.json by `swarmnav bench odometry --write`; do not edit by hand -->"
END = "<!-- end of odometry-table -->"
SPEED_M_S = 0.5
LOOP = np.array([[3.0, 3.0], [6.0, 3.0], [6.0, 6.0], [3.0, 6.0]])  # three sides of a 3 m square, two left turns

SCENE = """name = "odometry-{robot}-{kind}"
description = "swarmnav bench odometry: {kind} loop"
seed = 0
time_limit_s = {time_limit_s}
arena = {{ width_m = 9, height_m = 9, walls = false }}
robot = {{ model = "{robot}", max_speed_m_s = {speed} }}
start = {{ x = 3, y = 3, heading_deg = 0.0 }}
goal = {{ x = 3, y = 6, tolerance_m = 0.1 }}
knowledge = {{ pose = "odometry" }}
planner = {{ name = "astar", params = {{}} }}
navigator = {{ name = "follow", params = {{}} }}
{obstacles}"""
# A fixed box across the first side, 2 m ahead of the start: the robot meets it square on.
CONTACT_BOX = "[[boxes]]\nx_min_m = 4.9\ny_min_m = 2.5\nx_max_m = 5.1\ny_max_m = 3.5\n"


def run_one(robot: str, kind: str, time_limit_s: float) -> dict[str, Any]:
    """One run of ``robot`` on the ``clean`` or ``contact`` loop: its row."""
    from swarmnav.models.robots import robot_model
    from swarmnav.models.scenario import parse_scenario
    from swarmnav.sim.episode import EpisodeSpec, given_episode, run_episode

    speed = min(robot_model(robot).max_speed_m_s, SPEED_M_S)
    text = SCENE.format(robot=robot, kind=kind, time_limit_s=time_limit_s, speed=speed,
                        obstacles=CONTACT_BOX if kind == "contact" else "")
    scenario = parse_scenario(text, f"bench odometry[{robot}/{kind}]")
    episode = run_episode(given_episode(EpisodeSpec(scenario), LOOP, "bench odometry"))
    result = episode.result
    summary = result.summary()
    distance = float(result.path_length_m)
    return {"robot": robot, "run": kind, "speed_m_s": speed, "distance_m": round(distance, 3),
            "pose_error_m": round(float(summary["pose_error_m"]), 4),
            "max_pose_error_m": round(float(summary["max_pose_error_m"]), 4),
            "error_per_m": round(float(summary["pose_error_m"]) / distance, 4) if distance > 0 else None,
            "collisions": int(result.collisions), "outcome": str(result.outcome),
            "sim_time_s": round(float(result.sim_time_s), 2)}


def benchmark_odometry(robots: list[str] | None = None, time_limit_s: float = 60.0) -> list[dict[str, Any]]:
    """One row per robot and run (clean, contact), robots in the catalogue's order."""
    from swarmnav.models.robots import ROBOTS
    return [run_one(robot, kind, time_limit_s) for robot in (robots or list(ROBOTS)) for kind in ("clean", "contact")]


def table(rows: list[dict[str, Any]]) -> str:
    """The rows as a Markdown table."""
    lines = ["| robot | run | speed (m/s) | driven (m) | final pose error (m) | max pose error (m) | error per m | "
             "collisions | outcome |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        per_m = "-" if r["error_per_m"] is None else f"{r['error_per_m']:.4f}"
        lines.append(f"| {r['robot']} | {r['run']} | {r['speed_m_s']:g} | {r['distance_m']:.3f} | "
                     f"{r['pose_error_m']:.4f} | {r['max_pose_error_m']:.4f} | {per_m} | {r['collisions']} | "
                     f"{r['outcome']} |")
    return "\n".join(lines)


def block(rows: list[dict[str, Any]] | None = None) -> str:
    """The page's block (markers included) of ``rows``, by default the committed :data:`RESULTS`."""
    if rows is None:
        rows = json.loads(RESULTS.read_text(encoding="utf-8"))
    return f"{BEGIN}\n{table(rows)}\n{END}"


MARKERS = MarkedBlock(BEGIN, END, "odometry-table markers")
current_block = MARKERS.current


def write(rows: list[dict[str, Any]], page: Path) -> None:
    """Commit-ready output: ``rows`` as :data:`RESULTS` and the page's block regenerated from them."""
    RESULTS.write_text(json.dumps(rows, indent=1) + "\n", encoding="utf-8")
    page.write_text(MARKERS.replace(page.read_text(encoding="utf-8"), block(rows), str(page)), encoding="utf-8")


def run(args) -> int:
    """``bench odometry [--quick] [--json] [--write]``: the rows, as JSON lines or the Markdown table."""
    if args.write and args.quick:  # refused before any run
        from swarmnav.models.errors import ConfigError
        raise ConfigError("--write", "writes the full benchmark's figures: not with --quick")
    rows = benchmark_odometry(time_limit_s=20.0 if args.quick else 60.0)
    if args.write:
        write(rows, PAGE)
    if args.json:
        for row in rows:
            print(json.dumps(row))
    else:
        print(table(rows))
    return 0
