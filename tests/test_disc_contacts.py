"""controllers.disc_contacts.inside_any: the k-d tree answer equals the brute-force test bit for bit."""

import numpy as np

from swarmnav.controllers.disc_contacts import BRUTE_FORCE_MAX, LatticeDiscs, inside_any, lattice_inside_any


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


def sensed_cells(rng, n: int, origin=(0.0, 0.0), cell=0.05, rows=120, cols=100):
    """(n, 2) distinct cell centres of a rows x cols grid, computed as SensedMap._build computes them."""
    flat = rng.choice(rows * cols, size=n, replace=False)
    index = np.column_stack([flat % cols, flat // cols])
    return (index + 0.5) * cell + np.array(origin)


def robot_frame_case(rng, centres, near_m: float):
    """A robot pose; the cells near() keeps (hypot - 0.0 <= near_m), turned into its frame as dwa turns them."""
    x0, y0 = float(rng.uniform(1.5, 3.5)), float(rng.uniform(1.5, 4.5))
    heading = float(rng.uniform(-np.pi, np.pi))
    c, s = float(np.cos(heading)), float(np.sin(heading))
    keep = np.hypot(centres[:, 0] - x0, centres[:, 1] - y0) - np.zeros(len(centres)) <= near_m
    rel_x, rel_y = centres[keep, 0] - x0, centres[keep, 1] - y0
    return x0, y0, c, s, c * rel_x + s * rel_y, -s * rel_x + c * rel_y


def test_lattice_inside_any_is_inside_any_bit_for_bit():
    """The k-d tree's answer (the brute-force test's) on the near cells, for points anywhere (some beyond the
    near cells, next to cells that are not among them), on the discs' edges in the robot's frame and one ulp
    either side: the world-frame lattice must not settle them (its band) nor count a cell that is not near."""
    rng = np.random.default_rng(5)
    origin, cell, rows, cols = (0.3, -0.2), 0.05, 120, 100
    for trial in range(60):
        centres = sensed_cells(rng, int(rng.integers(40, 700)), origin, cell, rows, cols)
        lattice = LatticeDiscs.of(centres, origin, cell, rows, cols)
        near_m, radius = float(rng.choice([1.0, 2.5])), float(rng.choice([0.3, 0.2997, 0.265]))
        x0, y0, c, s, ox, oy = robot_frame_case(rng, centres, near_m)
        px, py = rng.uniform(-3.5, 3.5, size=(2, 600))
        if len(ox):  # points on the edges of the near discs, in the robot's frame, and an ulp in and out
            k = rng.integers(0, len(ox), 200)
            a = rng.uniform(0, 2 * np.pi, 200)
            ex, ey = ox[k] + radius * np.cos(a), oy[k] + radius * np.sin(a)
            px = np.concatenate([px, ex, np.nextafter(ex, ox[k]), np.nextafter(ex, 2.0 * ex - ox[k])])
            py = np.concatenate([py, ey, ey, ey])
        got = lattice_inside_any(lattice, x0, y0, c, s, px, py, ox, oy, radius, 0.0, near_m)
        assert np.array_equal(got, inside_any(px, py, ox, oy, np.full(len(ox), radius))), trial


def test_lattice_settles_most_points_and_refuses_centres_off_the_grid():
    rng = np.random.default_rng(6)
    origin, cell = (0.0, 0.0), 0.05
    centres = sensed_cells(rng, 400, origin, cell)
    lattice = LatticeDiscs.of(centres, origin, cell, 120, 100)
    wx, wy = rng.uniform(0, 5, size=(2, 2000))
    outside, inside, _, _ = lattice.settled(wx, wy, 0.3)
    assert (outside | inside).mean() > 0.9
    assert LatticeDiscs.of(centres + 1e-12, origin, cell, 120, 100) is None
    assert LatticeDiscs.of(centres, origin, cell, 50, 50) is None
