"""The vectorised prediction and rasterising helpers against straightforward references: the same values,
bit for bit, on random inputs with ties (lattice positions, zero velocities, signed zeros)."""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest

from swarmnav.controllers.navigator import DetectedObstacle
from swarmnav.controllers.prediction import swept_discs, swept_discs_reference, time_to_collision_s
from swarmnav.models.world import Disc, Rect, rasterise


def ttc_reference(position_m, velocities_m_s, centres_m, obstacle_velocities_m_s, radii_m) -> np.ndarray:
    """time_to_collision_s as it was written first: the sums over x and y by np.sum(axis=2)."""
    u = np.asarray(velocities_m_s, dtype=float).reshape(-1, 1, 2)
    d = (np.asarray(centres_m, dtype=float) - np.asarray(position_m, dtype=float)).reshape(1, -1, 2)
    q = np.asarray(obstacle_velocities_m_s, dtype=float).reshape(1, -1, 2) - u
    r = np.asarray(radii_m, dtype=float).reshape(1, -1)
    a = np.sum(q * q, axis=2)
    b = 2.0 * np.sum(d * q, axis=2)
    c = np.sum(d * d, axis=2) - r * r
    disc = b * b - 4.0 * a * c
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (-b - np.sqrt(np.maximum(disc, 0.0))) / (2.0 * a)
    t = np.where((disc >= 0.0) & (a > 1e-12) & (t >= 0.0), t, np.inf)
    return np.where(c <= 0.0, np.where(b >= 0.0, np.inf, 0.0), t)


def lattice(rng, shape, step: float) -> np.ndarray:
    """Values on a coarse lattice (ties, exact zeros of both signs) mixed with arbitrary ones."""
    out = rng.integers(-4, 5, shape) * step
    out = np.where(rng.random(shape) < 0.3, rng.normal(0.0, 1.0, shape), out)
    return np.where(rng.random(shape) < 0.1, -0.0, out)


def test_time_to_collision_is_the_reference_bit_for_bit():
    rng = np.random.default_rng(35)
    for trial in range(400):
        v, n = int(rng.integers(1, 30)), int(rng.integers(0, 12))
        args = (lattice(rng, 2, 0.5), lattice(rng, (v, 2), 0.25), lattice(rng, (n, 2), 0.5),
                lattice(rng, (n, 2), 0.25), np.abs(lattice(rng, n, 0.25)))
        got, want = time_to_collision_s(*args), ttc_reference(*args)
        assert got.shape == want.shape and got.tobytes() == want.tobytes(), trial


def test_swept_discs_are_the_one_at_a_time_chains_with_the_same_types():
    rng = np.random.default_rng(36)
    for trial in range(300):
        n = int(rng.integers(0, 8))
        detections = tuple(DetectedObstacle(float(x), float(y), float(r), float(vx), float(vy), i)
                           for i, (x, y, r, vx, vy) in enumerate(zip(
                               lattice(rng, n, 0.5), lattice(rng, n, 0.5), 0.05 + np.abs(lattice(rng, n, 0.1)),
                               lattice(rng, n, 0.25), lattice(rng, n, 0.25))))
        horizon_s = float(rng.choice([0.0, 0.5, 1.0, 2.0, 3.0, rng.uniform(0.1, 4.0)]))
        got, want = swept_discs(detections, horizon_s), swept_discs_reference(detections, horizon_s)
        assert len(got) == len(want), trial
        for a, b in zip(got, want):
            assert (a.x_m, a.y_m, a.radius_m) == (b.x_m, b.y_m, b.radius_m), trial
            assert [type(a.x_m), type(a.y_m)] == [type(b.x_m), type(b.y_m)], trial
            assert [math.copysign(1.0, a.x_m), math.copysign(1.0, a.y_m)] == \
                [math.copysign(1.0, b.x_m), math.copysign(1.0, b.y_m)], trial


def rasterise_reference(bounds: Rect, discs, inflation_m: float, cell_m: float) -> np.ndarray:
    """rasterise's discs one at a time, each on its window of cells (as it was written first)."""
    cols = max(1, int(math.ceil(bounds.width_m / cell_m - 1e-9)))
    rows = max(1, int(math.ceil(bounds.height_m / cell_m - 1e-9)))
    xs = bounds.x_min_m + (np.arange(cols) + 0.5) * cell_m
    ys = bounds.y_min_m + (np.arange(rows) + 0.5) * cell_m
    reach = inflation_m + cell_m / math.sqrt(2.0)
    occupied = np.zeros((rows, cols), dtype=bool)
    for disc in discs:
        grown = disc.radius_m + reach
        c0 = max(0, int(math.floor((disc.x_m - grown - bounds.x_min_m) / cell_m)))
        c1 = min(cols, int(math.ceil((disc.x_m + grown - bounds.x_min_m) / cell_m)) + 1)
        r0 = max(0, int(math.floor((disc.y_m - grown - bounds.y_min_m) / cell_m)))
        r1 = min(rows, int(math.ceil((disc.y_m + grown - bounds.y_min_m) / cell_m)) + 1)
        rs, cs = slice(r0, max(r0, r1)), slice(c0, max(c0, c1))
        occupied[rs, cs] |= (ys[rs] - disc.y_m)[:, None] ** 2 + (xs[cs] - disc.x_m)[None, :] ** 2 < grown * grown
    return occupied


@pytest.mark.parametrize("cell_m", [0.05, 0.1, 0.25])
def test_rasterised_discs_are_the_one_at_a_time_cells(cell_m):
    rng = np.random.default_rng(37)
    bounds = Rect(-0.3, 0.1, 5.2, 4.9)
    for trial in range(60):
        n = int(rng.integers(1, 60))
        centres = np.where(rng.random((n, 2)) < 0.5, rng.integers(-4, 60, (n, 2)) * (cell_m / 2),
                           rng.uniform(-1.0, 6.0, (n, 2)))
        radii = np.where(rng.random(n) < 0.1, rng.uniform(0.5, 3.0, n), rng.uniform(0.0, 0.4, n))
        discs = tuple(Disc(float(x), float(y), float(r)) for (x, y), r in zip(centres, radii))
        inflation_m = float(rng.choice([0.0, 0.1, 0.17, 0.3]))
        got = rasterise(bounds, discs, (), inflation_m, cell_m).occupied
        assert np.array_equal(got, rasterise_reference(bounds, discs, inflation_m, cell_m)), trial


def test_one_large_disc_among_many_small_ones_costs_its_own_box():
    """Sized by the largest disc, 460 boxes of a 10 m disc's span at 5 cm cells would take ~600 MB."""
    rng = np.random.default_rng(38)
    bounds = Rect(0.0, 0.0, 30.0, 30.0)
    discs = tuple(Disc(float(x), float(y), 0.1) for x, y in rng.uniform(0.0, 30.0, (460, 2))) + (Disc(15.0, 15.0, 10.0),)
    tracemalloc.start()
    try:
        got = rasterise(bounds, discs, (), 0.2, 0.05).occupied
        peak_b = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak_b < 64e6
    assert np.array_equal(got, rasterise_reference(bounds, discs, 0.2, 0.05))
