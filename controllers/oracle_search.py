"""The clairvoyant yardstick's search: the earliest collision-free arrival in space-time (no MuJoCo).

**Clairvoyant**: this module reads the obstacles' *true future motion* (each
obstacle's ``trajectory().positions_at``, random walks drawn from the run's
world seed).  It is the one component of swarmnav allowed to; every online
navigator sees only its sensing.  Its answer is a yardstick ("could any robot
with these limits have made it, and how soon?"), never a navigator to compare
on equal terms.

The search is a time-expanded lattice, breadth-first in time, so the first
tick at which a goal state is reached is the earliest arrival on the lattice:

* **States**: a cell centre of a square grid (``cell_m``, aligned so the start
  is a centre) x one of 8 headings (multiples of 45 degrees) x a tick
  (``tick_s = cell_m / (2 v)``, v = ``speed_fraction`` x the robot's top speed).
* **Actions** (the robot's speed and turning limits): wait one tick; drive one
  cell along the heading (2 ticks on an axis: speed v; 3 ticks on a diagonal:
  speed 0.94 v); turn on the spot by 45 degrees in ``ceil(pi/4 / (omega tick))``
  ticks, omega = ``turn_rate_rad_s``.  A differential drive turns on the spot,
  so these motions are within its limits; a path that drives while turning is
  not on the lattice (the lattice's arrival is an upper bound of the true T*).
* **Collision-free**: at every tick of an action the robot's interpolated
  position keeps ``robot radius + margin_m`` from every obstacle's footprint at
  that tick, plus what either can travel in half a tick (so the check between
  ticks is covered: distances are 1-Lipschitz).  Per tick the clearance of every
  cell centre is one NumPy expression over obstacles x cells; a point on a move,
  ``delta`` from the endpoint it is checked at, needs that much more clearance.
* **Goal**: any cell centre within half the goal's tolerance (the nearest centre when
  none is; half, so the physics drive's tracking error stays inside the tolerance).  T* is the tick of
  the first arrival there times ``tick_s``.

The whole frontier advances one tick per iteration as boolean arrays (headings
x rows x cols); each state records the action that first reached it, so the
trajectory is read back from the goal.  Resolution, speed fraction and margin
are stated in every verdict.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from swarmnav.models.crowd_agents import AgentMotion
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario import Scenario

HEADINGS = 8
STEPS = np.array([(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)])  # (dx, dy) cells
MAX_LATTICE = 100_000_000  # states x ticks recorded (one byte each): a coarser cell beyond (``search``)
WAIT, MOVE, LEFT, RIGHT = 1, 2, 3, 4


class NoClairvoyantYardstick(Exception):
    """The scenario's agents see the robot (``sees_robot``): their motion depends on what the robot does, so no
    search over their motion as a function of time can be exact, and the oracle does not pretend to one."""


def reactive_agents(scenario: Scenario) -> bool:
    """Whether any agent of the scenario reacts to the robot."""
    return any(isinstance(ob.motion, AgentMotion) and ob.motion.crowd.sees_robot for ob in scenario.obstacles)


@dataclass(frozen=True)
class OracleSettings:
    """The lattice's resolution and margins (stated with every verdict)."""

    cell_m: float = 0.1
    speed_fraction: float = 0.9     # of the robot's top speed: the physics drive keeps the rest to catch up
    turn_rate_rad_s: float = 1.0     # below the point-to-point controller's 1.2 rad/s limit
    margin_m: float = 0.04           # beyond the robot radius (tracking error in physics)

    def check(self, where: str = "oracle") -> None:
        for key in ("cell_m", "speed_fraction", "turn_rate_rad_s"):
            if not getattr(self, key) > 0:
                raise ConfigError(f"{where}.{key}", f"must be positive, got {getattr(self, key)!r}")
        if self.speed_fraction > 1.0:
            raise ConfigError(f"{where}.speed_fraction", f"must be at most 1, got {self.speed_fraction!r}")
        if not self.margin_m >= 0:
            raise ConfigError(f"{where}.margin_m", f"must not be negative, got {self.margin_m!r}")


@dataclass(frozen=True, eq=False)
class OraclePlan:
    """The search's verdict and, when solvable, the trajectory (one row per tick).

    Attributes:
        solvable: a collision-free arrival exists on the lattice within the time limit.
        arrival_s: T*, the earliest arrival on the lattice (None when not solvable).
        reason: why not solvable ("" when solvable): ``start_blocked``, ``trapped`` (every state is hit),
            ``time_limit``.
        tick_s: the lattice's time step.
        poses: (K+1, 3) x, y, heading at ticks 0..K (K = arrival tick); empty when not solvable.
        search_s: wall time of the search (not deterministic; not logged).
    """

    solvable: bool
    arrival_s: float | None
    reason: str
    tick_s: float
    settings: OracleSettings
    poses: np.ndarray = field(repr=False, default_factory=lambda: np.zeros((0, 3)))
    search_s: float = 0.0

    def verdict(self) -> dict:
        """The verdict as JSON values."""
        s = self.settings
        return {"solvable": self.solvable, "arrival_s": None if self.arrival_s is None else round(self.arrival_s, 4),
                "reason": self.reason, "cell_m": s.cell_m, "tick_s": round(self.tick_s, 6),
                "speed_fraction": s.speed_fraction, "turn_rate_rad_s": s.turn_rate_rad_s, "margin_m": s.margin_m}


def _shift(a: np.ndarray, dy: int, dx: int) -> np.ndarray:
    """``out[..., r, c] = a[..., r - dy, c - dx]``, False (or 0) where that falls outside."""
    out = np.zeros_like(a)
    rows, cols = a.shape[-2:]
    out[..., max(dy, 0):rows + min(dy, 0), max(dx, 0):cols + min(dx, 0)] = \
        a[..., max(-dy, 0):rows + min(-dy, 0), max(-dx, 0):cols + min(-dx, 0)]
    return out


class _Clearance:
    """Per tick, the clearance (m) of every cell centre: distance to the nearest obstacle's footprint."""

    def __init__(self, scenario: Scenario, xs: np.ndarray, ys: np.ndarray, tick_s: float):
        self.xs, self.ys, self.tick_s = xs, ys, tick_s
        static = [ob for ob in scenario.obstacles if not ob.moving]
        self.moving = [ob for ob in scenario.obstacles if ob.moving]
        field = np.full((len(ys), len(xs)), np.inf)
        for ob in static:
            field = np.minimum(field, np.hypot(xs[None, :] - ob.x_m, ys[:, None] - ob.y_m) - ob.radius_m)
        for b in scenario.boxes:
            gx = np.maximum(np.maximum(b.x_min_m - xs, xs - b.x_max_m), 0.0)
            gy = np.maximum(np.maximum(b.y_min_m - ys, ys - b.y_max_m), 0.0)
            field = np.minimum(field, np.hypot(gx[None, :], gy[:, None]))
        self.static = field
        self.radii = np.array([ob.radius_m for ob in self.moving])
        self._track: np.ndarray | None = None

    def positions(self, ticks: int) -> np.ndarray:
        """(ticks, M, 2) true positions of the moving obstacles (clairvoyance)."""
        times = np.arange(ticks) * self.tick_s
        if not self.moving:
            return np.zeros((ticks, 0, 2))
        return np.stack([ob.trajectory().positions_at(times) for ob in self.moving], axis=1)

    def at(self, positions: np.ndarray) -> np.ndarray:
        """(rows, cols) clearance with the moving obstacles at ``positions`` (M, 2)."""
        if not len(positions):
            return self.static
        dx2 = (self.xs[None, :] - positions[:, 0:1]) ** 2                    # (M, cols)
        dy2 = (self.ys[None, :] - positions[:, 1:2]) ** 2                    # (M, rows)
        d = np.sqrt(dy2[:, :, None] + dx2[:, None, :]) - self.radii[:, None, None]
        return np.minimum(self.static, d.min(axis=0))


def obstacle_speed_bound_m_s(positions: np.ndarray, tick_s: float) -> float:
    """The largest distance any obstacle moves in one tick, over the track, per second."""
    if positions.shape[0] < 2 or positions.shape[1] == 0:
        return 0.0
    return float(np.max(np.linalg.norm(np.diff(positions, axis=0), axis=2))) / tick_s


def _lattice_size(scenario: Scenario, settings: OracleSettings, time_limit_s: float | None) -> float:
    """States x ticks of the lattice (an estimate to within a row and a column)."""
    speed = settings.speed_fraction * scenario.max_speed_m_s
    ticks = (scenario.time_limit_s if time_limit_s is None else time_limit_s) * 2.0 * speed / settings.cell_m
    cells = (scenario.arena_width_m / settings.cell_m + 1) * (scenario.arena_height_m / settings.cell_m + 1)
    return HEADINGS * cells * (ticks + 1)


def search(scenario: Scenario, settings: OracleSettings | None = None,
           time_limit_s: float | None = None) -> OraclePlan:
    """The earliest collision-free arrival on the lattice (module docstring), from the scenario's true motion.

    A lattice beyond :data:`MAX_LATTICE` state-ticks at ``settings.cell_m`` is searched at the smallest
    doubling of the cell that fits (large maps); the verdict states the cell used.
    """
    import time as _time
    if reactive_agents(scenario):
        raise NoClairvoyantYardstick("no clairvoyant yardstick: the agents see the robot and react to it "
                                     "(sees_robot), so their motion is not a function of time")
    wall0 = _time.perf_counter()
    settings = settings or OracleSettings()
    settings.check()
    while _lattice_size(scenario, settings, time_limit_s) > MAX_LATTICE:
        settings = replace(settings, cell_m=2.0 * settings.cell_m)
    cell = settings.cell_m
    speed = settings.speed_fraction * scenario.max_speed_m_s
    tick = cell / (2.0 * speed)
    horizon_s = scenario.time_limit_s if time_limit_s is None else time_limit_s
    ticks = int(math.floor(horizon_s / tick)) + 1
    bounds = scenario.planning_bounds(scenario.robot_radius_m)
    sx, sy = scenario.start.x_m, scenario.start.y_m
    x0 = sx - math.floor((sx - bounds.x_min_m) / cell + 1e-9) * cell
    y0 = sy - math.floor((sy - bounds.y_min_m) / cell + 1e-9) * cell
    xs = np.arange(x0, bounds.x_max_m + 1e-9, cell)
    ys = np.arange(y0, bounds.y_max_m + 1e-9, cell)
    rows, cols = len(ys), len(xs)
    clearance = _Clearance(scenario, xs, ys, tick)
    track = clearance.positions(ticks)
    need = (scenario.robot_radius_m + settings.margin_m
            + 0.5 * tick * (speed + obstacle_speed_bound_m_s(track, tick)))
    turn_ticks = max(1, int(math.ceil((math.pi / 4.0) / (settings.turn_rate_rad_s * tick))))
    start_rc = (int(round((sy - y0) / cell)), int(round((sx - x0) / cell)))
    start_h = int(round(scenario.start.heading_rad / (math.pi / 4.0))) % HEADINGS
    goal_mask = _goal_cells(scenario, xs, ys)

    def finish(solvable: bool, reason: str, arrival_tick: int | None = None, poses=None) -> OraclePlan:
        return OraclePlan(solvable, None if arrival_tick is None else arrival_tick * tick, reason, tick, settings,
                          np.zeros((0, 3)) if poses is None else poses, _time.perf_counter() - wall0)

    # Per tick: the clearance field, and how many consecutive ticks each cell has been free (for waits and turns).
    fields: list[np.ndarray] = []
    run = np.zeros((rows, cols), dtype=np.int32)
    runs: list[np.ndarray] = []
    actions = np.zeros((ticks, HEADINGS, rows, cols), dtype=np.int8)
    reach = np.zeros((HEADINGS, rows, cols), dtype=bool)
    reached_at: list[np.ndarray] = []

    def advance_fields(t: int) -> None:
        fields.append(clearance.at(track[t]))
        free = fields[t] >= need
        nonlocal run
        run = np.where(free, run + 1, 0)
        runs.append(run)

    advance_fields(0)
    if runs[0][start_rc] == 0:
        return finish(False, "start_blocked")
    reach[start_h][start_rc] = True
    actions[0, start_h][start_rc] = WAIT
    reached_at.append(reach.copy())
    for t in range(1, ticks):
        advance_fields(t)
        # Wait: free at t-1 and t.
        waited = reach & (runs[t] >= 2)[None]
        turned_l, turned_r = _turned(reached_at, runs, t, turn_ticks, reach)
        reach = _record(actions[t], ((_moved(reached_at, fields, t, cell, need, reach), MOVE), (turned_l, LEFT),
                                     (turned_r, RIGHT), (waited, WAIT)))
        reached_at.append(reach)
        keep = max(3, turn_ticks)  # what the next ticks look back on; older layers are dropped
        if t > keep:
            fields[t - keep - 1] = runs[t - keep - 1] = reached_at[t - keep - 1] = None
        if (reach & goal_mask[None]).any():
            h, r, c = np.argwhere(reach & goal_mask[None])[0]
            return finish(True, "", t, _read_back(actions, t, int(h), int(r), int(c), xs, ys, turn_ticks))
        if not reach.any():
            return finish(False, "trapped")
    return finish(False, "time_limit")


def _goal_cells(scenario: Scenario, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """(rows, cols) the lattice cells within half the goal tolerance of the goal (the nearest, if none is)."""
    gx, gy = scenario.goal.x_m, scenario.goal.y_m
    goal_d = np.hypot(xs[None, :] - gx, ys[:, None] - gy)
    goal_mask = goal_d <= 0.5 * scenario.goal_tolerance_m
    if not goal_mask.any():
        goal_mask = goal_d <= goal_d.min() + 1e-12
    return goal_mask


def _moved(reached_at: list[np.ndarray], fields: list[np.ndarray], t: int, cell: float, need: np.ndarray | float,
           reach: np.ndarray) -> np.ndarray:
    """(HEADINGS, rows, cols) the states reached at tick ``t`` by a move: departed at ``t - n`` from the
    neighbour behind, each tick's interpolated point clear."""
    moved = np.zeros_like(reach)
    for h in range(HEADINGS):
        dx, dy = STEPS[h]
        n = 2 if (dx == 0 or dy == 0) else 3
        if t < n:
            continue
        length = cell * math.hypot(dx, dy)
        ok = _shift(reached_at[t - n][h], dy, dx)
        for j in range(n + 1):
            frac = j / n
            f = fields[t - n + j]
            src_ok = _shift(f, dy, dx) >= need + frac * length      # checked at the departure cell
            dst_ok = f >= need + (1.0 - frac) * length              # or at the arrival cell
            ok &= src_ok | dst_ok
        moved[h] = ok
    return moved


def _turned(reached_at: list[np.ndarray], runs: list[np.ndarray], t: int, turn_ticks: int,
            reach: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The states reached at tick ``t`` by turning on the spot, (left, right): the neighbouring heading,
    the cell free for the whole turn."""
    turned_l = np.zeros_like(reach)
    turned_r = np.zeros_like(reach)
    if t >= turn_ticks:
        still = runs[t] >= turn_ticks + 1
        before = reached_at[t - turn_ticks]
        turned_l = np.roll(before, 1, axis=0) & still[None]         # heading h from h - 1 (counter-clockwise)
        turned_r = np.roll(before, -1, axis=0) & still[None]
    return turned_l, turned_r


def _record(code: np.ndarray, ways: tuple[tuple[np.ndarray, int], ...]) -> np.ndarray:
    """The states reached at one tick, the union of ``ways`` (each a mask and its action); ``code`` (the
    tick's actions) gets, for each state, the first way that reaches it."""
    new = np.zeros_like(ways[0][0])
    for mask, value in ways:
        fresh = mask & ~new
        code[fresh] = value
        new |= mask
    return new


def _read_back(actions: np.ndarray, t: int, h: int, r: int, c: int, xs: np.ndarray, ys: np.ndarray,
               turn_ticks: int) -> np.ndarray:
    """(t+1, 3) poses at every tick, from the recorded actions, walking back from the goal state."""
    poses = np.zeros((t + 1, 3))
    while t > 0:
        code = actions[t, h, r, c]
        if code == WAIT:
            poses[t] = (xs[c], ys[r], h * math.pi / 4)
            t -= 1
        elif code == MOVE:
            dx, dy = STEPS[h]
            n = 2 if (dx == 0 or dy == 0) else 3
            pr, pc = r - dy, c - dx
            for j in range(n):
                frac = 1.0 - j / n
                poses[t - j] = (xs[pc] + frac * (xs[c] - xs[pc]), ys[pr] + frac * (ys[r] - ys[pr]), h * math.pi / 4)
            t, r, c = t - n, pr, pc
        else:
            before = (h - 1) % HEADINGS if code == LEFT else (h + 1) % HEADINGS
            turn = (math.pi / 4) if code == LEFT else -(math.pi / 4)
            for j in range(turn_ticks):
                frac = 1.0 - j / turn_ticks
                poses[t - j] = (xs[c], ys[r], before * math.pi / 4 + frac * turn)
            t, h = t - turn_ticks, before
    poses[0] = (xs[c], ys[r], h * math.pi / 4)
    return poses
