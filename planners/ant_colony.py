"""The ant-colony core shared by ``immas``, ``iaco`` and ``maco``.

What the three papers have in common lives here, once:

* :func:`roulette`: roulette-wheel choice of one option per ant, for all ants in one call;
* :func:`evaporate` and :func:`deposit`: the pheromone update ``tau <- (1 - rho) tau + sum(delta)``;
* :class:`GridGraph`: the 8-connected, no-corner-cutting cell graph of an occupancy grid;
* :func:`walk_colony`: tour construction on a :class:`GridGraph`, vectorised over ants:
  every walking ant advances one cell per NumPy step, with masks for the ants that
  reached the goal or got stuck (no unvisited neighbour left).

Each planner supplies only its desirability (how Eq. (1)/(3)/(6) of its paper
weighs the neighbours) and its update rule, and runs through
:class:`planners.swarm.SwarmPlanner`, the one optimisation loop.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from planners.grid_search import DIRECTIONS, STEP_COSTS, neighbour_table
from planners.problem import OccupancyGrid

#: Index used for "no previous move" (an ant on its first step).
NO_DIRECTION = 8
STEP_LENGTHS = np.array(STEP_COSTS)
DIRECTION_VECTORS = np.array(DIRECTIONS, dtype=float)  # (d_row, d_col)


def roulette(weights: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Draw one column per row with probability proportional to its weight.

    Args:
        weights: (A, K) non-negative weights, one row per ant (0 = not allowed).
        rng: the run's generator; exactly ``A`` uniforms are drawn.

    Returns:
        (choice (A,) column indices, ok (A,) bool: False where a row has no positive weight;
        its choice is then meaningless).
    """
    w = np.asarray(weights, dtype=float)
    cumulative = w.cumsum(axis=1)
    total = cumulative[:, -1]
    ok = total > 0.0
    draw = rng.random(w.shape[0]) * total
    choice = (cumulative <= draw[:, None]).sum(axis=1)
    np.minimum(choice, w.shape[1] - 1, out=choice)
    return choice, ok


def evaporate(tau: np.ndarray, rho: float) -> None:
    """In place: ``tau <- (1 - rho) * tau`` (the evaporation half of the ACO update)."""
    tau *= 1.0 - rho


def deposit(tau: np.ndarray, indices: np.ndarray, amounts: np.ndarray | float) -> None:
    """In place: add ``amounts`` at ``indices`` (repeated indices accumulate)."""
    np.add.at(tau, np.asarray(indices, dtype=np.int64), amounts)


@dataclass(frozen=True, eq=False)
class GridGraph:
    """The cell graph ants walk on.

    Attributes:
        grid: the occupancy grid (cells are flat indices ``row * cols + col``).
        table: (N, 8) neighbour indices in :data:`planners.grid_search.DIRECTIONS` order, -1 where illegal.
    """

    grid: OccupancyGrid
    table: np.ndarray

    @classmethod
    def of(cls, grid: OccupancyGrid) -> "GridGraph":
        return cls(grid=grid, table=neighbour_table(grid.occupied))

    @property
    def cols(self) -> int:
        return self.grid.occupied.shape[1]

    @property
    def size(self) -> int:
        return self.table.shape[0]

    def index(self, cell: tuple[int, int]) -> int:
        return int(cell[0]) * self.cols + int(cell[1])

    def cells(self, indices: np.ndarray) -> np.ndarray:
        """(K, 2) (row, col) of flat indices."""
        idx = np.asarray(indices, dtype=np.int64)
        return np.column_stack(np.divmod(idx, self.cols))


@dataclass
class ColonyWalk:
    """Tours of one colony iteration.

    Attributes:
        paths: (A, S + 1) flat cell indices, -1 after an ant's last cell.
        steps: (A,) moves made by each ant.
        length_cells: (A,) tour length in cells (1 per orthogonal move, sqrt 2 per diagonal).
        turns: (A,) direction changes along each tour.
        reached: (A,) the ant reached the goal.
    """

    paths: np.ndarray
    steps: np.ndarray
    length_cells: np.ndarray
    turns: np.ndarray
    reached: np.ndarray

    def tour(self, ant: int) -> np.ndarray:
        """Flat cell indices of one ant's tour."""
        return self.paths[ant, : self.steps[ant] + 1]


Desirability = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray]


def walk_colony(graph: GridGraph, start: int, goal: int, ants: int, desirability: Desirability,
                rng: np.random.Generator, max_steps: int, backtrack: bool = True,
                max_length: float = np.inf) -> ColonyWalk:
    """Let ``ants`` ants walk from ``start`` until each reaches ``goal``, gets stuck, or runs out of steps.

    An ant never re-enters a cell it has visited (its tabu list).  All walking
    ants move in the same NumPy step; finished and stuck ants are masked out.

    Args:
        graph: the cell graph.
        start, goal: flat cell indices.
        ants: colony size.
        desirability: ``f(position (A,), previous direction (A,), candidates (A, 8),
            allowed (A, 8)) -> weights (A, 8)``, for the A ants still walking;
            previous direction is :data:`NO_DIRECTION` on the first move.
            Weights where ``allowed`` is False are ignored.
        rng: the run's generator (one uniform per walking ant per step).
        max_steps: NumPy steps after which an ant that has not arrived counts as failed.
        backtrack: an ant with no unvisited neighbour steps back one cell (the dead
            end stays on its tabu list) instead of failing; it fails only when
            back at the start with nowhere to go.
        max_length: an ant whose tour grows longer than this (in cells) stops and fails.
    """
    table = graph.table
    n = graph.size
    pos = np.full(ants, start, dtype=np.int64)
    visited = np.zeros((ants, n), dtype=bool)
    visited[:, start] = True
    paths = np.full((ants, max_steps + 1), -1, dtype=np.int64)
    paths[:, 0] = start
    dirs = np.full((ants, max_steps + 1), NO_DIRECTION, dtype=np.int64)  # dirs[a, k]: move into paths[a, k]
    steps = np.zeros(ants, dtype=np.int64)
    length = np.zeros(ants)
    reached = np.zeros(ants, dtype=bool)
    reached[:] = start == goal
    walking = np.arange(ants) if start != goal else np.arange(0)
    for _ in range(max_steps):
        if walking.size == 0:
            break
        here = pos[walking]
        cand = table[here]                                    # (A, 8)
        allowed = cand >= 0
        safe = np.where(allowed, cand, 0)
        allowed &= ~visited[walking[:, None], safe]
        prev = dirs[walking, steps[walking]]
        weights = np.where(allowed, desirability(here, prev, cand, allowed), 0.0)
        choice, ok = roulette(weights, rng)
        movers = walking[ok]
        d = choice[ok]
        nxt = cand[ok, d]
        k = steps[movers] + 1
        pos[movers] = nxt
        visited[movers, nxt] = True
        paths[movers, k] = nxt
        dirs[movers, k] = d
        steps[movers] = k
        length[movers] += STEP_LENGTHS[d]
        arrived = nxt == goal
        reached[movers[arrived]] = True
        still = movers[~arrived & (length[movers] <= max_length)]
        stuck = walking[~ok]
        if backtrack and stuck.size:
            stuck = stuck[steps[stuck] > 0]
            back = steps[stuck] - 1
            length[stuck] -= STEP_LENGTHS[np.minimum(dirs[stuck, steps[stuck]], 7)]
            paths[stuck, steps[stuck]] = -1
            dirs[stuck, steps[stuck]] = NO_DIRECTION
            steps[stuck] = back
            pos[stuck] = paths[stuck, back]
            still = np.sort(np.concatenate([still, stuck]))
        walking = still
    moved = np.arange(max_steps + 1)[None, :] <= steps[:, None]
    moved[:, 0] = False
    change = moved[:, 2:] & (dirs[:, 2:] != dirs[:, 1:-1])
    turns = change.sum(axis=1)
    return ColonyWalk(paths=paths, steps=steps, length_cells=length, turns=turns, reached=reached)


def cosine_table() -> np.ndarray:
    """(9, 8) cosine of the turn from a previous move direction (row; 8 = none) to a next one.

    The row for "no previous move" is 1 (treated as straight on).
    """
    unit = DIRECTION_VECTORS / np.linalg.norm(DIRECTION_VECTORS, axis=1, keepdims=True)
    table = np.ones((9, 8))
    table[:8] = unit @ unit.T
    return table
