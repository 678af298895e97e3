"""IMMAS: the improved MAX-MIN ant system of Hasan, Abdullah & Saleh (2023).

A wide-free-space planner in two stages, on the inflated occupancy grid:

1. **Environment analysis** (Algorithm 1).  Pheromone propagates from the goal
   (the food) over the free cells in order of route cost, D*-style, until the
   start (the nest) is reached.  While expanding a cell X:

   * ``clean(X)`` grows by the clean weight (0.5) for each obstacle neighbour (line 16);
   * GateRaiseState (line 18): X is closed when two diagonally opposite neighbours
     (NE and SW, or NW and SE) are both obstacles - a gate the robot cannot pass;
   * CheckTightTunnelState (Algorithm 2, line 19): each horizontal or vertical
     neighbour Y of X whose two flanking cells (the diagonal neighbours of X on
     either side of Y) are both obstacles is a tight-tunnel entrance and is closed;
   * PheromoneTrails (line 17): each free neighbour Y gets route cost
     ``k(Y) = k(X) + c`` and pheromone ``tau(Y) = rho * tau(X) + c`` (Eq. 2 with the
     arc cost as deposit), ``c`` = 1 for a horizontal or vertical move and the
     diagonal factor 1.4 for a diagonal one; rho = 0.98.

2. **Tour construction** (Algorithm 3, Eq. 3).  From the start, each iteration
   moves the robot (the ant) to the neighbour with the best value of
   ``(tau + clean)^alpha * eta^beta``, with ``eta`` the distance to the goal, and adds
   the new cell's route cost ``k`` to the total arc cost (line 25).

Readings of the paper where its text is ambiguous (our choices):

* Algorithm 3 lines 14-20 keep the neighbour with the *smallest* value of Eq. (3):
  tau is read as the propagated route cost (it grows away from the goal), clean
  penalises obstacle neighbours and eta is a distance, so the smallest value is
  the cell nearest the goal away from walls.  ``selection="roulette"`` instead
  draws the neighbour with probability proportional to 1 / Eq. (3) with the
  shared roulette wheel.
* The robot never re-enters a cell; with no unvisited candidate it follows the
  propagation tree one step towards the goal (tau strictly decreases along it),
  so every tour ends at the goal.
* Clean values for the tour are counted on the final grid (after all closings).
* The start and goal cells are never closed.  If closing disconnects them, the
  analysis is redone without closing and ``closing_reverted`` is reported.
* Cells closed by Algorithms 1-2 are grid cells of *our* inflated grid: with a
  robot one cell wide (the papers' setting, see ``planners.movingai.inflated_map_grid``)
  they are the map's one-cell gates and tunnels.
"""

from __future__ import annotations

import heapq
import math
import time
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from scipy import ndimage

from swarmnav.models.parameters import Range, above, within
from swarmnav.planners.ant_colony import roulette
from swarmnav.planners.errors import NoPathFound, check_parameters
from swarmnav.planners.grid_graph import DIRECTIONS, Cell, cells_to_waypoints, count_bends, grid_endpoints, grid_problem
from swarmnav.planners.grid_shortcut import exact_shortcut
from swarmnav.planners.problem import Problem
from swarmnav.planners.swarm import SwarmPlanner, SwarmState

INF = math.inf
ORTHOGONAL = ((-1, 0), (1, 0), (0, -1), (0, 1))


@dataclass
class EnvironmentAnalysis:
    """Result of Algorithms 1-2.

    Attributes:
        blocked: (rows, cols) obstacles after closing gates and tunnels.
        route_cost: (rows, cols) k, the route cost to the goal (inf where not propagated).
        pheromone: (rows, cols) tau (inf where not propagated).
        clean: (rows, cols) clean weight times the number of obstacle neighbours.
        parent: (rows, cols, 2) the next cell towards the goal in the propagation tree (-1 if none).
        gates: cells closed by GateRaiseState.
        tunnels: cells closed by CheckTightTunnelState.
        expansions: cells expanded by the propagation.
        closing_reverted: closing disconnected start from goal, so nothing was closed.
    """

    blocked: np.ndarray
    route_cost: np.ndarray
    pheromone: np.ndarray
    clean: np.ndarray
    parent: np.ndarray
    gates: list[Cell] = field(default_factory=list)
    tunnels: list[Cell] = field(default_factory=list)
    expansions: int = 0
    closing_reverted: bool = False


def is_gate(blocked: list[list[bool]], r: int, c: int) -> bool:
    """GateRaiseState: both cells of a diagonally opposite pair of neighbours are obstacles."""
    rows, cols = len(blocked), len(blocked[0])

    def occ(rr: int, cc: int) -> bool:
        return 0 <= rr < rows and 0 <= cc < cols and blocked[rr][cc]

    return (occ(r + 1, c + 1) and occ(r - 1, c - 1)) or (occ(r + 1, c - 1) and occ(r - 1, c + 1))


def is_tight_tunnel(blocked: list[list[bool]], r: int, c: int, dr: int, dc: int) -> bool:
    """Algorithm 2 for the horizontal or vertical neighbour Y = (r + dr, c + dc) of X = (r, c).

    Y is a tight-tunnel entrance when the two diagonal neighbours of X that
    flank it are both obstacles.
    """
    rows, cols = len(blocked), len(blocked[0])

    def occ(rr: int, cc: int) -> bool:
        return 0 <= rr < rows and 0 <= cc < cols and blocked[rr][cc]

    if dr:
        return occ(r + dr, c - 1) and occ(r + dr, c + 1)
    return occ(r - 1, c + dc) and occ(r + 1, c + dc)


def analyse_environment(occupied: np.ndarray, start: Cell, goal: Cell, rho: float = 0.98,
                        clean_weight: float = 0.5, diagonal_factor: float = 1.4,
                        close: bool = True) -> EnvironmentAnalysis:
    """Algorithms 1-2: propagate pheromone from the goal, closing gates and tight tunnels.

    Raises:
        NoPathFound: the start is unreachable from the goal even without closing.
    """
    occ = np.asarray(occupied, dtype=bool)
    rows, cols = occ.shape
    blocked = occ.tolist()
    k = [[INF] * cols for _ in range(rows)]
    tau = [[INF] * cols for _ in range(rows)]
    parent = [[None] * cols for _ in range(rows)]
    closed_set = [[False] * cols for _ in range(rows)]
    keep = {start, goal}
    gates: list[Cell] = []
    tunnels: list[Cell] = []
    gr, gc = goal
    k[gr][gc] = 0.0
    tau[gr][gc] = 0.0
    heap = [(0.0, gr, gc)]
    expansions = 0
    reached = False
    moves = [(dr, dc, diagonal_factor if dr and dc else 1.0) for dr, dc in DIRECTIONS]
    while heap:
        kx, r, c = heapq.heappop(heap)
        if closed_set[r][c] or blocked[r][c] or kx > k[r][c]:
            continue
        closed_set[r][c] = True
        if (r, c) == start:
            reached = True
            break
        if close and (r, c) not in keep and is_gate(blocked, r, c):
            blocked[r][c] = True
            gates.append((r, c))
            continue
        expansions += 1
        if close:
            for dr, dc in ORTHOGONAL:
                yr, yc = r + dr, c + dc
                if (0 <= yr < rows and 0 <= yc < cols and not blocked[yr][yc] and (yr, yc) not in keep
                        and not closed_set[yr][yc] and is_tight_tunnel(blocked, r, c, dr, dc)):
                    blocked[yr][yc] = True
                    tunnels.append((yr, yc))
        tx = tau[r][c]
        for dr, dc, cost in moves:
            yr, yc = r + dr, c + dc
            if not (0 <= yr < rows and 0 <= yc < cols) or blocked[yr][yc] or closed_set[yr][yc]:
                continue
            if dr and dc and (blocked[r][yc] or blocked[yr][c]):
                continue
            ky = kx + cost
            if ky < k[yr][yc]:
                k[yr][yc] = ky
                tau[yr][yc] = rho * tx + cost
                parent[yr][yc] = (r, c)
                heapq.heappush(heap, (ky, yr, yc))
    if not reached:
        if close:
            result = analyse_environment(occ, start, goal, rho, clean_weight, diagonal_factor, close=False)
            result.closing_reverted = True
            return result
        raise NoPathFound(f"goal cell {goal} is unreachable from start cell {start}")
    blocked_arr = np.array(blocked, dtype=bool)
    neighbours = ndimage.convolve(blocked_arr.astype(np.int64), np.array([[1, 1, 1], [1, 0, 1], [1, 1, 1]]),
                                  mode="constant", cval=0)
    parent_arr = np.full((rows, cols, 2), -1, dtype=np.int64)
    for r in range(rows):
        for c in range(cols):
            if parent[r][c] is not None:
                parent_arr[r, c] = parent[r][c]
    return EnvironmentAnalysis(blocked=blocked_arr, route_cost=np.array(k), pheromone=np.array(tau),
                               clean=clean_weight * neighbours * ~blocked_arr, parent=parent_arr,
                               gates=gates, tunnels=tunnels, expansions=expansions)


def tour_scores(tau: np.ndarray, clean: np.ndarray, eta: np.ndarray, alpha: float, beta: float) -> np.ndarray:
    """Eq. (3)'s numerator, ``(tau + clean)^alpha * eta^beta``, for candidate cells."""
    return np.power(tau + clean, alpha) * np.power(eta, beta)


@dataclass
class MaxMinAntSystemPlanner(SwarmPlanner):
    """IMMAS (Hasan et al. 2023): wide free space by cleaning weights and closing gates and tight tunnels.

    Each iteration of the loop is one move of the robot (Algorithm 3), so the
    reported iterations are the paper's "No. of Iteration".

    Args:
        alpha: pheromone weight (3 in most of Table 1, 5 in environment 1).
        beta: heuristic weight (1; 0 in environment 2).
        rho: evaporation rate of the propagation (0.98).
        clean_weight: added per obstacle neighbour (0.5).
        diagonal_factor: arc cost of a diagonal move (1.4).
        close_gates_and_tunnels: apply GateRaiseState and Algorithm 2.
        selection: "best" (Algorithm 3: the smallest Eq. (3) value) or "roulette".
        iterations: max_itr, the move budget; 0 means the number of cells.
        cell_m: grid resolution; ``None`` keeps the problem's.  The grid may have at most
            :data:`planners.grid_graph.MAX_GRID_CELLS` (5,000,000) cells.
        shortcut: line-of-sight shortcut of the tour (the raw cells stay in stats).
    """

    name: ClassVar[str] = "immas"
    parameter_ranges: ClassVar[dict[str, Range]] = {
        "alpha": within(0, 100), "beta": within(0, 100), "rho": above(0, 1), "clean_weight": within(0, 1e6),
        "diagonal_factor": within(1, 10), "iterations": within(0, 10_000_000), "cell_m": within(1e-6, 100),
        "max_evaluations": within(0, 1e9)}  # models.parameters: checked on build
    supports: ClassVar[frozenset[str]] = frozenset({"discs", "boxes"})
    alpha: float = 3.0
    beta: float = 1.0
    rho: float = 0.98
    clean_weight: float = 0.5
    diagonal_factor: float = 1.4
    close_gates_and_tunnels: bool = True
    selection: str = "best"
    iterations: int = 0
    cell_m: float | None = None
    shortcut: bool = True
    max_evaluations: int | None = None

    def __post_init__(self) -> None:
        check_parameters(self, (
            ("selection", self.selection in ("best", "roulette"), "must be 'best' or 'roulette'"),
            ("rho", 0.0 < self.rho <= 1.0, "must lie in (0, 1]"),
            ("iterations", self.iterations >= 0, "must not be negative"),
            ("cell_m", self.cell_m is None or self.cell_m > 0, "must be positive"),
        ))

    def prepare(self, problem: Problem) -> Problem:
        return grid_problem(problem, self.cell_m)

    def iteration_limit(self, problem: Problem) -> int:
        """max_itr: ``iterations``, or the number of cells when it is 0."""
        rows, cols = problem.grid.shape
        return self.iterations or rows * cols

    def init_state(self, state: SwarmState, problem: Problem, rng: np.random.Generator) -> None:
        t0 = time.perf_counter()
        grid = problem.grid
        start, goal = grid_endpoints(problem, grid)
        analysis = analyse_environment(grid.occupied, start, goal, self.rho, self.clean_weight,
                                       self.diagonal_factor, self.close_gates_and_tunnels)
        rows, cols = grid.shape
        rr, cc = np.mgrid[0:rows, 0:cols]
        eta = np.hypot(rr - goal[0], cc - goal[1])
        visited = np.zeros((rows, cols), dtype=bool)
        visited[start] = True
        state.data = {"analysis": analysis, "eta": eta, "visited": visited, "start": start, "goal": goal,
                      "cells": [start], "arc_cost": 0.0, "analysis_time_s": time.perf_counter() - t0,
                      "fallbacks": 0}
        state.done = start == goal

    def step(self, state: SwarmState, problem: Problem, rng: np.random.Generator, iteration: int) -> None:
        data = state.data
        a: EnvironmentAnalysis = data["analysis"]
        rows, cols = a.blocked.shape
        r, c = data["cells"][-1]
        candidates = []
        for dr, dc in DIRECTIONS:
            yr, yc = r + dr, c + dc
            if not (0 <= yr < rows and 0 <= yc < cols) or a.blocked[yr, yc] or data["visited"][yr, yc]:
                continue
            if dr and dc and (a.blocked[r, yc] or a.blocked[yr, c]):
                continue
            if not math.isfinite(a.route_cost[yr, yc]):
                continue
            candidates.append((yr, yc))
        if candidates:
            cand = np.array(candidates)
            scores = tour_scores(a.pheromone[cand[:, 0], cand[:, 1]], a.clean[cand[:, 0], cand[:, 1]],
                                 data["eta"][cand[:, 0], cand[:, 1]], self.alpha, self.beta)
            if self.selection == "best":
                pick = int(np.argmin(scores))
            else:
                weights = np.where(scores > 0, 1.0 / np.maximum(scores, 1e-300), 1e300)[None, :]
                pick = int(roulette(weights, rng)[0][0])
            nxt = (int(cand[pick, 0]), int(cand[pick, 1]))
        else:
            pr, pc = a.parent[r, c]
            if pr < 0:
                raise NoPathFound(f"the tour is stuck at cell {(r, c)}")
            nxt = (int(pr), int(pc))
            data["fallbacks"] += 1
        data["cells"].append(nxt)
        data["visited"][nxt] = True
        data["arc_cost"] += float(a.route_cost[nxt])
        state.evaluations += 1
        if nxt == data["goal"]:
            state.done = True
            cells = _without_loops(data["cells"])
            data["cells"] = cells
            arr = np.array(cells, dtype=float)
            state.best_solution = cells
            state.best_cost = float(np.sum(np.hypot(*np.diff(arr, axis=0).T))) * problem.grid.cell_m

    def finish(self, state: SwarmState, problem: Problem,
               rng: np.random.Generator) -> tuple[np.ndarray, dict[str, Any]]:
        data = state.data
        grid = problem.grid
        if state.best_solution is None:
            if data["start"] == data["goal"]:
                state.best_solution, state.best_cost = [data["start"]], 0.0
            else:
                raise NoPathFound(f"the tour did not reach the goal within {self.iteration_limit(problem)} moves")
        cells = state.best_solution
        raw = cells_to_waypoints(problem, grid, cells)
        waypoints = exact_shortcut(problem, raw) if self.shortcut else raw
        a: EnvironmentAnalysis = data["analysis"]
        clearance = ndimage.distance_transform_edt(~grid.occupied) * grid.cell_m
        idx = np.array(cells)
        extra = {
            "raw_cells": [list(cell) for cell in cells],
            "raw_length_m": state.best_cost,
            "gates_raised": len(a.gates),
            "tunnels_closed": len(a.tunnels),
            "closed_cells": [list(cell) for cell in a.gates + a.tunnels],
            "closing_reverted": a.closing_reverted,
            "moves": len(data["cells"]) - 1,
            "total_arc_cost": data["arc_cost"],
            "propagation_expansions": a.expansions,
            "fallback_moves": data["fallbacks"],
            "bends": count_bends(cells),
            "mean_cell_clearance_m": float(np.mean(clearance[idx[:, 0], idx[:, 1]])),
            "analysis_time_s": data["analysis_time_s"],
        }
        return waypoints, extra


def _without_loops(cells: list[Cell]) -> list[Cell]:
    """Cut every loop out of a cell walk (keeps the first visit of a revisited cell)."""
    out: list[Cell] = []
    where: dict[Cell, int] = {}
    for cell in cells:
        if cell in where:
            cut = where[cell]
            for dropped in out[cut + 1:]:
                del where[dropped]
            out = out[: cut + 1]
        else:
            where[cell] = len(out)
            out.append(cell)
    return out
