"""Random disc fields: static scenes of ``count`` discs drawn from a seed, as scenario files.

The scenes the continuous planners' robust mode is measured on beyond the bundled
ones (``swarmnav bench planners``, the planner tests).  A field is a 10 x 10 m arena
without walls, start (0.5, 0.5), goal (9.5, 9.5), a robot of radius 0.15 m with
0.05 m clearance, and ``count`` discs of radius 0.15-0.5 m with centres uniform in
[1, 9] x [1, 9], drawn one by one with ``numpy.random.default_rng(seed)`` and redrawn
while one would overlap another (a gap of at least 0.1 m between footprints) or come
within its inflated radius of the start or the goal.  The same ``(count, seed)``
always gives the same field, and :func:`disc_field_toml` writes it in the scenario
format, so a study can run it like any bundled scenario.
"""

from __future__ import annotations

import numpy as np

from swarmnav.models.world import Disc

ARENA_M = 10.0
ROBOT_RADIUS_M = 0.15
CLEARANCE_M = 0.05
START_XY_M = (0.5, 0.5)
GOAL_XY_M = (ARENA_M - 0.5, ARENA_M - 0.5)
START_HEADING_DEG = 45.0  # facing the goal
MIN_GAP_M = 0.1  # between two discs' footprints


def draw_disc_field(count: int, seed: int) -> tuple[Disc, ...]:
    """The discs of field ``(count, seed)`` (fewer than ``count`` only if 100 draws per disc cannot place them)."""
    rng = np.random.default_rng(seed)
    start, goal = np.array(START_XY_M), np.array(GOAL_XY_M)
    centres: list[np.ndarray] = []
    radii: list[float] = []
    for _ in range(100 * count):
        if len(centres) == count:
            break
        centre = rng.uniform(1.0, ARENA_M - 1.0, 2)
        radius = float(rng.uniform(0.15, 0.5))
        reach = radius + ROBOT_RADIUS_M + CLEARANCE_M
        if min(np.hypot(*(centre - start)), np.hypot(*(centre - goal))) <= reach:
            continue
        if any(np.hypot(*(centre - c)) < radius + r + MIN_GAP_M for c, r in zip(centres, radii)):
            continue
        centres.append(centre)
        radii.append(radius)
    return tuple(Disc(float(c[0]), float(c[1]), r) for c, r in zip(centres, radii))


def disc_field_name(count: int, seed: int) -> str:
    return f"random-field-{count}-seed-{seed}"


def disc_field_toml(count: int, seed: int) -> str:
    """Field ``(count, seed)`` as scenario TOML (coordinates written with ``repr``: they read back exactly)."""
    lines = [f'name = "{disc_field_name(count, seed)}"',
             f'description = "A random disc field: {count} static discs drawn with numpy seed {seed} '
             f'(swarmnav.models.disc_fields)."',
             "seed = 0", "time_limit_s = 150.0",
             f"arena = {{ width_m = {ARENA_M!r}, height_m = {ARENA_M!r}, walls = false }}",
             f"robot = {{ radius_m = {ROBOT_RADIUS_M!r}, max_speed_m_s = 0.2, clearance_m = {CLEARANCE_M!r} }}",
             f"start = {{ x = {START_XY_M[0]!r}, y = {START_XY_M[1]!r}, heading_deg = {START_HEADING_DEG!r} }}",
             f"goal = {{ x = {GOAL_XY_M[0]!r}, y = {GOAL_XY_M[1]!r}, tolerance_m = 0.1 }}",
             "sensors = { count = 12, range_m = 0.4 }", 'planner = { name = "gwo", params = {} }']
    for disc in draw_disc_field(count, seed):
        lines += ["", "[[obstacles]]", f"x = {disc.x_m!r}", f"y = {disc.y_m!r}", f"radius_m = {disc.radius_m!r}"]
    return "\n".join(lines) + "\n"
