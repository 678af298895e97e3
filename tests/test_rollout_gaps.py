"""MPPI's rollout gaps (controllers/navigators/rollout_gaps.py) equal the pairwise loop's bit for bit, on the
sensed-map-sized groups where the k-d tree is used, with ties, coincident centres and moving discs."""

import numpy as np
import pytest

from swarmnav.controllers.navigators.rollout_gaps import TREE_FROM, disc_gaps


def _loop(px, py, cx, cy, clearance):
    gap = None
    for k in range(len(cx)):
        dx, dy = px - cx[k], py - cy[k]
        d = np.sqrt(dx * dx + dy * dy)
        d -= clearance[k]
        gap = d if gap is None else np.minimum(gap, d, out=gap)
    return gap


def _scene(seed, n_static, n_moving=0, grid=False):
    rng = np.random.default_rng(seed)
    px = rng.uniform(0, 4, (60, 20)).astype(np.float32)
    py = rng.uniform(0, 4, (60, 20)).astype(np.float32)
    if grid:  # sensed-map cell centres on a 5 cm grid, as with the map unknown; points on cell corners: ties
        cells = rng.choice(80 * 80, n_static, replace=False)
        centres = np.column_stack([(cells % 80 + 0.5) * 0.05, (cells // 80 + 0.5) * 0.05])
        px[:, ::2] = (rng.integers(0, 80, (60, 10)) * 0.05).astype(np.float32)
        py[:, ::2] = (rng.integers(0, 80, (60, 10)) * 0.05).astype(np.float32)
    else:
        centres = rng.uniform(-1, 5, (n_static, 2))
    centres = np.vstack([centres, centres[:3]])  # coincident centres
    velocities = np.vstack([np.zeros_like(centres), rng.uniform(-1, 1, (n_moving, 2))])
    centres = np.vstack([centres, rng.uniform(0, 4, (n_moving, 2))])
    radii = np.concatenate([np.zeros(len(centres) - n_moving), np.full(n_moving, 0.3)])
    if not grid:
        radii[: len(radii) // 3] = 0.075  # two clearances among the static discs
    t = 0.1 * np.arange(1, 21)
    cx = (centres[:, 0:1] + velocities[:, 0:1] * t[None, :]).astype(np.float32)
    cy = (centres[:, 1:2] + velocities[:, 1:2] * t[None, :]).astype(np.float32)
    return px, py, cx, cy, (radii + 0.15).astype(np.float32)


@pytest.mark.parametrize("seed, n_static, n_moving, grid", [
    (0, 3 * TREE_FROM, 0, False), (1, 3 * TREE_FROM, 5, False), (2, 500, 0, True), (3, 900, 4, True),
    (4, TREE_FROM - 10, 5, False), (5, 5, 0, False)])
def test_gaps_equal_the_pairwise_loop_bit_for_bit(seed, n_static, n_moving, grid):
    px, py, cx, cy, clearance = _scene(seed, n_static, n_moving, grid)
    expected = _loop(px, py, cx, cy, clearance)
    got = disc_gaps(px, py, cx, cy, clearance)
    assert got.dtype == np.float32 and got.shape == px.shape
    assert np.array_equal(got, expected)
