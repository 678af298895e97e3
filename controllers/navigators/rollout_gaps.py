"""The gap from each rollout point to the nearest obstacle disc, in float32, equal bit for bit to the pairwise
loop over the discs (``sqrt(dx * dx + dy * dy) - clearance``, the smallest over the discs) but without its cost.

With the map unknown MPPI's near obstacles are the sensed map's blocked cells, hundreds of them (500 on average
on a BARN world, measured), and the loop computed every point against every one of them. Discs that do not move
over the horizon are grouped by clearance and searched with a k-d tree: each point keeps its few nearest centres,
their float32 gaps are computed exactly as the loop does, and a point whose nearest excluded centre could still
round below them (within the float32 arithmetic's error) is computed against the whole group instead. Moving
discs (a crowd's), and groups of fewer than ``TREE_FROM`` discs, keep the loop. Taking the smallest of the same float32 values in another order gives the same
value, and subtracting a group's one clearance is monotone, so the result is the loop's.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

NEAREST = 4                 # centres kept per point before the exactness check
TREE_FROM = 96              # fewer static discs of one clearance: the loop (the tree's own cost outweighs it)
_ROUNDING = 8.0 * 2.0**-24  # a float32 distance's relative error is below 4 units in the last place; twice that


def disc_gaps(px: np.ndarray, py: np.ndarray, cx: np.ndarray, cy: np.ndarray, clearance: np.ndarray) -> np.ndarray:
    """(K, T) float32 gap of each point (``px``, ``py``: (K, T) float32) to the nearest of N discs whose centres at
    each of the T steps are ``cx``, ``cy`` ((N, T) float32), less each disc's float32 ``clearance`` ((N,): its
    radius plus the inflation); N >= 1."""
    static = np.all(cx == cx[:, :1], axis=1) & np.all(cy == cy[:, :1], axis=1)
    looped = ~static
    gap = None
    for value in np.unique(clearance[static]):
        group = static & (clearance == value)
        if np.count_nonzero(group) < TREE_FROM:
            looped |= group
            continue
        index = np.flatnonzero(group)
        g = _static_gaps(px, py, cx[index, 0], cy[index, 0], value)
        gap = g if gap is None else np.minimum(gap, g, out=gap)
    for k in np.flatnonzero(looped):
        dx, dy = px - cx[k], py - cy[k]
        d = np.sqrt(dx * dx + dy * dy)
        d -= clearance[k]
        gap = d if gap is None else np.minimum(gap, d, out=gap)
    return gap


def _static_gaps(px: np.ndarray, py: np.ndarray, ox: np.ndarray, oy: np.ndarray, clearance: np.float32) -> np.ndarray:
    x, y = px.ravel(), py.ravel()
    tree = cKDTree(np.column_stack([ox, oy]).astype(np.float64))
    exact, index = tree.query(np.column_stack([x, y]).astype(np.float64), k=NEAREST)
    nearest = _nearest_distance(x, y, ox, oy, index)
    # a centre beyond the k nearest is at least exact[:, -1] away: its float32 distance cannot round below
    # ``nearest`` unless that bound comes within the rounding error of it; those points search the whole group
    unsure = np.flatnonzero(exact[:, -1] * (1.0 - _ROUNDING) <= nearest)
    if len(unsure):
        every = np.broadcast_to(np.arange(len(ox)), (len(unsure), len(ox)))
        nearest[unsure] = _nearest_distance(x[unsure], y[unsure], ox, oy, every)
    nearest -= clearance
    return nearest.reshape(px.shape)


def _nearest_distance(x: np.ndarray, y: np.ndarray, ox: np.ndarray, oy: np.ndarray, index: np.ndarray) -> np.ndarray:
    """Each point's smallest float32 distance to the centres ``index`` ((M, k)) names, computed as the loop does."""
    dx = x[:, None] - ox[index]
    dy = y[:, None] - oy[index]
    return np.sqrt(dx * dx + dy * dy).min(axis=1)


BOX_NEAREST = 16            # cells kept per rollout point by box_gaps before its exactness check


def box_gaps(px: np.ndarray, py: np.ndarray, heading: np.ndarray, box_m: np.ndarray, cx: np.ndarray,
             cy: np.ndarray, clearance: np.ndarray, within_m: float) -> np.ndarray:
    """(K, T) float32 gap of the chassis box ``box_m`` ((x_min, y_min, x_max, y_max) in the base frame) at each
    rollout point (``px``, ``py``) and ``heading`` ((K, T)) to the nearest of N discs (centres ``cx``, ``cy``
    (N, T) at each step, ``clearance`` (N,): radius plus margin): the box's own distance to a disc centre less
    the clearance, not its covering discs'.  Exact wherever it is below ``within_m``; elsewhere at least
    ``within_m`` (the repulsion band ends there, so the cost is the same).  Discs that stand still are searched
    with a k-d tree about the box's centre (a centre farther than the box's circumscribed radius + its clearance
    + ``within_m`` cannot come within ``within_m``), the moving ones one by one."""
    box_m = np.asarray(box_m, dtype=np.float64)
    half = 0.5 * (box_m[2:] - box_m[:2])
    mid = 0.5 * (box_m[:2] + box_m[2:])
    c, s = np.cos(heading).astype(np.float64), np.sin(heading).astype(np.float64)
    bx = px.astype(np.float64) + mid[0] * c - mid[1] * s                 # the box's centre at each point
    by = py.astype(np.float64) + mid[0] * s + mid[1] * c
    gap = np.full(px.shape, np.inf)
    static = np.all(cx == cx[:, :1], axis=1) & np.all(cy == cy[:, :1], axis=1)
    clearance = clearance.astype(np.float64)

    def edge(dx, dy, cc, ss):  # distance from the box to offsets (dx, dy) from its centre, in its frame
        lon, lat = np.abs(dx * cc + dy * ss), np.abs(-dx * ss + dy * cc)
        return np.hypot(np.maximum(lon - half[0], 0.0), np.maximum(lat - half[1], 0.0))

    index = np.flatnonzero(static)
    if len(index):
        ox, oy, oc = cx[index, 0].astype(np.float64), cy[index, 0].astype(np.float64), clearance[index]
        bound = float(np.hypot(*half) + oc.max() + within_m)
        tree = cKDTree(np.column_stack([ox, oy]))
        x, y, cc, ss = bx.ravel(), by.ravel(), c.ravel(), s.ravel()
        k = min(BOX_NEAREST, len(ox))
        dist, near = tree.query(np.column_stack([x, y]), k=k, distance_upper_bound=bound)
        dist, near = dist.reshape(len(x), k), near.reshape(len(x), k)
        found = near < len(ox)
        safe = np.where(found, near, 0)
        g = edge(ox[safe] - x[:, None], oy[safe] - y[:, None], cc[:, None], ss[:, None]) - oc[safe]
        flat = np.where(found, g, np.inf).min(axis=1)
        # a centre beyond the k nearest is at least dist[:, -1] from the box's centre: its gap is at least that
        # less the circumscribed radius and the largest clearance; points where that could be lower search all
        unsure = np.flatnonzero(np.isfinite(dist[:, -1])
                                & (dist[:, -1] - np.hypot(*half) - oc.max() < np.minimum(flat, within_m)))
        for i in unsure:
            every = np.array(tree.query_ball_point([x[i], y[i]], bound), dtype=int)
            flat[i] = (edge(ox[every] - x[i], oy[every] - y[i], cc[i], ss[i]) - oc[every]).min()
        gap = flat.reshape(px.shape)
    for n in np.flatnonzero(~static):
        g = edge(cx[n][None, :] - bx, cy[n][None, :] - by, c, s) - clearance[n]
        np.minimum(gap, g, out=gap)
    return np.minimum(gap, max(within_m, 0.0) + 1.0).astype(np.float32)
