"""``dwa``: the Dynamic Window Approach (Fox, Burgard & Thrun 1997), guided by the global path,
with sensed obstacles predicted forward by their estimated velocities.

As in the paper (§§ 3-4): the search space is the robot's translational and
rotational velocities (v, omega), each held constant over the prediction
(circular arcs, §3.1); the *dynamic window* V_d keeps the pairs reachable from
the measured (v, omega) within one window of the acceleration limits
(Eq. 13); *admissible* pairs V_a are those from which the robot can still stop
before the nearest obstacle on its arc, v <= sqrt(2 dist(v, omega) a_v) and
|omega| <= sqrt(2 dist(v, omega) a_omega) (Eq. 12); among V_r = V_s ∩ V_a ∩ V_d
the pair maximising

    G(v, omega) = sigma(alpha heading + beta dist + gamma velocity)     (Eq. 14)

is commanded.  sigma is the paper's smoothing, here a normalisation of each
term to [0, 1] over the window.

Where we differ or the paper is silent (our choices):

* **Guidance**: ``heading`` measures the alignment at the arc's end with the
  direction to a carrot point ``lookahead_m`` along the global path
  (:class:`~controllers.guidance.PathCarrot`), not to the goal: the global path
  says how to get around the known map.  When the carrot (then the path's end)
  is within the arcs' reach, the alignment is taken where each arc comes
  closest to it, and an arc passing within the goal tolerance counts as
  aligned: judged at the arc's end, an arc through the goal scored worse than
  standing still facing it, and the robot stopped short of the goal.
* **Moving obstacles**: the paper's obstacles are static points of the
  occupancy grid (and PythonRobotics' DWA treats them so).  Here every sensed
  obstacle moves along its estimated velocity at each simulated step of the
  arc, so ``dist`` is the arc length the robot can drive before its disc
  (radius plus ``margin_m``) would meet an obstacle *at that time*; the known
  map's discs and boxes stand still.
* ``dist`` is capped at ``dist_cap_m`` (the paper caps it at a constant too)
  and arcs are simulated for ``horizon_s`` in steps of ``sim_step_s``.
* With no admissible pair the robot brakes at full deceleration and turns
  toward the carrot (nothing the window allows is safe).
* **Sampling** (the paper searches a discretised velocity space): a fixed
  lattice of ``v_samples`` speeds over [0, v_max] x ``omega_samples`` turn
  rates over [-omega_max, omega_max], whose arcs are computed once, in the
  robot's frame, at reset; each step takes the block of lattice pairs inside
  the dynamic window (on an axis where the window holds no lattice value, the
  value nearest the measured one) and moves the obstacles into the robot's
  frame instead of the arcs into the world's.  The speed lattice is made fine
  enough for the window: at least ``ceil(2 v_max / (accel_m_s2 window_s)) + 1``
  speeds (at most 50, ``v_samples``' bound), so that the window (+-0.125 m/s at the defaults) always holds two or
  more of them (a bug fix: at 1 m/s the 7 default speeds were 0.167 m/s apart,
  the window from standing held 0 alone and the robot never moved; at or
  below 0.75 m/s, dyn300's 0.2 m/s included, the lattice is the 7 speeds as
  before).
* **Cost**: only whether each arc point's disc overlaps an obstacle matters (the first such point ends the
  arc's ``dist``); the obstacles that stand still (on an unknown map, the sensed map's cells, thousands) are
  tested through a k-d tree (:func:`controllers.disc_contacts.inside_any`), which decides every point as the
  (points x obstacles) distances did, bit for bit: a BARN run's CPU fell from ~21-33 s to ~6 s, the same
  trajectories.  On a sensed map without detections (BARN) the map's cells are tested through a lattice kept
  per map revision (:class:`controllers.disc_contacts.LatticeDiscs`: a distance transform with the nearest
  cells, in the world frame), which settles almost every point and leaves the rest to ``inside_any``, the same
  answer bit for bit (a further ~25 % of a BARN run's CPU).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.models.parameters import above, param, within
from swarmnav.controllers.controller import ControlCommand
from swarmnav.controllers.disc_contacts import LatticeDiscs, inside_any, lattice_inside_any
from swarmnav.controllers.guidance import local_setup
from swarmnav.controllers.footprint import chassis_box_m
from swarmnav.controllers.guided import box_guidance
from swarmnav.controllers.kinematics import wheel_speeds
from swarmnav.controllers.navigator import Belief, NavigationSetup, NavigationStep, Observation
from swarmnav.models.world import wrap_angle_rad


CLEARANCES = ("distance", "time")


@dataclass
class DynamicWindowNavigator:
    """Fox, Burgard & Thrun (1997) with the global path as guidance and moving obstacles predicted.

    Args:
        alpha, beta, gamma: weights of heading, clearance and velocity in G (Eq. 14).
        accel_m_s2, angular_accel_rad_s2: the acceleration limits of the window.
        window_s: the time over which the window is open (the paper's cycle, 0.25 s).
        max_angular_rad_s: turn-rate limit.
        v_samples, omega_samples: the velocity lattice over [0, v_max] x [-omega_max, omega_max] (the speeds
            at least as many as keep two in the window: see the module's note on sampling).
        horizon_s, sim_step_s: how far and how finely arcs are simulated.
        dist_cap_m: ``dist`` beyond this counts as free.
        margin_m: extra distance kept beyond the robot radius.
        lookahead_m: the carrot's distance along the path.
        carrot_in_sight: the carrot is the farthest point of the lookahead the robot can reach straight past
            the known map (:meth:`controllers.guidance.PathCarrot.keep_in_sight`; ours, on by default: on
            dyn300's door scenes the carrot behind a wall held the robot still against it; false: the plain
            lookahead point).  The bundled dyn-* scenes have no static obstacle: there it changes nothing.
        clearance: how an arc that meets an obstacle within the horizon is scored and admitted:
            "distance" (default; the paper's dist) the length driven before contact, ``v t_contact``; "time"
            (named option, ours) ``v_max t_contact``, the time before contact at top speed: a standing robot
            then scores 0 only if nothing comes at it.  With "distance" stopping is always admissible and
            scores as well as any arc that meets an obstacle at once, so among people who do not see the robot
            it stood in their way and was walked into (CrowdNav's circle crossing, robot invisible).
        footprint: "circle" (default: the robot radius about the base) or "box" (named option, ours; BARN's
            Jackal): every arc point is checked with the chassis box's covering discs at the arc's heading
            there (:func:`controllers.footprint.covering_discs`: two 0.25 m discs for the Jackal, where its
            circumscribed circle, 0.333 m, does not pass BARN's 0.75 m gaps), and with the map unknown the
            guidance path is planned for the chassis' inscribed circle and kept to the middle of passages
            (:class:`controllers.centred_path.CentredPlanner`) instead of the run's planner's.
        cost_weight, cost_reach_m: with ``footprint = "box"``, the guidance path's penalty near obstacles
            (:func:`controllers.footprint.cell_penalty`).
        speed_cap_m_s: the top speed of the lattice, at most the robot's (named option, ours; 0: the robot's).
        aligned_within: where an arc passing within the goal tolerance counts as aligned (see Guidance): near
            the ``"carrot"`` (default, as before) or only near the ``"goal"`` (named option, ours).  Why: with
            BARN's 1 m goal tolerance and the 1 m carrot, every arc of the window passed within the tolerance of
            the carrot, all scored as aligned, and the tie went to the hardest right turn: on BARN the robot
            drove in a curve into the start area's right wall.
        inside_margin: what the window does while the robot stands closer to an obstacle than its radius plus
            ``margin_m`` (the sensed map grew under it, or it ran in): ``"stop"`` (default, the paper's: every arc
            meets the obstacle at once, none is admissible, the robot brakes and turns toward the carrot) or
            ``"shrink"`` (named option, ours): the arcs are checked against the clearance the robot has now, so it
            can drive out along or away from the obstacle (BARN: it stood there until the time limit, worlds 85,
            169, 277).
        recovery_s: seconds the window's best pair may stand still (v = omega = 0) before a recovery (named option,
            ours, as move_base's rotate recovery; 0: none, the default).  The recovery turns on the spot toward
            the carrot at ``recovery_turn_rad_s`` (the other way if that way is blocked) until within 0.1 rad of
            it, else backs straight off ``recovery_back_m`` at 0.1 m/s, each while the chassis (its box with
            ``footprint = "box"``, else its discs) keeps ``recovery_margin_m`` from every obstacle, or no less than
            it has now; if neither is free the window chooses again with standing still left out.  With the
            recovery on, the window's fallback (no admissible pair) turns only if that turn is free likewise: its
            blind turn swung the Jackal's rear into a cylinder (BARN world 85).  Why: the window's standing
            still outscores every slow arc near an obstacle (beta > alpha) and a turn on the spot is admissible
            only if nothing is met within the whole horizon, so in clutter the robot stood still facing away from
            the carrot until the time limit (BARN worlds 181, 265, 277).
        recovery_turn_rad_s, recovery_back_m, recovery_margin_m: the recovery's turn rate, how far it backs off
            (0: it does not), and the clearance its motions keep (0.035 m: half a 0.05 m sensed cell's diagonal,
            below ``margin_m``, which is what the robot stands inside).
        sight_inside: what the carrot's sight test (``carrot_in_sight``) does while the robot stands within the
            sight radius of an obstacle: ``"block"`` (default, as before: every segment from the robot starts
            blocked, no sample is in sight and the carrot is the robot's own projection on the path) or
            ``"shrink"`` (named option, ours): the sight radius is lowered to the clearance the robot has now, so
            a sample counts as in sight when the straight way to it comes no nearer to any obstacle than the robot
            stands (as ``inside_margin = "shrink"`` does for the arcs).  Why: on BARN (``footprint = "box"``, the
            sight radius 0.265 m) the robot stood beside a cylinder, its carrot a few centimetres from itself,
            and turned back and forth on the spot until the time limit.
        recovery_back: how the recovery backs off: ``"straight"`` (default, as before: only when no turn toward the
            carrot is free, straight along the chassis' axis) or ``"carrot"`` (named option, ours): when the carrot
            is behind the robot (more than 90 degrees off) and the whole turn on the spot to face it is not free,
            the recovery first reverses ``recovery_back_m`` at 0.1 m/s with its rear steered toward the carrot
            (turn rate 2 x the rear's bearing error, at most ``recovery_turn_rad_s``; straight if that arc is not
            free), each second of it kept free as the other motions are.  Why: on BARN the guidance path, replanned
            from a robot that had driven into a pocket, led back behind it; the Jackal's box could not turn on the
            spot there, the recovery turned ~30 degrees either way, the window stood still (every forward arc met
            a cylinder within centimetres) and the robot stayed until the time limit (worlds 118, 256, 260).
    """

    name: ClassVar[str] = "dwa"
    safety_layer: ClassVar[dict[str, bool]] = {"safety_filter": False, "evade": False}  # controllers.safety_layer
    # The evasion's options (controllers.evasion), off by default, as dstar_replan offers them (docs/navigation.md).
    safety_layer_options: ClassVar[tuple[str, ...]] = ("evade_still_m_s", "evade_reverse", "evade_turn_cost_m_s_rad")
    uses_detections: ClassVar[bool] = True
    uses_planner: ClassVar[bool] = False
    replan_wall_s: ClassVar[float] = 0.0  # plans nothing in step()

    # v_samples x omega_samples x horizon_s / sim_step_s rollout points: at most 50 x 100 x 500
    alpha: float = param(1.0, within(0, 1e6))
    beta: float = param(1.2, within(0, 1e6))
    gamma: float = param(0.3, within(0, 1e6))
    accel_m_s2: float = param(0.5, above(0, 1000))
    angular_accel_rad_s2: float = param(3.0, above(0, 1000))
    window_s: float = param(0.25, above(0, 10))
    max_angular_rad_s: float = param(1.2, above(0, 100))
    v_samples: int = param(7, within(1, 50))
    omega_samples: int = param(25, within(1, 100))
    horizon_s: float = param(3.0, above(0, 10))
    sim_step_s: float = param(0.15, within(0.02, 1))
    dist_cap_m: float = param(1.0, above(0, 1000))
    margin_m: float = param(0.05, within(0, 100))
    lookahead_m: float = param(1.0, above(0, 1000))
    carrot_in_sight: bool = True
    clearance: str = param("distance", choices=CLEARANCES)
    footprint: str = param("circle", choices=("circle", "box"))
    cost_weight: float = param(0.0, within(0, 1000))
    cost_reach_m: float = param(0.3, above(0, 100))
    speed_cap_m_s: float = param(0.0, within(0, 100))
    aligned_within: str = param("carrot", choices=("carrot", "goal"))
    inside_margin: str = param("stop", choices=("stop", "shrink"))
    recovery_s: float = param(0.0, within(0, 1000))
    recovery_turn_rad_s: float = param(0.6, above(0, 100))
    recovery_back_m: float = param(0.0, within(0, 10))
    recovery_margin_m: float = param(0.035, within(0, 100))
    sight_inside: str = param("block", choices=("block", "shrink"))
    recovery_back: str = param("straight", choices=("straight", "carrot"))

    def __post_init__(self) -> None:
        if self.horizon_s < self.sim_step_s:  # no rollout step at all
            raise ConfigError("navigator.params.horizon_s", f"must be at least sim_step_s ({self.sim_step_s:g} s), "
                                                            f"got {self.horizon_s!r}")

    def reset(self, setup: NavigationSetup) -> None:
        self.box = chassis_box_m(setup) if self.footprint == "box" else None
        self.centred, self.discs, radius = box_guidance(setup, self.footprint, self.cost_weight, self.cost_reach_m)
        (self.geometry, self.max_speed, self.inflation, self.local, self.carrot, self.goal) = local_setup(
            setup, self.margin_m, self.lookahead_m, self.carrot_in_sight, self.centred, radius, self.speed_cap_m_s)
        if self.sight_inside == "shrink":
            self.carrot.sight_shrink = True
        self.goal_tolerance_m = setup.goal.tolerance_m
        self.world_map = setup.world_map
        self._lattice: tuple[int, LatticeDiscs | None] | None = None  # (the sensed map's revision, its cells)
        self.control_dt_s = setup.control_dt_s
        self.stopped_s = 0.0          # how long the window's best pair has been standing still
        self.recovering: tuple[str, float] | None = None  # ("turn", +-1), ("back" / "reverse", metres left)
        self.times = np.arange(1, int(round(self.horizon_s / self.sim_step_s)) + 1) * self.sim_step_s  # (T,)
        self.reach = self.max_speed * self.horizon_s + 1.0
        # The lattice V_s and its arcs in the robot's frame (start at the origin facing +x).
        dv = self.accel_m_s2 * self.window_s
        n_speeds = max(self.v_samples, min(math.ceil(2.0 * self.max_speed / dv - 1e-9) + 1, 50)) \
            if self.v_samples > 1 else 1                                                    # 50: v_samples' bound
        self.speeds = np.linspace(0.0, self.max_speed, n_speeds) if n_speeds > 1 \
            else np.array([self.max_speed])                                                 # (V,)
        self.turns = np.linspace(-self.max_angular_rad_s, self.max_angular_rad_s, self.omega_samples) \
            if self.omega_samples > 1 else np.zeros(1)                                      # (W,)
        v, w = np.meshgrid(self.speeds, self.turns, indexing="ij")
        v, w, t = v[..., None], w[..., None], self.times
        small = np.abs(w) < 1e-6
        safe_w = np.where(small, 1.0, w)
        self.arc_x = np.where(small, v * t, v / safe_w * np.sin(w * t))                     # (V, W, T)
        self.arc_y = np.where(small, 0.0, v / safe_w * (1.0 - np.cos(w * t)))
        # Per pair: v, omega, |omega|, the heading at the arc's end (robot frame).
        self.pair = np.stack([v[..., 0], w[..., 0], np.abs(w[..., 0]), w[..., 0] * self.times[-1]], axis=-1)

    def step(self, observation: Observation) -> NavigationStep:
        pose, twist = observation.pose, observation.twist
        target = self.carrot.update(pose)
        if self.recovery_s > 0.0 and self.stopped_s >= self.recovery_s:
            recovery = self._recover(observation, target)
            if recovery is not None:
                v_cmd, w_cmd = recovery
                command = ControlCommand(wheel_speeds(v_cmd, w_cmd, self.geometry), v_cmd, w_cmd, 0)
                return NavigationStep(command, None, (), Belief(observation.detections, self.horizon_s))
        # Dynamic window (Eq. 13) on the lattice V_s.
        dv, dw = self.accel_m_s2 * self.window_s, self.angular_accel_rad_s2 * self.window_s
        vi = _window(self.speeds, twist.linear_m_s, dv)
        wi = _window(self.turns, twist.angular_rad_s, dw)
        n_t = len(self.times)
        x = self.arc_x[vi, wi].reshape(-1, n_t)                                         # (K, T), robot frame
        y = self.arc_y[vi, wi].reshape(-1, n_t)
        v, w, w_abs, theta_end = self.pair[vi, wi].reshape(-1, 4).T                     # (K,) each
        c, s = math.cos(pose.heading_rad), math.sin(pose.heading_rad)
        if self.centred is None:
            arcs = [(x, y)]
        else:  # the chassis' covering discs along each arc, at the arc's heading there
            theta = w[:, None] * self.times[None, :]
            ct, st = np.cos(theta), np.sin(theta)
            arcs = [(x + dx * ct - dy * st, y + dx * st + dy * ct) for dx, dy in self.discs]
        hit = self._hits(pose.x_m, pose.y_m, c, s, arcs, observation)                    # (K, T) or None
        if hit is None:
            dist = np.full(len(v), self.dist_cap_m)
            admissible = (v <= math.sqrt(2.0 * self.dist_cap_m * self.accel_m_s2) + 1e-9) & \
                         (w_abs <= math.sqrt(2.0 * self.dist_cap_m * self.angular_accel_rad_s2) + 1e-9)
        else:
            first = np.where(hit.any(axis=1), hit.argmax(axis=1), n_t)
            t_free = np.where(first > 0, self.times[np.maximum(first - 1, 0)], 0.0)
            driven = self.max_speed * t_free if self.clearance == "time" else v * t_free
            dist = np.where(first == n_t, self.dist_cap_m, np.minimum(driven, self.dist_cap_m))  # before contact
            admissible = (v <= np.sqrt(2.0 * dist * self.accel_m_s2) + 1e-9) & \
                         (w_abs <= np.sqrt(2.0 * dist * self.angular_accel_rad_s2) + 1e-9)
        # The three terms of G, each normalised to [0, 1]; the carrot in the robot's frame.
        rx, ry = target[0] - pose.x_m, target[1] - pose.y_m
        tx, ty = c * rx + s * ry, -s * rx + c * ry
        if math.hypot(rx, ry) > self.reach - 1.0 + self.goal_tolerance_m:
            bearing = np.arctan2(ty - y[:, -1], tx - x[:, -1])
            heading = 1.0 - np.abs(wrap_angle_rad(bearing - theta_end)) / math.pi
        else:
            # The carrot is within the arcs' reach (the path's end): judge each arc where it comes
            # closest to the carrot, and one that passes within the goal tolerance as aligned.
            d2 = (tx - x) ** 2 + (ty - y) ** 2
            j = d2.argmin(axis=1)
            rows = np.arange(len(j))
            bearing = np.arctan2(ty - y[rows, j], tx - x[rows, j])
            near_goal = self.aligned_within == "carrot" or \
                math.hypot(target[0] - self.goal[0], target[1] - self.goal[1]) <= 1e-6
            heading = np.where((d2[rows, j] <= self.goal_tolerance_m ** 2) & near_goal, 1.0,
                               1.0 - np.abs(wrap_angle_rad(bearing - w * self.times[j])) / math.pi)
        clearance = dist / self.dist_cap_m
        remaining = math.hypot(self.goal[0] - pose.x_m, self.goal[1] - pose.y_m)
        v_top = min(self.max_speed, max(remaining, 0.05))  # no reward for overshooting the goal
        velocity = 1.0 - np.abs(v - v_top) / max(self.max_speed, 1e-9)
        score = self.alpha * _norm(heading) + self.beta * _norm(clearance) + self.gamma * _norm(velocity)
        if self.recovery_s > 0.0 and self.stopped_s >= self.recovery_s:  # stood still too long: move if any
            moving = admissible & ((v != 0.0) | (w != 0.0))
            admissible = moving if moving.any() else admissible
        if admissible.any():
            k = int(np.argmax(np.where(admissible, score, -np.inf)))
            v_cmd, w_cmd = float(v[k]), float(w[k])
        else:
            v_cmd = max(0.0, twist.linear_m_s - dv)
            err = wrap_angle_rad(math.atan2(ry, rx) - pose.heading_rad)
            w_cmd = float(np.clip(2.0 * err, -self.max_angular_rad_s, self.max_angular_rad_s))
            if self.recovery_s > 0.0 and w_cmd != 0.0 and not self._free(  # with the recovery: a turn kept clear
                    pose, c, s, observation, math.copysign(0.3, w_cmd) * np.arange(1, n_t + 1) / n_t, 0.0):
                w_cmd = 0.0
        if self.recovery_s > 0.0:
            self.stopped_s = self.stopped_s + self.control_dt_s if v_cmd == 0.0 and w_cmd == 0.0 else 0.0
        command = ControlCommand(wheel_speeds(v_cmd, w_cmd, self.geometry), v_cmd, w_cmd, 0)
        return NavigationStep(command, None, (), Belief(observation.detections, self.horizon_s))

    def _recover(self, observation: Observation, target: np.ndarray) -> tuple[float, float] | None:
        """``recovery_s`` > 0: after the window's best pair has stood still that long, turn on the spot toward
        the carrot (the other way if that way is blocked), else back off ``recovery_back_m`` straight, each
        while :meth:`_free`; with ``recovery_back = "carrot"`` a carrot behind that the robot has no room to turn
        to is first reversed toward (rear steered to it); (v, omega) to command, or None when aligned or nothing is
        free (the window decides again, standing still left out)."""
        pose = observation.pose
        c, s = math.cos(pose.heading_rad), math.sin(pose.heading_rad)
        err = wrap_angle_rad(math.atan2(target[1] - pose.y_m, target[0] - pose.x_m) - pose.heading_rad)
        n_t, step_rad = len(self.times), 0.3
        if self.recovering is None and self.recovery_back == "carrot" and self.recovery_back_m > 0.0 \
                and abs(err) > 0.5 * math.pi and not self._free(  # the carrot behind, no room to turn to face it
                    pose, c, s, observation, np.linspace(0.0, err, max(n_t, math.ceil(abs(err) / 0.05)) + 1)[1:], 0.0):
            self.recovering = ("reverse", self.recovery_back_m)
        if self.recovering is not None and self.recovering[0] == "reverse":
            left = self.recovering[1] - 0.1 * self.control_dt_s
            rear_err = wrap_angle_rad(err - math.pi)  # the carrot's bearing from the rear
            w_back = float(np.clip(2.0 * rear_err, -self.recovery_turn_rad_s, self.recovery_turn_rad_s))
            w_back = float(np.clip(w_back, -self.max_angular_rad_s, self.max_angular_rad_s))
            for w_try in dict.fromkeys((w_back, 0.0)):  # the rear steered toward the carrot, else straight
                if left > 0.0 and self._free(pose, c, s, observation, w_try * np.arange(1, n_t + 1) / n_t, -0.1):
                    self.recovering = ("reverse", left)
                    return -0.1, w_try
            self.recovering = None
        if self.recovering is None:
            turns = (math.copysign(1.0, err), -math.copysign(1.0, err)) if abs(err) > step_rad else ()
            for sign in turns:
                if self._free(pose, c, s, observation, sign * step_rad * np.arange(1, n_t + 1) / n_t, 0.0):
                    self.recovering = ("turn", sign)
                    break
            else:
                if self.recovery_back_m > 0.0 and self._free(pose, c, s, observation, np.zeros(n_t), -0.1):
                    self.recovering = ("back", self.recovery_back_m)
        if self.recovering is not None and self.recovering[0] == "turn":
            sign = self.recovering[1]
            if abs(err) > 0.1 and \
                    self._free(pose, c, s, observation, sign * step_rad * np.arange(1, n_t + 1) / n_t, 0.0):
                return 0.0, sign * min(self.recovery_turn_rad_s, self.max_angular_rad_s)
            self.recovering = ("back", self.recovery_back_m) if abs(err) > 0.1 and self.recovery_back_m > 0.0 \
                and self._free(pose, c, s, observation, np.zeros(n_t), -0.1) else None
        elif self.recovering is not None and self.recovering[0] == "back":
            left = self.recovering[1] - 0.1 * self.control_dt_s
            if left > 0.0 and self._free(pose, c, s, observation, np.zeros(n_t), -0.1):
                self.recovering = ("back", left)
                return -0.1, 0.0
        self.recovering = None  # nothing to turn or back: the window's choice, standing still left out
        return None

    def _free(self, pose, c: float, s: float, observation: Observation, turn_rad: np.ndarray, back_m: float) -> bool:
        """Whether the chassis, turned on the spot by each of ``turn_rad`` (robot frame) or moved ``back_m`` along
        its axis in as many steps, keeps ``recovery_margin_m`` from every obstacle, or no less than it has now."""
        return self._free_discs(pose, c, s, observation, turn_rad, back_m * np.arange(1, len(turn_rad) + 1)
                                / len(turn_rad)) if self.box is None else \
            self._box_free(pose, c, s, observation, turn_rad, back_m * np.arange(1, len(turn_rad) + 1) / len(turn_rad))

    def _free_discs(self, pose, c: float, s: float, observation: Observation, turn_rad: np.ndarray,
                    shift_m: np.ndarray) -> bool:
        """:meth:`_free` for the covering discs (``footprint = "circle"``, or map boxes)."""
        ct, st = np.cos(turn_rad), np.sin(turn_rad)
        arcs = [((dx * ct - dy * st + shift_m)[None, :], (dx * st + dy * ct)[None, :]) for dx, dy in self.discs]
        hit = self._hits(pose.x_m, pose.y_m, c, s, arcs, observation, shrink=True)
        return hit is None or not bool(hit.any())

    def _box_free(self, pose, c: float, s: float, observation: Observation, turn_rad: np.ndarray,
                  shift_m: np.ndarray) -> bool:
        """:meth:`_free` for the chassis box: each pose (turned by ``turn_rad``, then moved ``shift_m`` along its
        axis) keeps ``recovery_margin_m`` from every obstacle's edge, or no less than the box has now."""
        centres, _, radii, boxes = self.local.near(pose.x_m, pose.y_m, 2.0, observation.detections)
        if len(boxes):  # map boxes: the covering discs' check
            return self._free_discs(pose, c, s, observation, turn_rad, shift_m)
        if not len(centres):
            return True
        rel_x, rel_y = centres[:, 0] - pose.x_m, centres[:, 1] - pose.y_m
        ox, oy = c * rel_x + s * rel_y, -s * rel_x + c * rel_y                            # (N,) robot frame
        x0, y0, x1, y1 = self.box

        def edge(phi: np.ndarray, shift: np.ndarray) -> np.ndarray:
            cp, sp = np.cos(phi)[:, None], np.sin(phi)[:, None]
            px = cp * ox[None, :] + sp * oy[None, :] - shift[:, None]                       # (P, N) box frame
            py = -sp * ox[None, :] + cp * oy[None, :]
            dx = np.maximum(np.maximum(x0 - px, px - x1), 0.0)
            dy = np.maximum(np.maximum(y0 - py, py - y1), 0.0)
            return np.hypot(dx, dy) - radii[None, :]

        now = float(edge(np.zeros(1), np.zeros(1)).min())
        return bool(edge(turn_rad, shift_m).min() >= min(self.recovery_margin_m, now - 1e-6))

    def _hits(self, x0: float, y0: float, c: float, s: float, arcs: list[tuple[np.ndarray, np.ndarray]],
              observation: Observation, shrink: bool = False) -> np.ndarray | None:
        """(K, T) whether a robot disc on an arc (each of ``arcs``: the (K, T) x and y of one disc's centre,
        robot frame) overlaps an obstacle at that time, its radius plus ``inflation`` from the obstacle's edge
        (None: nothing within reach).  The obstacles that stand still (the map's and the sensed map's cells)
        are tested through :func:`controllers.disc_contacts.inside_any`, exactly as the (points x obstacles)
        distances would decide it; the moving ones are moved to each time of the arc."""
        centres, velocities, radii, boxes = self.local.near(x0, y0, self.reach, observation.detections)
        if not len(centres) and not len(boxes):
            return None
        hit = np.zeros(arcs[0][0].shape, dtype=bool)
        rel_x, rel_y = centres[:, 0] - x0, centres[:, 1] - y0
        ox = c * rel_x + s * rel_y                                                       # (N,) robot frame
        oy = -s * rel_x + c * rel_y
        if shrink:  # the recovery's motions: recovery_margin_m beyond the discs, or no nearer than now
            inflation = min(self.inflation - self.margin_m + self.recovery_margin_m,
                            self._clearance_now(x0, y0, c, s, ox, oy, radii, boxes) - 1e-6)
        elif self.inside_margin == "shrink":
            inflation = min(self.inflation, self._clearance_now(x0, y0, c, s, ox, oy, radii, boxes) - 1e-6)
        else:
            inflation = self.inflation
        if len(centres):
            reach = radii + inflation
            moving = (velocities[:, 0] != 0.0) | (velocities[:, 1] != 0.0)
            still = ~moving
            if moving.any():
                ovx = c * velocities[moving, 0] + s * velocities[moving, 1]
                ovy = -s * velocities[moving, 0] + c * velocities[moving, 1]
                ox_t = ox[None, moving] + ovx[None, :] * self.times[:, None]            # (T, M)
                oy_t = oy[None, moving] + ovy[None, :] * self.times[:, None]
            lattice = self._lattice_now() if not observation.detections else None
            if lattice is not None:  # the sensed map's cells alone, all still, one radius (no detections)
                hit |= self._lattice_hits(lattice, x0, y0, c, s, arcs, ox, oy, reach).any(axis=0)
            for x, y in arcs:
                if still.any() and lattice is None:
                    hit |= inside_any(x, y, ox[still], oy[still], reach[still])
                if moving.any():
                    d = np.hypot(x[:, :, None] - ox_t[None], y[:, :, None] - oy_t[None]) - reach[moving]
                    hit |= d.min(axis=2) < 0.0
        if len(boxes):
            for x, y in arcs:
                wx, wy = x0 + c * x - s * y, y0 + s * x + c * y                           # boxes stay in the world
                dx = np.maximum(np.maximum(boxes[:, 0] - wx[..., None], wx[..., None] - boxes[:, 2]), 0.0)
                dy = np.maximum(np.maximum(boxes[:, 1] - wy[..., None], wy[..., None] - boxes[:, 3]), 0.0)
                hit |= (np.hypot(dx, dy) - inflation).min(axis=2) < 0.0
        return hit

    def _lattice_now(self) -> LatticeDiscs | None:
        """The sensed map's cells as a :class:`~controllers.disc_contacts.LatticeDiscs` (kept while the map's
        revision is), or None: the map is known, or its discs are not its grid's cells of one radius."""
        revision = getattr(self.local, "revision", None)
        grid = getattr(self.world_map, "grid", None)  # a SensedMap's log-odds grid
        if grid is None or revision is None:
            return None
        if self._lattice is None or self._lattice[0] != revision:
            radii = self.local.radii
            lattice = LatticeDiscs.of(self.local.centres, grid.origin_m, grid.cell_m, grid.rows, grid.cols) \
                if len(radii) and bool((radii == radii[0]).all()) else None
            self._lattice = (revision, lattice)
        return self._lattice[1]

    def _lattice_hits(self, lattice: LatticeDiscs, x0: float, y0: float, c: float, s: float,
                      arcs: list[tuple[np.ndarray, np.ndarray]], ox: np.ndarray, oy: np.ndarray,
                      reach: np.ndarray) -> np.ndarray:
        """(len(arcs), K, T): :func:`~controllers.disc_contacts.inside_any` of the arcs' points against the
        obstacles ``ox, oy`` (robot frame: exactly the map's cells within ``self.reach`` of the robot, each
        ``reach`` wide), bit for bit, through the lattice (:func:`~controllers.disc_contacts.lattice_inside_any`).
        Why (speed): the k-d tree over the cells near the robot, built and asked at every step, cost ~30-45 % of
        a BARN run's CPU."""
        px = np.stack([x for x, _ in arcs]).reshape(-1)
        py = np.stack([y for _, y in arcs]).reshape(-1)
        out = lattice_inside_any(lattice, x0, y0, c, s, px, py, ox, oy, float(reach[0]), float(self.local.radii[0]),
                                 self.reach)
        return out.reshape((len(arcs),) + np.shape(arcs[0][0]))

    def _clearance_now(self, x0: float, y0: float, c: float, s: float, ox: np.ndarray, oy: np.ndarray,
                       radii: np.ndarray, boxes: np.ndarray) -> float:
        """The smallest distance from a chassis disc's centre, where the robot stands, to an obstacle's edge
        (``inside_margin = "shrink"``: the arcs' inflation is lowered to it when the robot stands inside it)."""
        px, py = self.discs[:, 0], self.discs[:, 1]                                      # robot frame
        now = np.inf
        if len(ox):
            now = min(now, float((np.hypot(px[:, None] - ox[None, :], py[:, None] - oy[None, :]) - radii).min()))
        if len(boxes):
            wx, wy = x0 + c * px - s * py, y0 + s * px + c * py
            dx = np.maximum(np.maximum(boxes[:, 0] - wx[:, None], wx[:, None] - boxes[:, 2]), 0.0)
            dy = np.maximum(np.maximum(boxes[:, 1] - wy[:, None], wy[:, None] - boxes[:, 3]), 0.0)
            now = min(now, float(np.hypot(dx, dy).min()))
        return now


def _window(lattice: np.ndarray, centre: float, half_width: float) -> slice:
    """The slice of an evenly spaced lattice within ``centre +- half_width`` (the nearest point if none)."""
    n = len(lattice)
    if n == 1:
        return slice(0, 1)
    lo, step = float(lattice[0]), float(lattice[1] - lattice[0])
    first = max(0, math.ceil((centre - half_width - lo) / step - 1e-9))
    last = min(n - 1, math.floor((centre + half_width - lo) / step + 1e-9))
    if first > last:
        nearest = min(max(int(round((centre - lo) / step)), 0), n - 1)
        return slice(nearest, nearest + 1)
    return slice(first, last + 1)


def _norm(values: np.ndarray) -> np.ndarray:
    """The paper's smoothing sigma, as a normalisation to [0, 1] over the window."""
    lo, hi = float(values.min()), float(values.max())
    return (values - lo) / (hi - lo) if hi > lo else np.zeros_like(values)
