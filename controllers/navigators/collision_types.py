"""The four collision types of Gong, Yang, Yuan & Wang (2022) §4, and their equations.

Units are the paper's: the robot occupies one cell and moves one cell per
step; a moving obstacle, regularised to a ``Grid_scale`` x ``Grid_scale`` block
(§4.1, Fig. 4), moves ``Step_scale`` cells per step (§2.1 assumption 2).
:func:`classify` turns one sensed obstacle and the robot's path into these
units; the time base is one step = the time the robot needs for one move at its
top speed, so ``Step_scale = |v_obs| / v_rob`` and distances along the robot's
line count in robot moves (a diagonal move is one step of ``sqrt(2)`` cells).

Types (§4.1): 1 trajectories not on one line; 2 one line, head-on; 3 one line,
same direction, the obstacle faster and behind; 4 one line, same direction, the
robot faster and behind.  A sensed obstacle on none of these courses (moving
away, or crossing without meeting the robot) is no conflict (type 0).

Readings of the garbled equations (our choices, checked against the text's examples):

* Eq. (12): ``X = floor(Ld / sqrt(2)) * Step_scale - (Grid_scale mod 2) <= ng``, with
  ``Ld`` (undefined in the paper) the Euclidean distance in cells from the robot's
  cell to the escape cell, so ``floor(Ld / sqrt(2))`` is the number of moves that
  the escape costs the obstacle (2 for Eq. 14's diagonal cells, 1 for Eq. 13's
  knight-move cells) and ``mod(Grid_scale / 2)`` is ``Grid_scale mod 2``.  This
  fits §5.4: Obs1 (3 x 3, 3 cells/step) at ng = 5 gives X = 5 <= 5 (act now);
  Obs2 (2 x 2, 2 cells/step) at ng = 3 gives X = 2; Obs3 (2 x 2, 3 cells/step,
  from behind) at ng = 5 gives X = 3, Eq. (19) holds and Eq. (20) gives D = 1.
* Eqs. (13)-(14) are written in the figures' frame (a diagonal heading, image
  rows growing downwards).  We apply them relative to the robot's heading ``h``
  and its two perpendiculars ``q = +-p`` (``p`` = ``h`` turned by 90 degrees):
  odd size, Eq. (14): ``2q`` (two cells on each side); even size, Eq. (13):
  ``2q``, ``2q + (h - q) / 2`` and ``2q - (h + q) / 2`` for a diagonal heading
  (exactly Eq. 13's six cells for the heading (1, -1) of the figures), and
  ``2q``, ``2q + h``, ``2q - h`` for a heading along an axis (ours: the paper has
  no such figure).  ``(x_rob, y_rob)`` is the robot's cell when it acts.
* Eq. (17) is read as ``D = floor((ng - X) / (V_rob + V_obs))`` and Eq. (20) as
  ``D = floor((ng - X) / (V_obs - V_rob))``: the cells the robot may still go on
  before acting (the printed set ``{0, 1, 2, 3} + D(...)`` only says the remainder
  is below one closing step).
* Type 4 (§4.2): "the type-2 strategy at a distance of rg grids", ``rg = V_rob / V_obs``
  cells: the robot goes on while ``ng > rg`` and escapes (Eqs. 13-14) once ``ng <= rg``.
* Figs. 6 and 7 swap even and odd between text and captions; we follow the
  procedure (odd: Eq. 14, even: Eq. 13).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

Cell = tuple[int, int]

NO_CONFLICT, CROSSING, HEAD_ON, FROM_BEHIND, CATCHING_UP = 0, 1, 2, 3, 4


def regularised_size(radius_m: float, cell_m: float) -> int:
    """``Grid_scale``: the side in cells of the block a round obstacle is regularised to (§4.1)."""
    return max(1, int(round(2.0 * radius_m / cell_m)))


def precondition_x(ld_cells: float, step_scale: float, grid_scale: int, lead_steps: int = 0) -> float:
    """Eq. (12)'s left side, ``X = floor(Ld / sqrt(2)) * Step_scale - (Grid_scale mod 2)``.

    ``lead_steps`` (ours, 0 in the paper) adds robot steps to the escape's, for the
    time a real robot needs to turn towards the escape cell.
    """
    return precondition_x_of_moves(math.floor(ld_cells / math.sqrt(2.0) + 1e-9), step_scale, grid_scale, lead_steps)


def precondition_x_of_moves(moves: int, step_scale: float, grid_scale: int, lead_steps: int = 0) -> float:
    """Eq. (12)'s left side for an escape of ``moves`` robot moves: ``(moves + lead_steps) * Step_scale - (Grid_scale mod 2)``."""
    return (moves + lead_steps) * step_scale - (grid_scale % 2)


def escape_moves(heading: Cell, offset: Cell) -> int:
    """The robot moves an escape to ``offset`` costs in Eq. (12).

    Diagonal heading (the paper's figures): ``floor(Ld / sqrt(2))``, Eq. (12) as read
    above.  Heading along an axis (ours): the 8-neighbour moves to the cell,
    ``max(|dr|, |dc|)``; reading ``floor(Ld / sqrt(2))`` there (as this module's first
    version did) counted the two straight moves to ``2q`` as one.
    """
    if heading[0] and heading[1]:
        return math.floor(math.hypot(*offset) / math.sqrt(2.0) + 1e-9)
    return max(abs(offset[0]), abs(offset[1]))


def escape_offsets(heading: Cell, grid_scale: int) -> list[Cell]:
    """Eq. (14) (odd ``Grid_scale``: two cells) or Eq. (13) (even: six cells), relative to the robot's cell.

    ``heading`` is the robot's 8-neighbour step (dr, dc); offsets are (dr, dc) too.
    """
    hr, hc = heading
    if (hr, hc) == (0, 0):
        raise ValueError("the robot has no heading")
    out: list[Cell] = []
    for side in (1, -1):
        qr, qc = -hc * side, hr * side          # the heading turned by +-90 degrees
        base = (2 * qr, 2 * qc)
        if grid_scale % 2:
            out.append(base)
            continue
        if hr and hc:
            extra = [(base[0] + (hr - qr) // 2, base[1] + (hc - qc) // 2),
                     (base[0] - (hr + qr) // 2, base[1] - (hc + qc) // 2)]
        else:
            extra = [(base[0] + hr, base[1] + hc), (base[0] - hr, base[1] - hc)]
        out.extend([base] + extra)
    return out


def closing_speed(kind: int, step_scale: float) -> float:
    """Cells per step by which the gap shrinks: ``V_rob + V_obs`` (Eqs. 15-17) or ``V_obs - V_rob`` (18-20)."""
    return 1.0 + step_scale if kind == HEAD_ON else step_scale - 1.0


def timing(kind: int, ng: float, x: float, step_scale: float) -> tuple[str, int]:
    """Eqs. (15)-(17) (head-on) or (18)-(20) (from behind): act now, or go on D cells first.

    Returns:
        ("act", 0) when Eq. (15)/(18) holds, ("go_on", D) when Eq. (16)/(19) holds,
        ("too_close", 0) when Eq. (12) fails (ng < X).
    """
    eps = 1e-6  # speeds come from sensed velocities: 0.6 / 0.2 is not exactly 3
    if ng < x - eps:
        return "too_close", 0
    closing = closing_speed(kind, step_scale)
    if closing <= 0 or ng < x + closing - eps:
        return "act", 0
    return "go_on", int(math.floor((ng - x) / closing + eps))


@dataclass(frozen=True)
class Encounter:
    """One sensed obstacle in the paper's units.

    Attributes:
        kind: 0 (no conflict) or the collision type 1-4.
        ng: gap from the robot's cell to the obstacle's nearest regularised cell along the robot's
            line, in robot moves (types 2-4).
        step_scale: obstacle cells per robot step, ``|v_obs| / v_rob``.
        grid_scale: the regularised block's side in cells.
        lateral_m: distance of the obstacle's centre from the robot's line.
    """

    kind: int
    ng: int
    step_scale: float
    grid_scale: int
    lateral_m: float

    def details(self) -> dict[str, Any]:
        return {"type": self.kind, "ng": self.ng, "step_scale": round(self.step_scale, 4),
                "grid_scale": self.grid_scale, "lateral_m": round(self.lateral_m, 4)}


def classify(robot_xy: np.ndarray, heading: Cell, obstacle_xy: np.ndarray, obstacle_v: np.ndarray,
             obstacle_radius_m: float, robot_radius_m: float, robot_speed_m_s: float, cell_m: float,
             conflict: bool, same_line_rad: float = math.radians(15.0)) -> Encounter:
    """Classify one sensed obstacle against the robot's line (§4.1).

    Args:
        robot_xy, obstacle_xy: centres in metres.
        heading: the robot's next 8-neighbour step (dr, dc); rows grow with y.
        obstacle_v: the obstacle's velocity in m/s.
        conflict: whether a crossing obstacle is predicted to meet the robot on its path
            (decides between type 1 and no conflict when the lines differ).
        same_line_rad: largest angle between the two directions that counts as one line.
    """
    direction = np.array([heading[1], heading[0]], dtype=float)
    step_m = float(np.linalg.norm(direction)) * cell_m
    u = direction / np.linalg.norm(direction)
    speed = float(np.linalg.norm(obstacle_v))
    step_scale = speed / robot_speed_m_s
    grid_scale = regularised_size(obstacle_radius_m, cell_m)
    rel = np.asarray(obstacle_xy, dtype=float) - np.asarray(robot_xy, dtype=float)
    along = float(rel @ u)
    lateral = abs(float(u[0] * rel[1] - u[1] * rel[0]))
    ng = int(math.floor((abs(along) - obstacle_radius_m) / step_m + 0.5))
    kind = NO_CONFLICT
    if speed > 1e-9:
        w = np.asarray(obstacle_v, dtype=float) / speed
        cos = float(u @ w)
        on_line = abs(float(u[0] * w[1] - u[1] * w[0])) <= math.sin(same_line_rad) and \
            lateral < obstacle_radius_m + robot_radius_m
        if on_line and cos < 0 and along > 0:
            kind = HEAD_ON
        elif on_line and cos > 0 and along < 0 and step_scale > 1.0:
            kind = FROM_BEHIND
        elif on_line and cos > 0 and along > 0 and step_scale < 1.0:
            kind = CATCHING_UP
        elif not on_line and conflict:
            kind = CROSSING
    elif conflict:
        kind = CATCHING_UP  # a stopped obstacle on the path: caught up with at any speed (rg infinite)
    return Encounter(kind, ng, step_scale, grid_scale, lateral)


def predicted_meeting_s(path_xy: np.ndarray, speed_m_s: float, obstacle_xy: np.ndarray,
                        obstacle_v: np.ndarray, reach_m: float, horizon_s: float,
                        dt_s: float = 0.05) -> float | None:
    """First time the robot, driving ``path_xy`` from its first point at ``speed_m_s``, comes within
    ``reach_m`` of the obstacle moving at constant velocity; None within the horizon.
    """
    pts = np.asarray(path_xy, dtype=float).reshape(-1, 2)
    t = np.arange(0.0, horizon_s + dt_s, dt_s)
    if len(pts) > 1:
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        cum = np.concatenate([[0.0], np.cumsum(seg)])
        s = np.minimum(t * speed_m_s, cum[-1])
        robot = np.column_stack([np.interp(s, cum, pts[:, 0]), np.interp(s, cum, pts[:, 1])])
    else:
        robot = np.repeat(pts[:1], len(t), axis=0)
    obstacle = np.asarray(obstacle_xy, dtype=float)[None, :] + t[:, None] * np.asarray(obstacle_v, dtype=float)[None, :]
    hit = np.flatnonzero(np.linalg.norm(robot - obstacle, axis=1) < reach_m)
    return float(t[hit[0]]) if hit.size else None


def first_band_index(path_xy: np.ndarray, obstacle_xy: np.ndarray, obstacle_v: np.ndarray, reach_m: float,
                     horizon_s: float) -> int | None:
    """Index of the first path point within ``reach_m`` of the obstacle's future track (the crossing
    point of type 1, Fig. 5's A); None when the track misses the path within the horizon."""
    a = np.asarray(obstacle_xy, dtype=float)
    b = a + horizon_s * np.asarray(obstacle_v, dtype=float)
    pts = np.asarray(path_xy, dtype=float).reshape(-1, 2)
    ab = b - a
    denom = float(ab @ ab)
    f = np.clip(((pts - a) @ ab) / denom, 0.0, 1.0) if denom > 0 else np.zeros(len(pts))
    dist = np.linalg.norm(pts - (a[None, :] + f[:, None] * ab[None, :]), axis=1)
    hit = np.flatnonzero(dist < reach_m)
    return int(hit[0]) if hit.size else None
