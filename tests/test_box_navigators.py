"""The box-chassis options of ``replan``, ``dwa``, ``velocity_obstacle`` and ``mppi`` (issue 34: BARN's Jackal):
the centred planner of :mod:`controllers.centred_path`, the chassis' covering discs, and real runs through a
BARN passage (0.75 m) that the Jackal's circumscribed circle (0.333 m) cannot pass."""

import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from swarmnav.controllers.centred_path import CentredPlanner
from swarmnav.controllers.footprint import covering_discs
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.world import Disc, Pose2D, Rect
from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.problem import Problem
from swarmnav.sim.episode import EpisodeSpec, run_episode

from tests.test_footprint import GAP

# a row of BARN's cylinders across the whole 5 m arena with one 0.75 m passage, x in (2.125, 2.875)
ROW = [2.05 - 0.15 * k for k in range(14)] + [2.95 + 0.15 * k for k in range(14)]


def gap_problem(**kw) -> Problem:
    return Problem(bounds=Rect(0.0, 0.0, 5.0, 8.0), start=Pose2D(2.5, 1.5, 0.0), goal=Pose2D(2.5, 6.5, 0.0),
                   obstacles=tuple(Disc(x, 4.0, 0.075) for x in ROW), robot_radius_m=0.333, cell_m=0.05, **kw)


def test_the_centred_planner_keeps_to_the_middle_of_a_passage_the_circle_closes():
    problem = gap_problem()
    with pytest.raises(NoPathFound):
        CentredPlanner(0.333, 10.0, 0.3).plan(problem, (2.5, 1.5))      # 2 x 0.333 m + the cells > 0.75 m
    path = CentredPlanner(0.215, 10.0, 0.3).plan(problem, (1.2, 1.5))  # from off to the side
    through = np.interp(4.0, path[:, 1], path[:, 0])                     # where it crosses the row
    assert abs(through - 2.5) <= 0.05
    bare = CentredPlanner(0.215, 0.0, 0.3).plan(problem, (1.2, 1.5))     # no penalty: it may graze the side
    assert np.allclose(path[0], (1.2, 1.5)) and np.allclose(path[-1], (2.5, 6.5)) and len(bare) >= 2
    planner = CentredPlanner(0.215, 10.0, 0.3)
    assert not planner.blocks(problem, path, 0.0)
    assert planner.blocks(problem, np.array([[1.2, 1.5], [1.2, 6.5]]), 0.0)  # straight through the cylinders


def test_a_pocket_closes_the_passage_it_stands_in_and_is_forgotten_when_no_other_way_passes():
    """``CentredPlanner.pockets`` (mppi's ``recovery_block_m``): with a second passage in the row, a pocket in the
    first sends the path through the second; with the first passage the only one, the pocket is forgotten and the
    path goes through it as before."""
    two = replace(gap_problem(), obstacles=tuple(Disc(x, 4.0, 0.075) for x in ROW if not 0.9 < x < 1.7))
    planner = CentredPlanner(0.215, 10.0, 0.3)
    assert abs(np.interp(4.0, *planner.plan(two, (2.5, 1.5))[:, ::-1].T) - 2.5) <= 0.05   # the middle one, nearest
    planner.pockets = (Disc(2.5, 3.9, 0.1),)
    path = planner.plan(two, (2.5, 1.5))
    assert abs(np.interp(4.0, *path[:, ::-1].T) - 1.3) <= 0.2 and planner.pockets          # the other one, kept
    assert planner.blocks(two, np.array([[2.5, 1.5], [2.5, 6.5]]), 0.0)                       # the pocket blocks
    alone = CentredPlanner(0.215, 10.0, 0.3, pockets=(Disc(2.5, 3.9, 0.1),))
    path = alone.plan(gap_problem(), (2.5, 1.5))
    assert alone.pockets == () and abs(np.interp(4.0, *path[:, ::-1].T) - 2.5) <= 0.05


def test_the_covering_discs_cover_the_jackal_box_and_are_smaller_than_its_circumscribed_circle():
    setup = type("S", (), {})()
    setup.scenario = parse_scenario(GAP, "<jackal gap>")
    setup.problem = replace(gap_problem(), robot_radius_m=0.333)
    centres, radius = covering_discs(setup)
    assert centres.shape == (2, 2) and radius < 0.26
    xs, ys = np.meshgrid(np.linspace(-0.254, 0.254, 41), np.linspace(-0.215, 0.215, 41))
    pts = np.column_stack([xs.ravel(), ys.ravel()])
    d = np.hypot(pts[:, None, 0] - centres[None, :, 0], pts[:, None, 1] - centres[None, :, 1]).min(axis=1)
    assert d.max() <= radius + 1e-9


BOX = {"replan": {"footprint": "box", "cost_weight": 10.0, "max_decel_m_s2": 2.0},
       "dwa": {"footprint": "box", "cost_weight": 10.0, "aligned_within": "goal"},
       "velocity_obstacle": {"footprint": "box", "cost_weight": 10.0, "margin_m": 0.05, "time_horizon_s": 1.5,
                             "speed_cap_m_s": 1.0, "turn_in_place_rad": 0.35},
       "mppi": {"footprint": "box", "cost_weight": 10.0, "reference_speed_m_s": 0.2, "samples": 300}}


@pytest.mark.parametrize("navigator", sorted(BOX))
def test_the_box_options_pass_a_barn_passage(navigator):
    scenario = parse_scenario(GAP.replace("time_limit_s = 14.0", "time_limit_s = 25.0"), "<jackal gap>")
    box = run_episode(EpisodeSpec(scenario, navigator=navigator, navigator_params=BOX[navigator])).result
    assert box.reached and box.collisions == 0


DWA_RECOVERY = {**BOX["dwa"], "inside_margin": "shrink", "recovery_s": 1.0, "recovery_back_m": 0.3}


@pytest.mark.skipif(not (Path(__file__).resolve().parents[2] / "shared/benchmarks/barn/worlds").is_dir()
                    and not os.environ.get("SWARMNAV_BARN_DIR"), reason="the BARN data (../shared) is not here")
def test_dwa_recovery_gets_out_where_the_window_stood_still(tmp_path):
    """BARN world 265 (not a test world), run 0: with the BARN configuration alone dwa stood still facing away
    from the carrot from ~40 s to the time limit (measured: timeout, 60.8 s standing); with the recovery and
    inside_margin = "shrink" it turns / backs out and reaches the goal without touching a cylinder."""
    from swarmnav.benchmarks.barn import write_barn_suite
    from swarmnav.models.scenario import load_scenario
    (path,), _, _ = write_barn_suite(str(tmp_path), False, worlds=(265,), runs=1)
    result = run_episode(EpisodeSpec(load_scenario(path), navigator="dwa", navigator_params=DWA_RECOVERY)).result
    assert result.reached and result.collisions == 0
