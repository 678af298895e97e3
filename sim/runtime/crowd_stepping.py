"""Agents that see the robot (``sees_robot = true``), advanced by the stepper one control period at a time.

A crowd that cannot see the robot is a pure function of time (:mod:`swarmnav.models.crowd_agents`) and moves
like every scripted obstacle.  One that sees it depends on where the robot is: at control step ``s``, once the
robot's pose and velocity are known, :meth:`ReactiveCrowd.advance` moves the agents to their positions at step
``s + 1`` (written into the stepper's track) and sets their velocity at ``s`` (what the ``detector`` reports:
the velocity they chose, never a later one).
"""

from __future__ import annotations

import numpy as np

from swarmnav.models.crowd_agents import AgentMotion, Crowd, CrowdSession


def rollout_unneeded(crowd: Crowd) -> bool:
    """Whether a stepper can do without the no-robot rollout of this crowd (see :class:`ReactiveCrowd`)."""
    return all(spec.kind == "orca" for spec in crowd.specs)


class ReactiveCrowd:
    """The agents among a stepper's moving obstacles (``columns`` of its track) and their episode.

    ``lazy``: the stepper need not roll the agents out without a robot over the whole time limit (their
    columns of its track are written by :meth:`advance` before anything reads them).  That rollout gave two
    things, both kept: a bound on each step's hop, never above :meth:`max_hop_m` for ORCA agents (RVO2 caps
    a velocity at ``v_pref``, below the bound by at least ``PERTURB_M_S``, while its float32 positions round
    by micrometres), so the stepper's bound is ``max_hop_m`` either way; and the detector's velocity at the
    last step (a backward difference of rows the episode never writes at that step), which :meth:`advance`
    then computes from the same rollout, made only for a run that reaches its last step.  Social-force agents
    (capped at exactly the bound) keep the rollout.
    """

    def __init__(self, crowd: Crowd, columns: np.ndarray, robot_radius_m: float, dt_s: float,
                 motions: list[AgentMotion] | None = None):
        self.crowd = crowd
        self.columns = columns
        self.robot_radius_m = float(robot_radius_m)
        self.dt_s = dt_s
        self.session: CrowdSession | None = None
        self.motions = motions  # each column's motion (its rollout without a robot); None: not lazy
        self.lazy = motions is not None and rollout_unneeded(crowd)
        self._written = 0  # the last row of the track any episode's advance wrote (the rows after: the rollout's)

    @classmethod
    def of(cls, scenario, moving: list, dt_s: float) -> "ReactiveCrowd | None":
        """The scenario's crowd when it sees the robot (None otherwise); ``moving``: the scene's moving obstacles."""
        motions = [scenario.obstacles[ob.scenario_index].motion for ob in moving]
        agents = [(col, m) for col, m in enumerate(motions) if isinstance(m, AgentMotion)]
        if not agents or not agents[0][1].crowd.sees_robot:
            return None
        ordered = sorted(agents, key=lambda a: a[1].index)
        return cls(agents[0][1].crowd, np.array([col for col, _ in ordered], dtype=np.int64),
                   scenario.robot_radius_m, dt_s, [m for _, m in ordered])

    def max_hop_m(self) -> float:
        """How far an agent can move in one control period."""
        return self.crowd.max_speed_m_s * self.dt_s

    def reset(self, track_m: np.ndarray, velocity_m_s: np.ndarray, times_s: np.ndarray) -> None:
        """A new episode writing into the stepper's ``track_m`` (T, M, 2) and the sensing's ``velocity_m_s``
        (made from ``track_m`` as it is now); ``times_s``: the track's times."""
        self.session = CrowdSession(self.crowd)
        self.track_m = track_m
        self.velocity_m_s = velocity_m_s
        if self.lazy and len(track_m) > 1:  # the last two rows as the sensing's last velocity saw them
            self._last_rows = track_m[-2:, self.columns].copy()
            self._last_unwritten = [len(track_m) - 2 > self._written, len(track_m) - 1 > self._written]
            self._last_times_s = np.asarray(times_s, dtype=float)[-2:]
        track_m[0, self.columns] = self.session.positions_m

    def advance(self, step: int, base_qpos: np.ndarray, base_qvel: np.ndarray) -> None:
        """The agents from step ``step`` to ``step + 1``, seeing the robot where the physics has it now."""
        if step + 1 >= len(self.track_m):
            if self.lazy and len(self.track_m) > 1 and step == len(self.track_m) - 1:
                self._last_velocity(step)
            return
        self._written = max(self._written, step + 1)
        robot = (float(base_qpos[0]), float(base_qpos[1]), float(base_qvel[0]), float(base_qvel[1]),
                 self.robot_radius_m)
        now = self.session.positions_m.copy()
        self.track_m[step + 1, self.columns] = self.session.advance(step, robot)
        self.velocity_m_s[step, self.columns] = (self.track_m[step + 1, self.columns] - now) / self.dt_s

    def _last_velocity(self, step: int) -> None:
        """The sensing's velocity at the last step, as a stepper that rolled the agents out without a robot
        has it (ObstacleSensing: the backward difference of the track's last two rows as they were at reset)."""
        rows = self._last_rows
        if any(self._last_unwritten):
            alone = np.stack([m.positions_at(self._last_times_s) for m in self.motions], axis=1)
            for k, unwritten in enumerate(self._last_unwritten):
                if unwritten:
                    rows[k] = alone[k]
        self.velocity_m_s[step, self.columns] = np.diff(rows, axis=0)[0] / self.dt_s


class RolledCrowd:
    """Agents that do not see the robot, rolled out as the episode goes instead of over the whole time limit.

    Their motion is a pure function of the world seed (:attr:`Crowd.track_m`, one
    :class:`~models.crowd_agents.CrowdSession` without a robot); a run that ends early needs only its
    beginning.  :meth:`extend` writes the same rows into the stepper's track (its columns ``columns``), the
    sensing's velocities (forward differences, the last step's backward) and the stepper's hop bounds
    (``obstacle_shift_m``: the largest hop over every moving obstacle, summed in order).  Only when the
    track's times are the rollout's own control steps (the interpolation then gives its rows exactly) and
    nothing has rolled the crowd out already (a cached rollout costs nothing).
    """

    def __init__(self, crowd: Crowd, columns: np.ndarray, dt_s: float):
        self.crowd = crowd
        self.columns = columns
        self.dt_s = dt_s
        self.session = CrowdSession(crowd)
        self.rows = 0  # the track's rows written: 0 ..rows - 1 (row 0, the start, by obstacle_positions)

    @classmethod
    def of(cls, scenario, moving: list, dt_s: float, n_max: int) -> "RolledCrowd | None":
        """The scenario's crowd when it is blind to the robot and can be rolled out step by step (else None)."""
        motions = [scenario.obstacles[ob.scenario_index].motion for ob in moving]
        agents = [(col, m) for col, m in enumerate(motions) if isinstance(m, AgentMotion)]
        if not agents:
            return None
        crowd = agents[0][1].crowd
        if crowd.sees_robot or crowd.dt_s != dt_s or crowd.steps < n_max or "track_m" in crowd.__dict__ \
                or any(m.crowd is not crowd for _, m in agents):
            return None
        ordered = sorted(agents, key=lambda a: a[1].index)
        if [m.index for _, m in ordered] != list(range(len(crowd.specs))):
            return None
        return cls(crowd, np.array([col for col, _ in ordered], dtype=np.int64), dt_s)

    def attach(self, track_m: np.ndarray, velocity_m_s: np.ndarray, other_hops_m: np.ndarray,
               shift_m: list[float]) -> None:
        """Write into a stepper's ``track_m`` (its agent columns holding their start), a new sensing's
        ``velocity_m_s`` (its agent columns re-written for the rows already rolled out), with the other
        obstacles' hops ``other_hops_m`` (T - 1,) and the hop bounds ``shift_m`` (extended in place)."""
        if self.rows == 0:
            self.rows = 1
        self.track_m, self.velocity_m_s, self.other_hops_m, self.shift_m = track_m, velocity_m_s, other_hops_m, shift_m
        if self.rows > 1:
            self._velocities(0, self.rows - 1)

    def extend(self, row: int) -> None:
        """Roll the agents out up to the track's row ``row`` (at most its last)."""
        row = min(row, len(self.track_m) - 1)
        if row < self.rows:
            return
        first = self.rows
        cols = self.columns
        for k in range(first - 1, row):
            self.track_m[k + 1, cols] = self.session.advance(k, None)
        self.rows = row + 1
        self._velocities(first - 1, row)

    def _velocities(self, first: int, last: int) -> None:
        """Velocities at steps ``first`` ..``last - 1`` (and the backward one at the last step), hop bounds."""
        cols, track = self.columns, self.track_m
        part = track[first:last + 1, cols]
        step = np.diff(part, axis=0)
        self.velocity_m_s[first:last, cols] = step / self.dt_s
        if last == len(track) - 1:
            self.velocity_m_s[last, cols] = step[-1] / self.dt_s
        hops = np.maximum(np.hypot(*np.moveaxis(step, 2, 0)).max(axis=1), self.other_hops_m[first:last])
        shift = self.shift_m
        for k, hop in enumerate(hops.tolist(), start=first):
            if k + 1 == len(shift):
                shift.append(shift[-1] + hop)


def human_columns(scenario, moving: list) -> np.ndarray:
    """The columns of the stepper's track that are agents (CrowdNav's humans), in track order."""
    return np.array([col for col, ob in enumerate(moving)
                     if isinstance(scenario.obstacles[ob.scenario_index].motion, AgentMotion)], dtype=np.int64)


DISCOMFORT_M = 0.2  # Chen et al. (2019)'s discomfort distance, rim to rim


def crowd_metrics(poses: np.ndarray, track_m: np.ndarray, radii_m: np.ndarray, robot_radius_m: float,
                  path_length_m: float) -> dict[str, float]:
    """The crowd-navigation metrics of a run among agents (``poses``, ``track_m``: its control steps, start first;
    ``track_m`` and ``radii_m`` of the agents only).

    * ``discomfort_frequency``: the share of control steps after the start whose observation has a human within
      ``DISCOMFORT_M`` of the robot's rim (CrowdNav's "frequency of being in danger": steps with the closest
      rim-to-rim distance below the discomfort distance, over all steps).
    * ``min_separation_m``: the smallest rim-to-rim distance to a human over the run's observations (negative:
      overlap).
    * ``path_irregularity_rad_m``: all turning of the robot's heading along the run (rad) per metre driven; our
      reading of Guzzi et al. (2013)'s "unnecessary turning per unit path length" (the robot starts facing its
      goal, so a straight run needs none); 0 for a run that did not move.
    """
    gap = np.hypot(*np.moveaxis(track_m - poses[:, None, :2], 2, 0)) - radii_m[None, :] - robot_radius_m
    closest = gap.min(axis=1)
    after = closest[1:]
    turning = float(np.abs((np.diff(poses[:, 2]) + np.pi) % (2.0 * np.pi) - np.pi).sum())
    return {"discomfort_frequency": float(np.mean(after < DISCOMFORT_M)) if len(after) else 0.0,
            "min_separation_m": float(closest.min()),
            "path_irregularity_rad_m": turning / path_length_m if path_length_m > 0 else 0.0}
