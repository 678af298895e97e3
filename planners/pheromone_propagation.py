"""Algorithms 1-2 of Hasan, Abdullah & Saleh (2023): the goal-to-start pheromone propagation of IMMAS.

The environment-analysis stage of :mod:`planners.improved_max_min_ant_system` (whose docstring gives the
equations, the MAX-MIN layering and the choices made): the D*-style propagation from the goal
with the clean weights, GateRaiseState and CheckTightTunnelState (Algorithm 2), and the trails'
MAX-MIN bounds (:mod:`planners.max_min_trails`).  The ``immas_stepwise`` navigator runs it too.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy import ndimage

from swarmnav.planners.errors import NoPathFound
from swarmnav.planners.grid_graph import DIRECTIONS, Cell
from swarmnav.planners.max_min_trails import P_BEST, TrailLimits, unit_limits

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
        limits: the MAX-MIN bounds of the trails (``None`` for ``propagation="route_cost"``).
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
    limits: TrailLimits | None = None


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


PROPAGATIONS = ("mmas", "route_cost")


def analyse_environment(occupied: np.ndarray, start: Cell, goal: Cell, rho: float = 0.98,
                        clean_weight: float = 0.5, diagonal_factor: float = 1.4,
                        close: bool = True, propagation: str = "mmas", evaporation_doubling: bool = False,
                        p_best: float = P_BEST, trace: list[tuple[Cell, float]] | None = None
                        ) -> EnvironmentAnalysis:
    """Algorithms 1-2: propagate pheromone from the goal, closing gates and tight tunnels
    (:func:`analyse_environment_reference`'s propagation, the same cells expanded in the same order with the
    same arithmetic, on flat lists: see :func:`_propagate`).

    Args:
        propagation: ``"mmas"`` (the MAX-MIN trails of the module docstring) or ``"route_cost"``
            (the trail is the route cost, ``tau(Y) = rho tau(X) + c``, unbounded).
        evaporation_doubling: §3.2's prose: the evaporation rate rho doubles with each expansion
            (``"mmas"`` only; Algorithm 1 and §4.2 keep rho = 0.98).
        trace: if given, every ``(cell, tau)`` written, in order (tests check the bounds after
            every update).

    Raises:
        NoPathFound: the start is unreachable from the goal even without closing.
    """
    if propagation not in PROPAGATIONS:
        raise ValueError(f"propagation must be one of {PROPAGATIONS}, got {propagation!r}")
    occ = np.asarray(occupied, dtype=bool)
    bounded = propagation == "mmas"
    limits = mmas_limits(occ, rho, diagonal_factor, p_best) if bounded else None
    arrays, gates, tunnels, expansions, reached = _propagate(occ, start, goal, rho, diagonal_factor, close, limits,
                                                             evaporation_doubling, trace)
    if not reached:
        if close:
            result = analyse_environment(occ, start, goal, rho, clean_weight, diagonal_factor, close=False,
                                         propagation=propagation, evaporation_doubling=evaporation_doubling,
                                         p_best=p_best, trace=trace)
            result.closing_reverted = True
            return result
        raise NoPathFound(f"goal cell {goal} is unreachable from start cell {start}")
    return _analysis_of(*arrays, clean_weight, bounded, gates, tunnels, expansions, limits)


def _propagate(occ: np.ndarray, start: Cell, goal: Cell, rho: float, diagonal_factor: float, close: bool,
               limits: TrailLimits | None, evaporation_doubling: bool, trace: list[tuple[Cell, float]] | None
               ) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], list[Cell], list[Cell], int, bool]:
    """The propagation loop of :func:`analyse_environment_reference` on flat lists with a one-cell border.

    Speed (profiled on BARN's 140 x 320 cells: ~0.5 s an analysis, 30 a run of ``immas_stepwise+barn``, in
    Python function calls per cell): a cell is one integer ``(r + 1) * (cols + 2) + c + 1``, so the heap's
    ``(k, index)`` pops in the reference's ``(k, r, c)`` order; the border is free for GateRaiseState and
    CheckTightTunnelState (the reference's ``occ`` is False outside the grid) and closed for the relaxation (it
    skips cells outside); the gate, tunnel and trail tests are written out in the loop.  The same cells are
    closed, expanded and relaxed in the same order with the same floating-point operations, so the arrays are
    the reference's bit for bit (``tests/test_ant_papers.py`` compares them).

    Returns:
        ((blocked, route cost k, tau, parent (rows, cols, 2)), gates, tunnels, expansions, whether the start
        was reached).
    """
    rows, cols = occ.shape
    width = cols + 2
    padded = np.zeros((rows + 2, width), dtype=bool)
    padded[1:-1, 1:-1] = occ
    blocked = padded.ravel().tolist()
    border = np.ones((rows + 2, width), dtype=bool)
    border[1:-1, 1:-1] = False
    closed = border.ravel().tolist()
    size = (rows + 2) * width
    bounded = limits is not None
    k = [INF] * size
    # MMAS: every trail starts at tau_max (§2 item 3); the goal's goal_pher = 0 (Algorithm 1 line 6), clamped.
    tau = [limits.tau_max if bounded else INF] * size
    parent = [-1] * size
    first = (start[0] + 1) * width + start[1] + 1
    last = (goal[0] + 1) * width + goal[1] + 1
    keep = {first, last}
    gates: list[int] = []
    tunnels: list[int] = []
    k[last] = 0.0
    tau[last] = limits.clamp_value(0.0) if bounded else 0.0
    if trace is not None:
        trace.append((goal, tau[last]))
    heap = [(0.0, last)]
    pop, push = heapq.heappop, heapq.heappush
    expansions = 0
    reached = False
    # (offset, step cost, and for a diagonal the offsets of the two cells it must not cut: 0 for a straight move)
    moves = [(dr * width + dc, diagonal_factor if dr and dc else 1.0, dc if dr and dc else 0,
              dr * width if dr and dc else 0) for dr, dc in DIRECTIONS]
    tau_min, tau_max = (limits.tau_min, limits.tau_max) if bounded else (0.0, 0.0)
    persistence = rho
    w = width
    # CheckTightTunnelState's neighbours in ORTHOGONAL order, each with the two cells flanking it
    tunnel_offsets = ((-w, -w - 1, -w + 1), (w, w - 1, w + 1), (-1, -w - 1, w - 1), (1, -w + 1, w + 1))
    while heap:
        kx, x = pop(heap)
        if closed[x] or blocked[x] or kx > k[x]:
            continue
        closed[x] = True
        if x == first:
            reached = True
            break
        if close and x not in keep and ((blocked[x + w + 1] and blocked[x - w - 1])
                                        or (blocked[x + w - 1] and blocked[x - w + 1])):   # is_gate
            blocked[x] = True
            gates.append(x)
            continue
        expansions += 1
        if close:  # _close_tight_tunnels
            for dy, da, db in tunnel_offsets:
                y = x + dy
                if not blocked[y] and y not in keep and not closed[y] and blocked[x + da] and blocked[x + db]:
                    blocked[y] = True
                    tunnels.append(y)
        tx = tau[x]
        for offset, cost, side, ahead in moves:  # _relax
            y = x + offset
            if blocked[y] or closed[y]:
                continue
            if side and (blocked[x + side] or blocked[x + ahead]):
                continue
            ky = kx + cost
            if ky < k[y]:
                k[y] = ky
                if bounded:
                    # Eq. (2) by the iteration-best ant X (unit deposit), then "multiply by 1.4 or 1"
                    # (§3.2), then the MMAS bounds (§2.1): TrailLimits.clamp_value's min(max(v, lo), hi) written
                    # out (each keeps v unless the bound lies strictly beyond it, as min and max do).
                    value = cost * (persistence * tx + 1.0)
                    if tau_min > value:
                        value = tau_min
                    if tau_max < value:
                        value = tau_max
                    tau[y] = value
                else:
                    tau[y] = rho * tx + cost
                if trace is not None:
                    trace.append(((y // w - 1, y % w - 1), tau[y]))
                parent[y] = x
                push(heap, (ky, y))
        if bounded and evaporation_doubling:
            persistence *= 2.0                                   # §3.2: "the evaporation rate doubles"

    def inner(values: list, dtype: type) -> np.ndarray:
        return np.ascontiguousarray(np.array(values, dtype=dtype).reshape(rows + 2, width)[1:-1, 1:-1])

    up = inner(parent, np.int64)
    parent_arr = np.where((up >= 0)[:, :, None], np.stack([up // w - 1, up % w - 1], axis=-1), -1)
    cells = [(x // w - 1, x % w - 1) for x in gates], [(x // w - 1, x % w - 1) for x in tunnels]
    return ((inner(blocked, bool), inner(k, float), inner(tau, float), parent_arr), cells[0], cells[1], expansions,
            reached)


def analyse_environment_reference(occupied: np.ndarray, start: Cell, goal: Cell, rho: float = 0.98,
                                  clean_weight: float = 0.5, diagonal_factor: float = 1.4,
                                  close: bool = True, propagation: str = "mmas", evaporation_doubling: bool = False,
                                  p_best: float = P_BEST, trace: list[tuple[Cell, float]] | None = None
                                  ) -> EnvironmentAnalysis:
    """Algorithms 1-2 as first written, one function call per test (the reference :func:`analyse_environment`
    is checked against).

    Args:
        propagation: ``"mmas"`` (the MAX-MIN trails of the module docstring) or ``"route_cost"``
            (the trail is the route cost, ``tau(Y) = rho tau(X) + c``, unbounded).
        evaporation_doubling: §3.2's prose: the evaporation rate rho doubles with each expansion
            (``"mmas"`` only; Algorithm 1 and §4.2 keep rho = 0.98).
        trace: if given, every ``(cell, tau)`` written, in order (tests check the bounds after
            every update).

    Raises:
        NoPathFound: the start is unreachable from the goal even without closing.
    """
    if propagation not in PROPAGATIONS:
        raise ValueError(f"propagation must be one of {PROPAGATIONS}, got {propagation!r}")
    occ = np.asarray(occupied, dtype=bool)
    rows, cols = occ.shape
    blocked = occ.tolist()
    bounded = propagation == "mmas"
    limits = mmas_limits(occ, rho, diagonal_factor, p_best) if bounded else None
    k = [[INF] * cols for _ in range(rows)]
    # MMAS: every trail starts at tau_max (§2 item 3); the goal's goal_pher = 0 (Algorithm 1 line 6), clamped.
    tau = [[limits.tau_max if bounded else INF] * cols for _ in range(rows)]
    parent = [[None] * cols for _ in range(rows)]
    closed_set = [[False] * cols for _ in range(rows)]
    keep = {start, goal}
    gates: list[Cell] = []
    tunnels: list[Cell] = []
    gr, gc = goal
    k[gr][gc] = 0.0
    tau[gr][gc] = limits.clamp_value(0.0) if bounded else 0.0
    if trace is not None:
        trace.append((goal, tau[gr][gc]))
    heap = [(0.0, gr, gc)]
    expansions = 0
    reached = False
    moves = [(dr, dc, diagonal_factor if dr and dc else 1.0) for dr, dc in DIRECTIONS]
    persistence = rho
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
            _close_tight_tunnels(blocked, closed_set, keep, r, c, tunnels)
        tx = tau[r][c]
        if bounded:
            # Eq. (2) by the iteration-best ant X (unit deposit), then "multiply by 1.4 or 1"
            # (§3.2), then the MMAS bounds (§2.1).
            def trail(cost: float, tx: float = tx, persistence: float = persistence) -> float:
                return limits.clamp_value(cost * (persistence * tx + 1.0))
        else:
            def trail(cost: float, tx: float = tx) -> float:
                return rho * tx + cost
        _relax(r, c, kx, trail, moves, blocked, closed_set, k, tau, parent, heap, trace)
        if bounded and evaporation_doubling:
            persistence *= 2.0                                   # §3.2: "the evaporation rate doubles"
    if not reached:
        if close:
            result = analyse_environment_reference(occ, start, goal, rho, clean_weight, diagonal_factor, close=False,
                                                   propagation=propagation, evaporation_doubling=evaporation_doubling,
                                                   p_best=p_best, trace=trace)
            result.closing_reverted = True
            return result
        raise NoPathFound(f"goal cell {goal} is unreachable from start cell {start}")
    return _analysis(blocked, k, tau, parent, clean_weight, bounded, gates, tunnels, expansions, limits)


def _close_tight_tunnels(blocked: list[list[bool]], closed_set: list[list[bool]], keep: set[Cell], r: int, c: int,
                         tunnels: list[Cell]) -> None:
    """CheckTightTunnelState (Algorithm 2) around the expanded cell X = (r, c): close each free, unexpanded
    horizontal or vertical neighbour that is a tight-tunnel entrance (never the start or the goal)."""
    rows, cols = len(blocked), len(blocked[0])
    for dr, dc in ORTHOGONAL:
        yr, yc = r + dr, c + dc
        if (0 <= yr < rows and 0 <= yc < cols and not blocked[yr][yc] and (yr, yc) not in keep
                and not closed_set[yr][yc] and is_tight_tunnel(blocked, r, c, dr, dc)):
            blocked[yr][yc] = True
            tunnels.append((yr, yc))


def _relax(r: int, c: int, kx: float, trail: Callable[[float], float], moves: list[tuple[int, int, float]],
           blocked: list[list[bool]], closed_set: list[list[bool]], k: list[list[float]], tau: list[list[float]],
           parent: list[list[Cell | None]], heap: list[tuple[float, int, int]],
           trace: list[tuple[Cell, float]] | None) -> None:
    """PheromoneTrails (Algorithm 1 line 17) from the expanded cell X = (r, c): each free neighbour Y that X
    reaches more cheaply (no corner cutting) gets the route cost ``k(X) + c``, the trail ``trail(c)`` and X as
    its parent, and joins the open list."""
    rows, cols = len(blocked), len(blocked[0])
    for dr, dc, cost in moves:
        yr, yc = r + dr, c + dc
        if not (0 <= yr < rows and 0 <= yc < cols) or blocked[yr][yc] or closed_set[yr][yc]:
            continue
        if dr and dc and (blocked[r][yc] or blocked[yr][c]):
            continue
        ky = kx + cost
        if ky < k[yr][yc]:
            k[yr][yc] = ky
            tau[yr][yc] = trail(cost)
            if trace is not None:
                trace.append(((yr, yc), tau[yr][yc]))
            parent[yr][yc] = (r, c)
            heapq.heappush(heap, (ky, yr, yc))


def _analysis(blocked: list[list[bool]], k: list[list[float]], tau: list[list[float]],
              parent: list[list[Cell | None]], clean_weight: float, bounded: bool, gates: list[Cell],
              tunnels: list[Cell], expansions: int, limits: TrailLimits | None) -> EnvironmentAnalysis:
    """The reference propagation's lists as arrays, then :func:`_analysis_of`."""
    blocked_arr = np.array(blocked, dtype=bool)
    rows, cols = blocked_arr.shape
    parent_arr = np.full((rows, cols, 2), -1, dtype=np.int64)
    for r in range(rows):
        for c in range(cols):
            if parent[r][c] is not None:
                parent_arr[r, c] = parent[r][c]
    return _analysis_of(blocked_arr, np.array(k), np.array(tau), parent_arr, clean_weight, bounded, gates, tunnels,
                        expansions, limits)


def _analysis_of(blocked_arr: np.ndarray, k_arr: np.ndarray, tau_arr: np.ndarray, parent_arr: np.ndarray,
                 clean_weight: float, bounded: bool, gates: list[Cell], tunnels: list[Cell], expansions: int,
                 limits: TrailLimits | None) -> EnvironmentAnalysis:
    """The propagation's arrays as an :class:`EnvironmentAnalysis`, with the clean weights (line 16)."""
    neighbours = ndimage.convolve(blocked_arr.astype(np.int64), np.array([[1, 1, 1], [1, 0, 1], [1, 1, 1]]),
                                  mode="constant", cval=0)
    if bounded:
        tau_arr[~np.isfinite(k_arr)] = INF   # never propagated: no trail (Algorithm 3 skips them)
    return EnvironmentAnalysis(blocked=blocked_arr, route_cost=k_arr, pheromone=tau_arr,
                               clean=clean_weight * neighbours * ~blocked_arr, parent=parent_arr,
                               gates=gates, tunnels=tunnels, expansions=expansions, limits=limits)


def mmas_limits(occupied: np.ndarray, rho: float, diagonal_factor: float, p_best: float = P_BEST) -> TrailLimits:
    """The propagation's ``[tau_min, tau_max]`` (Stützle & Hoos 2000 Eqs. 7 and 11, :mod:`planners.max_min_trails`).

    ``tau_max = 1 / (1 - rho)``: Eq. (7) for the unit deposit of Eq. (2) (the fixed point of
    ``tau <- rho tau + 1``; ``rho < 1``); ``n`` of Eq. (11) is the number of free cells (each a
    decision point of the tour) and ``avg`` half the eight moves, 4.  ``diagonal_factor`` does not
    enter: a diagonal step's ``c (rho tau + 1)`` above ``tau_max`` is clamped to it.
    """
    free = int(np.count_nonzero(~np.asarray(occupied, dtype=bool)))
    return unit_limits(rho, 1.0, max(free, 1), 4.0, p_best)
