"""controllers.guidance.PathCarrot._visible against the version it replaced (every disc measured against every
segment, kept here as the reference): the same answer, on random maps and on discs at the edge of the reach."""

from __future__ import annotations

import math

import numpy as np

from swarmnav.controllers.guidance import PathCarrot
from swarmnav.models.geometry import segment_box_distances, segment_disc_distances


def visible_reference(carrot: PathCarrot, origin: np.ndarray, points: np.ndarray) -> np.ndarray:
    centres, radii, boxes, radius = carrot.sight
    starts = np.repeat(origin[None, :], len(points), axis=0)
    ok = np.ones(len(points), dtype=bool)
    if len(centres):
        ok &= np.all(segment_disc_distances(starts, points, centres) >= radii[None, :] + radius, axis=1)
    if len(boxes):
        ok &= np.all(segment_box_distances(starts, points, boxes) >= radius, axis=1)
    return ok


def carrot_with(centres, radii, boxes, radius) -> PathCarrot:
    carrot = PathCarrot(np.array([[0.0, 0.0], [10.0, 0.0]]), 1.0)
    carrot.keep_in_sight(centres, radii, boxes, radius)
    return carrot


def test_visible_is_the_reference_on_sensed_maps():
    rng = np.random.default_rng(71)
    for trial in range(200):
        n = int(rng.integers(1, 3000))
        centres = (rng.integers(0, 200, size=(n, 2)) + 0.5) * 0.05
        radii = np.zeros(n) if rng.random() < 0.7 else rng.uniform(0.0, 0.3, n)
        boxes = np.array([[2.0, 2.0, 3.0, 2.5]]) if rng.random() < 0.2 else np.zeros((0, 4))
        carrot = carrot_with(centres, radii, boxes, float(rng.uniform(0.1, 0.4)))
        origin = rng.uniform(0, 10, 2)
        points = origin + rng.uniform(-1.5, 1.5, size=(9, 2))
        assert np.array_equal(carrot._visible(origin, points), visible_reference(carrot, origin, points)), trial


def test_visible_at_the_edge_of_the_reach():
    """Discs just beyond the longest segment plus both radii, in its direction: a bound without the slack
    drops some whose measured distance rounds below the radii."""
    rng = np.random.default_rng(72)
    differ = 0
    for trial in range(400):
        origin = rng.uniform(0, 10, 2)
        points = origin + rng.uniform(-1.5, 1.5, size=(9, 2))
        k = int(np.argmax(np.hypot(*(points - origin).T)))
        direction = (points[k] - origin) / np.hypot(*(points[k] - origin))
        longest = float(np.hypot(*(points[k] - origin)))
        radius, r = float(rng.uniform(0.1, 0.4)), float(rng.choice([0.0, 0.035]))
        centres = origin + (longest + radius + r + rng.integers(-2, 3, size=(6, 1)) * 1e-16) * direction
        carrot = carrot_with(centres, np.full(6, r), np.zeros((0, 4)), radius)
        want = visible_reference(carrot, origin, points)
        differ += bool(not want[k])
        assert np.array_equal(carrot._visible(origin, points), want), trial
    assert differ > 10  # the edge is reached: some segments are blocked by a disc at exactly the reach


def first_reference(carrot: PathCarrot, origin: np.ndarray, points: np.ndarray):
    """update()'s choice as it was: the first visible point of the whole array's test, None if none."""
    visible = visible_reference(carrot, origin, points)
    return int(np.argmax(visible)) if visible.any() else None


def test_first_visible_is_the_first_of_the_reference():
    rng = np.random.default_rng(73)
    for trial in range(300):
        n = int(rng.integers(0, 2000))
        centres = (rng.integers(0, 100, size=(n, 2)) + 0.5) * 0.05
        radii = np.zeros(n) if rng.random() < 0.7 else rng.uniform(0.0, 0.3, n)
        boxes = np.array([[2.0, 2.0, 3.0, 2.5]]) if rng.random() < 0.3 else np.zeros((0, 4))
        if not n and not len(boxes):
            continue
        carrot = carrot_with(centres, radii, boxes, float(rng.uniform(0.1, 0.4)))
        origin = rng.uniform(0, 5, 2)
        points = origin + rng.uniform(-1.5, 1.5, size=(9, 2))
        assert carrot._first_visible(origin, points) == first_reference(carrot, origin, points), trial


def test_first_visible_at_the_edge_of_each_segment_reach():
    """A disc just beyond the first point's own reach (its segment's length plus both radii): dropped by a bound
    without the slack though its measured distance rounds below the radii, the first point is then taken as
    visible where the reference has a later one."""
    rng = np.random.default_rng(74)
    wrong = 0
    for trial in range(400):
        origin = rng.uniform(0, 10, 2)
        points = origin + rng.uniform(-1.5, 1.5, size=(9, 2))
        direction = (points[0] - origin) / np.hypot(*(points[0] - origin))
        length = float(np.hypot(*(points[0] - origin)))
        radius, r = float(rng.uniform(0.1, 0.4)), float(rng.choice([0.0, 0.035]))
        centres = origin + (length + radius + r + rng.integers(-2, 3, size=(6, 1)) * 1e-16) * direction
        carrot = carrot_with(centres, np.full(6, r), np.zeros((0, 4)), radius)
        want = first_reference(carrot, origin, points)
        wrong += want != 0
        assert carrot._first_visible(origin, points) == want, trial
    assert wrong > 10


def test_first_visible_at_the_edge_of_the_other_samples_reach():
    """The first sample blocked (a disc on its segment), a disc just beyond the reach of the farthest of the
    others: the others, tested together, keep it (a bound without the slack drops some)."""
    rng = np.random.default_rng(75)
    wrong = 0
    for trial in range(400):
        origin = rng.uniform(0, 10, 2)
        points = origin + rng.uniform(-1.0, 1.0, size=(9, 2))
        angle = rng.uniform(0, 2 * np.pi)
        points[1] = origin + 1.6 * np.array([np.cos(angle), np.sin(angle)])  # the farthest of the others
        k = 1
        direction = (points[k] - origin) / np.hypot(*(points[k] - origin))
        length = float(np.hypot(*(points[k] - origin)))
        radius, r = float(rng.uniform(0.1, 0.4)), float(rng.choice([0.0, 0.035]))
        edge = origin + (length + radius + r + rng.integers(-2, 3, size=(5, 1)) * 1e-16) * direction
        blocker = (origin + 0.5 * (points[0] - origin))[None, :]
        centres = np.vstack([blocker, edge])
        carrot = carrot_with(centres, np.full(6, r), np.zeros((0, 4)), radius)
        want = first_reference(carrot, origin, points)
        wrong += want != k  # the edge disc (or the blocker's) hides sample 1
        assert carrot._first_visible(origin, points) == want, trial
    assert wrong > 10

