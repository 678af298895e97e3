"""IACO: the improved ant colony of Gong, Yang, Yuan & Wang (2022).

On the inflated occupancy grid, on the grid colony base
(:class:`planners.ant_colony.GridColonyPlanner`) and the one optimisation loop:

* **Collar line** (§3.1): a guide polyline from start to goal through feature
  points of the obstacles it meets; the cells it crosses start with extra pheromone.
* **Heuristic** (Eq. 6): ``eta_ij = d_ig / (d_ij + d_jg) * (cos(omega) + 1)``,
  goal guidance times bend suppression.
* **Pheromone update** (Eqs. 3, 7, 8): only ants that reach the goal deposit
  ``Q_m / (L_m + turn)`` with ``Q_m = Q * t_c ** ((L_GL - L_m) ** 3)``.
* **Adaptive parameters** (Eqs. 9-11): alpha rises then falls, beta decays, rho follows
  the ratio of the collar length to the best length.
* Roulette selection (Eq. 1) with 50 ants x 100 iterations by default (Table 2).

Readings of the paper where its text is ambiguous (our choices):

* Pheromone sits on cells (the move into cell j reads ``tau_j``), as grid ACO
  implementations usually store it; the paper writes ``tau_ij``.
* Feature points (§3.1.1) are taken as the free cell diagonally outside each
  convex corner of an obstacle (a grid vertex with exactly one of its four cells
  occupied), so the collar line joins free cell centres.  Rule 2 (concave corners
  dropped) and rule 4 (map-boundary vertices dropped) follow from that; the
  U-shape rule 3 depends on a figure missing from the text and is not applied.
* omega in Eq. (6) is the turning angle between the previous move and the
  candidate move (0 when going straight on, factor 2; a U-turn gives 0).  The
  paper's sentence "the closer to 180 degrees, the greater eta" describes the
  interior angle, which this equals 180 degrees minus.  The first move counts as straight.
* Eq. (7) is garbled in the text; we read it as ``Q_m = Q * t_c ** ((L_GL - L_m) ** 3)``
  with lengths in cells.  Tours longer than the collar line get ``t_c`` to a negative
  power, uncapped as the paper writes it (a tour a few cells longer deposits next to
  nothing: that is the "difference of pheromone on different paths" §3.3 wants).
  Tours shorter than the collar line would get ``t_c`` to a large positive power; we
  cap the exponent above at ``exponent_limit`` (ours: 3) so that it cannot overflow
  and the first such tour does not swamp all others.  Cells keep at least
  ``tau_floor`` pheromone (a numerical floor, 1e-12) so that none underflows.
* Before any ant has reached the goal, Eqs. (9)-(10) use ``L_GL / (LF_best + L_GL) = 0``
  and rho keeps its initial value (Table 2: 0.3).
* An ant never re-enters a cell (tabu list); in a dead end it steps back one
  cell (the dead end stays tabu).  It fails after ``max_steps`` NumPy steps or
  once its tour can neither beat the best so far nor deposit more than
  ``tau_floor`` under Eq. (7) (:func:`prune_length`); our additions: the paper does
  not say how its ants leave dead ends, and pruning only saves time.

What Table 1's parameters change on the bundled maps (the ``iaco-parameters`` study) and why, and how the
defaults the paper does not give were chosen: ``docs/papers.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from scipy import ndimage

from swarmnav.models.parameters import Range, above, param, within
from swarmnav.planners.ant_colony import GridColonyPlanner, deposit, evaporate
from swarmnav.planners.colony_walk import STEP_LENGTHS, ColonyWalk, cosine_table
from swarmnav.planners.grid_graph import Cell, grid_line_of_sight, line_cells
from swarmnav.planners.problem import Problem
from swarmnav.planners.swarm import SwarmState


def feature_cells(occupied: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Feature points of the obstacle grids (§3.1.1), as free cells outside convex corners.

    Returns:
        (cells (K, 2) row/col, their obstacle component labels (K,), the label image).
    """
    occ = np.asarray(occupied, dtype=bool)
    labels, _ = ndimage.label(occ, structure=np.ones((3, 3), dtype=bool))
    # Interior grid vertices (i, j), 1 <= i < rows, 1 <= j < cols, and their four cells.
    quad = np.stack([occ[:-1, :-1], occ[:-1, 1:], occ[1:, :-1], occ[1:, 1:]], axis=-1)
    convex = quad.sum(axis=-1) == 1
    which = np.argmax(quad, axis=-1)                  # the one occupied cell of the four
    vi, vj = np.nonzero(convex)
    k = which[vi, vj]
    occ_r = vi + (k >= 2)
    occ_c = vj + (k % 2)
    free_r = vi + (k < 2)                              # the diagonally opposite cell
    free_c = vj + (k % 2 == 0)
    cells = np.column_stack([free_r, free_c])
    return cells, labels[occ_r, occ_c], labels


def collar_line(occupied: np.ndarray, start: Cell, goal: Cell, max_points: int | None = None
                ) -> tuple[list[Cell], float]:
    """The collar (leading) line of §3.1.2 from ``start`` to ``goal``.

    From the current point: if the goal is visible, join it.  Otherwise the
    obstacles crossed by the straight line to the goal join the set of classed
    obstacles (Class I from the start, Class II later); among their unused
    feature points visible from the current point, join the one closest to the
    goal; when none is visible, join the closest one anyway (Fig. 3 b, c).

    Returns:
        (points from start to goal, length in cells).
    """
    occ = np.asarray(occupied, dtype=bool)
    rows, cols = occ.shape
    free = (~occ).tolist()
    features, feature_labels, labels = feature_cells(occ)
    limit = max_points if max_points is not None else 4 * len(features) + 4
    points = [start]
    classed: set[int] = set()
    used = np.zeros(len(features), dtype=bool)
    goal_xy = np.array(goal, dtype=float)
    cur = start
    for _ in range(limit):
        if grid_line_of_sight(free, cur, goal):
            break
        for r, c in line_cells(cur, goal):
            if 0 <= r < rows and 0 <= c < cols and labels[r, c]:
                classed.add(int(labels[r, c]))
        pool = np.flatnonzero(~used & np.isin(feature_labels, list(classed))
                              & np.any(features != np.array(cur), axis=1))
        if pool.size == 0:
            break
        visible = [k for k in pool if grid_line_of_sight(free, cur, tuple(features[k]))]
        if visible:
            vis = np.array(visible)
            k = int(vis[np.argmin(np.hypot(*(features[vis] - goal_xy).T))])
        else:
            k = int(pool[np.argmin(np.hypot(*(features[pool] - np.array(cur)).T))])
        used[k] = True
        cur = (int(features[k, 0]), int(features[k, 1]))
        points.append(cur)
    points.append(goal)
    arr = np.array(points, dtype=float)
    return points, float(np.sum(np.hypot(*np.diff(arr, axis=0).T)))


def iaco_heuristic(d_ig: np.ndarray, d_ij: np.ndarray, d_jg: np.ndarray, cos_omega: np.ndarray) -> np.ndarray:
    """Eq. (6): ``eta_ij = d_ig / (d_ij + d_jg) * (cos(omega) + 1)``."""
    return np.asarray(d_ig) / (np.asarray(d_ij) + np.asarray(d_jg)) * (np.asarray(cos_omega) + 1.0)


def adaptive_parameters(alpha0: float, beta0: float, delta: float, kappa: float, iteration: int,
                        iterations: int, collar_length: float, best_length: float | None,
                        rho0: float) -> tuple[float, float, float]:
    """Eqs. (9)-(11): alpha, beta and rho for iteration ``Nc = iteration`` (1-based) of ``N``.

    ``x = (Nc / N + L_GL / (LF_best + L_GL)) / 2``;
    ``alpha = alpha0 + delta * sin(x * pi)``; ``beta = beta0 * exp(-2 x^2)``;
    ``rho = kappa * L_GL / (L_best + L_GL)``.  Without a best length yet the
    ratio counts as 0 and rho stays ``rho0``.
    """
    ratio = 0.0 if best_length is None else collar_length / (best_length + collar_length)
    x = (iteration / iterations + ratio) / 2.0
    alpha = alpha0 + delta * math.sin(x * math.pi)
    beta = beta0 * math.exp(-2.0 * x * x)
    rho = rho0 if best_length is None else kappa * ratio
    return alpha, beta, rho


def pheromone_intensity(q: float, t_c: float, collar_length: float, lengths: np.ndarray,
                        exponent_limit: float = 30.0) -> np.ndarray:
    """Eq. (7): ``Q_m = Q * t_c ** ((L_GL - L_m) ** 3)``, the exponent capped above at ``exponent_limit``.

    Below there is no cap: a tour much longer than the collar line gets ``t_c`` to a
    large negative power, which underflows harmlessly to 0 (it deposits nothing).
    """
    exponent = np.minimum((collar_length - np.asarray(lengths, dtype=float)) ** 3, exponent_limit)
    return q * np.power(t_c, exponent)


def prune_length(q: float, t_c: float, collar_length: float, negligible: float) -> float:
    """Tour length beyond which Eq. (7) gives ``Q_m < negligible``: ``L_GL + (log(Q / negligible) / log t_c) ** (1/3)``.

    Infinite when ``t_c = 1`` (Eq. (7) is then the constant ``Q``: it never shrinks a deposit); the
    planner refuses ``t_c < 1``.
    """
    if t_c <= 1.0:
        return math.inf
    # Q at or below the floor: every tour past the collar line deposits below it (never a complex root)
    return collar_length + (max(0.0, math.log(q / negligible)) / math.log(t_c)) ** (1.0 / 3.0)


@dataclass
class ImprovedAntColonyPlanner(GridColonyPlanner):
    """IACO (Gong et al. 2022).  Defaults are the paper's Table 2.

    The quantities of the paper's Table 3 are in ``stats.extra``: its "optimal
    length" is the best tour's length, ``raw_length_m`` (the best any ant walked,
    not a proven optimum); ``mean_length_m`` and ``std_length_m`` over the last
    iteration's arrived tours, ``convergence_iteration`` and ``bends``.

    Args:
        ants: colony size m (50; at most :data:`planners.ant_colony.MAX_ANTS`, 10,000).
        iterations: N (100).
        alpha, beta: initial alpha and beta of Eqs. (9)-(10) (1 and 5).
        rho: initial evaporation, until Eq. (11) has a best length (0.3).
        q: pheromone intensity Q (100).
        t_c: base of Eq. (7) (1.5).
        delta: adjustment coefficient of Eq. (9) (2).
        kappa: adjustment coefficient of Eq. (11) (0.7).
        initial_pheromone: pheromone tau_0 on every free cell at the start (the paper gives
            no value; ours: 2, i.e. about one ant's Eq. (8) deposit, so the first tours do not
            take over at once).
        collar_pheromone: pheromone added to the cells the collar line crosses (§3.1 gives no
            amount; ours: 4, so collar cells start at 3 x tau_0; how it was chosen: ``docs/papers.md``).
        tau_floor: smallest pheromone a cell keeps.
        exponent_limit: upper cap of Eq. (7)'s exponent (ours: 3); there is no cap below (a cap
            below would make Eq. (7) a constant for every tour longer than the collar line).
        max_steps: NumPy steps after which an ant fails; 0 means ``step_ratio`` x the
            iteration's length limit (see ``prune_ratio``), at least rows + cols and at
            most half the number of cells.
        step_ratio: see ``max_steps`` (ours: 1.25: a backtracking ant otherwise walks long
            without a chance to arrive, and an iteration lasts as long as its slowest ant).
        prune_ratio: an ant stops once its tour is longer than this multiple of the best
            length so far and than :func:`prune_length` (1: it could not become the best,
            and its Eq. (7) deposit would lie below ``tau_floor``); before any best, the
            limit is 4 x the collar length (at least rows + cols).
        cell_m: grid resolution; ``None`` keeps the problem's.  The grid may have at most
            :data:`planners.ant_colony.MAX_COLONY_CELLS` (500,000) cells.
        shortcut: line-of-sight shortcut of the best tour (the raw cells stay in stats).
    """

    name: ClassVar[str] = "iaco"
    supports: ClassVar[frozenset[str]] = frozenset({"discs", "boxes"})
    rho: float = 0.3
    beta: float = 5.0
    q: float = param(100.0, above(0, 1e12))
    # t_c >= 1: below 1, Eq. (7) would reward longer tours without bound (Table 1's values are 1 to 5).
    t_c: float = param(1.5, within(1, 1e6))
    delta: float = param(2.0, within(0, 100))
    kappa: float = param(0.7, Range(0, 1, low_open=True, high_open=True))
    initial_pheromone: float = param(2.0, above(0, 1e12))
    collar_pheromone: float = param(4.0, within(0, 1e12))
    tau_floor: float = param(1e-12, above(0, 1e6))
    exponent_limit: float = param(3.0, within(0, 700))
    step_ratio: float = param(1.25, above(0, 1000))
    prune_ratio: float = param(1.0, above(0, 1000))

    def init_trails(self, state: SwarmState, problem: Problem, start: tuple[int, int], goal: tuple[int, int]) -> None:
        """tau_0 on every free cell, more on the cells the collar line crosses (§3.1), and Eq. (6)'s goal guidance."""
        data = state.data
        grid = problem.grid
        rows, cols = grid.shape
        points, collar_cells = collar_line(grid.occupied, start, goal)
        tau = np.where(grid.occupied.ravel(), 0.0, self.initial_pheromone)
        crossed = {cell for a, b in zip(points[:-1], points[1:]) for cell in line_cells(a, b)}
        crossed_idx = np.array([r * cols + c for r, c in crossed
                                if 0 <= r < rows and 0 <= c < cols and not grid.occupied[r, c]], dtype=np.int64)
        tau[crossed_idx] += self.collar_pheromone
        d_goal = data["d_goal"]
        # Eq. (6)'s goal guidance d_ig / (d_ij + d_jg) of every move, fixed for the run.
        guidance = iaco_heuristic(d_goal[:, None], STEP_LENGTHS[None, :], d_goal[data["safe_table"]], 0.0)
        data.update({"guidance": guidance, "cos": cosine_table(), "tau": tau, "collar_length": collar_cells,
                     "collar_points": points, "params": (self.alpha, self.beta, self.rho)})

    def move_weights(self, state: SwarmState, problem: Problem,
                     iteration: int) -> tuple[np.ndarray, np.ndarray | None, int, float]:
        """Eqs. (9)-(11)'s alpha, beta and rho of this iteration, then Eq. (1)'s numerator with Eq. (6),
        and the length beyond which an ant stops (``prune_ratio``, :func:`prune_length`)."""
        data = state.data
        best_cells = None if state.best_solution is None else data["best_length_cells"]
        alpha, beta, rho = adaptive_parameters(self.alpha, self.beta, self.delta, self.kappa, iteration + 1,
                                               self.iterations, data["collar_length"], best_cells, self.rho)
        data["params"] = (alpha, beta, rho)
        tau, cos = data["tau"], data["cos"]
        # Eq. (6) split into its goal-guidance factor (per cell and move) and its bend
        # factor (per turn), each raised to beta once per iteration (alpha and beta are
        # fixed within one); Eq. (1)'s numerator is then their product with tau_j^alpha.
        cell_weights = np.power(data["guidance"], beta)
        cell_weights *= np.power(tau, alpha)[data["safe_table"]]
        cell_weights *= data["legal"]
        bend_beta = np.power(cos + 1.0, beta)                          # (9, 8)
        rows, cols = problem.grid.shape
        limit = (max(self.prune_ratio * best_cells,
                     prune_length(self.q, self.t_c, data["collar_length"], self.tau_floor))
                 if best_cells is not None else max(4.0 * data["collar_length"], float(rows + cols)))
        # An ant that backtracks keeps walking without growing its tour: cap its NumPy steps too.
        # (``limit`` is infinite when t_c = 1: Eq. (7) is then the constant Q and prunes nothing.)
        max_steps = self.max_steps or int(min(rows * cols // 2, max(rows + cols, self.step_ratio * limit)))
        return cell_weights, bend_beta, max_steps, limit

    def update(self, state: SwarmState, walk: ColonyWalk, arrived: np.ndarray, lengths: np.ndarray,
               iteration_best: tuple[np.ndarray, float] | None) -> None:
        """Eq. (3): evaporate, then Eq. (8): each arrived ant deposits ``Q_m / (L_m + turn)`` on its cells."""
        data = state.data
        tau = data["tau"]
        evaporate(tau, data["params"][2])
        if arrived.size:
            q_m = pheromone_intensity(self.q, self.t_c, data["collar_length"], lengths, self.exponent_limit)
            amounts = q_m / (lengths + walk.turns[arrived])
            tours = [walk.tour(a)[1:] for a in arrived]
            deposit(tau, np.concatenate(tours), np.repeat(amounts, [len(t) for t in tours]))
        free = tau > 0.0
        np.maximum(tau, self.tau_floor, out=tau, where=free)

    def extra_stats(self, state: SwarmState, problem: Problem) -> dict[str, Any]:
        data = state.data
        alpha, beta, rho = data["params"]
        return {
            "collar_length_m": data["collar_length"] * problem.grid.cell_m,
            "collar_points": [list(p) for p in data["collar_points"]],
            "final_alpha": alpha, "final_beta": beta, "final_rho": rho,
        }
