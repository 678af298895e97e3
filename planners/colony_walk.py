"""Tour construction on the grid, shared by the grid ant colonies (``aco``, ``mmas``, ``iaco``).

* :class:`GridGraph`: the 8-connected, no-corner-cutting cell graph of an occupancy grid;
* :func:`walk_colony_reference`: tour construction on a :class:`GridGraph`, vectorised over ants:
  every walking ant advances one cell per NumPy step, with masks for the ants that
  reached the goal or got stuck (no unvisited neighbour left); :func:`walk_colony`
  is the same walk compiled (``planners/_colony_walk.c``), which the planners use.

Speed: the state of an ant is one integer ``key = p * N + i`` (previous direction and cell),
so a step reads its weights and candidates with one gather each from per-iteration ``(9 N, 8)``
tables; tabu lists are flat masks multiplied into the weights; tours are stored as keys (cells
and directions are recovered after the walk).

A planner folds its paper's transition rule (``tau^alpha * eta^beta``, Eq. (1) of the ACO
papers) into a per-cell and a per-turn weight table; the walk only draws from them
(:class:`planners.ant_colony.GridColonyPlanner` runs it once per iteration).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from swarmnav.planners._colony_walk import walk_block
from swarmnav.planners.grid_graph import DIRECTIONS, STEP_COSTS, neighbour_table
from swarmnav.models.world import OccupancyGrid

#: Index used for "no previous move" (an ant on its first step).
NO_DIRECTION = 8
STEP_LENGTHS = np.array(STEP_COSTS)
#: Steps of a colony walk whose roulette uniforms are drawn in one call.
UNIFORM_BLOCK = 32
#: :data:`STEP_LENGTHS` with a 0 for :data:`NO_DIRECTION`.
STEP_LENGTHS_9 = np.append(STEP_LENGTHS, 0.0)
DIRECTION_VECTORS = np.array(DIRECTIONS, dtype=float)  # (d_row, d_col)


@dataclass(frozen=True, eq=False)
class GridGraph:
    """The cell graph ants walk on.

    Attributes:
        grid: the occupancy grid (cells are flat indices ``row * cols + col``).
        table: (N, 8) neighbour indices in :data:`planners.grid_graph.DIRECTIONS` order, -1 where illegal.
        key_table: (9 N, 8) the same table repeated once per previous direction
            (:data:`NO_DIRECTION` last), indexed by an ant's key ``direction * N + cell``.
    """

    grid: OccupancyGrid
    table: np.ndarray
    key_table: np.ndarray

    @classmethod
    def of(cls, grid: OccupancyGrid) -> "GridGraph":
        table = neighbour_table(grid.occupied)
        return cls(grid=grid, table=table, key_table=np.tile(table, (NO_DIRECTION + 1, 1)))

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


def walk_colony(graph: GridGraph, start: int, goal: int, ants: int, cell_weights: np.ndarray,
                turn_weights: np.ndarray | None, rng: np.random.Generator, max_steps: int,
                backtrack: bool = True, max_length: float = np.inf) -> ColonyWalk:
    """:func:`walk_colony_reference`, compiled (``planners/_colony_walk.c``): the same tours and draws.

    The NumPy walk costs about 25 NumPy calls per step whatever the number of
    ants, and an IACO ant walks ~180 steps on a 50 x 50 map (it backs out of dead
    ends): ~0.6-0.8 s of call overhead per 50 x 100 plan (profiled, issue 14).
    The C kernel does the same arithmetic per ant, in the same order, a block of
    :data:`UNIFORM_BLOCK` steps per call; the block's uniforms are drawn here as
    the reference draws them (one ``rng.random((UNIFORM_BLOCK, ants))`` per block
    begun with an ant still walking), and the j-th ant still walking at a step,
    in ant order, uses column j, as in the reference's compacted arrays.
    """
    n = graph.size
    cw = np.ascontiguousarray(cell_weights, dtype=float)
    turns = np.ones((1, 8)) if turn_weights is None else np.ascontiguousarray(turn_weights, dtype=float)
    table = np.ascontiguousarray(graph.table, dtype=np.int64)
    width, keys, steps, length, reached, unvisited = _walk_stores(ants, n, start, goal, max_steps)
    walking = np.full(ants, start != goal)
    key = np.full(ants, NO_DIRECTION * n + start, dtype=np.int64)
    run = np.zeros(ants, dtype=np.int64)
    walked = np.zeros(ants)
    still = int(walking.sum())
    for first in range(0, max_steps, UNIFORM_BLOCK):
        if still == 0:
            break
        uniforms = rng.random((UNIFORM_BLOCK, ants))
        still = walk_block(cw, turns, table, STEP_LENGTHS_9, uniforms, UNIFORM_BLOCK, first,
                           min(first + UNIFORM_BLOCK, max_steps), n, goal, width, bool(backtrack),
                           float(max_length), keys, unvisited, walking, key, run, walked, steps, length, reached)
    steps[walking] = run[walking]
    length[walking] = walked[walking]
    return _colony_walk(keys, steps, length, reached, n, start)


def walk_colony_reference(graph: GridGraph, start: int, goal: int, ants: int, cell_weights: np.ndarray,
                          turn_weights: np.ndarray | None, rng: np.random.Generator, max_steps: int,
                          backtrack: bool = True, max_length: float = np.inf) -> ColonyWalk:
    """Let ``ants`` ants walk from ``start`` until each reaches ``goal``, gets stuck, or runs out of steps.

    An ant at cell i that last moved in direction p picks direction d with
    probability proportional to ``turn_weights[p, d] * cell_weights[i, d]``
    over the neighbours it has not visited (its tabu list): Eq. (1) of the ACO
    papers once a planner has folded its ``tau^alpha * eta^beta`` into the two
    tables (they are fixed within one iteration).  All walking ants move in the
    same NumPy step; finished, pruned and failed ants leave the walking set (speed: see the module docstring).

    Args:
        graph: the cell graph (N cells).
        start, goal: flat cell indices.
        ants: colony size.
        cell_weights: (N, 8) non-negative weight of each move of :data:`planners.grid_graph.DIRECTIONS`
            out of each cell; it must be 0 where ``graph.table`` is -1.
        turn_weights: (9, 8) factor from the previous direction (row; :data:`NO_DIRECTION`
            on the first move) to the next, or ``None`` for none.
        rng: the run's generator (uniforms drawn in blocks of :data:`UNIFORM_BLOCK` steps x ``ants``).
        max_steps: NumPy steps after which an ant that has not arrived counts as failed.
        backtrack: an ant with no unvisited neighbour steps back one cell (the dead
            end stays on its tabu list) instead of failing; it fails only when
            back at the start with nowhere to go.
        max_length: an ant whose tour grows longer than this (in cells) stops and fails.
    """
    n = graph.size
    weights = _key_weights(cell_weights, turn_weights)
    candidates = graph.key_table                              # (9 N, 8) cells, -1 where illegal
    width, keys, steps, length, reached, unvisited = _walk_stores(ants, n, start, goal, max_steps)
    # The walking set, in ant order, and its gathered per-ant state.
    ids = np.arange(ants) if start != goal else np.arange(0)
    key = np.full(ids.size, NO_DIRECTION * n + start, dtype=np.int64)
    run = np.zeros(ids.size, dtype=np.int64)                   # steps of the walking ants
    walked = np.zeros(ids.size)                                # their lengths
    uniforms = np.empty((0, ants))
    for step in range(max_steps):
        if ids.size == 0:
            break
        if step % UNIFORM_BLOCK == 0:
            uniforms = rng.random((UNIFORM_BLOCK, ants))       # one draw per ant and step, fetched in blocks
        tabu_base, key_base = ids * (n + 1), ids * width
        cand = candidates[key]                                 # (A, 8)
        w = weights[key]
        w *= unvisited[tabu_base[:, None] + cand]              # -1 reads the previous dummy slot: weight 0
        cumulative = w.cumsum(axis=1)
        total = cumulative[:, -1]
        draw = uniforms[step % UNIFORM_BLOCK, :ids.size] * total
        # Roulette (as :func:`planners.ant_colony.roulette`): the first column whose running sum exceeds the draw.
        choice = np.add.reduce(np.less_equal(cumulative, draw[:, None]), axis=1)
        np.minimum(choice, 7, out=choice)                      # draw == total by rounding
        ok = total > 0.0
        nxt = cand[np.arange(ids.size), choice]
        if np.minimum.reduce(total) > 0.0:
            # Every walking ant moves (the common case): no masks needed.
            key = choice * n + nxt
            unvisited[tabu_base + nxt] = False
            run += 1
            keys[key_base + run] = key
            walked += STEP_LENGTHS[choice]
            arrived = nxt == goal
            if not np.logical_or.reduce(arrived) and np.maximum.reduce(walked) <= max_length:
                continue
            keep = ~arrived & (walked <= max_length)
        else:
            key, arrived, keep = _move_or_step_back(ok, choice, nxt, key, n, goal, run, walked, keys, key_base,
                                                    unvisited, tabu_base, backtrack, max_length)
            if np.logical_and.reduce(keep):
                continue
        steps[ids] = np.maximum(run, 0)
        length[ids] = walked
        reached[ids[arrived]] = True
        ids, key, run, walked = ids[keep], key[keep], run[keep], walked[keep]
    if ids.size:
        steps[ids] = run
        length[ids] = walked
    return _colony_walk(keys, steps, length, reached, n, start)


def _walk_stores(ants: int, n: int, start: int, goal: int, max_steps: int
                 ) -> tuple[int, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A walk's per-ant stores: (the width ``max_steps + 1`` of one ant's tour, the tours as keys,
    ant-major, each beginning at the start; steps; lengths; arrivals; the tabu masks, N cells and a
    dummy slot per ant, the start already visited)."""
    width = max_steps + 1
    keys = np.empty(ants * width, dtype=np.int64)
    keys[::width] = NO_DIRECTION * n + start
    unvisited = np.ones(ants * (n + 1), dtype=bool)
    unvisited[np.arange(ants) * (n + 1) + start] = False
    return width, keys, np.zeros(ants, dtype=np.int64), np.zeros(ants), np.full(ants, start == goal), unvisited


def _move_or_step_back(ok: np.ndarray, choice: np.ndarray, nxt: np.ndarray, key: np.ndarray, n: int, goal: int,
                       run: np.ndarray, walked: np.ndarray, keys: np.ndarray, key_base: np.ndarray,
                       unvisited: np.ndarray, tabu_base: np.ndarray, backtrack: bool, max_length: float
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One step of :func:`walk_colony_reference` when some ants are stuck (``ok`` False): they step
    back one cell (masks, no index lists); ``run`` and ``walked`` change in place.

    Returns:
        (the walking ants' new keys, which arrived, which keep walking).
    """
    new_key = choice * n + nxt
    walked += np.where(ok, STEP_LENGTHS_9[choice], -STEP_LENGTHS_9[key // n])  # a step back undoes its length
    keys[key_base + run + ok] = new_key                 # a stuck ant overwrites the top it leaves
    run += np.where(ok, 1, -1 if backtrack else 0)
    unvisited[tabu_base + np.where(ok, nxt, n)] = False  # slot n: a per-ant dummy
    key = np.where(ok, new_key, keys[key_base + run])
    arrived = ok & (nxt == goal)
    keep = ~arrived & (walked <= max_length) & (run >= 0 if backtrack else ok)
    return key, arrived, keep


def _key_weights(cell_weights: np.ndarray, turn_weights: np.ndarray | None) -> np.ndarray:
    """(9 N, 8) weight of each move by key ``direction * N + cell``: the turn factor times the cell's."""
    cw = np.asarray(cell_weights, dtype=float)
    if turn_weights is None:
        return np.tile(cw, (NO_DIRECTION + 1, 1))
    return (np.asarray(turn_weights, dtype=float)[:, None, :] * cw[None, :, :]).reshape(-1, 8)


def _colony_walk(keys: np.ndarray, steps: np.ndarray, length: np.ndarray, reached: np.ndarray, n: int,
                 start: int) -> ColonyWalk:
    """The tours (cells, turns) from the walk's key stacks (ant-major, ``steps + 1`` valid keys each)."""
    ants = steps.size
    used = int(steps.max()) + 1 if ants else 1
    keys = keys.reshape(ants, -1)[:, :used]
    keys[:, 0] = NO_DIRECTION * n + start                      # an ant stuck at the start overwrote it
    moved = np.arange(used)[None, :] <= steps[:, None]
    paths = np.where(moved, keys % n, -1)
    dirs = np.where(moved, keys // n, NO_DIRECTION)
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

