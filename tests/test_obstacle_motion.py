"""Obstacle motions: held starts, random walks that keep off the map and on its grid."""

from __future__ import annotations

import math

import numpy as np
import pytest

from swarmnav.models.errors import ConfigError
from swarmnav.models.obstacle_motion import RandomWalkMotion, segment_box_distances_m
from swarmnav.models.scenario import load_scenario, parse_scenario

BASE = """
name = "motion-test"
time_limit_s = 60.0
arena = {{ width_m = 4.0, height_m = 4.0, walls = {walls} }}
start = {{ x = 0.2, y = 0.2 }}
goal = {{ x = 3.8, y = 3.8 }}
{map}
[[obstacles]]
x = {x}
y = {y}
radius_m = 0.1
motion = {motion}
"""


def _scenario(motion: str, x: float = 2.2, y: float = 2.2, walls: str = "false", map_text: str = "") -> object:
    return parse_scenario(BASE.format(motion=motion, x=x, y=y, walls=walls, map=map_text), "motion-test.toml")


def test_segment_box_distance_matches_dense_sampling():
    rng = np.random.default_rng(1)
    a = rng.uniform(-1, 3, (40, 2))
    b = rng.uniform(-1, 3, (40, 2))
    lo = rng.uniform(0, 1.5, (6, 2))
    boxes = np.hstack([lo, lo + rng.uniform(0.1, 1.0, (6, 2))])
    exact = segment_box_distances_m(a, b, boxes)
    f = np.linspace(0.0, 1.0, 4001)
    pts = a[:, None, :] + f[None, :, None] * (b - a)[:, None, :]                    # (N, S, 2)
    gap = np.maximum(np.maximum(boxes[None, None, :, :2] - pts[:, :, None, :],
                                pts[:, :, None, :] - boxes[None, None, :, 2:]), 0.0)
    sampled = np.linalg.norm(gap, axis=3).min(axis=1)                               # (N, B)
    step = np.linalg.norm(b - a, axis=1)[:, None] / 4000
    assert np.all(exact <= sampled + 1e-12)
    assert np.all(sampled - exact <= step + 1e-12)
    assert np.any(exact == 0.0) and np.any(exact > 0.0)


def test_start_s_holds_every_kind_at_its_start_then_moves():
    for motion in ('{ kind = "linear", speed_m_s = 0.5, heading_deg = 0.0, at_edge = "stop", start_s = 10.0 }',
                   '{ kind = "waypoints", points = [[3.0, 2.2]], speed_m_s = 0.5, start_s = 10.0 }',
                   '{ kind = "random_walk", step_m = 0.4, period_s = 1.0, start_s = 10.0 }'):
        track = _scenario(motion).obstacles[0].trajectory().positions_at(np.array([0.0, 5.0, 10.0, 12.0]))
        assert np.allclose(track[:3], [2.2, 2.2]), motion
        assert not np.allclose(track[3], [2.2, 2.2]), motion
    linear = _scenario('{ kind = "linear", speed_m_s = 0.5, heading_deg = 0.0, at_edge = "stop", start_s = 4.0 }')
    assert linear.obstacles[0].trajectory().positions_at(np.array([6.0]))[0] == pytest.approx([3.2, 2.2])


@pytest.mark.parametrize("motion, field", [
    ('{ kind = "linear", speed_m_s = 0.5, heading_deg = 0.0, at_edge = "stop", start_s = -1.0 }', "start_s"),
    ('{ kind = "random_walk", step_m = 0.4, period_s = 1.0, start_s = "later" }', "start_s"),
    ('{ kind = "random_walk", step_m = 0.4, period_s = 1.0, steps = "hex" }', "steps"),
])
def test_bad_motion_fields_name_the_field(motion, field):
    with pytest.raises(ConfigError) as err:
        _scenario(motion)
    assert err.value.field == f"obstacles[0].motion.{field}"


def test_map_walkers_stay_on_cell_centres_and_never_touch_a_box():
    for name in ("immas-dynamic-10x10", "immas-env3-dynamic", "immas-env4-dynamic"):
        base = load_scenario(name)
        for world_seed in range(5):
            for ob in base.with_world_seed(world_seed).obstacles:
                walk = ob.motion
                assert walk.steps == "grid"
                nodes = walk.nodes_m
                on_grid = nodes / base.cell_m - 0.5
                assert np.allclose(on_grid, np.round(on_grid), atol=1e-9), name
                moves = np.abs(np.diff(np.round(on_grid), axis=0))
                assert moves.max() <= 1 and np.any(moves.sum(axis=1) == 2), name   # diagonals of one cell
                gaps = segment_box_distances_m(nodes[:-1], nodes[1:], walk.static_boxes_m)
                assert gaps.min() > walk.radius_m, (name, world_seed)


def test_walls_keep_the_whole_disc_inside_the_arena():
    scenario = _scenario('{ kind = "random_walk", step_m = 0.3, period_s = 0.5 }', x=3.7, y=0.3, walls="true")
    nodes = scenario.obstacles[0].motion.nodes_m
    assert nodes.min() >= 0.1 - 1e-12 and nodes.max() <= 3.9 + 1e-12 and nodes.max() > 3.8
    open_arena = _scenario('{ kind = "random_walk", step_m = 0.3, period_s = 0.5 }', x=3.7, y=0.3)
    assert open_arena.obstacles[0].motion.nodes_m.max() > 3.9   # without walls only the centre is kept in


def test_grid_and_compass_walks_draw_the_same_directions_from_the_same_stream():
    """In open space the two readings differ only in the length of a diagonal step."""
    grid = _scenario('{ kind = "random_walk", step_m = 0.1, period_s = 1.0, steps = "grid" }').obstacles[0].motion
    compass = _scenario('{ kind = "random_walk", step_m = 0.1, period_s = 1.0 }').obstacles[0].motion
    assert compass.steps == "compass"
    for world_seed in (0, 7):
        g = np.diff(grid.reseeded(world_seed).nodes_m, axis=0)[:20]
        c = np.diff(compass.reseeded(world_seed).nodes_m, axis=0)[:20]
        assert np.allclose(np.arctan2(g[:, 1], g[:, 0]), np.arctan2(c[:, 1], c[:, 0]))
        diagonal = np.all(np.abs(g) > 1e-12, axis=1)
        assert diagonal.any()
        assert np.allclose(np.abs(g[diagonal]), 0.1) and np.allclose(np.abs(c[diagonal]), 0.1 / math.sqrt(2))
    assert isinstance(grid, RandomWalkMotion)
