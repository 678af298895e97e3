"""The two grid papers' navigators under BARN's protocol (issue 34): their options beyond the papers, off by
default (``map_updates``, ``footprint``, ``drive``, ``max_decel_m_s2``; :mod:`controllers.navigators.sensed_grid`)."""

from types import SimpleNamespace

import numpy as np
import pytest

from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.navigators.cell_path import CellWalker, pulled_corners, static_grid
from swarmnav.controllers.navigators.sensed_grid import free_cell_near, navigator_grid
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.world import Pose2D
from swarmnav.planners.problem import scenario_problem
from swarmnav.sim.episode import EpisodeSpec, run_episode
from tests.jackal_gap import jackal_gap

# A row of BARN's cylinders (0.15 m apart) across the straight line from start to goal, with one 0.75 m passage
# off that line (x in (3.125, 3.875)): a robot planning on the empty map it starts with drives into the row.
GAP = jackal_gap("jackal-gap-aside", 20.0, [0.05 + 0.15 * k for k in range(21)] + [3.95 + 0.15 * k for k in range(7)])

BARN_IACO = {"map_updates": "replan", "footprint": "box", "drive": "pulled", "max_decel_m_s2": 2.0}
BARN_IMMAS = {"map_updates": "replan", "footprint": "box", "lookahead_cells": 20, "carrot_m": 0.6,
              "max_decel_m_s2": 2.0}


@pytest.mark.parametrize("name, options", [("iaco_local", BARN_IACO), ("immas_stepwise", BARN_IMMAS)])
def test_with_the_map_unknown_the_options_pass_the_passage_the_papers_robot_drives_into(name, options):
    scenario = parse_scenario(GAP, "<jackal gap aside>")
    paper = run_episode(EpisodeSpec(scenario, navigator=name)).result
    barn = run_episode(EpisodeSpec(scenario, navigator=name, navigator_params=options)).result
    assert paper.collisions >= 1 and not paper.reached  # planned once on the empty map it started with
    assert barn.reached and barn.collisions == 0


def _setup(text: str = GAP):
    scenario = parse_scenario(text, "<gap>")
    problem = scenario_problem(scenario)
    return SimpleNamespace(map_problem=problem, problem=problem, scenario=scenario), problem


def test_the_box_footprint_opens_the_passage_the_circumscribed_circle_closes():
    setup, problem = _setup()
    circle, box = navigator_grid(setup, "circle"), navigator_grid(setup, "box")
    assert np.array_equal(circle.occupied, static_grid(problem).occupied)  # the default: the papers' grid
    row = circle.cell_of(3.5, 4.0)[0]
    assert circle.occupied[row].all()        # 0.75 m < 2 x (0.333 m + clearance): closed
    assert not box.occupied[row].all()       # 2 x (0.215 m + clearance) fits
    assert box.occupied[box.cell_of(2.5, 4.0)]


def test_the_nearest_free_cell_is_the_cell_itself_when_free_else_the_closest():
    occupied = np.zeros((9, 9), dtype=bool)
    occupied[3:6, 3:6] = True
    assert free_cell_near(occupied, (0, 0)) == (0, 0)
    assert free_cell_near(occupied, (4, 5)) == (4, 6)
    assert free_cell_near(np.ones((9, 9), dtype=bool), (4, 4)) is None


class _Controller:
    def reset(self, path):
        self.waypoints = np.asarray(path.waypoints)

    def command(self, pose, twist):
        return ControlCommand.stop()


def test_a_pulled_walk_hands_the_corners_and_still_counts_the_cells_it_passes():
    setup, problem = _setup()
    grid = static_grid(problem)
    cells = [(10, c) for c in range(10, 30)] + [(10 + k, 30 + k) for k in range(1, 6)]
    assert pulled_corners(grid.occupied, cells) == [cells[0], cells[-1]]  # free: one straight segment
    controller = _Controller()
    walker = CellWalker(controller, grid, 0.1, pulled=True)
    walker.start(cells)
    assert len(controller.waypoints) == 2
    x, y = grid.centres_m(np.array([cells[8]]))[0]  # beside the centres of cells 4-12: the furthest counts
    _, reached = walker.command(Pose2D(float(x), float(y) + 0.02, 0.0), None)
    assert reached and walker.index == 9  # cells 7-9 within 0.1 m on 0.05 m cells
    paper = CellWalker(controller, grid, 0.1)
    paper.start(cells)
    assert len(controller.waypoints) == len(cells)
