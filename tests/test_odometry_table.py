"""docs/sensing.md's odometry table is generated from the committed results (models/suites/results/odometry.json):
it fails when either drifts from the other, or when a committed row is no longer what the run gives."""

import json

from swarmnav.models.robots import ROBOTS
from swarmnav.benchmarks import odometry

PAGE = odometry.PAGE


def test_the_page_block_is_generated_from_the_committed_results():
    assert odometry.current_block(PAGE.read_text(encoding="utf-8")) == odometry.block()


def test_committed_rows_cover_every_robot_and_contact_drifts_more_per_metre():
    rows = json.loads(odometry.RESULTS.read_text(encoding="utf-8"))
    assert [(r["robot"], r["run"]) for r in rows] == [(name, kind) for name in ROBOTS for kind in ("clean", "contact")]
    by = {(r["robot"], r["run"]): r for r in rows}
    for name in ROBOTS:
        clean, contact = by[(name, "clean")], by[(name, "contact")]
        assert clean["collisions"] == 0 < contact["collisions"]
        assert 0.0 < clean["error_per_m"] < contact["error_per_m"]
        for r in (clean, contact):
            assert abs(r["pose_error_m"] / r["distance_m"] - r["error_per_m"]) < 1e-3
            assert r["pose_error_m"] <= r["max_pose_error_m"]


def test_a_committed_row_is_what_the_run_gives_today():
    committed = next(r for r in json.loads(odometry.RESULTS.read_text(encoding="utf-8"))
                     if (r["robot"], r["run"]) == ("turtlebot3_burger", "clean"))
    assert odometry.run_one("turtlebot3_burger", "clean", 60.0) == committed
