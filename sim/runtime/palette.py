"""One palette for every figure and frame swarmnav draws: the report, ``plot`` and the video.

Colours are hex strings (Matplotlib takes them as they are); :func:`rgba` turns one into the 0..1 floats
MuJoCo's ``rgba`` attributes and the video's overlays take.  Planners take the Okabe & Ito (2008)
colour-blind-safe set in the order a figure lists them (then Matplotlib's tab20); navigators a line style
each; moving obstacles' tracks the ``TIME_COLORMAP`` over simulated time.
"""

from __future__ import annotations

OBSTACLE = "#7a7f87"           # static obstacles (discs, boxes, map cells)
MOVING_OBSTACLE = "#b0b5bc"    # a moving obstacle's footprint at t = 0
TIME_COLORMAP = "viridis"      # moving obstacles' tracks, a trajectory's time
ARENA = "#30343a"              # the arena's outline
FLOOR = "#f4f4f2"
START = "#009e73"
GOAL = "#d55e00"
PLANNED = "#0072b2"            # the plan (the last one, when replanned)
REPLANNED = "#56b4e9"          # earlier plans of a replanning run
DRIVEN = "#1b1b1b"             # the trajectory the robot drove
COLLISION = "#cc0000"          # where a collision began
ROBOT = "#e69f00"

# Okabe & Ito (2008), "Color Universal Design", without black (the driven trajectory's colour).
PLANNERS = ("#0072b2", "#e69f00", "#009e73", "#cc79a7", "#56b4e9", "#d55e00", "#f0e442", "#999999")
_MORE = ("#1f77b4", "#aec7e8", "#ff7f0e", "#ffbb78", "#2ca02c", "#98df8a", "#d62728", "#ff9896", "#9467bd",
         "#c5b0d5", "#8c564b", "#c49c94", "#e377c2", "#f7b6d2", "#7f7f7f", "#c7c7c7", "#bcbd22", "#dbdb8d",
         "#17becf", "#9edae5")  # Matplotlib's tab20, after the first eight
NAVIGATOR_STYLES = {"follow": "-", "replan": "--", "dstar_replan": "-.", "immas": ":", "iaco": (0, (5, 1, 1, 1))}
_MORE_STYLES = ((0, (3, 1, 1, 1, 1, 1)), (0, (1, 1)), (0, (5, 5)))


def planner_colour(index: int) -> str:
    """The colour of the ``index``-th planner (or arm) of a figure."""
    if index < len(PLANNERS):
        return PLANNERS[index]
    return _MORE[(index - len(PLANNERS)) % len(_MORE)]


def navigator_style(name: str | None):
    """A Matplotlib line style for a navigator's name (its base name, before any sweep)."""
    base = (name or "follow").split("(", 1)[0]
    if base in NAVIGATOR_STYLES:
        return NAVIGATOR_STYLES[base]
    return _MORE_STYLES[sum(map(ord, base)) % len(_MORE_STYLES)]


def rgba(colour: str, alpha: float = 1.0) -> tuple[float, float, float, float]:
    """``"#rrggbb"`` as (r, g, b, a) floats in 0..1."""
    text = colour.lstrip("#")
    if len(text) != 6:
        raise ValueError(f"expected a colour as #rrggbb, got {colour!r}")
    return (int(text[0:2], 16) / 255.0, int(text[2:4], 16) / 255.0, int(text[4:6], 16) / 255.0, float(alpha))
