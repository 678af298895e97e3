"""The map unknown (controllers/world_map.py, models/occupancy.py): the log-odds grid a laser builds, the one
seam every planning navigator reads it through, and runs that reach the goal on it with /map logged."""

import math

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from swarmnav.models.errors import ConfigError
from swarmnav.models.occupancy import LogOddsGrid
from swarmnav.models.scenario import load_scenario, parse_scenario
from swarmnav.models.world import Rect
from swarmnav.sim.episode import EpisodeSpec, plan_episode, run_episode
from swarmnav.log.writer import McapRecorder


def cell_value(grid: LogOddsGrid, x_m: float, y_m: float) -> float:
    return float(grid.log_odds[int(y_m / grid.cell_m), int(x_m / grid.cell_m)])


def test_a_beam_frees_the_cells_it_crosses_marks_its_hit_and_leaves_the_rest_unknown():
    grid = LogOddsGrid(Rect(0.0, 0.0, 4.0, 2.0), 0.05)
    for _ in range(2):
        grid.integrate(1.0, 1.02, 0.0, np.array([1.5]), np.array([0.0]))  # a surface at x = 2.5
    assert all(cell_value(grid, x, 1.02) < 0.0 for x in np.arange(1.01, 2.45, 0.05))
    assert grid.occupied[int(1.02 / 0.05), int(2.5 / 0.05)]
    assert cell_value(grid, 3.0, 1.02) == 0.0 and cell_value(grid, 1.0, 1.5) == 0.0  # never seen
    assert grid.occupied.sum() == 1


def test_an_obstacle_that_leaves_is_cleared_by_the_beams_that_pass_where_it_was():
    grid = LogOddsGrid(Rect(0.0, 0.0, 4.0, 2.0), 0.05)
    for _ in range(5):
        grid.integrate(1.0, 1.02, 0.0, np.array([1.5]), np.array([0.0]))
    scans_to_clear = 0
    while grid.occupied.any():
        grid.integrate(1.0, 1.02, 0.0, np.array([math.inf]), np.array([0.0]))  # it is gone
        scans_to_clear += 1
        assert scans_to_clear < 50
    assert scans_to_clear > 1  # the clamped log odds take several free scans, not one


def test_a_map_finer_than_the_stated_maximum_is_refused_naming_the_field():
    text = load_scenario("gwo-scenario-1").source_text.replace(
        "planner = ", 'knowledge = { map = "unknown", map_cell_m = 0.001 }\nplanner = ', 1)
    with pytest.raises(ConfigError, match="knowledge.map_cell_m"):
        parse_scenario(text)


def test_with_the_map_unknown_the_first_plan_sees_no_obstacle():
    scenario = load_scenario("gwo-scenario-1").with_knowledge("unknown")
    episode = plan_episode(EpisodeSpec(scenario, navigator="replan"))
    assert not episode.problem.obstacles and not episode.problem.boxes
    assert len(episode.path.waypoints) == 2  # straight through what it has not seen


@pytest.mark.parametrize("navigator", ["replan", "dstar_replan"])
def test_planning_navigators_reach_the_goal_on_the_sensed_map_and_log_it(tmp_path, navigator):
    scenario = load_scenario("gwo-scenario-1").with_knowledge("unknown")
    out = tmp_path / "run.mcap"
    result = run_episode(EpisodeSpec(scenario, navigator=navigator), [McapRecorder(str(out))]).result
    assert result.reached and result.collisions == 0
    grids = []
    with out.open("rb") as stream:
        for schema, _, _, message in make_reader(stream, decoder_factories=[DecoderFactory()]) \
                .iter_decoded_messages(topics=["/map"]):
            grids.append(message)
    assert schema.name == "foxglove.Grid" and len(grids) >= int(result.sim_time_s) - 1
    last = grids[-1]
    cells = np.frombuffer(last.data, dtype=np.int8).reshape(-1, last.column_count)
    cell_m = last.cell_size.x
    # Every occupied cell is on an obstacle's rim (within a cell diagonal and a half of it): no phantom; the
    # obstacles the robot passed are on the map; the far corner was never seen.
    occupied = (np.argwhere(cells > 50)[:, ::-1] + 0.5) * cell_m  # (x, y) of the cells' centres
    centres = np.array([(ob.x_m, ob.y_m) for ob in scenario.obstacles])
    radii = np.array([ob.radius_m for ob in scenario.obstacles])
    rim_gap = np.abs(np.hypot(*(occupied[:, None, :] - centres[None]).transpose(2, 0, 1)) - radii).min(axis=1)
    assert len(occupied) >= 5 and rim_gap.max() < 1.5 * math.sqrt(2) * cell_m
    assert cells[int(9.8 / cell_m), int(0.2 / cell_m)] == -1


def test_a_run_with_map_and_pose_given_on_the_command_line_replays(tmp_path):
    """--map / --pose are logged in the run record, so replay --verify re-simulates the same run."""
    import json
    import re

    from swarmnav.cli.main import main
    from swarmnav.log.reader import read_log

    text = re.sub(r"(?m)^time_limit_s\s*=.*$", "time_limit_s = 4.0", load_scenario("gwo-scenario-1").source_text)
    path = tmp_path / "short.toml"
    path.write_text(text)
    out = tmp_path / "run.mcap"
    argv = ["run", str(path), "--navigator", "replan", "--map", "unknown", "--pose", "odometry", "--out", str(out)]
    assert main(argv) in (0, 5)
    run = read_log(str(out)).metadata["run"]
    assert json.loads(run["map_knowledge"]) == "unknown" and json.loads(run["pose_source"]) == "odometry"
    assert main(["replay", str(out), "--verify"]) == 0


def test_grown_discs_cover_each_sensed_cell_reach_behind_it_and_never_over_a_cell_seen_free():
    """The planners' view of the sensed map (controllers.world_map.grown_discs): a cylinder scanned from one
    side is mapped as a rim of cells; each is presented as a disc that covers it, larger than the cell where
    the unseen space behind it leaves room, and none covers the centre of a cell seen free or driven over."""
    from swarmnav.controllers.world_map import GROWN_MAX_M, grown_discs
    grid = LogOddsGrid(Rect(0.0, 0.0, 4.0, 4.0), 0.05)
    angles = np.linspace(-0.6, 0.6, 61)
    # A cylinder of radius 0.3 m at (2.5, 2.0), seen from (1.0, 2.0): each beam's range to its surface.
    d = np.array([1.5 * math.cos(a) - math.sqrt(max(0.09 - (1.5 * math.sin(a)) ** 2, 0.0))
                  if abs(1.5 * math.sin(a)) < 0.3 else math.inf for a in angles])
    for _ in range(3):
        grid.integrate(1.0, 2.0, 0.0, d, angles)
    occupied = grid.occupied
    seen_free = grid.log_odds < 0.0
    driven = np.zeros_like(occupied)
    driven[38:42, 18:22] = True
    centres, radii = grown_discs(occupied, seen_free, driven, grid.cell_m, grid.origin_m)
    cells = (np.argwhere(occupied)[:, ::-1] + 0.5) * grid.cell_m
    assert len(centres) == len(cells) >= 5
    half_diagonal = grid.cell_m * math.sqrt(0.5)
    # Each disc covers its cell (the cell's far corner included).
    assert np.all(np.hypot(*(centres - cells).T) + half_diagonal <= radii + 1e-9)
    # The rim's middle is grown into the unseen shadow behind it (away from the laser), up to the stated largest
    # radius; its ends, with the space seen free beside them, stay near their cells' size.
    grown = radii > half_diagonal
    assert grown.sum() >= len(radii) / 3 and radii.max() >= 0.15 and radii.max() <= GROWN_MAX_M + 1e-12
    assert np.all(centres[grown, 0] >= cells[grown, 0]) and np.any(centres[grown, 0] > cells[grown, 0] + 0.05)
    # No disc reaches the centre of a cell seen free (or driven over).
    free_centres = (np.argwhere((seen_free | driven) & ~occupied)[:, ::-1] + 0.5) * grid.cell_m
    gaps = np.hypot(*(free_centres[:, None, :] - centres[None]).transpose(2, 0, 1)) - radii[None]
    assert gaps[:, radii > half_diagonal].min() >= -1e-9
