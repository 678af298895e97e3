"""The small scenario the CLI and hostile-input tests edit: a 5 x 5 m arena, one disc in the middle."""

PROBE_SCENARIO = """
name = "probe"
seed = 0
time_limit_s = 30.0
arena = { width_m = 5.0, height_m = 5.0, walls = false }
robot = { radius_m = 0.15, max_speed_m_s = 0.2 }
start = { x = 0.5, y = 0.5, heading_deg = 45.0 }
goal = { x = 4.5, y = 4.5, tolerance_m = 0.1 }
sensors = { count = 12, range_m = 0.4 }
planner = { name = "astar", params = {} }

[[obstacles]]
x = 2.5
y = 2.5
radius_m = 0.5
"""
