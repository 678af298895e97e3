"""controllers.disc_contacts.inside_any: the k-d tree answer equals the brute-force test bit for bit."""

import numpy as np

from swarmnav.controllers.disc_contacts import BRUTE_FORCE_MAX, inside_any


def brute(px, py, ox, oy, radius):
    d = np.hypot(px[..., None] - ox, py[..., None] - oy) - radius
    return d.min(axis=-1) < 0.0


def test_matches_brute_force_on_a_sensed_map_like_cloud():
    rng = np.random.default_rng(3)
    cells = rng.integers(-60, 60, size=(300, 2)) * 0.05 + 0.025           # cell centres, as a sensed map's
    ox, oy = cells[:, 0], cells[:, 1]
    radius = np.full(len(ox), 0.2997)
    px, py = rng.uniform(-3, 3, size=(2, 75, 20))
    assert len(ox) > BRUTE_FORCE_MAX
    got = inside_any(px, py, ox, oy, radius)
    assert got.shape == (75, 20)
    assert np.array_equal(got, brute(px, py, ox, oy, radius))
    assert 0 < got.sum() < got.size


def test_points_on_and_next_to_the_circles_edge():
    """Points at exactly the radius from a centre are outside (strict <); one ulp nearer is inside."""
    rng = np.random.default_rng(4)
    ox, oy = rng.uniform(-5, 5, size=(2, 200))
    radius = np.where(np.arange(200) % 2 == 0, 0.3, 0.45)                  # two radii: one query each
    angles = rng.uniform(0, 2 * np.pi, 200)
    px = ox + radius * np.cos(angles)
    py = oy + radius * np.sin(angles)
    nearer_x = np.nextafter(px, ox)
    expected_edge = brute(px, py, ox, oy, radius)
    assert np.array_equal(inside_any(px, py, ox, oy, radius), expected_edge)
    assert np.array_equal(inside_any(nearer_x, py, ox, oy, radius), brute(nearer_x, py, ox, oy, radius))
    # the edge points round in and out about evenly: the band, not the tree, decides them
    assert 0 < expected_edge.sum() < len(expected_edge)
    assert inside_any(nearer_x, py, ox, oy, radius).sum() >= expected_edge.sum()

def test_few_discs_take_the_brute_force():
    px, py = np.array([0.0, 1.0]), np.array([0.0, 0.0])
    got = inside_any(px, py, np.array([0.9]), np.array([0.0]), np.array([0.2]))
    assert got.tolist() == [False, True]
