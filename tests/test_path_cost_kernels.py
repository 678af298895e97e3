"""The fast cost kernels against their reference implementations, on seeded random inputs
and the edge cases: a sample exactly on a disc's edge, candidates outside the bounds, a
disc containing the start, odd sample counts, thousands of discs."""

from __future__ import annotations

import numpy as np
import pytest

from swarmnav.models.world import Rect
from swarmnav.planners.path_cost import (bounds_penalty, bounds_penalty_of_columns, obstacle_penalty,
                                         obstacle_penalty_reference, sampled_length_m)


def reference_length_m(xs, ys):
    return np.sum(np.hypot(np.diff(xs, axis=1), np.diff(ys, axis=1)), axis=1)


@pytest.mark.parametrize("samples", [2, 3, 7, 10, 97, 100, 101])
@pytest.mark.parametrize("discs", [0, 1, 6, 30])
def test_fast_penalty_and_length_equal_the_reference(samples, discs):
    rng = np.random.default_rng(samples * 100 + discs)
    xs = rng.uniform(-1.0, 11.0, (40, samples))
    ys = rng.uniform(-1.0, 11.0, (40, samples))
    # Smooth curves too (most candidates are), and one curve that stays far from every disc.
    t = np.linspace(0.0, 1.0, samples)
    xs[:10] = 10.0 * t + rng.normal(0.0, 0.5, (10, 1)) * np.sin(np.pi * t)
    ys[:10] = 10.0 * t + rng.normal(0.0, 0.5, (10, 1)) * np.sin(np.pi * t)
    xs[10], ys[10] = -50.0, -50.0
    centres = rng.uniform(0.0, 10.0, (discs, 2))
    radii = rng.uniform(0.1, 1.5, discs)
    if discs:
        centres[0] = (xs[0, 0], ys[0, 0])                       # a disc containing the start
        xs[1, 3 % samples] = centres[-1, 0] + radii[-1]          # a sample exactly on an edge
        ys[1, 3 % samples] = centres[-1, 1]
    np.testing.assert_allclose(obstacle_penalty(xs, ys, centres, radii),
                               obstacle_penalty_reference(xs, ys, centres, radii), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(sampled_length_m(xs, ys), reference_length_m(xs, ys), rtol=1e-12)
    bounds = Rect(0.0, 0.0, 10.0, 10.0)
    fast = bounds_penalty_of_columns(xs.T.copy(), ys.T.copy(), bounds)
    reference = bounds_penalty(xs, ys, bounds)
    np.testing.assert_allclose(fast, reference, rtol=1e-12, atol=0.0)
    np.testing.assert_array_equal(fast == 0.0, reference == 0.0)


def test_the_penalty_is_zero_exactly_where_no_sample_is_inside_a_disc():
    xs = np.array([[0.0, 1.0, 2.0], [0.0, 1.0, 2.0]])
    ys = np.array([[0.0, 0.0, 0.0], [3.0, 3.0, 3.0]])
    centres = np.array([[1.0, 1.0]])
    # Radius 1: the first curve's middle sample lies exactly on the edge (v = 0), the second is far.
    assert obstacle_penalty(xs, ys, centres, np.array([1.0])).tolist() == [0.0, 0.0]
    inside = obstacle_penalty(xs, ys, centres, np.array([2.0]))
    assert inside[0] == pytest.approx((0.5 + 2 * (1 - np.sqrt(2) / 2)) / 3) and inside[1] == 0.0


@pytest.mark.parametrize("seed", range(4))
def test_cell_culling_keeps_every_term_with_many_discs_and_far_samples(seed):
    """Thousands of small discs of mixed sizes (the cells grow to stay under the cap), samples
    far outside the grid on every side, and samples a hair inside or on disc edges."""
    rng = np.random.default_rng(seed)
    discs = 3000
    centres = rng.uniform(0.0, 400.0, (discs, 2))
    radii = rng.choice([0.01, 0.2, 3.0], discs)
    xs = rng.uniform(-300.0, 700.0, (30, 64))
    ys = rng.uniform(-300.0, 700.0, (30, 64))
    picked = rng.integers(0, discs, 200)
    angle = rng.uniform(0.0, 2.0 * np.pi, 200)
    scale = rng.choice([1.0, 1.0 - 1e-12, 0.5], 200)
    xs.flat[:200] = centres[picked, 0] + scale * radii[picked] * np.cos(angle)
    ys.flat[:200] = centres[picked, 1] + scale * radii[picked] * np.sin(angle)
    reference = obstacle_penalty_reference(xs, ys, centres, radii)
    assert (reference > 0).sum() >= 3
    np.testing.assert_allclose(obstacle_penalty(xs, ys, centres, radii), reference, rtol=1e-12, atol=1e-15)
