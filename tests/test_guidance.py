"""The path's carrot for the local navigators: progress, lookahead, and kept in sight past the known map."""

import numpy as np
import pytest

from swarmnav.controllers.guidance import PathCarrot
from swarmnav.models.geometry import segment_box_distances
from swarmnav.models.world import Pose2D

# A path up through a door in a wall along x = 4 (boxes below y = 4 and above y = 5), then on to the right.
PATH = np.array([[1.0, 4.5], [3.5, 4.5], [4.5, 4.5], [7.0, 4.5]])
WALL = np.array([[3.9, 0.0, 4.1, 4.0], [3.9, 5.0, 4.1, 8.0]])


def test_the_carrot_is_the_lookahead_point_ahead_of_the_projection():
    carrot = PathCarrot(PATH, 1.0)
    target = carrot.update(Pose2D(2.0, 4.0, 0.0))
    assert carrot.progress_m == pytest.approx(1.0) and target == pytest.approx([3.0, 4.5])
    back = carrot.update(Pose2D(1.0, 4.0, 0.0))                  # progress never goes back
    assert carrot.progress_m == pytest.approx(1.0) and back == pytest.approx([3.0, 4.5])


def test_a_robot_pushed_below_the_door_gets_a_carrot_it_can_reach_straight():
    pose = Pose2D(3.6, 3.5, 0.0)                                  # beside the wall, below the door
    plain, seeing = PathCarrot(PATH, 1.2), PathCarrot(PATH, 1.2)
    seeing.keep_in_sight(np.zeros((0, 2)), np.zeros(0), WALL, 0.15)
    for carrot in (plain, seeing):
        carrot.progress_m = 2.6                                  # it had got to x = 3.6 on the path
    behind = plain.update(pose)
    ahead = seeing.update(pose)
    start = np.array([[pose.x_m, pose.y_m]])
    assert segment_box_distances(start, behind[None, :], WALL).min() < 0.15      # through the wall
    assert segment_box_distances(start, ahead[None, :], WALL).min() >= 0.15      # reachable
    assert ahead[1] == pytest.approx(4.5) and 3.6 <= ahead[0] < behind[0]         # on the path, short of it
    # Nothing in the way: the same carrot as without the option.
    clear = PathCarrot(PATH, 1.2)
    clear.keep_in_sight(np.zeros((0, 2)), np.zeros(0), WALL, 0.15)
    assert clear.update(Pose2D(1.5, 4.5, 0.0)) == pytest.approx(PathCarrot(PATH, 1.2).update(Pose2D(1.5, 4.5, 0.0)))
