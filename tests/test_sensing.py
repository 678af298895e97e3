"""Sensing of moving obstacles: the hit tracker on synthetic rays, and the range-limited detector."""

import math

import numpy as np
import pytest

from swarmnav.controllers.tracking import HitTracker
from swarmnav.models.scenario import parse_scenario
from swarmnav.models.world import Pose2D
from swarmnav.sim.detector import ObstacleSensing, hit_points, known_surface_gap_m


def ray_disc_ranges(origin_m, directions, centre_m, radius_m, range_m):
    """Exact distances along unit rays to a disc (inf where a ray misses or the hit is out of range)."""
    d = np.asarray(centre_m) - np.asarray(origin_m)
    along = directions @ d
    miss2 = d @ d - along ** 2
    half = np.sqrt(np.maximum(radius_m ** 2 - miss2, 0.0))
    t = along - half
    return np.where((miss2 <= radius_m ** 2) & (t > 0) & (t <= range_m), t, np.inf)


@pytest.mark.parametrize("rays, radius_m, start_m, velocity_m_s", [
    (36, 0.3, (-0.1, 1.0), (0.12, -0.05)), (36, 0.2, (-0.1, 1.0), (-0.2, 0.0)), (36, 0.4, (-0.1, 1.0), (0.0, 0.15)),
    # Abdulla & Hadi (2025)'s 12 beams, 30 degrees apart: a disc coming down a beam (a sideways motion seen by one
    # beam only is not observable: the hit stays on that beam)
    (12, 0.3, (0.0, 1.6), (0.0, -0.2)), (12, 0.2, (1.4, 0.0), (-0.15, 0.0))])
def test_tracker_recovers_centre_and_velocity_of_a_disc_seen_by_a_ring_of_rays(rays, radius_m, start_m, velocity_m_s):
    """A disc moving at a known velocity, seen by a ring of rays (0.155 m rim, 1.5 m range) at 50 Hz for 2 s.

    Tolerances: the centre within 0.05 m plus the error of the radius estimate
    (with fewer than three hits the tracker assumes its default radius, and the
    centre is one radius behind the hit); the velocity within 0.03 m/s.
    """
    angles = np.linspace(0.0, 2 * math.pi, rays, endpoint=False)
    dirs = np.column_stack([np.cos(angles), np.sin(angles)])
    pose = Pose2D(0.0, 0.0, 0.0)
    tracker = HitTracker()
    start = np.array(start_m)
    v = np.array(velocity_m_s)
    detections = ()
    for k in range(101):
        t = k * 0.02
        centre = start + v * t
        origins = 0.155 * dirs
        ranges = np.array([ray_disc_ranges(o, d[None, :], centre, radius_m, 1.5)[0] for o, d in zip(origins, dirs)])
        hits, hit_origins = hit_points(pose, ranges, angles, 0.155)
        detections = tracker.update(t, hits, hit_origins)
    assert len(detections) == 1
    est = detections[0]
    true_centre = start + v * 2.0
    radius_error = abs(est.radius_m - radius_m)
    assert math.hypot(est.x_m - true_centre[0], est.y_m - true_centre[1]) < 0.05 + radius_error
    assert math.hypot(est.vx_m_s - v[0], est.vy_m_s - v[1]) < 0.03
    if rays == 36:  # three hits or more: the radius is measured
        assert est.radius_m == pytest.approx(radius_m, abs=0.01)


def test_tracker_keeps_two_separate_discs_apart_and_forgets_them_after_keep_s():
    tracker = HitTracker()
    origins = np.zeros((2, 2))
    hits = np.array([[1.0, 0.0], [-1.0, 0.0]])
    first = tracker.update(0.0, hits, origins)
    assert len({d.track_id for d in first}) == 2
    assert len(tracker.update(tracker.keep_s * 0.5, np.zeros((0, 2)), np.zeros((0, 2)))) == 2  # coasting
    assert tracker.update(tracker.keep_s * 1.5, np.zeros((0, 2)), np.zeros((0, 2))) == ()


DETECTOR_TOML = """
name = "detector-range"
arena = { width_m = 6.0, height_m = 6.0 }
robot = { radius_m = 0.15 }
start = { x = 1.0, y = 1.0 }
goal = { x = 5.0, y = 5.0 }
sensors = { model = "detector", range_m = 0.5 }
[[obstacles]]
x = 3.0
y = 3.0
radius_m = 0.3
motion = { kind = "linear", speed_m_s = 0.1, heading_deg = 0.0, at_edge = "stop" }
[[obstacles]]
x = 4.0
y = 1.0
radius_m = 0.25
"""


def test_detector_reports_only_moving_obstacles_whose_surface_is_within_range():
    scenario = parse_scenario(DETECTOR_TOML)
    dt = 0.02
    times = np.arange(3) * dt
    track = scenario.obstacles[0].trajectory().positions_at(times)[:, None, :]
    sensing = ObstacleSensing(scenario, track, np.array([0.3]), dt, np.zeros(12), 0.155)
    centre = track[1, 0]
    for gap, seen in ((0.49, True), (0.51, False)):
        distance = gap + 0.3 + 0.15
        pose = Pose2D(centre[0] - distance, centre[1], 0.0)
        found = sensing.detect(1, pose)
        assert (len(found) == 1) == seen, gap
        if seen:
            assert found[0].vx_m_s == pytest.approx(0.1) and found[0].vy_m_s == pytest.approx(0.0, abs=1e-12)
            assert (found[0].x_m, found[0].y_m, found[0].radius_m) == pytest.approx((centre[0], centre[1], 0.3))
    # The static obstacle at (4, 1) is the map's: never reported, however close.
    assert sensing.detect(1, Pose2D(3.5, 1.0, 0.0)) == ()


def test_rangefinder_hits_on_the_known_map_are_dropped():
    scenario = parse_scenario(DETECTOR_TOML)
    on_static = np.array([[4.0 - 0.25, 1.0]])
    on_moving = np.array([[3.0 - 0.3, 3.0]])
    assert known_surface_gap_m(on_static, scenario)[0] == pytest.approx(0.0, abs=1e-12)
    assert known_surface_gap_m(on_moving, scenario)[0] > 0.5


def test_a_still_disc_the_robot_drives_past_does_not_seem_to_move_with_it():
    """One beam sweeping along a still disc's rim as the robot drives by at 0.2 m/s: the hit slides
    over the surface.  Placing the centre one radius beyond each hit along the ray made the disc
    seem to follow the robot at its 0.2 m/s; with the prior what remains is the drift the first
    (one-hit) centre's error causes, below 0.08 m/s over the pass."""
    tracker = HitTracker(default_radius_m=0.3)
    centre, radius = np.array([1.0, 0.55]), 0.3
    angle = math.pi / 2  # the beam points left of the robot, which drives along +x
    direction = np.array([[math.cos(angle), math.sin(angle)]])
    speeds = []
    for k in range(60):
        t = k * 0.02
        origin = np.array([0.9 + 0.2 * t, 0.0]) + 0.155 * direction[0]
        r = ray_disc_ranges(origin, direction, centre, radius, 1.0)[0]
        if not np.isfinite(r):
            continue
        found = tracker.update(t, (origin + r * direction[0])[None, :], origin[None, :])
        speeds.append(math.hypot(found[0].vx_m_s, found[0].vy_m_s))
    assert len(speeds) > 40 and max(speeds) < 0.08


def test_a_coasting_track_that_a_beam_sees_through_is_dropped_at_once():
    tracker = HitTracker()
    tracker.update(0.0, np.array([[1.0, 0.0]]), np.zeros((1, 2)))  # a disc about (1.3, 0)
    origins, directions = np.zeros((1, 2)), np.array([[1.0, 0.0]])
    # No hit, and a beam straight through where the disc would be, with a reach of 2 m: gone.
    tracker.reach_m = 2.0
    assert tracker.update(0.1, np.zeros((0, 2)), np.zeros((0, 2)), (origins, directions, np.array([np.inf]))) == ()
    # The same without the beam passing through it (it points away): the track coasts.
    tracker.update(0.2, np.array([[1.0, 0.0]]), np.zeros((1, 2)))
    away = np.array([[-1.0, 0.0]])
    assert len(tracker.update(0.3, np.zeros((0, 2)), np.zeros((0, 2)), (origins, away, np.array([np.inf])))) == 1


@pytest.mark.parametrize("hit_motion", [True, False])
def test_a_disc_coming_at_a_turning_robot_gets_its_velocity_from_the_raw_hits(hit_motion):
    """Abdulla & Hadi (2025)'s 12 beams 30 degrees apart on a robot turning in place at 0.3 rad/s; a disc of the
    tracker's default radius comes at it from 10 degrees off its heading at 0.15 m/s.  The beams sweep over
    the rim, so each step's centre slides with the hit: regressed through those centres (``hit_motion``
    false) the velocity is off by 0.15 m/s in the median over the approach; fitted to the window's raw hits
    (:mod:`controllers.hit_motion`) by under 0.03 m/s (0.002 here)."""
    angles = np.linspace(0.0, 2 * math.pi, 12, endpoint=False)
    tracker = HitTracker(hit_motion=hit_motion)
    tracker.reach_m = 1.0
    radius, velocity = 0.3, np.array([-0.15, 0.0])
    start = 1.6 * np.array([math.cos(math.radians(10)), math.sin(math.radians(10))])
    errors, first_hit_s = [], None
    for k in range(400):
        t = k * 0.02
        centre = start + velocity * t
        if math.hypot(*centre) - radius < 0.3:
            break
        heading = 0.3 * t
        dirs = np.column_stack([np.cos(angles + heading), np.sin(angles + heading)])
        origins = 0.155 * dirs
        ranges = np.array([ray_disc_ranges(o, d[None, :], centre, radius, 1.0)[0] for o, d in zip(origins, dirs)])
        hits, hit_origins = hit_points(Pose2D(0.0, 0.0, heading), ranges, angles, 0.155)
        found = tracker.update(t, hits, hit_origins, (origins, dirs, ranges))
        first_hit_s = t if first_hit_s is None and len(hits) else first_hit_s
        if found and first_hit_s is not None and t - first_hit_s >= 0.5:  # the window has filled
            est = min(found, key=lambda d: math.hypot(d.x_m - centre[0], d.y_m - centre[1]))
            errors.append(math.hypot(est.vx_m_s - velocity[0], est.vy_m_s - velocity[1]))
    assert len(errors) > 200
    assert (np.median(errors) < 0.03) == hit_motion, np.median(errors)


@pytest.mark.parametrize("max_link_angle_deg", [90.0, 180.0])
def test_hits_on_two_discs_either_side_of_the_robot_are_not_one_disc_over_it(max_link_angle_deg):
    """The robot between two discs 0.43 m apart (dyn-overtake-2 near its goal), 12 beams: the hits on either
    side are closer than ``2 * default_radius_m``.  Linked (180: no angle limit) they made one disc fitted
    between them, over the robot itself; with the limit (the default), two discs where the two are."""
    angles = np.linspace(0.0, 2 * math.pi, 12, endpoint=False)
    dirs = np.column_stack([np.cos(angles), np.sin(angles)])
    origins = 0.155 * dirs
    discs = [(np.array([-0.45, -0.23]), 0.25), (np.array([0.57, -0.23]), 0.35)]
    ranges = np.min([[ray_disc_ranges(o, d[None, :], c, r, 1.0)[0] for o, d in zip(origins, dirs)]
                     for c, r in discs], axis=0)
    hits, hit_origins = hit_points(Pose2D(0.0, 0.0, 0.0), ranges, angles, 0.155)
    tracker = HitTracker(max_link_angle_deg=max_link_angle_deg)
    tracker.reach_m = 1.0
    found = tracker.update(0.0, hits, hit_origins, (origins, dirs, ranges))
    over_robot = [d for d in found if math.hypot(d.x_m, d.y_m) < d.radius_m + 0.15]
    near_truth = all(min(math.hypot(d.x_m - c[0], d.y_m - c[1]) for d in found) < 0.1 for c, _ in discs)
    assert (not over_robot and near_truth and len(found) == 2) == (max_link_angle_deg < 180.0)


@pytest.mark.parametrize("split_seen_gaps", [True, False])
@pytest.mark.parametrize("heading_deg", [0.0, 10.0, 20.0])
def test_hits_on_two_discs_with_a_seen_gap_between_them_are_not_one_disc_over_the_gap(split_seen_gaps, heading_deg):
    """dyn-overtake-2 at 50.6 s: the robot waits above a 0.42 m gap between two discs (the goal lies in it),
    12 beams; hits on both are closer than ``2 * default_radius_m`` and less than 90 degrees apart.  Linked,
    they made one disc fitted over the gap (where a beam passes freely); with ``split_seen_gaps`` (the
    default), a disc at each of the two and none over the gap's middle."""
    angles = np.linspace(0.0, 2 * math.pi, 12, endpoint=False)
    heading = math.radians(heading_deg)
    dirs = np.column_stack([np.cos(angles + heading), np.sin(angles + heading)])
    origins = 0.155 * dirs
    discs = [(np.array([-0.47, -0.38]), 0.25), (np.array([0.55, -0.38]), 0.35)]
    gap_middle = np.array([0.5 * (-0.47 + 0.25 + 0.55 - 0.35), -0.38])
    ranges = np.min([[ray_disc_ranges(o, d[None, :], c, r, 1.0)[0] for o, d in zip(origins, dirs)]
                     for c, r in discs], axis=0)
    hits, hit_origins = hit_points(Pose2D(0.0, 0.0, heading), ranges, angles, 0.155)
    tracker = HitTracker(split_seen_gaps=split_seen_gaps)
    tracker.reach_m = 1.0
    found = tracker.update(0.0, hits, hit_origins, (origins, dirs, ranges))
    over_gap = [d for d in found if math.hypot(d.x_m - gap_middle[0], d.y_m - gap_middle[1]) < d.radius_m]
    near_truth = all(min(math.hypot(d.x_m - c[0], d.y_m - c[1]) for d in found) < 0.1 for c, _ in discs)
    assert (not over_gap and near_truth and len(found) == 2) == split_seen_gaps
