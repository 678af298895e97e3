"""``dwa``'s ``sight_inside`` and ``recovery_back`` options (issue 34: BARN).

``sight_inside``: the carrot's sight test while the robot stands within the sight radius of an obstacle --
``"block"`` (default: no sample is in sight, the carrot is the robot's own projection on the path) or
``"shrink"`` (the radius lowered to the clearance the robot has now).  ``recovery_back = "carrot"``: with the
carrot behind and no room to turn to it, the recovery reverses toward it."""

import os
from pathlib import Path

import numpy as np
import pytest

from swarmnav.controllers.guidance import PathCarrot
from swarmnav.controllers.navigators import make_navigator
from swarmnav.controllers.navigators.dwa import DynamicWindowNavigator
from swarmnav.models.errors import ConfigError
from swarmnav.models.world import Pose2D
from swarmnav.sim.episode import EpisodeSpec, run_episode

SIGHT_M = 0.265  # dwa's sight radius with footprint = "box" on BARN's Jackal (inscribed 0.215 m + clearance 0.05 m)
CELL_M = 0.05 * 2 ** 0.5 / 2  # a sensed cell's disc


def carrot(shrink: bool, cell_y_m: float) -> PathCarrot:
    """A straight path along +x from the robot at the origin, one sensed cell abeam at (0, cell_y_m)."""
    out = PathCarrot(np.array([[0.0, 0.0], [5.0, 0.0]]), 1.0)
    out.keep_in_sight(np.array([[0.0, cell_y_m]]), np.array([CELL_M]), np.zeros((0, 4)), SIGHT_M)
    out.sight_shrink = shrink
    return out


def test_block_leaves_the_carrot_on_the_robot_and_shrink_sees_along_the_obstacle():
    y = 0.28  # the robot's centre 0.245 m from the cell's edge: inside the 0.265 m sight radius
    assert np.allclose(carrot(False, y).update(Pose2D(0.0, 0.0, 0.0)), (0.0, 0.0))  # the default, as before
    assert np.allclose(carrot(True, y).update(Pose2D(0.0, 0.0, 0.0)), (1.0, 0.0))   # driving along it, no nearer


def test_shrink_changes_nothing_outside_the_radius_and_still_blocks_a_way_nearer():
    far = 0.40  # 0.365 m from the cell's edge: both see the lookahead point
    assert np.allclose(carrot(False, far).update(Pose2D(0.0, 0.0, 0.0)), (1.0, 0.0))
    assert np.allclose(carrot(True, far).update(Pose2D(0.0, 0.0, 0.0)), (1.0, 0.0))
    # the cell ahead beside the path: the straight way passes nearer to it than the robot stands: not in sight
    out = PathCarrot(np.array([[0.0, 0.0], [5.0, 0.0]]), 1.0)
    out.keep_in_sight(np.array([[0.0, 0.28], [0.5, 0.2]]), np.array([CELL_M, CELL_M]), np.zeros((0, 4)), SIGHT_M)
    out.sight_shrink = True
    target = out.update(Pose2D(0.0, 0.0, 0.0))
    assert target[0] < 0.5 - 1e-9  # only samples short of the second cell: the way past it comes nearer


def test_sight_inside_is_bounded_and_off_by_default():
    assert DynamicWindowNavigator().sight_inside == "block"
    with pytest.raises(ConfigError, match="navigator.params.sight_inside"):
        make_navigator("dwa", {"sight_inside": "wide"})


BARN_CONFIG = {"footprint": "box", "cost_weight": 10.0, "aligned_within": "goal", "inside_margin": "shrink",
               "recovery_s": 1.0, "recovery_back_m": 0.3}


@pytest.mark.skipif(not (Path(__file__).resolve().parents[2] / "shared/benchmarks/barn/worlds").is_dir()
                    and not os.environ.get("SWARMNAV_BARN_DIR"), reason="the BARN data (../shared) is not here")
def test_sight_inside_shrink_gets_out_where_the_carrot_sat_on_the_robot(tmp_path):
    """BARN world 62 (not a test world), run 0: with dwa's BARN configuration the robot stood beside a cylinder
    from ~15 s to the time limit, its carrot on itself (measured: timeout); with sight_inside = "shrink" it
    reaches the goal (measured: 18.4 s) without touching a cylinder."""
    from swarmnav.benchmarks.barn import write_barn_suite
    from swarmnav.models.scenario import load_scenario
    (path,), _, _ = write_barn_suite(str(tmp_path), False, worlds=(62,), runs=1)
    scenario = load_scenario(path)
    base = run_episode(EpisodeSpec(scenario, navigator="dwa", navigator_params=BARN_CONFIG)).result
    assert not base.reached and base.collisions == 0
    shrink = run_episode(EpisodeSpec(scenario, navigator="dwa",
                                     navigator_params={**BARN_CONFIG, "sight_inside": "shrink"})).result
    assert shrink.reached and shrink.collisions == 0


def test_recovery_back_is_bounded_and_off_by_default():
    assert DynamicWindowNavigator().recovery_back == "straight"
    with pytest.raises(ConfigError, match="navigator.params.recovery_back"):
        make_navigator("dwa", {"recovery_back": "around"})


@pytest.mark.skipif(not (Path(__file__).resolve().parents[2] / "shared/benchmarks/barn/worlds").is_dir()
                    and not os.environ.get("SWARMNAV_BARN_DIR"), reason="the BARN data (../shared) is not here")
def test_recovery_back_carrot_reverses_out_of_a_pocket(tmp_path):
    """BARN world 118 (not a test world), run 0, with sight_inside = "shrink": the path replanned from the robot
    led back behind it, the box could not turn on the spot and the robot stood until the time limit (measured:
    timeout); with recovery_back = "carrot" it reverses toward the carrot and reaches the goal (measured: 45.5 s)
    without touching a cylinder."""
    from swarmnav.benchmarks.barn import write_barn_suite
    from swarmnav.models.scenario import load_scenario
    (path,), _, _ = write_barn_suite(str(tmp_path), False, worlds=(118,), runs=1)
    scenario = load_scenario(path)
    shrink = {**BARN_CONFIG, "sight_inside": "shrink"}
    before = run_episode(EpisodeSpec(scenario, navigator="dwa", navigator_params=shrink)).result
    assert not before.reached and before.collisions == 0
    after = run_episode(EpisodeSpec(scenario, navigator="dwa",
                                    navigator_params={**shrink, "recovery_back": "carrot"})).result
    assert after.reached and after.collisions == 0
