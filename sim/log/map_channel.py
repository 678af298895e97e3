"""``/map``: the sensed occupancy grid as a ``foxglove.Grid`` (optional: only runs with the map unknown).

One ``int8`` field ``occupancy`` per cell, as ROS' ``nav_msgs/OccupancyGrid`` holds it: the occupancy
probability in percent (0..100), -1 where the laser never saw; rows grow with y, columns with x, the
grid's corner at the arena's origin in the ``world`` frame.  Written at a low rate by the runner
(``sim.simulation.MAP_LOG_PERIOD_S``).
"""

from __future__ import annotations

import foxglove
import numpy as np
from foxglove.channels import GridChannel
from foxglove.messages import Grid, PackedElementField, PackedElementFieldNumericType, Pose, Quaternion, Vector2, \
    Vector3

from swarmnav.log.format import MAP_TOPIC, WORLD_FRAME
from swarmnav.log.messages import stamp


def occupancy_percent(log_odds: np.ndarray) -> np.ndarray:
    """(rows, cols) int8: occupancy probability in percent, -1 for never-seen cells (log odds exactly 0)."""
    lo = np.asarray(log_odds, dtype=float)
    percent = np.rint(100.0 * (1.0 - 1.0 / (1.0 + np.exp(lo)))).astype(np.int8)
    percent[lo == 0.0] = -1
    return percent


class MapChannel:
    """Made at the first grid, on the writer's Foxglove context."""

    def __init__(self, context: foxglove.Context):
        self._channel = GridChannel(MAP_TOPIC, context=context)

    def log(self, t_ns: int, grid) -> None:
        """Log a :class:`models.occupancy.LogOddsGrid` at ``t_ns``."""
        cells = occupancy_percent(grid.log_odds)
        rows, cols = cells.shape
        x0, y0 = grid.origin_m
        message = Grid(timestamp=stamp(t_ns), frame_id=WORLD_FRAME,
                       pose=Pose(position=Vector3(x=float(x0), y=float(y0), z=0.002),
                                 orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)),
                       column_count=cols, cell_size=Vector2(x=grid.cell_m, y=grid.cell_m),
                       row_stride=cols, cell_stride=1,
                       fields=[PackedElementField(name="occupancy", offset=0,
                                                  type=PackedElementFieldNumericType.Int8)],
                       data=cells.tobytes())
        self._channel.log(message, log_time=t_ns)
