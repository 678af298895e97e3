"""CrowdNav's test scenes (Chen, Liu, Kreiss and Alahi 2019): ``crowdnav_circle`` and ``crowdnav_square``.

The setting of CrowdNav's ``crowd_nav/configs/env.config`` (read at github:vita-epfl/CrowdNav, not copied):
humans of radius 0.3 m and preferred speed 1 m/s walking with ORCA; the robot of radius 0.3 m and top speed
1 m/s from (0, -4) to (0, 4), the goal reached within its radius; 25 s; 5 humans.  Sampled as CrowdNav's
``crowd_sim.py`` samples a test case (the rules below, written here from reading it):

* ``crowdnav_circle`` (circle crossing): each human at a uniform angle on the circle of radius 4 m, its
  position jittered by ``(u - 0.5) v_pref`` in x and y, redrawn until it is at least ``r_h + r_a + 0.2`` m
  (the discomfort distance) from every agent placed so far (the robot first) and from their goals; its goal
  is the opposite point ``(-x, -y)``.
* ``crowdnav_square`` (square crossing, width 10 m): each human starts on a side ``x = u w/2 s`` (``s = -1``
  when a first draw exceeds 0.5, else 1), ``y = (u - 0.5) w`` and walks to ``x = -u w/2 s``,
  ``y = (u - 0.5) w``; start and goal redrawn until clear of the others' starts (resp. goals) by
  ``r_h + r_a + 0.2``.  Our one addition: a start is also redrawn when it lies that close to the robot's goal
  (CrowdNav allows it; our scenario format refuses an obstacle on the goal at t = 0), so a square case that
  meets this rule differs from CrowdNav's from that human on.

Test case ``N`` draws from NumPy's legacy generator seeded ``1000 + N`` (CrowdNav seeds test case ``N`` with
``counter_offset['test'] + N``, the offset being the validation capacity, 1000), in CrowdNav's order of draws,
so ``--seed N`` gives CrowdNav's test case N.  CrowdNav's world has its origin at the circle's centre; ours
is the arena [0, 12] x [0, 12] m, so every point is shifted by (6, 6).

The robot is sensed as CrowdNav's ``coordinates`` sensor gives it: every human's position, radius and
velocity (the ``detector`` with a 20 m range); the humans see the robot when ``robot_visible``.
"""

from __future__ import annotations

import math

import numpy as np

from swarmnav.models.errors import ConfigError

CROWDNAV_KINDS = ("crowdnav_circle", "crowdnav_square")
ARENA_M = 12.0
OFFSET_M = 6.0  # CrowdNav's origin in our arena
CIRCLE_RADIUS_M = 4.0
SQUARE_WIDTH_M = 10.0
HUMAN_RADIUS_M = 0.3
HUMAN_V_PREF_M_S = 1.0
ROBOT_RADIUS_M = 0.3
ROBOT_SPEED_M_S = 1.0
DISCOMFORT_M = 0.2
TIME_LIMIT_S = 25.0
TEST_SEED_OFFSET = 1000  # CrowdNav's counter_offset['test'] (the validation capacity)
DETECTOR_RANGE_M = 20.0
MAX_HUMANS = 20
MAX_DRAWS = 100_000  # per human: a request that does not fit fails instead of looping


def _sample(kind: str, seed: int, humans: int) -> list[tuple[float, float, float, float]]:
    """(x, y, goal x, goal y) of each human, in CrowdNav's frame."""
    rng = np.random.RandomState(TEST_SEED_OFFSET + seed)
    robot = (0.0, -CIRCLE_RADIUS_M, 0.0, CIRCLE_RADIUS_M, ROBOT_RADIUS_M)
    placed = [robot]  # (x, y, gx, gy, radius)
    for k in range(humans):
        clear = HUMAN_RADIUS_M + DISCOMFORT_M
        if kind == "crowdnav_circle":
            for _ in range(MAX_DRAWS):
                angle = rng.random_sample() * 2.0 * math.pi
                x = CIRCLE_RADIUS_M * math.cos(angle) + (rng.random_sample() - 0.5) * HUMAN_V_PREF_M_S
                y = CIRCLE_RADIUS_M * math.sin(angle) + (rng.random_sample() - 0.5) * HUMAN_V_PREF_M_S
                if all(math.hypot(x - a[0], y - a[1]) >= clear + a[4] and math.hypot(x - a[2], y - a[3]) >= clear + a[4]
                       for a in placed):
                    break
            else:
                raise _too_many(k)
            placed.append((x, y, -x, -y, HUMAN_RADIUS_M))
            continue
        sign = -1.0 if rng.random_sample() > 0.5 else 1.0
        for _ in range(MAX_DRAWS):
            x = rng.random_sample() * SQUARE_WIDTH_M * 0.5 * sign
            y = (rng.random_sample() - 0.5) * SQUARE_WIDTH_M
            if all(math.hypot(x - a[0], y - a[1]) >= clear + a[4] for a in placed) \
                    and math.hypot(x - robot[2], y - robot[3]) >= clear + robot[4]:
                break
        else:
            raise _too_many(k)
        for _ in range(MAX_DRAWS):
            gx = rng.random_sample() * SQUARE_WIDTH_M * 0.5 * -sign
            gy = (rng.random_sample() - 0.5) * SQUARE_WIDTH_M
            if all(math.hypot(gx - a[2], gy - a[3]) >= clear + a[4] for a in placed):
                break
        else:
            raise _too_many(k)
        placed.append((x, y, gx, gy, HUMAN_RADIUS_M))
    return [p[:4] for p in placed[1:]]


def _too_many(k: int) -> ConfigError:
    return ConfigError("--humans", f"human {k} finds no free place after {MAX_DRAWS:,} draws", "scenarios generate")


def crowdnav_lines(kind: str, seed: int, humans: int, robot_visible: bool, time_limit_s: float, planner: str,
                   navigator: str) -> tuple[list[str], list[tuple[float, float, float, str]]]:
    """The scenario's head lines and its obstacles (x, y, radius, motion) for :func:`generate`."""
    if not 1 <= humans <= MAX_HUMANS:
        raise ConfigError("--humans", f"must be from 1 to {MAX_HUMANS}, got {humans}", "scenarios generate")
    sees = "true" if robot_visible else "false"
    obstacles = []
    for x, y, gx, gy in _sample(kind, seed, humans):
        motion = (f'{{ kind = "orca", goal = [{gx + OFFSET_M:.4f}, {gy + OFFSET_M:.4f}], '
                  f'v_pref_m_s = {HUMAN_V_PREF_M_S:g}, sees_robot = {sees} }}')
        obstacles.append((x + OFFSET_M, y + OFFSET_M, HUMAN_RADIUS_M, motion))
    head = [
        f"time_limit_s = {time_limit_s or TIME_LIMIT_S:.12g}",
        f"arena = {{ width_m = {ARENA_M:g}, height_m = {ARENA_M:g}, walls = false }}",
        f"robot = {{ radius_m = {ROBOT_RADIUS_M:g}, max_speed_m_s = {ROBOT_SPEED_M_S:g} }}",
        f"start = {{ x = {OFFSET_M:g}, y = {OFFSET_M - CIRCLE_RADIUS_M:g}, heading_deg = 90.0 }}",
        f"goal = {{ x = {OFFSET_M:g}, y = {OFFSET_M + CIRCLE_RADIUS_M:g}, tolerance_m = {ROBOT_RADIUS_M:g} }}",
        f'sensors = {{ model = "detector", count = 12, range_m = {DETECTOR_RANGE_M:g} }}',
        f'planner = {{ name = "{planner}", params = {{}} }}',
        f'navigator = {{ name = "{navigator}", params = {{}} }}',
        "sim = { cell_m = 0.1 }",
    ]
    return head, obstacles
