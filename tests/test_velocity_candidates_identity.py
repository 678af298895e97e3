"""controllers.velocity_candidates.footprint_candidate_times_s against the version it replaced (the (C, N, 2)
arrays over every obstacle, kept here as the reference): the same times, bit for bit, wherever either is below
the horizon, the same ones at or beyond it, so the same candidate chosen."""

from __future__ import annotations

import math

import numpy as np

from swarmnav.controllers.velocity_candidates import chosen_candidate, footprint_candidate_times_s
from swarmnav.models.geometry import segment_box_distances
from swarmnav.models.world import Pose2D


def footprint_times_reference(pose, rotate, candidates, headings_rad, discs_m, centres, velocities, grown_radii_m,
                              boxes, box_clearance_m, horizon_s) -> np.ndarray:
    """footprint_candidate_times_s as it was first written: every candidate against every obstacle."""
    ttc = np.full(len(candidates), np.inf)
    c, s = np.cos(headings_rad), np.sin(headings_rad)
    local = (centres - (pose.x_m, pose.y_m)) @ rotate if len(centres) else centres
    obstacle_v = velocities @ rotate if len(centres) else velocities
    for dx, dy in np.asarray(discs_m, dtype=float).reshape(-1, 2):
        start = np.column_stack([dx * c - dy * s, dx * s + dy * c])
        if len(centres):
            d = local[None, :, :] - start[:, None, :]
            q = obstacle_v[None, :, :] - candidates[:, None, :]
            a = np.sum(q * q, axis=2)
            b = 2.0 * np.sum(d * q, axis=2)
            cc = np.sum(d * d, axis=2) - grown_radii_m[None, :] ** 2
            disc = b * b - 4.0 * a * cc
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (-b - np.sqrt(np.maximum(disc, 0.0))) / (2.0 * a)
            t = np.where((disc >= 0.0) & (a > 1e-12) & (t >= 0.0), t, np.inf)
            t = np.where(cc <= 0.0, np.where(b >= 0.0, np.inf, 0.0), t)
            ttc = np.minimum(ttc, t.min(axis=1))
        if len(boxes):
            p = np.array([pose.x_m, pose.y_m]) + start @ rotate.T
            ends = p + (candidates * horizon_s) @ rotate.T
            gap = segment_box_distances(p, ends, boxes).min(axis=1)
            ttc = np.where(gap < box_clearance_m, np.minimum(ttc, horizon_s * 0.5), ttc)
    return ttc


def candidate_grid(max_speed: float, speed_samples: int, heading_samples: int):
    """velocity_obstacle's candidates (robot frame) and their headings, standing still last."""
    speeds = np.linspace(max_speed / speed_samples, max_speed, speed_samples)
    offsets = np.linspace(-math.pi, math.pi, heading_samples)
    speed, offset = (a.ravel() for a in np.meshgrid(speeds, offsets, indexing="ij"))
    speed, offset = np.append(speed, 0.0), np.append(offset, 0.0)
    return np.column_stack([speed * np.cos(offset), speed * np.sin(offset)]), offset


def assert_same_decision(got: np.ndarray, want: np.ndarray, horizon_s: float, rng, trial) -> None:
    below = want < horizon_s
    assert np.array_equal(got < horizon_s, below), trial
    assert got[below].tobytes() == want[below].tobytes(), trial  # signed zeros included
    for _ in range(3):
        cost = rng.random(len(got))
        assert chosen_candidate(got, cost, horizon_s) == chosen_candidate(want, cost, horizon_s), trial


def test_footprint_times_equal_the_reference_below_the_horizon():
    rng = np.random.default_rng(61)
    discs = np.array([[0.1, 0.0], [-0.1, 0.0]])
    for trial in range(300):
        horizon_s = float(rng.choice([0.5, 1.5, 4.0]))
        candidates, headings = candidate_grid(float(rng.choice([0.5, 1.0, 2.0])), int(rng.integers(1, 6)),
                                              int(rng.integers(1, 26)))
        n = int(rng.integers(0, 400))
        pose = Pose2D(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), float(rng.uniform(-math.pi, math.pi)))
        # Sensed cells on a 5 cm lattice around the robot (still: velocity 0, some -0.0), a few moving discs.
        centres = np.column_stack([pose.x_m + np.round(rng.uniform(-3, 3, n) / 0.05) * 0.05,
                                   pose.y_m + np.round(rng.uniform(-3, 3, n) / 0.05) * 0.05])
        velocities = np.where(rng.random((n, 2)) < 0.5, 0.0, -0.0)
        moving = rng.random(n) < 0.05
        velocities[moving] = rng.normal(0.0, 0.5, (int(moving.sum()), 2))
        radii = np.full(n, 0.3) if rng.random() < 0.5 else rng.uniform(0.2, 0.5, n)
        boxes = np.array([[1.0, 1.0, 1.5, 2.0]]) if rng.random() < 0.3 else np.zeros((0, 4))
        c, s = math.cos(pose.heading_rad), math.sin(pose.heading_rad)
        args = (pose, np.array([[c, -s], [s, c]]), candidates, headings, discs, centres, velocities, radii, boxes,
                0.3, horizon_s)
        assert_same_decision(footprint_candidate_times_s(*args), footprint_times_reference(*args), horizon_s, rng,
                             trial)


def test_footprint_times_at_the_edge_of_a_candidate_reach():
    """Obstacles met at the horizon or just before, from as far as a candidate reaches (its speed x the horizon
    plus the disc's offset), the robot anywhere: a bound without the offset drops those met before the horizon,
    one without the slack those that rounding brings in just before it."""
    rng = np.random.default_rng(62)
    discs = np.array([[0.12, 0.0], [-0.12, 0.0]])
    horizon_s = 1.5
    candidates, headings = candidate_grid(1.0, 5, 25)
    speeds = np.hypot(candidates[:, 0], candidates[:, 1])
    fastest = np.flatnonzero(speeds == speeds.max())  # a group's reach is its fastest candidate's: these reach it
    met = 0
    for trial in range(800):
        k = int(rng.integers(0, len(candidates) - 1)) if trial % 2 else int(rng.choice(fastest))
        speed = math.hypot(*candidates[k])
        pose = Pose2D(float(rng.uniform(-5, 5)), float(rng.uniform(-5, 5)), float(rng.uniform(-3, 3)))
        c, s = math.cos(pose.heading_rad), math.sin(pose.heading_rad)
        direction = headings[k] + pose.heading_rad
        radii = rng.uniform(0.2, 0.4, 1)  # one obstacle: no other is met first
        lag_s = rng.choice([0.0, 0.0, 0.0, 1e-9, 1e-6, 1e-3]) if trial % 2 else 0.0
        dist = 0.12 + speed * (horizon_s - lag_s) + radii
        centres = np.column_stack([pose.x_m + dist * math.cos(direction), pose.y_m + dist * math.sin(direction)])
        centres = centres + rng.integers(-3, 4, centres.shape) * 1e-15
        args = (pose, np.array([[c, -s], [s, c]]), candidates, headings, discs, centres, np.zeros_like(centres),
                radii, np.zeros((0, 4)), 0.3, horizon_s)
        want = footprint_times_reference(*args)
        met += bool((want < horizon_s).any())
        assert_same_decision(footprint_candidate_times_s(*args), want, horizon_s, rng, trial)
    assert met > 300  # most obstacles are met before the horizon


def test_footprint_times_for_obstacles_grazing_a_candidate_corridor():
    """Obstacles whose grown radius just reaches the line a candidate's disc drives along (met, if at all, at a
    tangent): a corridor without the slack drops some that rounding lets the reference meet."""
    rng = np.random.default_rng(63)
    discs = np.array([[0.12, 0.0], [-0.12, 0.0]])
    horizon_s = 1.5
    candidates, headings = candidate_grid(1.0, 5, 25)
    met = 0
    for trial in range(600):
        k = int(rng.integers(0, len(candidates) - 1))
        pose = Pose2D(float(rng.uniform(-5, 5)), float(rng.uniform(-5, 5)), float(rng.uniform(-3, 3)))
        c, s = math.cos(pose.heading_rad), math.sin(pose.heading_rad)
        lead = discs[int(rng.integers(0, 2))]
        start = np.array([lead[0] * math.cos(headings[k]) - lead[1] * math.sin(headings[k]),
                          lead[0] * math.sin(headings[k]) + lead[1] * math.cos(headings[k])])
        along = np.array([math.cos(headings[k]), math.sin(headings[k])])
        side = np.array([-along[1], along[0]]) * rng.choice([-1.0, 1.0])
        radii = rng.uniform(0.2, 0.4, 1)
        local = start + rng.uniform(0.3, 1.0) * along + (radii[0] + rng.integers(-2, 3) * 1e-16) * side
        centres = np.array([[pose.x_m, pose.y_m]]) + local @ np.array([[c, s], [-s, c]])  # robot frame -> world
        args = (pose, np.array([[c, -s], [s, c]]), candidates, headings, discs, centres, np.zeros_like(centres),
                radii, np.zeros((0, 4)), 0.3, horizon_s)
        want = footprint_times_reference(*args)
        met += bool(want[k] < horizon_s)
        assert_same_decision(footprint_candidate_times_s(*args), want, horizon_s, rng, trial)
    assert met > 20
