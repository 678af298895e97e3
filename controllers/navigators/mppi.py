"""``mppi``: model-predictive path integral control (Williams et al. 2017) as Nav2's MPPI controller adapts it.

Williams, Wagener, Goldfain, Drews, Rehg, Boots & Theodorou (2017), "Information
theoretic MPC for model-based reinforcement learning" (ICRA): each control step,
sample K control sequences around the nominal one, U + eps_k with
eps_k ~ N(0, Sigma) (Alg. 2), roll each out through the model, score it with a
state cost plus the control cost gamma u^T Sigma^-1 eps (Eq. 30's
lambda-weighted term), and update the nominal sequence with the exponentially
weighted average of the noise, w_k = exp(-(S_k - min S) / lambda) / eta
(Eqs. 31-32); apply the first control, shift the sequence by one step.

As Nav2's ``nav2_mppi_controller`` adapts it (its critics, ours re-weighted for
this robot's 0.2 m/s scale): the model is the unicycle (v, omega) clipped to the
robot's limits (no reverse: v in [0, top speed]); the state cost sums

* obstacles (Nav2's ObstaclesCritic): sensed obstacles predicted along their
  estimated velocities (the sensing model's detections, :mod:`controllers.tracking`
  for the rangefinders; :mod:`controllers.prediction`'s constant-velocity model) at
  every step of every rollout, and the known map's discs and boxes; a point within
  the robot radius + ``margin_m`` of one is a collision (``collision_cost``, and the rest of the
  rollout counts as colliding), within ``repulsion_m`` beyond that a quadratic repulsion;
* path following (PathFollowCritic): the rollout's last point to the carrot, a point
  ``lookahead_m`` along the global path ahead of the robot's projection;
* path distance (PathAlignCritic, simplified: ours): the mean distance of the rollout's points to the
  path's sampled points ahead;
* goal (GoalCritic): within ``goal_radius_m`` of the goal, the mean distance of the rollout's points to it,
  replacing the two path terms.

Choices where the sources leave it open or Nav2's defaults do not fit (ours):
the update averages the noise as drawn (Williams et al.'s epsilon), while the rollouts apply the controls
clipped to the limits, so a nominal speed at the limit is not dragged down by the clipped half of its
samples; Nav2's Savitzky-Golay smoothing of the sequence is not applied.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.models.parameters import above, param, within
from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.guidance import local_setup
from swarmnav.controllers.guided import GuidedCarrot, box_guidance
from swarmnav.controllers.kinematics import wheel_speeds
from swarmnav.controllers.navigator import Belief, NavigationSetup, NavigationStep, Observation
from swarmnav.controllers.footprint import chassis_box_m
from swarmnav.controllers.navigators.rollout_gaps import box_gaps, disc_gaps
from swarmnav.models.errors import ConfigError
from swarmnav.models.world import Disc, wrap_angle_rad


@dataclass
class MppiNavigator:
    """MPPI (Williams et al. 2017, as Nav2 adapts it) over sensed obstacles' predicted motion.

    Args:
        samples: K, control sequences sampled per step (Nav2: batch_size).
        horizon_steps: T, steps per rollout (Nav2: time_steps); ``model_dt_s`` apart.
        linear_std_m_s, angular_std_rad_s: Sigma's diagonal (Nav2: vx_std, wz_std).
        temperature: lambda (Nav2: temperature), in cost units.
        control_cost: gamma of the control cost term (Nav2: gamma).
        margin_m: clearance kept beyond the robot radius before a point counts as a collision.
        repulsion_m, repulsion_weight: the repulsion band beyond the margin and its weight.  0.05 and 0.2 m
            (ours): at 0.1 and 0.3 m the robot kept 0.4 m from everything and timed out on dyn-overtake-2
            (the dyn-* suite, world seed 0: 11/12 -> 12/12 reached without collision, mean time 47 -> 42 s).
        collision_cost: the cost of a colliding point.
        lookahead_m, follow_weight, path_weight: the path-following terms.
        goal_radius_m, goal_weight: the goal term.
        max_angular_rad_s: the turn-rate limit.
        optimise_period_s: optimise every this long (Nav2: controller_frequency), applying the nominal
            sequence's step of the moment in between; 0: at every control step.  0.1 s (10 Hz, ours): the
            model's step, so an optimisation starts where the last one's first step ends.
        noise_bank: draw the noise from a bank of ``noise_bank`` x K sequences made at reset, K consecutive
            ones (circular) from a random start each step; 0: fresh draws every step, as the paper.  Drawing
            60,000 normals was most of a step's time (named option, ours).
        carrot_in_sight: the carrot is the farthest point of the lookahead the robot can reach straight past
            the known map (:meth:`controllers.guidance.PathCarrot.keep_in_sight`; ours, on by default: on
            dyn300's door scenes the carrot behind a wall held the robot still against it; false: the plain
            lookahead point).  The bundled dyn-* scenes have no static obstacle: there it changes nothing.
        reference_speed_m_s: the top speed ``linear_std_m_s`` and ``lookahead_m`` are given for; the robot's top
            speed over it scales both (named option, ours); 0 (default): both as given, whatever the top speed.
            Why: the control cost gamma u Sigma^-1 eps weighs a speed u by u / sigma_v, and the carrot
            ``lookahead_m`` ahead caps the speed at about lookahead / horizon (1 m in 3 s), so the defaults,
            set for dyn300's 0.2 m/s, held a 1 m/s robot near 0.29 m/s (CrowdNav's circle crossing: 6.5 m in
            25 s, timeouts); scaled (0.2: sigma_v 0.5 m/s, carrot 5 m at 1 m/s) it drives near its top speed.
            At a top speed equal to it nothing changes.
        footprint: "circle" (default: the robot radius about the base) or "box" (named option, ours; BARN's
            Jackal): every rollout point is checked with the chassis box's covering discs at the rollout's
            heading there (:func:`controllers.footprint.covering_discs`), and with the map unknown the
            guidance path is planned for the chassis' inscribed circle and kept to the middle of passages
            (:class:`controllers.centred_path.CentredPlanner`) instead of the run's planner's; the path term
            then follows that guidance path as it is replanned (at the defaults it keeps the first path).
        cost_weight, cost_reach_m: with ``footprint = "box"``, the guidance path's penalty near obstacles.
        speed_cap_m_s: the top speed of the rollouts, at most the robot's (named option, ours; 0: the robot's);
            ``reference_speed_m_s`` then scales by it.
        max_accel_m_s2: the rollouts' forward speed changes by at most this x ``model_dt_s`` per step, the first
            step's from the measured speed, and the sequence applied likewise (Nav2's ``ax_max`` / ``ax_min``;
            the update averages the bounded noise, as Nav2's); 0 (default): off, speeds jump at once.  Why (BARN,
            non-test worlds): standing 3-6 cm from a cylinder with every rollout colliding from its first step,
            the average drove off at 2 m/s into it (22 of 22 failures looked at); with 2 m/s^2 the rollouts that
            can no longer stop before it cost more, and 12 of those 22 worlds are reached (but 22 of a spread of 25
            other non-test worlds, where it reached 24 without: no net gain off the tuning worlds; docs/navigation.md).
        hard_check_s, hard_margin_m: ``hard_check_s`` > 0 (ours, not in Williams et al.; default 0: off): the
            averaged sequence's first ``hard_check_s`` must keep the chassis itself (its box, else the robot's
            disc) ``hard_margin_m`` (default half a 5 cm cell's diagonal) from the obstacles near, or no closer than
            it stands now; else the cheapest sampled sequence that does replaces it, else the sequence is reset to
            standing still (Nav2's fail flag when every trajectory collides).  A collision becomes a stop, and
            a stop can last until the time limit.
        box_rollouts: with ``footprint = "box"`` (named option, ours; default false: the covering discs), every
            rollout point is checked with the chassis box itself at the rollout's heading there, ``margin_m``
            beyond its edges (:func:`controllers.navigators.rollout_gaps.box_gaps`).  Why (BARN, non-test
            worlds): the two 0.25 m covering discs bulge 0.12 m past the Jackal's front face and 0.035 m past its
            sides, so with ``margin_m`` they called a cylinder 3-6 cm from the box a collision; the robot stood
            wedged there until every rollout collided from its first step, then drove off into it.
        recovery_s, recovery_back_m, recovery_margin_m: ``recovery_s`` > 0 (named option, ours, as move_base's
            recoveries and ``dwa``'s ``recovery_s``; default 0: none): once the robot and the sequence's first
            speed have stood (below 0.05 m/s) that long, turn on the spot toward the carrot at 0.6 rad/s (the
            other way if that way is blocked) until within 0.1 rad of it, else back straight off
            ``recovery_back_m`` at 0.2 m/s, each while the chassis (its box, else the robot's disc) keeps
            ``recovery_margin_m`` from the obstacles near over the next 0.5 s of the motion, or no less than it
            has now; then the sequence restarts from standing still.  The rollouts drive forward only, so a
            robot facing a pocket it cannot turn in has no way out without it.
        recovery_block_m: > 0 (named option, ours; default 0: off; needs ``footprint = "box"`` and ``recovery_s``
            > 0): once a recovery has backed off, the guidance path is replanned at once around a disc of this
            radius centred at the middle of the chassis' front face where it stood (grown, as every obstacle of
            the guidance, by the inscribed circle: :meth:`controllers.guided.GuidedCarrot.block_pocket`), and
            keeps it from then on; the discs are forgotten when no path passes them.  Why (BARN, non-test
            worlds): the guidance path, planned for the inscribed circle, leads through gaps the box cannot
            turn in; the recovery backed off and the robot drove into the same pocket again until the time
            limit (world 140).  With the map known (no guidance replanned) it does nothing.
    """

    name: ClassVar[str] = "mppi"
    safety_layer: ClassVar[dict[str, bool]] = {"safety_filter": False, "evade": False}  # controllers.safety_layer
    uses_detections: ClassVar[bool] = True
    uses_planner: ClassVar[bool] = False
    replan_wall_s: ClassVar[float] = 0.0  # plans nothing in step()
    # noise_bank x samples x horizon_steps x 2 float32 are drawn at reset: at most 16 x 20,000 x 100 x 2 (256 MB)

    samples: int = param(1000, within(1, 20_000))
    horizon_steps: int = param(30, within(1, 100))
    model_dt_s: float = param(0.1, above(0, 10))
    # float32 rollouts: sigma and lambda at least 1e-6 (a smaller one underflows sigma^-1 or -1/lambda to inf)
    linear_std_m_s: float = param(0.1, within(1e-6, 100))
    angular_std_rad_s: float = param(0.6, within(1e-6, 100))
    temperature: float = param(0.3, within(1e-6, 1e6))
    control_cost: float = param(0.015, within(0, 1e6))
    margin_m: float = param(0.05, within(0, 100))
    repulsion_m: float = param(0.2, within(0, 100))
    repulsion_weight: float = param(20.0, within(0, 1e6))
    collision_cost: float = param(1000.0, above(0, 1e9))
    lookahead_m: float = param(1.0, above(0, 1000))
    follow_weight: float = param(5.0, within(0, 1e6))
    path_weight: float = param(1.0, within(0, 1e6))
    goal_radius_m: float = param(0.6, above(0, 1000))
    goal_weight: float = param(5.0, within(0, 1e6))
    max_angular_rad_s: float = param(1.2, above(0, 100))
    noise_bank: int = param(8, within(1, 16))
    optimise_period_s: float = param(0.1, within(0, 10))
    carrot_in_sight: bool = True
    reference_speed_m_s: float = param(0.0, within(0, 100))
    footprint: str = param("circle", choices=("circle", "box"))
    cost_weight: float = param(0.0, within(0, 1000))
    cost_reach_m: float = param(0.3, above(0, 100))
    speed_cap_m_s: float = param(0.0, within(0, 100))
    max_accel_m_s2: float = param(0.0, within(0, 1000))
    hard_check_s: float = param(0.0, within(0, 10))
    hard_margin_m: float = param(0.035, within(0, 1))
    box_rollouts: bool = False
    recovery_s: float = param(0.0, within(0, 1000))
    recovery_back_m: float = param(0.3, within(0, 10))
    recovery_margin_m: float = param(0.035, within(0, 1))
    recovery_block_m: float = param(0.0, within(0, 1))

    def __post_init__(self) -> None:
        # Each field's own range is declared with it (param); what no single field can say:
        if self.samples * self.horizon_steps > 1_000_000:
            raise ConfigError("navigator.params.samples", f"samples x horizon_steps must be at most 1,000,000, "
                                                          f"got {self.samples * self.horizon_steps:,}")
        if self.box_rollouts and self.footprint != "box":
            raise ConfigError("navigator.params.box_rollouts", "needs footprint = \"box\"")
        if self.recovery_block_m > 0 and (self.footprint != "box" or self.recovery_s <= 0):
            raise ConfigError("navigator.params.recovery_block_m", "needs footprint = \"box\" and recovery_s > 0")

    def reset(self, setup: NavigationSetup) -> None:
        top_m_s = min(setup.max_speed_m_s, self.speed_cap_m_s) if self.speed_cap_m_s > 0 else setup.max_speed_m_s
        scale = top_m_s / self.reference_speed_m_s if self.reference_speed_m_s > 0 else 1.0
        scale = min(scale, 1000.0)  # a tiny reference speed: sigma_v and the carrot stay finite
        self.centred, self.discs, radius = box_guidance(setup, self.footprint, self.cost_weight, self.cost_reach_m)
        (self.geometry, self.max_speed, self.inflation, self.local, self.carrot, self.goal) = local_setup(
            setup, self.margin_m, self.lookahead_m * scale, self.carrot_in_sight, self.centred, radius,
            self.speed_cap_m_s)
        self.path_replans = 0
        self.rng = setup.rng
        box = chassis_box_m(setup)  # the hard check's chassis: the box, or the robot's disc about the base
        self.chassis = (np.array(box, dtype=float) if box is not None else None, float(setup.map_problem.robot_radius_m))
        self.chassis_reach = (0.0, self.chassis[1]) if box is None else (max(abs(box[0]), abs(box[2])),
                                                                         max(abs(box[1]), abs(box[3])))
        self.hard_steps = min(self.horizon_steps, int(math.ceil(self.hard_check_s / self.model_dt_s - 1e-9)))
        self.optimised_at_s = -1.0
        self.stopped_s, self.last_time_s, self.last_v, self.recovering = 0.0, None, 0.0, None
        # recovery_block_m: where the last recovery started, the disc to block once backed off, the discs blocked
        self.stuck_pose, self.pocket, self.pockets = None, None, 0
        self.target, self.near = None, None  # the carrot and the obstacles near, once the optimiser has run
        self.nominal = np.zeros((self.horizon_steps, 2), dtype=np.float32)
        self.std = np.array([self.linear_std_m_s * scale, self.angular_std_rad_s], dtype=np.float32)
        self.lo = np.array([0.0, -self.max_angular_rad_s], dtype=np.float32)
        self.hi = np.array([self.max_speed, self.max_angular_rad_s], dtype=np.float32)
        if self.noise_bank > 0:
            self.bank = self.rng.standard_normal((self.noise_bank * self.samples, self.horizon_steps, 2),
                                                 dtype=np.float32) * self.std
        self.step_times = self.model_dt_s * np.arange(1, self.horizon_steps + 1)             # (T,)
        self.reach = self.max_speed * self.model_dt_s * self.horizon_steps + self.inflation + self.repulsion_m + 1.0
        pts = np.asarray(setup.path.waypoints, dtype=float).reshape(-1, 2)
        self.path_points = _resample(pts, 0.1)
        self.path_cum = np.arange(len(self.path_points)) * 0.1

    def _clip(self, controls: np.ndarray) -> np.ndarray:
        """Clip (..., 2) controls to the limits in place, channel by channel: a scalar bound per channel is about
        ten times faster than broadcasting the (2,) bound arrays over a (K, T, 2) array (same values)."""
        for channel in (0, 1):
            np.clip(controls[..., channel], self.lo[channel], self.hi[channel], out=controls[..., channel])
        return controls

    def _ramp(self, speeds: np.ndarray, start_m_s: float) -> None:
        """Limit (K, T) forward speeds in place so that each step's is within ``max_accel_m_s2`` x ``model_dt_s`` of
        the step before's, the first one's of ``start_m_s`` (the measured speed): Nav2's acceleration limits."""
        step = np.float32(self.max_accel_m_s2 * self.model_dt_s)
        before = np.full(speeds.shape[0], start_m_s, dtype=np.float32)
        for t in range(speeds.shape[1]):
            np.clip(speeds[:, t], before - step, before + step, out=speeds[:, t])
            before = speeds[:, t]
        np.clip(speeds, self.lo[0], self.hi[0], out=speeds)

    def rollouts(self, x: float, y: float, heading: float, controls: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(K, T) x and y after each step of each (K, T, 2) control sequence (the unicycle, explicit Euler:
        each step moves along the heading it starts with, as Nav2's motion model)."""
        dt = np.float32(self.model_dt_s)
        omega = controls[:, :, 1] * dt
        before = np.cumsum(omega, axis=1)
        before -= omega                                                  # heading before each step
        before += np.float32(heading)
        step = controls[:, :, 0] * dt
        px = np.cumsum(step * np.cos(before), axis=1)
        py = np.cumsum(step * np.sin(before), axis=1)
        px += np.float32(x)
        py += np.float32(y)
        return px, py

    def costs(self, px: np.ndarray, py: np.ndarray, observation: Observation,
              heading: np.ndarray | None = None) -> np.ndarray:
        """(K,) state cost of each rollout (float32); ``heading`` ((K, T), with ``footprint = "box"``): the
        rollouts' headings, where the chassis' covering discs are checked instead of the base."""
        pose = observation.pose
        cost = np.zeros(len(px), dtype=np.float32)
        centres, velocities, radii, boxes = self.local.near(pose.x_m, pose.y_m, self.reach, observation.detections)
        self.near = (centres, velocities, radii, boxes)
        gap = self._footprint_gap(px, py, heading, centres, velocities, radii, boxes)
        cost = self._obstacle_cost(cost, gap)
        return self._tracking_cost(cost, px, py, pose)

    def _footprint_gap(self, px, py, heading, centres, velocities, radii, boxes) -> np.ndarray | None:
        """(K, T) gap of each rollout point's footprint: the base's, or (``heading`` given) the covering discs'."""
        if heading is None:
            return self._gap(px, py, centres, velocities, radii, boxes)
        if self.box_rollouts and self.chassis[0] is not None:
            return self._box_gap(px, py, heading, centres, velocities, radii, boxes)
        c, s = np.cos(heading), np.sin(heading)
        gap = None
        for dx, dy in self.discs.astype(np.float32):
            g = self._gap(px + dx * c - dy * s, py + dx * s + dy * c, centres, velocities, radii, boxes)
            gap = g if gap is None else np.minimum(gap, g, out=gap)
        return gap

    def _box_gap(self, px, py, heading, centres, velocities, radii, boxes) -> np.ndarray | None:
        """``box_rollouts``: (K, T) gap of the chassis box itself at each rollout point and heading, ``margin_m``
        beyond it (the map's boxes by their circumscribed discs), exact below ``repulsion_m``."""
        cx = [centres[:, 0:1] + velocities[:, 0:1] * self.step_times[None, :]]
        cy = [centres[:, 1:2] + velocities[:, 1:2] * self.step_times[None, :]]
        r = [np.asarray(radii, dtype=float)]
        if len(boxes):
            cx.append(np.repeat(0.5 * (boxes[:, 0:1] + boxes[:, 2:3]), len(self.step_times), axis=1))
            cy.append(np.repeat(0.5 * (boxes[:, 1:2] + boxes[:, 3:4]), len(self.step_times), axis=1))
            r.append(0.5 * np.hypot(boxes[:, 2] - boxes[:, 0], boxes[:, 3] - boxes[:, 1]))
        cx, cy, r = np.vstack(cx), np.vstack(cy), np.concatenate(r)
        if not len(r):
            return None
        return box_gaps(px, py, heading, self.chassis[0], cx, cy, r + self.margin_m, float(self.repulsion_m))

    def _gap(self, px: np.ndarray, py: np.ndarray, centres, velocities, radii, boxes) -> np.ndarray | None:
        """(K, T) gap of each rollout point to the nearest obstacle beyond the inflation (None: none near)."""
        gap = None
        if len(centres):
            # Obstacles predicted along their velocities at each step: (N, T) centres.
            cx = (centres[:, 0:1] + velocities[:, 0:1] * self.step_times[None, :]).astype(np.float32)
            cy = (centres[:, 1:2] + velocities[:, 1:2] * self.step_times[None, :]).astype(np.float32)
            gap = disc_gaps(px, py, cx, cy, (np.asarray(radii, dtype=float) + self.inflation).astype(np.float32))
        if len(boxes):
            for b in boxes.astype(np.float32):
                gx = np.maximum(np.maximum(b[0] - px, px - b[2]), 0.0)
                gy = np.maximum(np.maximum(b[1] - py, py - b[3]), 0.0)
                d = np.hypot(gx, gy) - np.float32(self.inflation)
                gap = d if gap is None else np.minimum(gap, d, out=gap)
        return gap

    def _obstacle_cost(self, cost: np.ndarray, gap: np.ndarray | None) -> np.ndarray:
        if gap is not None:
            hit = np.logical_or.accumulate(gap < 0.0, axis=1)            # after a collision the rollout stays collided
            cost += np.float32(self.collision_cost / gap.shape[1]) * np.count_nonzero(hit, axis=1)
            if np.float32(self.repulsion_m) > 0:                           # below float32's range: off, as 0
                near = np.clip((self.repulsion_m - gap) / np.float32(self.repulsion_m), 0.0, 1.0)
                cost += np.float32(self.repulsion_weight) * np.mean(near * near, axis=1)
        return cost

    def _tracking_cost(self, cost: np.ndarray, px: np.ndarray, py: np.ndarray, pose) -> np.ndarray:
        to_goal = math.hypot(self.goal[0] - pose.x_m, self.goal[1] - pose.y_m)
        if to_goal <= self.goal_radius_m:
            cost += np.float32(self.goal_weight) * np.mean(np.hypot(px - self.goal[0], py - self.goal[1]), axis=1)
            return cost
        target = self.carrot.update(pose)
        self.target = target
        if self.centred is not None and getattr(self.carrot, "replans", 0) != self.path_replans:
            self.path_replans = self.carrot.replans  # footprint = "box": the path term follows the guidance
            self.path_points = _resample(np.asarray(self.carrot.points, dtype=float), 0.1)
            self.path_cum = np.arange(len(self.path_points)) * 0.1
        cost += np.float32(self.follow_weight) * np.hypot(px[:, -1] - target[0], py[:, -1] - target[1])
        if self.path_weight > 0:
            s0 = self.carrot.progress_m
            ahead = self.path_points[(self.path_cum >= s0) & (self.path_cum <= s0 + self.reach)][::3]
            if len(ahead):
                sx, sy = px[:, ::3], py[:, ::3]
                best = None
                for ax, ay in ahead.astype(np.float32):
                    d = (sx - ax) ** 2 + (sy - ay) ** 2
                    best = d if best is None else np.minimum(best, d, out=best)
                cost += np.float32(self.path_weight) * np.sqrt(best).mean(axis=1)
        return cost

    def step(self, observation: Observation) -> NavigationStep:
        pose = observation.pose
        if self.recovery_s > 0.0:
            recovery = self._recovery(observation)
            if recovery is not None:
                return self._answer(pose, recovery[0], recovery[1], observation)
        elapsed = observation.time_s - self.optimised_at_s
        index = min(int(elapsed / self.model_dt_s + 1e-9), self.horizon_steps - 1)  # the sequence's step now
        if self.optimised_at_s >= 0.0 and elapsed < self.optimise_period_s - 1e-9:
            v, omega = (float(u) for u in self.nominal[index])
            return self._answer(pose, v, omega, observation)
        if self.optimised_at_s >= 0.0 and index > 0:                      # drop the steps already driven
            self.nominal = np.concatenate([self.nominal[index:], np.repeat(self.nominal[-1:], index, axis=0)])
        self.optimised_at_s = observation.time_s
        if self.noise_bank > 0:  # K sequences of the bank, from a random start (circular)
            start = int(self.rng.integers(len(self.bank)))
            noise = np.take(self.bank, np.arange(start, start + self.samples), axis=0, mode="wrap")
        else:
            noise = self.rng.standard_normal((self.samples, self.horizon_steps, 2), dtype=np.float32)
            noise *= self.std
        controls = noise + self.nominal[None]
        self._clip(controls)                                               # rolled out within the limits
        if self.max_accel_m_s2 > 0:  # Nav2's ax_max / ax_min: each step's speed within reach of the last one's
            self._ramp(controls[:, :, 0], observation.twist.linear_m_s)
            noise = controls - self.nominal[None]                          # the bounded noise, as Nav2 averages it
        px, py = self.rollouts(pose.x_m, pose.y_m, pose.heading_rad, controls)
        if self.centred is None:
            cost = self.costs(px, py, observation)
        else:  # the heading after each step
            heading = np.cumsum(controls[:, :, 1] * np.float32(self.model_dt_s), axis=1) + np.float32(pose.heading_rad)
            cost = self.costs(px, py, observation, heading)
        # Control cost gamma u^T Sigma^-1 eps (Williams et al. 2017, Eq. 30), summed over the sequence.
        if self.control_cost > 0:
            cost += np.tensordot(noise, self.nominal / (self.std * self.std), axes=([1, 2], [0, 1])) \
                * np.float32(self.control_cost)
        low = float(cost.min())
        weights = np.exp((cost - low) * np.float32(-1.0 / self.temperature))
        weights /= weights.sum()
        self.nominal = self._clip(self.nominal + np.tensordot(weights, noise, axes=1))
        if self.max_accel_m_s2 > 0:
            self._ramp(self.nominal[None, :, 0], observation.twist.linear_m_s)
        if self.hard_steps > 0:
            self._hard_check(pose, controls, cost)
        return self._answer(pose, float(self.nominal[0, 0]), float(self.nominal[0, 1]), observation)

    def _hard_check(self, pose, controls: np.ndarray, cost: np.ndarray) -> None:
        """``hard_check_s`` > 0 (ours, not in Williams et al.): the averaged sequence's first ``hard_steps`` steps
        must keep the chassis itself (its box, or the robot's disc) ``hard_margin_m`` from every obstacle near (or,
        where the robot stands closer already, no closer than now); else the cheapest sampled sequence that does
        replaces it; else (Nav2's fail flag, every trajectory in collision) the sequence is reset to standing
        still."""
        n = self.hard_steps
        floor = min(self.hard_margin_m, self._chassis_gaps(pose, np.zeros((1, 1, 2), dtype=np.float32))[0, 0] - 1e-3)
        if self._chassis_gaps(pose, self.nominal[None, :n]).min() >= floor:
            return
        ok = self._chassis_gaps(pose, controls[:, :n]).min(axis=1) >= floor
        if ok.any():
            best = int(np.flatnonzero(ok)[np.argmin(cost[ok])])
            self.nominal = controls[best].copy()
        else:
            self.nominal = np.zeros_like(self.nominal)

    def _chassis_gaps(self, pose, controls: np.ndarray) -> np.ndarray:
        """(K, n) float64 clearance of the chassis to the obstacles near after each of ``controls``' (K, n, 2)
        steps (the obstacles' boxes by their circumscribed discs; discs predicted along their velocities)."""
        px, py = self.rollouts(pose.x_m, pose.y_m, pose.heading_rad, controls)
        heading = np.cumsum(controls[:, :, 1] * np.float32(self.model_dt_s), axis=1) + np.float32(pose.heading_rad)
        centres, velocities, radii, boxes = self.near
        t = self.step_times[: controls.shape[1]]
        reach = self.max_speed * float(t[-1]) + math.hypot(*self.chassis_reach) + 0.1   # what n steps can meet
        keep = (np.hypot(centres[:, 0] - pose.x_m, centres[:, 1] - pose.y_m) - np.asarray(radii, dtype=float)
                - np.hypot(velocities[:, 0], velocities[:, 1]) * float(t[-1])) <= reach
        centres, velocities, radii = centres[keep], velocities[keep], np.asarray(radii, dtype=float)[keep]
        cx = [centres[:, 0:1] + velocities[:, 0:1] * t[None, :]]
        cy = [centres[:, 1:2] + velocities[:, 1:2] * t[None, :]]
        r = [np.asarray(radii, dtype=float)]
        if len(boxes):
            cx.append(np.repeat(0.5 * (boxes[:, 0:1] + boxes[:, 2:3]), len(t), axis=1))
            cy.append(np.repeat(0.5 * (boxes[:, 1:2] + boxes[:, 3:4]), len(t), axis=1))
            r.append(0.5 * np.hypot(boxes[:, 2] - boxes[:, 0], boxes[:, 3] - boxes[:, 1]))
        cx, cy, r = np.vstack(cx), np.vstack(cy), np.concatenate(r)            # (N, n), (N,)
        if not len(r):
            return np.full(px.shape, np.inf)
        dx = cx[None] - px[:, None].astype(float)                                # (K, N, n)
        dy = cy[None] - py[:, None].astype(float)
        c, s = np.cos(heading)[:, None].astype(float), np.sin(heading)[:, None].astype(float)
        lon, lat = dx * c + dy * s, -dx * s + dy * c
        box, radius = self.chassis
        if box is None:
            d = np.hypot(lon, lat) - radius
        else:
            gx = np.maximum(np.maximum(box[0] - lon, lon - box[2]), 0.0)
            gy = np.maximum(np.maximum(box[1] - lat, lat - box[3]), 0.0)
            d = np.hypot(gx, gy)
        d -= r[None, :, None]
        return d.min(axis=1)

    def _recovery(self, observation: Observation) -> tuple[float, float] | None:
        """``recovery_s`` > 0 (ours, as move_base's recoveries and ``dwa``'s): after the robot and the sequence's
        first speed have stood (below ``STILL_M_S``) that long, turn on the spot toward the carrot (the other way
        if that way is blocked), else back straight off ``recovery_back_m`` at ``BACK_M_S``, each while the
        chassis keeps ``recovery_margin_m`` from the obstacles near, or no less than it has now; (v, omega) to
        command, or None (the optimiser's step).  After a recovery the sequence restarts from standing still."""
        now_s = observation.time_s
        dt = 0.0 if self.last_time_s is None else max(0.0, now_s - self.last_time_s)
        self.last_time_s = now_s
        pose = observation.pose
        if self.recovering is None:
            still = abs(observation.twist.linear_m_s) < STILL_M_S and abs(self.last_v) < STILL_M_S
            self.stopped_s = self.stopped_s + dt if still else 0.0
            if self.stopped_s < self.recovery_s or self.target is None or self.near is None:
                return None
            self.stopped_s = 0.0
            self.stuck_pose = pose
            err = wrap_angle_rad(math.atan2(self.target[1] - pose.y_m, self.target[0] - pose.x_m) - pose.heading_rad)
            turns = (math.copysign(1.0, err), -math.copysign(1.0, err)) if abs(err) > TURN_SWEEP_RAD else ()
            for sign in turns:
                if self._recovery_free(pose, 0.0, sign * self._turn_rate()):
                    self.recovering = ["turn", sign]
                    break
            else:
                if self.recovery_back_m > 0.0 and self._recovery_free(pose, -BACK_M_S, 0.0):
                    self.recovering = ["back", self.recovery_back_m]
                    self._pocket_ahead()
            if self.recovering is None:
                return None
        else:
            self.recovering[1] = self.recovering[1] - (BACK_M_S * dt if self.recovering[0] == "back" else 0.0)
        if self.recovering[0] == "turn":
            err = wrap_angle_rad(math.atan2(self.target[1] - pose.y_m, self.target[0] - pose.x_m) - pose.heading_rad)
            omega = self.recovering[1] * self._turn_rate()
            if abs(err) > 0.1 and self._recovery_free(pose, 0.0, omega):
                return self._recovered(0.0, omega)
            if self.recovery_back_m > 0.0 and abs(err) > 0.1 and self._recovery_free(pose, -BACK_M_S, 0.0):
                self.recovering = ["back", self.recovery_back_m]
                self._pocket_ahead()
        if self.recovering[0] == "back" and self.recovering[1] > 0.0 and self._recovery_free(pose, -BACK_M_S, 0.0):
            return self._recovered(-BACK_M_S, 0.0)
        self.recovering, self.stopped_s, self.last_v = None, 0.0, 0.0
        if self.pocket is not None:  # recovery_block_m: backed off, the guidance is replanned around the pocket
            self.carrot.block_pocket(self.pocket, pose)
            self.pocket, self.pockets = None, self.pockets + 1
        self.nominal = np.zeros_like(self.nominal)
        self.optimised_at_s = -1.0                                          # optimise at once, from standing
        return None

    def _pocket_ahead(self) -> None:
        """``recovery_block_m`` > 0 and a recovery backing off: the disc of that radius at the middle of the
        chassis' front face where the recovery started, blocked in the guidance once the robot has backed off
        (:meth:`controllers.guided.GuidedCarrot.block_pocket`)."""
        if self.recovery_block_m <= 0.0 or not isinstance(self.carrot, GuidedCarrot):
            return
        pose = self.stuck_pose
        front = float(self.chassis[0][2]) if self.chassis[0] is not None else self.chassis[1]
        self.pocket = Disc(pose.x_m + front * math.cos(pose.heading_rad),
                           pose.y_m + front * math.sin(pose.heading_rad), float(self.recovery_block_m))

    def _recovered(self, v: float, omega: float) -> tuple[float, float]:
        self.last_v = v
        return v, omega

    def _turn_rate(self) -> float:
        return min(RECOVERY_TURN_RAD_S, self.max_angular_rad_s)

    def _recovery_free(self, pose, v: float, omega: float) -> bool:
        """Whether the chassis driven at (v, omega) for ``RECOVERY_CHECK_S`` keeps ``recovery_margin_m`` from the
        obstacles near (:meth:`_chassis_gaps`), or no less than it has now (less 1 mm)."""
        n = max(1, int(math.ceil(RECOVERY_CHECK_S / self.model_dt_s - 1e-9)))
        controls = np.zeros((1, n, 2), dtype=np.float32)
        controls[0, :, 0], controls[0, :, 1] = v, omega
        now = self._chassis_gaps(pose, np.zeros((1, 1, 2), dtype=np.float32))[0, 0]
        return bool(self._chassis_gaps(pose, controls).min() >= min(self.recovery_margin_m, now - 1e-3))

    def _answer(self, pose, v: float, omega: float, observation: Observation) -> NavigationStep:
        if self.recovery_s > 0.0 and self.recovering is None:
            self.last_v = v
        command = ControlCommand(wheel_speeds(v, omega, self.geometry), v, omega, 0)
        horizon = self.model_dt_s * self.horizon_steps
        return NavigationStep(command, None, (), Belief(observation.detections, horizon))


STILL_M_S = 0.05           # recovery_s: the robot stands while its measured and commanded speeds are below this
BACK_M_S = 0.2             # recovery_s: the speed it backs off at
RECOVERY_TURN_RAD_S = 0.6  # recovery_s: the rate it turns on the spot at (at most max_angular_rad_s)
RECOVERY_CHECK_S = 0.5     # recovery_s: each recovery motion is checked this far ahead (0.3 rad, 0.1 m)
TURN_SWEEP_RAD = 0.3       # recovery_s: a turn toward the carrot only when it is off by more than this


def _resample(points: np.ndarray, spacing_m: float) -> np.ndarray:
    """The polyline's points every ``spacing_m`` of arc length (its end included)."""
    if len(points) < 2:
        return points.copy()
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.append(np.arange(0.0, cum[-1], spacing_m), cum[-1])
    return np.column_stack([np.interp(s, cum, points[:, 0]), np.interp(s, cum, points[:, 1])])
