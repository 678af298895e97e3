"""``swarmnav plot LOG -o out.png``: a run at a glance, from its log only.

Top panel: the arena, the obstacles (moving ones as their tracks coloured by
simulation time, with a few footprints along them), every planned path (the last
one solid, earlier plans of a replanning run dashed), the driven trajectory
coloured by time with a dot every few seconds, where collisions began and where
range beams hit something; one colour bar gives the time of both tracks, and a
legend names everything.  The title (scenario, planner, navigator, seeds, outcome)
is the figure's own, wrapped, so it is never clipped.  Colours: :mod:`sim.palette`.  Bottom panel: commanded and measured wheel
speeds over simulated time.  Matplotlib with the Agg backend, so it runs on
servers without a display.
"""

from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.sim import palette
from swarmnav.sim.defaults import MAX_DPI, MIN_DPI
from swarmnav.log.reader import RunLog, outcome_text, read_log, truncation_advice

MAX_SCANS = 400
MAX_TRACK_POINTS = 4000  # a track is decimated to this many points, about the figure's resolution
MOVING_OUTLINES = 6      # footprints outlined along each moving obstacle's track
TITLE_CHARS = 80         # a title line wraps at this width: at 11 pt it fits the 8-inch figure
TIME_PROXY = "#21918c"   # the legend's stand-in for a time-coloured line (the colormap's middle)
# The figure is 8 x 10.5 inches: MAX_DPI (sim.defaults) is 4800 x 6300 pixels.
# Formats Matplotlib writes on its own without a warning (pgf needs TeX; avif and webp depend on
# Pillow's build; eps and ps warn that they drop transparency).
SELF_CONTAINED_FORMATS = {"png", "jpg", "jpeg", "tif", "tiff", "svg", "svgz", "pdf"}


def range_hits_m(log: RunLog, max_scans: int = MAX_SCANS) -> np.ndarray:
    """World (x, y) of every beam hit, from at most ``max_scans`` evenly spread scans."""
    if len(log.scan_time_s) == 0 or len(log.time_s) == 0:
        return np.zeros((0, 2))
    pick = np.unique(np.linspace(0, len(log.scan_time_s) - 1, min(max_scans, len(log.scan_time_s))).astype(int))
    pose_index = np.clip(np.searchsorted(log.time_s, log.scan_time_s[pick]), 0, len(log.time_s) - 1)
    ranges = log.range_m[pick]                                        # (S, K) from base origin
    bearing = log.heading_rad[pose_index][:, None] + log.scan_angles_rad[None, :]
    x = log.position_m[pose_index, 0][:, None] + ranges * np.cos(bearing)
    y = log.position_m[pose_index, 1][:, None] + ranges * np.sin(bearing)
    hit = np.isfinite(ranges)
    return np.column_stack([x[hit], y[hit]])


def collision_points_m(log: RunLog) -> np.ndarray:
    """Robot (x, y) at every ``collision_begin`` event."""
    times = [t for t, kind, _ in log.events if kind == "collision_begin"]
    if not times or len(log.time_s) == 0:
        return np.zeros((0, 2))
    index = np.clip(np.searchsorted(log.time_s, times), 0, len(log.time_s) - 1)
    return log.position_m[index, :2]


def _time_line(ax, xy: np.ndarray, times_s: np.ndarray, norm, cmap, **style):
    """A polyline whose segments take the colour of their start time."""
    from matplotlib.collections import LineCollection

    if len(xy) < 2:
        return None
    segments = np.stack([xy[:-1], xy[1:]], axis=1)
    lines = LineCollection(segments, cmap=cmap, norm=norm, **style)
    lines.set_array(times_s[:-1])
    ax.add_collection(lines)
    return lines


def decimated(count: int, limit: int = MAX_TRACK_POINTS) -> np.ndarray:
    """Indices of at most ``limit`` evenly spread samples of ``count`` (first and last kept)."""
    if count <= limit:
        return np.arange(count)
    return np.unique(np.linspace(0, count - 1, limit).astype(int))


def _draw_obstacles(ax, log: RunLog, norm, cmap) -> None:
    """Static obstacles filled; each moving one as its track coloured by time, with its
    footprint outlined at a few times (coloured alike) and filled where it ended."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle, Rectangle

    static, outlines, outline_times = [], [], []
    for ob in log.obstacles:
        x, y = ob["position_m"][0], ob["position_m"][1]
        if ob["shape"] == "box":
            hx, hy = ob["size_m"][0], ob["size_m"][1]
            static.append(Rectangle((x - hx, y - hy), 2 * hx, 2 * hy))
            continue
        radius = ob["size_m"][0]
        track = log.obstacle_tracks.get(ob["entity_id"])
        if ob["moving"] and track is not None and len(track[0]) > 1:
            times, xy = track
            pick = decimated(len(times))
            _time_line(ax, xy[pick], times[pick], norm, cmap, lw=2.0, alpha=0.9, zorder=2)
            for k in np.unique(np.linspace(0, len(xy) - 1, MOVING_OUTLINES).astype(int)):
                outlines.append(Circle(tuple(xy[k]), radius))
                outline_times.append(times[k])
            ax.add_patch(Circle(tuple(xy[-1]), radius, fc=palette.MOVING_OBSTACLE, ec=cmap(norm(times[-1])),
                                lw=1.5, alpha=0.9, zorder=2))
        else:
            static.append(Circle((x, y), radius))
    ax.add_collection(PatchCollection(static, fc=palette.OBSTACLE, ec="black", lw=0.5, alpha=0.9, zorder=2))
    if outlines:
        rings = PatchCollection(outlines, fc="none", lw=0.8, alpha=0.6, cmap=cmap, norm=norm, zorder=2)
        rings.set_array(np.asarray(outline_times))
        rings.set_facecolor("none")
        ax.add_collection(rings)


def _legend_handles(log: RunLog, collisions: int):
    """Legend entries for what the map shows (proxies for the time-coloured collections)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [Patch(fc=palette.OBSTACLE, ec="black", lw=0.5, label="static obstacle")]
    if any(ob["moving"] for ob in log.obstacles):
        handles.append(Line2D([], [], color=TIME_PROXY, lw=2.0,
                              label="moving obstacle: track (time colour), outlines, end"))
    if len(log.paths) > 1:
        handles.append(Line2D([], [], color=palette.REPLANNED, lw=1.0, ls="--",
                              label=f"earlier plans ({len(log.paths) - 1} replans)"))
    if log.paths:
        handles.append(Line2D([], [], color=palette.PLANNED, lw=1.6, marker=".",
                              label="planned path" + (" (last)" if len(log.paths) > 1 else "")))
    if len(log.time_s):
        handles.append(Line2D([], [], color=TIME_PROXY, lw=3.0, label="driven trajectory (time colour)"))
        handles.append(Line2D([], [], color=palette.DRIVEN, marker="o", ls="none", ms=4,
                              label=f"robot every {_mark_step_s(log.duration_s):g} s"))
        handles.append(Line2D([], [], color=palette.START, marker="o", ls="none", ms=7, mec="black",
                              label="start"))
    if log.paths:
        handles.append(Line2D([], [], color=palette.GOAL, marker="*", ls="none", ms=12, mec="black", label="goal"))
    if collisions:
        handles.append(Line2D([], [], color=palette.COLLISION, marker="x", ls="none", ms=9, mew=2.5,
                              label=f"collision begins ({collisions})"))
    handles.append(Line2D([], [], color=palette.COLLISION, marker=".", ls="none", ms=4, alpha=0.5,
                          label="range hits"))
    return handles


def _mark_step_s(duration_s: float) -> float:
    """A round time step giving about 10 time marks over the run."""
    for step in (0.5, 1, 2, 5, 10, 20, 30, 60, 120, 300, 600, 1800, 3600):
        if duration_s / step <= 12:
            return float(step)
    return float(3600 * max(1, round(duration_s / 3600 / 12)))


def figure_title(log: RunLog, width_chars: int = TITLE_CHARS) -> str:
    """The figure's title, wrapped to lines of at most ``width_chars`` so it is never clipped."""
    planner = log.metadata.get("planner", {}).get("name", "?")
    navigator = log.metadata.get("navigator", {}).get("name", "follow")
    run = log.metadata.get("run", {})
    seed, world_seed = run.get("seed", "?"), run.get("world_seed", run.get("seed", "?"))
    truncated = " (truncated log)" if not log.complete else ""
    lines = [f"{log.scenario_name}: {planner} + {navigator}, seed {seed}, world seed {world_seed}",
             f"{outcome_text(log)}, {log.duration_s:.1f} s simulated{truncated}"]
    return "\n".join(textwrap.fill(line, width_chars) for line in lines)


def _pyplot():
    # Imported here so that the CLI starts without loading matplotlib.
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def image_format(out: str | Path, dpi: int) -> str:
    """The image format of ``out`` (its extension), checked together with ``dpi``.

    Raises:
        ConfigError: no extension, one Matplotlib cannot write, a directory, or a
            resolution outside MIN_DPI..MAX_DPI.
    """
    out = Path(out)
    if not MIN_DPI <= dpi <= MAX_DPI:
        raise ConfigError("--dpi", f"must be in {MIN_DPI}..{MAX_DPI} dots per inch, got {dpi}")
    if out.is_dir():
        raise ConfigError("-o", "is a directory; give an image file name such as run.png", str(out))
    _pyplot()
    from matplotlib.backend_bases import FigureCanvasBase

    formats = set(FigureCanvasBase.get_supported_filetypes()) & SELF_CONTAINED_FORMATS
    suffix = out.suffix.lower().lstrip(".")
    if suffix not in formats:
        known = ", ".join(f".{k}" for k in sorted(formats))
        what = f"unknown image format '.{suffix}'" if suffix else "has no extension to name the image format"
        raise ConfigError("-o", f"{what} (one of {known})", str(out))
    return suffix


def plot_run(log: RunLog, out: str | Path, dpi: int = 120) -> Path:
    """Draw the two panels of a run into exactly ``out`` (PNG, SVG, PDF, ... by extension).

    Raises:
        ConfigError: see :func:`image_format`.
        OSError: the file cannot be written (with its name).
    """
    image = image_format(out, dpi)
    plt = _pyplot()
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.patches import Rectangle

    fig, (ax, ax_wheels) = plt.subplots(
        2, 1, figsize=(8, 10.5), gridspec_kw={"height_ratios": [3, 1.1]}, layout="constrained"
    )
    width_m, height_m = log.run_value("arena_size_m", [10.0, 10.0])
    ax.add_patch(Rectangle((0, 0), width_m, height_m, fill=False, ec=palette.ARENA, lw=1.0))
    cmap = plt.get_cmap(palette.TIME_COLORMAP)
    norm = Normalize(0.0, max(log.duration_s, 1e-9))
    _draw_obstacles(ax, log, norm, cmap)

    driven = _draw_run(ax, log, norm, cmap)
    collisions = collision_points_m(log)
    if len(collisions):
        ax.plot(collisions[:, 0], collisions[:, 1], "x", color=palette.COLLISION, ms=10, mew=2.5, zorder=7)
    margin = 0.3
    ax.set_xlim(-margin, width_m + margin)
    ax.set_ylim(-margin, height_m + margin)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    fig.suptitle(figure_title(log), fontsize=11)
    # Below the map, outside it: the legend never hides an obstacle or the trajectory.
    ax.legend(handles=_legend_handles(log, len(collisions)), loc="upper center", bbox_to_anchor=(0.5, -0.07),
              ncol=3, fontsize=7, frameon=False)
    moving = any(ob["moving"] for ob in log.obstacles)
    if driven is not None or moving:
        colourbar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.8, pad=0.02)
        what = ", ".join(w for w, shown in (("trajectory", driven is not None), ("moving obstacles", moving)) if shown)
        colourbar.set_label(f"simulation time [s] ({what})")

    _draw_wheels(ax_wheels, log)

    out = Path(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        with open(out, "wb") as stream:  # exactly this path: no extension added, no rename
            fig.savefig(stream, format=image, dpi=dpi)
    except OSError as error:
        raise type(error)(error.errno, error.strerror, str(out)) from None
    finally:
        plt.close(fig)
    return out


def _draw_run(ax, log: RunLog, norm, cmap):
    """The range hits, every planned path, the driven trajectory (coloured by time, with time marks), the
    start and the goal; returns the trajectory's time-coloured line (None for a log without poses)."""
    hits = range_hits_m(log)
    if len(hits):
        ax.scatter(hits[:, 0], hits[:, 1], s=2, c=palette.COLLISION, alpha=0.35, zorder=3)
    for k, (_, path) in enumerate(log.paths):
        last = k == len(log.paths) - 1
        ax.plot(path[:, 0], path[:, 1], color=palette.PLANNED if last else palette.REPLANNED,
                lw=1.6 if last else 1.0, ls="-" if last else "--", marker="." if last else None, ms=4, zorder=4)
    driven = None
    if len(log.time_s):
        pick = decimated(len(log.time_s))
        xy, times = log.position_m[pick, :2], log.time_s[pick]
        ax.plot(xy[:, 0], xy[:, 1], color=palette.DRIVEN, lw=3.4, zorder=5, solid_capstyle="round")
        driven = _time_line(ax, xy, times, norm, cmap, lw=2.2, zorder=5, capstyle="round")
        step_s = _mark_step_s(log.duration_s)
        marks = np.searchsorted(log.time_s, np.arange(step_s, log.time_s[-1] + 1e-9, step_s))
        marks = marks[marks < len(log.time_s)]
        ax.plot(log.position_m[marks, 0], log.position_m[marks, 1], "o", color=palette.DRIVEN, ms=3.5, zorder=6)
        for index in marks[1::2] if len(marks) > 6 else marks:
            ax.annotate(f"{log.time_s[index]:g} s", log.position_m[index, :2], xytext=(4, 4),
                        textcoords="offset points", fontsize=7, color=palette.DRIVEN, zorder=7)
        ax.plot(*log.position_m[0, :2], "o", color=palette.START, ms=7, mec="black", zorder=6)
    if log.paths:
        goal = log.paths[-1][1][-1]
        ax.plot(goal[0], goal[1], "*", color=palette.GOAL, ms=14, mec="black", zorder=6)
    return driven


def _draw_wheels(ax_wheels, log: RunLog) -> None:
    """The bottom panel: commanded and measured wheel speeds over simulated time, collisions marked."""
    t = log.wheel_time_s
    for column, side, colour in ((0, "left", palette.PLANNERS[0]), (1, "right", palette.PLANNERS[1])):
        ax_wheels.plot(t, log.wheel_command_rad_s[:, column], color=colour, ls="--", lw=0.9,
                       label=f"{side} commanded")
        ax_wheels.plot(t, log.wheel_measured_rad_s[:, column], color=colour, lw=1.1,
                       label=f"{side} measured")
    for time_s, kind, _ in log.events:
        if kind == "collision_begin":
            ax_wheels.axvline(time_s, color=palette.COLLISION, lw=0.6, alpha=0.6)
    ax_wheels.set_xlabel("simulation time [s]")
    ax_wheels.set_ylabel("wheel speed [rad/s]")
    ax_wheels.grid(alpha=0.3)
    if len(t):
        ax_wheels.legend(loc="upper right", fontsize=8, ncol=2)


def run(args: argparse.Namespace) -> int:
    """Plot a log; a truncated log is plotted as far as it goes, with a warning."""
    image_format(args.out, args.dpi)  # before the work: a bad -o or --dpi is exit 2 at once
    log = read_log(args.log, allow_truncated=True)
    if not log.complete:
        print(f"warning: {args.log}: {truncation_advice(log.raw)}", file=sys.stderr)
    out = plot_run(log, args.out, dpi=args.dpi)
    print(out)
    return 0
