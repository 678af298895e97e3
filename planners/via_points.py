"""Via-point path encodings shared by every continuous swarm planner.

A candidate path is ``k`` free via-points between the fixed start and goal
(Kamil et al. 2020, Sect. 3: "cubic polynomial connects the start point to the end point
through three via points").  The curve through the ``k + 2`` knots is sampled at
``samples`` points; the cost functions in :mod:`planners.path_cost` read those
samples.

Both encodings are *linear in the knots*: the samples are ``B @ knots`` for a
fixed basis matrix ``B`` of shape ``(samples, k + 2)``.  So ``B`` is built once
per planner run and a whole population is evaluated with one matrix product
instead of one spline fit per candidate.

* ``"spline"``: a not-a-knot cubic spline over the uniform parameter
  ``t_j = j / (k + 1)`` (the same curve as ``scipy.interpolate.CubicSpline(t,
  knots, bc_type="not-a-knot")``; with 3 knots it is the parabola through them,
  with 2 the segment).  Kamil et al. (2020) does not say how its "cubic polynomial" is
  parameterised; a uniform parameter is the simplest choice that is linear in
  the knots.
* ``"polyline"``: straight segments start -> via-points -> goal, sampled
  uniformly in the same parameter (``samples`` points in total).  The exact path
  is the polyline through the knots themselves.

A population is stored as an array ``(P, 2 k)``: the ``x`` coordinates of the
via-points first, then the ``y`` coordinates, so that each of the ``2 k``
decision variables is one coordinate (ABC's Eq. (7) moves one of them).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

ENCODINGS = ("spline", "polyline")


def uniform_knot_parameters(knot_count: int) -> np.ndarray:
    """The uniform parameter values ``0, 1/(n-1), ..., 1`` of ``knot_count`` knots."""
    return np.linspace(0.0, 1.0, knot_count)


def not_a_knot_basis(knot_count: int, parameters: np.ndarray) -> np.ndarray:
    """Basis matrix of the not-a-knot cubic spline over uniform knots.

    Row ``s`` holds the weights of each knot value in the spline's value at
    ``parameters[s]``: for knot values ``y`` (shape ``(knot_count,)``) the spline
    at the parameters is ``basis @ y``.

    The second derivatives ``M`` at the knots solve, for spacing ``h``,
    ``M[i-1] + 4 M[i] + M[i+1] = 6 (y[i-1] - 2 y[i] + y[i+1]) / h**2`` at the
    interior knots, and the not-a-knot conditions (third derivative continuous at
    the second and the second-to-last knot) ``M[0] - 2 M[1] + M[2] = 0`` and
    ``M[n-3] - 2 M[n-2] + M[n-1] = 0``.  On piece ``i`` with local coordinate
    ``u`` in [0, 1] the spline is
    ``(1-u) y[i] + u y[i+1] + h**2/6 [((1-u)**3 - (1-u)) M[i] + (u**3 - u) M[i+1]]``.

    Args:
        knot_count: number of knots, at least 2.
        parameters: (S,) parameter values in [0, 1].

    Returns:
        (S, knot_count) basis matrix.
    """
    n = int(knot_count)
    if n < 2:
        raise ValueError("a spline needs at least two knots")
    t = np.asarray(parameters, dtype=float).reshape(-1)
    knots = uniform_knot_parameters(n)
    if n == 2:
        return np.column_stack([1.0 - t, t])
    if n == 3:
        # Not-a-knot with three knots is the single parabola through them (Lagrange form).
        basis = np.empty((t.size, 3))
        for j in range(3):
            others = [knots[m] for m in range(3) if m != j]
            basis[:, j] = ((t - others[0]) * (t - others[1])
                           / ((knots[j] - others[0]) * (knots[j] - others[1])))
        return basis
    h = 1.0 / (n - 1)
    # Linear system A M = R y, solved for every unit vector y at once.
    a = np.zeros((n, n))
    r = np.zeros((n, n))
    a[0, :3] = (1.0, -2.0, 1.0)
    a[-1, -3:] = (1.0, -2.0, 1.0)
    for i in range(1, n - 1):
        a[i, i - 1:i + 2] = (1.0, 4.0, 1.0)
        r[i, i - 1:i + 2] = np.array([1.0, -2.0, 1.0]) * 6.0 / h ** 2
    second = np.linalg.solve(a, r)  # (n, n): second derivatives per unit knot value
    # The cubic is the piecewise-linear interpolant plus the curvature terms.
    basis = polyline_basis(n, t)
    piece = np.clip(np.floor(t / h).astype(int), 0, n - 2)
    u = t / h - piece
    w_left = h ** 2 / 6.0 * ((1.0 - u) ** 3 - (1.0 - u))
    w_right = h ** 2 / 6.0 * (u ** 3 - u)
    basis += w_left[:, None] * second[piece] + w_right[:, None] * second[piece + 1]
    return basis


def polyline_basis(knot_count: int, parameters: np.ndarray) -> np.ndarray:
    """Basis matrix of piecewise-linear interpolation over uniform knots (see :func:`not_a_knot_basis`)."""
    n = int(knot_count)
    t = np.asarray(parameters, dtype=float).reshape(-1)
    h = 1.0 / (n - 1)
    piece = np.clip(np.floor(t / h).astype(int), 0, n - 2)
    u = t / h - piece
    basis = np.zeros((t.size, n))
    rows = np.arange(t.size)
    basis[rows, piece] += 1.0 - u
    basis[rows, piece + 1] += u
    return basis


def make_basis(encoding: str, knot_count: int, parameters: np.ndarray) -> np.ndarray:
    """Basis matrix of an encoding (``"spline"`` or ``"polyline"``)."""
    if encoding == "spline":
        return not_a_knot_basis(knot_count, parameters)
    if encoding == "polyline":
        return polyline_basis(knot_count, parameters)
    raise ValueError(f"unknown encoding {encoding!r} (known: {', '.join(ENCODINGS)})")


@dataclass(frozen=True, eq=False)
class ViaPointCurve:
    """Maps populations of via-points to sampled curves through start and goal.

    Attributes:
        encoding: ``"spline"`` or ``"polyline"``.
        via_point_count: ``k``, the number of free via-points.
        start_m, goal_m: (2,) fixed end points.
        samples: number of curve samples the costs see (Kamil et al. 2020's ``np``).
    """

    encoding: str
    via_point_count: int
    start_m: np.ndarray
    goal_m: np.ndarray
    samples: int = 100
    _via_basis: np.ndarray = field(init=False, repr=False)
    _end_offset: np.ndarray = field(init=False, repr=False)
    _block_basis: np.ndarray = field(init=False, repr=False)
    _end_column: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if self.via_point_count < 1:
            raise ValueError("via_point_count must be at least 1")
        if self.samples < 2:
            raise ValueError("samples must be at least 2")
        basis = make_basis(self.encoding, self.via_point_count + 2,
                           np.linspace(0.0, 1.0, self.samples))
        start = np.asarray(self.start_m, dtype=float).reshape(2)
        goal = np.asarray(self.goal_m, dtype=float).reshape(2)
        object.__setattr__(self, "start_m", start)
        object.__setattr__(self, "goal_m", goal)
        object.__setattr__(self, "_via_basis", np.ascontiguousarray(basis[:, 1:-1].T))  # (k, S)
        # Contribution of the fixed end points: (2, S), x row then y row.
        end_offset = np.outer(start, basis[:, 0]) + np.outer(goal, basis[:, -1])
        object.__setattr__(self, "_end_offset", end_offset)
        k, samples = self.via_point_count, self.samples
        block_basis = np.zeros((2 * samples, 2 * k))
        block_basis[:samples, :k] = basis[:, 1:-1]
        block_basis[samples:, k:] = basis[:, 1:-1]
        object.__setattr__(self, "_block_basis", block_basis)                  # (2S, 2k)
        object.__setattr__(self, "_end_column", end_offset.reshape(2 * samples, 1))

    @property
    def dimensions(self) -> int:
        """Number of decision variables, ``2 k``."""
        return 2 * self.via_point_count

    def via_points(self, solution: np.ndarray) -> np.ndarray:
        """(k, 2) via-points of one decision vector."""
        k = self.via_point_count
        flat = np.asarray(solution, dtype=float).reshape(2 * k)
        return np.column_stack([flat[:k], flat[k:]])

    def knots(self, solution: np.ndarray) -> np.ndarray:
        """(k + 2, 2) knots start, via-points..., goal of one decision vector."""
        return np.vstack([self.start_m, self.via_points(solution), self.goal_m])

    def sample(self, population: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Sample every candidate's curve with one matrix product per axis.

        Args:
            population: (P, 2 k) decision vectors.

        Returns:
            ``(xs, ys)``, each (P, samples).
        """
        pop = np.asarray(population, dtype=float).reshape(-1, self.dimensions)
        k = self.via_point_count
        xs = pop[:, :k] @ self._via_basis + self._end_offset[0]
        ys = pop[:, k:] @ self._via_basis + self._end_offset[1]
        return xs, ys

    def sample_columns(self, population: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`sample` stored sample-major: ``(xt, yt)``, each (samples, P), one column per
        candidate (the two halves of :meth:`sample_block`)."""
        block = self.sample_block(population)
        return block[0], block[1]

    def sample_block(self, population: np.ndarray) -> np.ndarray:
        """Every candidate's samples as one contiguous (2, samples, P) array: ``[0]`` the x,
        ``[1]`` the y coordinates, one column per candidate (the layout the fast costs in
        :mod:`planners.path_cost` reduce along: samples are rows).

        One matrix product for both axes, with the block-diagonal basis
        ``[[B, 0], [0, B]]`` (2 S, 2 k) times the population's transpose (2 k, P) (one
        BLAS call instead of two), plus the fixed end points' share."""
        pop = np.asarray(population, dtype=float).reshape(-1, self.dimensions)
        block = self._block_basis @ pop.T
        block += self._end_column
        return block.reshape(2, self.samples, pop.shape[0])

    def dense_waypoints(self, solution: np.ndarray, samples: int) -> np.ndarray:
        """(N, 2) waypoints of one candidate for output and the exact check.

        For ``"polyline"`` these are the knots themselves (the exact path);
        for ``"spline"`` the spline sampled at ``samples`` uniform parameters.
        """
        knots = self.knots(solution)
        if self.encoding == "polyline":
            return knots
        basis = make_basis(self.encoding, knots.shape[0], np.linspace(0.0, 1.0, int(samples)))
        return basis @ knots
