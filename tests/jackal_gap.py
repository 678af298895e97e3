"""A Jackal under BARN's protocol (its laser, the map unknown) before a row of BARN's cylinders (radius 0.075 m):
the scenario text the footprint, box-navigator and paper-navigator BARN tests drive through."""

from __future__ import annotations

from typing import Iterable


def jackal_gap(name: str, time_limit_s: float, cylinder_xs_m: Iterable[float]) -> str:
    """Scenario text: a 5 x 8 m arena, start (2.5, 1.5) facing +y, goal (2.5, 6.5) within 0.5 m, and a cylinder at
    each x of ``cylinder_xs_m`` on the line y = 4 (0.15 m apart, a gap where one is left out)."""
    return f"""
name = "{name}"
time_limit_s = {time_limit_s}
arena = {{ width_m = 5.0, height_m = 8.0, walls = false }}
start = {{ x = 2.5, y = 1.5, heading_deg = 90.0 }}
goal = {{ x = 2.5, y = 6.5, tolerance_m = 0.5 }}
robot = {{ model = "jackal" }}
sensors = {{ model = "rangefinder", count = 270, fov_deg = 270.0, range_m = 10.0 }}
knowledge = {{ map = "unknown" }}
sim = {{ stop_on_collision = true }}
""" + "".join(f"[[obstacles]]\nx = {x:.3f}\ny = 4.0\nradius_m = 0.075\n" for x in cylinder_xs_m)
