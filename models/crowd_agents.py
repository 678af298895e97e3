"""Agents that walk to goals and avoid each other: the ``orca`` and ``social_force`` motion kinds.

A scenario's agents (every obstacle whose ``motion.kind`` is ``orca`` or ``social_force``) form one
:class:`Crowd`, stepped together once per control period:

* ``orca``: van den Berg et al. (2011)'s optimal reciprocal collision avoidance through the RVO2 library's
  Python binding ``pyrvo`` (the library CrowdNav's humans use, through Python-RVO2), with CrowdNav's
  parameters (Chen et al. 2019, ``crowd_sim/envs/policy/orca.py``): neighbour distance 10 m, 10 neighbours,
  time horizons 5 s (agents and obstacles), each radius plus 0.01 m, the top speed ``v_pref_m_s``.
* ``social_force``: Helbing and Molnár (1995), :mod:`swarmnav.models.social_force`.

Each agent's preferred velocity points at its goal with speed ``min(v_pref, distance)`` (CrowdNav's: it
slows down over the last metre and stays at its goal); with ``goals`` (two or more points) it walks the loop,
taking the next point once within its radius of the current one.  ORCA's preferred velocity is perturbed by
at most 0.01 m/s in a random direction every step (RVO2's own examples perturb to break perfectly symmetric
deadlocks; CrowdNav has the same line, commented out; without it two agents meeting head-on on one line stop
face to face), drawn from the run's world seed like every other random motion.  Agents avoid the other
agents, the static discs and the map's boxes (ORCA: as polygons circumscribing the discs), and the walls when
the arena has them; scripted moving obstacles are not seen by them.

With ``sees_robot = true`` (the same for every agent of a scenario) the robot is one more agent for them:
ORCA sees it as an agent whose position and velocity are the robot's each step (it does not reciprocate),
the social force as one more pedestrian.  Then the crowd depends on the robot and the stepper advances it
online (:class:`CrowdSession`); without, the crowd's motion is a pure function of the world seed, rolled out
once (:attr:`Crowd.track_m`), and everything that reads obstacle motion as a function of time (the planners
at t = 0, the oracle, the sensing) sees the exact future.  :meth:`AgentMotion.positions_at` of a crowd that
sees the robot is its rollout without a robot: what the agents would do if the robot were not there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from swarmnav.models import social_force

AGENT_KINDS = ("orca", "social_force")
ORCA_NEIGHBOR_DIST_M = 10.0
ORCA_MAX_NEIGHBORS = 10
ORCA_TIME_HORIZON_S = 5.0
ORCA_TIME_HORIZON_OBST_S = 5.0
ORCA_RADIUS_PAD_M = 0.01
PERTURB_M_S = 0.01
DISC_POLYGON_SIDES = 12
CROWD_STREAM = 1 << 20  # the crowd's draws: SeedSequence(world_seed, spawn_key=(CROWD_STREAM,))
MAX_V_PREF_M_S = 5.0


@dataclass(frozen=True)
class AgentSpec:
    """One agent as the scenario file gives it."""

    kind: str  # "orca" | "social_force"
    start_m: tuple[float, float]
    radius_m: float
    goals_m: tuple[tuple[float, float], ...]  # one goal, or a loop of two or more
    v_pref_m_s: float
    sees_robot: bool = False
    start_s: float = 0.0


@dataclass(frozen=True, eq=False)
class Crowd:
    """A scenario's agents, the static world they avoid, and the run's clock and world seed."""

    specs: tuple[AgentSpec, ...]
    static_discs: np.ndarray = field(repr=False)  # (D, 3) x, y, radius
    static_boxes: np.ndarray = field(repr=False)  # (B, 4)
    arena_m: tuple[float, float]
    walls: bool
    dt_s: float
    steps: int  # control steps in the run (positions at steps + 1 times)
    world_seed: int = 0

    @property
    def sees_robot(self) -> bool:
        return any(s.sees_robot for s in self.specs)

    @property
    def max_speed_m_s(self) -> float:
        """No agent moves faster (ORCA: v_pref plus the perturbation; social force: 1.3 v_pref, Eq. (10))."""
        return max(max(s.v_pref_m_s + PERTURB_M_S, social_force.MAX_SPEED_FACTOR * s.v_pref_m_s)
                   for s in self.specs)

    def reseeded(self, world_seed: int) -> "Crowd":
        return replace(self, world_seed=int(world_seed))

    @cached_property
    def track_m(self) -> np.ndarray:
        """(steps + 1, A, 2) positions at every control step without a robot (exact when it is invisible)."""
        session = CrowdSession(self)
        out = np.empty((self.steps + 1, len(self.specs), 2))
        out[0] = session.positions_m
        for k in range(self.steps):
            out[k + 1] = session.advance(k, None)
        return out

    def positions_at(self, index: int, times_s: np.ndarray) -> np.ndarray:
        t = np.asarray(times_s, dtype=float).reshape(-1)
        if not np.any(t > 0.0):  # the start alone: no need to roll the crowd out (scenario checks, t = 0)
            return np.repeat(np.asarray(self.specs[index].start_m, dtype=float)[None, :], len(t), axis=0)
        track = self.track_m[:, index]
        grid = np.arange(len(track)) * self.dt_s
        return np.column_stack([np.interp(t, grid, track[:, 0]), np.interp(t, grid, track[:, 1])])


@dataclass(frozen=True, eq=False)
class AgentMotion:
    """Obstacle ``index`` of its crowd: ``positions_at`` like every motion kind."""

    crowd: Crowd
    index: int

    @property
    def spec(self) -> AgentSpec:
        return self.crowd.specs[self.index]

    def positions_at(self, times_s: np.ndarray) -> np.ndarray:
        return self.crowd.positions_at(self.index, times_s)


class CrowdSession:
    """One episode of a crowd: ``advance(step, robot)`` moves every agent one control period.

    ``robot`` is ``(x, y, vx, vy, radius)`` when the agents see the robot, else None.
    """

    def __init__(self, crowd: Crowd):
        self.crowd = crowd
        specs = crowd.specs
        self.rng = np.random.default_rng(np.random.SeedSequence(crowd.world_seed, spawn_key=(CROWD_STREAM,)))
        self.positions_m = np.array([s.start_m for s in specs], dtype=float).reshape(-1, 2)
        self.velocities_m_s = np.zeros_like(self.positions_m)
        self.radii_m = np.array([s.radius_m for s in specs], dtype=float)
        self.v_pref = np.array([s.v_pref_m_s for s in specs], dtype=float)
        self.start_s = np.array([s.start_s for s in specs], dtype=float)
        self.goal_index = np.zeros(len(specs), dtype=int)
        self._goals = [np.asarray(s.goals_m, dtype=float) for s in specs]
        self._goal_m = np.array([g[0] for g in self._goals], dtype=float).reshape(-1, 2)  # each one's current goal
        self._loops = [i for i, g in enumerate(self._goals) if len(g) > 1]
        self.orca = np.array([s.kind == "orca" for s in specs])
        self.social = ~self.orca
        self._boxes = np.asarray(crowd.static_boxes, dtype=float).reshape(-1, 4)
        if crowd.walls:
            w, h = crowd.arena_m
            t = 1.0
            self._boxes = np.vstack([self._boxes, [[-t, -t, w + t, 0.0], [-t, h, w + t, h + t],
                                                   [-t, 0.0, 0.0, h], [w, 0.0, w + t, h]]])
        self._discs = np.asarray(crowd.static_discs, dtype=float).reshape(-1, 3)
        self._sim = self._orca_sim() if self.orca.any() else None

    def _orca_sim(self):
        import pyrvo  # imported only by scenarios with ORCA agents

        c = self.crowd
        sim = pyrvo.RVOSimulator(c.dt_s, ORCA_NEIGHBOR_DIST_M, ORCA_MAX_NEIGHBORS, ORCA_TIME_HORIZON_S,
                                 ORCA_TIME_HORIZON_OBST_S, 0.3, 1.0)
        self._rvo_ids = {}
        # ORCA agents first, then every other body it must avoid (social-force agents, the robot), whose
        # positions and velocities are set from outside each step.
        for i in range(len(self.positions_m)):
            speed = self.v_pref[i] if self.orca[i] else social_force.MAX_SPEED_FACTOR * self.v_pref[i]
            self._rvo_ids[i] = sim.add_agent(tuple(self.positions_m[i]), ORCA_NEIGHBOR_DIST_M, ORCA_MAX_NEIGHBORS,
                                             ORCA_TIME_HORIZON_S, ORCA_TIME_HORIZON_OBST_S,
                                             float(self.radii_m[i] + ORCA_RADIUS_PAD_M), float(speed), (0.0, 0.0))
        self._robot_id = None
        if c.sees_robot:
            self._robot_id = sim.add_agent((-1e6, -1e6))  # placed each step
        for x, y, r in self._discs:
            outer = r / math.cos(math.pi / DISC_POLYGON_SIDES)  # the polygon contains the disc
            angles = np.arange(DISC_POLYGON_SIDES) * (2.0 * math.pi / DISC_POLYGON_SIDES)
            sim.add_obstacle([(float(x + outer * math.cos(a)), float(y + outer * math.sin(a))) for a in angles])
        for x0, y0, x1, y1 in self._boxes:
            sim.add_obstacle([(float(x0), float(y0)), (float(x1), float(y0)), (float(x1), float(y1)),
                              (float(x0), float(y1))])
        if len(self._discs) or len(self._boxes):
            sim.process_obstacles()
        return sim

    def preferred_velocities(self, time_s: float) -> np.ndarray:
        """Toward each agent's goal at ``min(v_pref, distance)``; zero before its ``start_s``."""
        for i in self._loops:  # a loop: the next point once this one is reached
            goals = self._goals[i]
            d = goals[self.goal_index[i]] - self.positions_m[i]
            if math.hypot(d[0], d[1]) <= self.radii_m[i]:
                self.goal_index[i] = (self.goal_index[i] + 1) % len(goals)
                self._goal_m[i] = goals[self.goal_index[i]]
        d = self._goal_m - self.positions_m
        dist = np.hypot(d[:, 0], d[:, 1])
        scale = np.divide(np.minimum(self.v_pref, dist), dist, out=np.zeros_like(dist), where=dist > 0)
        scale[time_s < self.start_s] = 0.0
        return d * scale[:, None]

    def advance(self, step: int, robot: tuple[float, float, float, float, float] | None) -> np.ndarray:
        """Every agent one control period on from ``step``; the new positions (A, 2)."""
        pref = self.preferred_velocities(step * self.crowd.dt_s)
        pos, vel = self.positions_m, self.velocities_m_s
        new_pos, new_vel = pos.copy(), vel.copy()
        if self.social.any():
            idx = np.flatnonzero(self.social)
            others, other_vel, other_r = pos, vel, self.radii_m
            if robot is not None:
                others = np.vstack([pos, robot[:2]])
                other_vel = np.vstack([vel, robot[2:4]])
                other_r = np.append(self.radii_m, robot[4])
            new_pos[idx], new_vel[idx] = social_force.step(
                pos[idx], vel[idx], self.radii_m[idx], pref[idx], self.v_pref[idx], others, other_vel, other_r,
                idx, self._discs, self._boxes, self.crowd.dt_s, self.rng)
        if self._sim is not None:
            sim = self._sim
            angle = self.rng.uniform(0.0, 2.0 * math.pi, len(pos))
            size = self.rng.uniform(0.0, PERTURB_M_S, len(pos))
            for i, rid in self._rvo_ids.items():
                if self.orca[i]:
                    sim.set_agent_pref_velocity(rid, (float(pref[i, 0] + size[i] * math.cos(angle[i])),
                                                      float(pref[i, 1] + size[i] * math.sin(angle[i]))))
                else:  # a social-force agent: where it is, as it moves
                    sim.set_agent_position(rid, (float(pos[i, 0]), float(pos[i, 1])))
                    sim.set_agent_velocity(rid, (float(vel[i, 0]), float(vel[i, 1])))
                    sim.set_agent_pref_velocity(rid, (float(vel[i, 0]), float(vel[i, 1])))
            if self._robot_id is not None:
                if robot is None:
                    sim.set_agent_position(self._robot_id, (-1e6, -1e6))
                    sim.set_agent_velocity(self._robot_id, (0.0, 0.0))
                else:
                    sim.set_agent_position(self._robot_id, (float(robot[0]), float(robot[1])))
                    sim.set_agent_velocity(self._robot_id, (float(robot[2]), float(robot[3])))
                    sim.set_agent_pref_velocity(self._robot_id, (float(robot[2]), float(robot[3])))
                    sim.set_agent_radius(self._robot_id, float(robot[4]))
            sim.do_step()
            for i, rid in self._rvo_ids.items():
                if self.orca[i]:
                    p, v = sim.get_agent_position(rid), sim.get_agent_velocity(rid)
                    new_pos[i] = (p.x, p.y)
                    new_vel[i] = (v.x, v.y)
        self.positions_m, self.velocities_m_s = new_pos, new_vel
        return new_pos


def reseed_agents(obstacles: tuple, world_seed: int) -> tuple:
    """``obstacles`` with every agent's crowd drawn from ``world_seed`` (one new crowd for all its agents)."""
    crowds: dict[int, Crowd] = {}
    out = []
    for ob in obstacles:
        motion = ob.motion
        if isinstance(motion, AgentMotion):
            new = crowds.setdefault(id(motion.crowd), motion.crowd.reseeded(world_seed))
            ob = replace(ob, motion=AgentMotion(new, motion.index))
        out.append(ob)
    return tuple(out)
