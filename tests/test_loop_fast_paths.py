"""The control loop's shortcuts give exactly what the plain computation gives.

* rangefinder conversion: one pass over a list against the NumPy masks it replaced;
* the clearance bound: never above what the probe measures, on random poses and
  obstacle shifts;
* a run that may skip clearance measurements against one that measures at every
  step: the same trajectory, minimum clearance, time in danger and collisions.
"""

import math

import mujoco
import numpy as np
import pytest

from swarmnav.models.scenario import load_scenario
from swarmnav.sim.clearance import CLEARANCE_HORIZON_M, ClearanceProbe
from swarmnav.sim.episode import EpisodeSpec, run_episode
from swarmnav.sim.simulation import Simulation
from swarmnav.sim.sensing import ranges_from_sensors


def ranges_reference(raw, cutoff_m):
    out = np.array(raw, dtype=float)
    out[(out < 0.0) | (out >= cutoff_m if cutoff_m > 0 else False)] = np.inf
    return out


def test_ranges_match_the_numpy_masks_bit_for_bit():
    rng = np.random.default_rng(3)
    for _ in range(300):
        cutoff = float(rng.choice([0.4, 1.5, 0.0, -1.0]))
        raw = rng.uniform(-1.5, 2.0, int(rng.integers(0, 20)))
        special = [-1.0, 0.0, -0.0, cutoff, abs(cutoff), np.nan, np.inf, -np.inf, np.nextafter(cutoff, -9)]
        pick = rng.random(raw.size) < 0.4
        raw[pick] = rng.choice(special, int(pick.sum()))
        fast, reference = ranges_from_sensors(raw, cutoff), ranges_reference(raw, cutoff)
        assert fast.dtype == reference.dtype and fast.shape == reference.shape
        assert fast.tobytes() == reference.tobytes()


@pytest.mark.parametrize("name", ["dense-field-30", "immas-env4-blocks", "dyn-crowd-1"])
def test_the_clearance_bound_never_exceeds_the_measured_clearance(name):
    """After a measure at one pose, the bound at a nearby pose (obstacles shifted by at most s)
    is below what measure returns there, and beyond the horizon measure returns the horizon."""
    simulation = Simulation(load_scenario(name))
    scene, model = simulation.scene, simulation.model
    data = simulation.reset()
    probe = ClearanceProbe(scene, data)
    mocap = data.mocap_pos.copy()
    rng = np.random.default_rng(1)
    adr = scene.free_qpos_adr
    width, height = simulation.scenario.arena_width_m, simulation.scenario.arena_height_m

    def place(x, y, heading, shift):
        data.qpos[adr:adr + 2] = [x, y]
        data.qpos[adr + 3:adr + 7] = [math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2)]
        if len(mocap):
            angle = rng.uniform(0, 2 * math.pi, len(mocap))
            data.mocap_pos[:, :2] = mocap[:, :2] + shift * np.column_stack([np.cos(angle), np.sin(angle)])
        mujoco.mj_forward(model, data)

    bounded = tight = beyond = 0
    for _ in range(400):
        x0, y0 = rng.uniform(0.3, width - 0.3), rng.uniform(0.3, height - 0.3)
        place(x0, y0, rng.uniform(-math.pi, math.pi), 0.0)
        probe.measure(data, x0, y0)
        step = rng.uniform(0.0, 0.3)
        direction = rng.uniform(0, 2 * math.pi)
        x, y = x0 + step * math.cos(direction), y0 + step * math.sin(direction)
        shift = float(rng.uniform(0.0, 0.1)) if len(mocap) else 0.0
        place(x, y, rng.uniform(-math.pi, math.pi), shift)
        bound = probe.lower_bound_m(shift)
        gap = probe.measure(data, x, y)
        if bound > CLEARANCE_HORIZON_M:
            beyond += 1
            assert gap == CLEARANCE_HORIZON_M
        else:
            assert gap > bound
            bounded += bound > 0.0
            tight += bound > 0.0 and gap < bound + 0.05
    assert bounded >= 50 and tight >= 5   # the bound is used, and sometimes close to the truth
    assert beyond >= 5 or name == "dense-field-30"


def test_no_bound_before_a_measure():
    simulation = Simulation(load_scenario("dense-field-30"))
    data = simulation.reset()
    probe = ClearanceProbe(simulation.scene, data)
    assert probe.lower_bound_m(0.0) == -math.inf
    probe.measure(data, 5.0, 5.0)
    assert -math.inf < probe.lower_bound_m(0.0) < probe.measure(data, 5.0, 5.0)


@pytest.mark.parametrize("name, navigator", [("dense-field-30", None), ("dyn-crowd-1", "follow"),
                                             ("dyn-crossing-1", "dwa"), ("immas-env1-dynamic", None)])
def test_skipping_clearance_measurements_changes_nothing(monkeypatch, name, navigator):
    spec = EpisodeSpec(load_scenario(name), navigator=navigator)
    fast = run_episode(spec, time_limit_s=30.0).result
    bounds = []
    original = ClearanceProbe.lower_bound_m

    def no_bound(self, shift_m):
        bounds.append(original(self, shift_m))
        return -math.inf

    monkeypatch.setattr(ClearanceProbe, "lower_bound_m", no_bound)
    slow = run_episode(spec, time_limit_s=30.0).result
    assert sum(b > 0.1 for b in bounds) >= 50            # measurements the fast run could skip
    assert np.array_equal(fast.poses, slow.poses)
    assert np.array_equal(fast.wheel_command_rad_s, slow.wheel_command_rad_s)
    assert fast.min_clearance_m == slow.min_clearance_m
    assert fast.time_in_danger_s == slow.time_in_danger_s
    assert (fast.collisions, fast.first_collision_s) == (slow.collisions, slow.first_collision_s)


@pytest.mark.parametrize("name, navigator", [("dyn-crowd-1", "follow"), ("dyn-head-on-1", "follow"),
                                             ("immas-env1-dynamic", None)])
def test_the_runners_bound_is_below_the_clearance_at_every_step_among_moving_obstacles(monkeypatch, name, navigator):
    """The bound the loop acts on (its obstacle-shift bookkeeping included) against a fresh probe's measure."""
    from swarmnav.sim import stepper

    original = stepper.EpisodeStepper._observe
    checked = []

    def checking_observe(self):
        truth = ClearanceProbe(self.scene)
        x, y = self.data.qpos[self.qadr:self.qadr + 2].tolist()
        bound = self.clearance_bound_m()
        gap = truth.measure(self.data, x, y)
        assert gap == CLEARANCE_HORIZON_M if bound > CLEARANCE_HORIZON_M else gap > bound
        checked.append(bound > 0.0)
        return original(self)

    monkeypatch.setattr(stepper.EpisodeStepper, "_observe", checking_observe)
    run_episode(EpisodeSpec(load_scenario(name), navigator=navigator), time_limit_s=40.0)
    assert sum(checked) >= 200


def nearest_reference(probe, data, x_m, y_m):
    """The probe's pick as first written: footprint distances with einsum, read from data every time."""
    d = np.maximum(np.abs(data.geom_xpos[probe.obstacle_ids, :2] - (x_m, y_m)) - probe.half_m, 0.0)
    footprint = np.sqrt(np.einsum("ij,ij->i", d, d)) - probe.radius_m
    return int(probe.obstacle_ids[np.argmin(footprint)]), float(np.min(footprint))


@pytest.mark.parametrize("name", ["dense-field-30", "immas-env4-blocks", "dyn-crowd-1", "iaco-dynamic"])
def test_the_nearest_obstacle_pick_matches_its_reference(name):
    """Cached static centres and the unrolled sum of squares pick the same obstacle, with the same
    footprint distance bit for bit, on random points (inside obstacles, on the arena's edge, beyond it)
    and with the moving obstacles moved."""
    simulation = Simulation(load_scenario(name))
    data = simulation.reset()
    probe = ClearanceProbe(simulation.scene, data)
    width, height = simulation.scenario.arena_width_m, simulation.scenario.arena_height_m
    rng = np.random.default_rng(5)
    mocap = data.mocap_pos.copy()
    centres = data.geom_xpos[probe.obstacle_ids, :2].copy()
    reused = 0
    for k in range(300):
        if len(mocap) and k % 10 == 0:
            data.mocap_pos[:, :2] = mocap[:, :2] + rng.normal(0.0, 0.5, (len(mocap), 2))
            mujoco.mj_kinematics(simulation.model, data)
        x, y = rng.uniform(-0.5, width + 0.5), rng.uniform(-0.5, height + 0.5)
        if k % 7 == 0:                                 # exactly on an obstacle's centre
            x, y = (float(v) for v in centres[rng.integers(len(centres))])
        # The point, then a few near it (where a static scene's probe reuses its last pick), then the point again.
        for dx, dy in [(0.0, 0.0), *rng.normal(0.0, 0.03, (3, 2)).tolist(), (0.0, 0.0)]:
            px, py = x + dx, y + dy
            expected_id, expected_footprint = nearest_reference(probe, data, px, py)
            gap = probe.measure(data, px, py)
            assert probe._reference[2] == expected_footprint
            assert probe._reference[:2] == (px, py)
            fromto = np.zeros(6)
            assert gap == min(mujoco.mj_geomDistance(simulation.model, data, g, expected_id, CLEARANCE_HORIZON_M,
                                                     fromto) for g in probe.robot_geom_ids)
            reused += probe._pick is not None and (dx, dy) != (0.0, 0.0) and probe._pick[1:3] != (px, py)
    assert reused >= 100 or len(mocap)  # the reused pick was exercised (static scenes)


@pytest.mark.parametrize("name", ["dyn-crowd-1", "immas-env4-blocks", "iaco-dynamic"])
def test_rangefinder_sensing_hands_the_tracker_what_hit_points_and_the_map_give(monkeypatch, name):
    """The sensing's one pass over the beams against hit_points and known_surface_gap_m, bit for bit,
    for random poses and ranges (no hit at all, every beam a hit)."""
    from swarmnav.controllers.tracking import HitTracker
    from swarmnav.models.world import Pose2D
    from swarmnav.sim.detector import STATIC_HIT_TOLERANCE_M, ObstacleSensing, hit_points, known_surface_gap_m

    scenario = load_scenario(name)
    simulation = Simulation(scenario)
    scene = simulation.scene
    track = simulation.obstacle_positions(np.arange(3) * 0.02)
    sensing = ObstacleSensing(scenario, track, np.full(track.shape[1], 0.2), 0.02, scene.range_angles_rad,
                              scene.range_offset_m)
    sensing.model = "rangefinder"
    seen = []
    monkeypatch.setattr(HitTracker, "update", lambda self, t, hits, origins, beams: seen.append((hits, origins, beams)))
    rng = np.random.default_rng(11)
    for k in range(200):
        pose = Pose2D(*rng.uniform(0.0, scenario.arena_width_m, 2), rng.uniform(-math.pi, math.pi))
        ranges = rng.uniform(0.0, scene.range_cutoff_m, len(scene.range_angles_rad))
        ranges[rng.random(ranges.size) < (0.5 if k % 3 else (1.0 if k % 2 else 0.0))] = np.inf
        sensing.sense(0, 0.0, pose, ranges)
        hits, origins, (beam_origins, directions, beam_ranges) = seen.pop()
        ref_hits, ref_origins = hit_points(pose, ranges, scene.range_angles_rad, scene.range_offset_m)
        unknown = known_surface_gap_m(ref_hits, scenario) > STATIC_HIT_TOLERANCE_M
        assert hits.tobytes() == ref_hits[unknown].tobytes() and hits.shape == ref_hits[unknown].shape
        assert origins.tobytes() == ref_origins[unknown].tobytes()
        world = pose.heading_rad + scene.range_angles_rad
        assert directions.tobytes() == np.column_stack([np.cos(world), np.sin(world)]).tobytes()
        assert beam_ranges.tobytes() == ranges.tobytes() and beam_origins.shape == (len(ranges), 2)


@pytest.mark.parametrize("name", ["dyn-crowd-1", "dyn-crossing-3"])  # rangefinder tracker, detector
def test_skipping_the_sensing_model_for_a_navigator_that_never_reads_it_changes_nothing(monkeypatch, name):
    """``follow`` declares ``uses_detections = False``: its observations carry no detections and the
    sensing model does no work; sensing anyway gives the same run, bit for bit (and does sense)."""
    from swarmnav.controllers.navigators.follow import FollowNavigator
    from swarmnav.sim.detector import ObstacleSensing

    spec = EpisodeSpec(load_scenario(name), navigator="follow")
    sensed = []
    original = ObstacleSensing.sense

    def counting_sense(self, *args):
        detections = original(self, *args)
        sensed.append(len(detections))
        return detections

    monkeypatch.setattr(ObstacleSensing, "sense", counting_sense)
    fast = run_episode(spec, time_limit_s=30.0).result
    assert not sensed
    monkeypatch.setattr(FollowNavigator, "uses_detections", True)
    slow = run_episode(spec, time_limit_s=30.0).result
    assert len(sensed) == slow.steps + 1 and sum(sensed) > 0
    assert np.array_equal(fast.poses, slow.poses)
    assert np.array_equal(fast.wheel_command_rad_s, slow.wheel_command_rad_s)
    assert fast.summary() | {"wall_time_s": 0} == slow.summary() | {"wall_time_s": 0}


def test_bench_sim_figures_are_rates_of_the_same_run_and_name_their_targets():
    from swarmnav.benchmarks.sim import benchmark_sim

    figures = benchmark_sim("dense-field-30", duration_s=1.0, repeats=1)
    assert figures["ratio"] == pytest.approx(figures["closed_loop_steps_per_s"] / figures["bare_steps_per_s"])
    assert figures["logging_ratio"] == pytest.approx(figures["logging_steps_per_s"] / figures["bare_steps_per_s"])
    assert 0 < figures["target_logging_ratio"] < figures["target_ratio"] <= 1
