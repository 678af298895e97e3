"""``swarmnav plot LOG -o out.png``: a run at a glance, from its log only.

Top panel: the arena, the obstacles (moving ones as the band they swept), every
planned path (the last one solid), the driven trajectory, where collisions began
and where range beams hit something.  Bottom panel: commanded and measured wheel
speeds over simulated time.  Matplotlib with the Agg backend, so it runs on
servers without a display.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from swarmnav.models.errors import ConfigError
from swarmnav.sim.commands import MAX_DPI, MIN_DPI
from swarmnav.sim.log_reader import RunLog, outcome_text, read_log, truncation_advice

MAX_SWEEP_DISCS = 40
MAX_SCANS = 400
# The figure is 8 x 10.5 inches: MAX_DPI (sim.commands) is 4800 x 6300 pixels.
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


def _draw_obstacles(ax, log: RunLog) -> None:
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle, Rectangle

    static, swept = [], []
    for ob in log.obstacles:
        x, y = ob["position_m"][0], ob["position_m"][1]
        if ob["shape"] == "box":
            hx, hy = ob["size_m"][0], ob["size_m"][1]
            static.append(Rectangle((x - hx, y - hy), 2 * hx, 2 * hy))
            continue
        radius = ob["size_m"][0]
        track = log.obstacle_tracks.get(ob["entity_id"])
        if ob["moving"] and track is not None and len(track[0]) > 1:
            xy = track[1]
            for k in np.unique(np.linspace(0, len(xy) - 1, MAX_SWEEP_DISCS).astype(int)):
                swept.append(Circle(tuple(xy[k]), radius))
            ax.plot(xy[:, 0], xy[:, 1], color="tab:orange", lw=0.8)
            ax.add_patch(Circle(tuple(xy[-1]), radius, fill=False, ec="tab:orange", lw=1.2))
        else:
            static.append(Circle((x, y), radius))
    ax.add_collection(PatchCollection(static, fc="saddlebrown", ec="black", lw=0.5, alpha=0.8))
    if swept:
        ax.add_collection(PatchCollection(swept, fc="tab:orange", ec="none", alpha=0.08))


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
    from matplotlib.patches import Rectangle

    fig, (ax, ax_wheels) = plt.subplots(
        2, 1, figsize=(8, 10.5), gridspec_kw={"height_ratios": [3, 1.1]}, layout="constrained"
    )
    width_m, height_m = log.run_value("arena_size_m", [10.0, 10.0])
    ax.add_patch(Rectangle((0, 0), width_m, height_m, fill=False, ec="black", lw=1.0))
    _draw_obstacles(ax, log)

    hits = range_hits_m(log)
    if len(hits):
        ax.scatter(hits[:, 0], hits[:, 1], s=2, c="tab:red", alpha=0.35, label="range hits", zorder=3)
    for k, (_, path) in enumerate(log.paths):
        last = k == len(log.paths) - 1
        ax.plot(path[:, 0], path[:, 1], color="tab:green", lw=1.6 if last else 0.9,
                ls="-" if last else "--", marker="." if last else None, ms=4,
                label="planned path" if last else None, zorder=4)
    if len(log.time_s):
        ax.plot(log.position_m[:, 0], log.position_m[:, 1], color="tab:blue", lw=1.4,
                label="driven", zorder=5)
        ax.plot(*log.position_m[0, :2], "o", color="tab:blue", ms=6, zorder=6)
    if log.paths:
        goal = log.paths[-1][1][-1]
        ax.plot(goal[0], goal[1], "*", color="tab:green", ms=14, mec="black", label="goal", zorder=6)
    collisions = collision_points_m(log)
    if len(collisions):
        ax.plot(collisions[:, 0], collisions[:, 1], "x", color="red", ms=10, mew=2.5,
                label=f"collisions ({len(collisions)})", zorder=7)
    margin = 0.3
    ax.set_xlim(-margin, width_m + margin)
    ax.set_ylim(-margin, height_m + margin)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    planner = log.metadata.get("planner", {}).get("name", "?")
    navigator = log.metadata.get("navigator", {}).get("name", "follow")
    run = log.metadata.get("run", {})
    seed, world_seed = run.get("seed", "?"), run.get("world_seed", run.get("seed", "?"))
    truncated = "" if log.complete else " (truncated log)"
    ax.set_title(f"{log.scenario_name} / {planner} + {navigator} / seed {seed}, world seed {world_seed}: "
                 f"{outcome_text(log)}, "
                 f"{log.duration_s:.1f} s{truncated}")
    ax.legend(loc="upper left", fontsize=8, framealpha=0.85)

    t = log.wheel_time_s
    for column, side, colour in ((0, "left", "tab:blue"), (1, "right", "tab:orange")):
        ax_wheels.plot(t, log.wheel_command_rad_s[:, column], color=colour, ls="--", lw=0.9,
                       label=f"{side} commanded")
        ax_wheels.plot(t, log.wheel_measured_rad_s[:, column], color=colour, lw=1.1,
                       label=f"{side} measured")
    for time_s, kind, _ in log.events:
        if kind == "collision_begin":
            ax_wheels.axvline(time_s, color="red", lw=0.6, alpha=0.6)
    ax_wheels.set_xlabel("simulation time [s]")
    ax_wheels.set_ylabel("wheel speed [rad/s]")
    ax_wheels.grid(alpha=0.3)
    ax_wheels.legend(loc="upper right", fontsize=8, ncol=2)

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


def run(args: argparse.Namespace) -> int:
    """Plot a log; a truncated log is plotted as far as it goes, with a warning."""
    image_format(args.out, args.dpi)  # before the work: a bad -o or --dpi is exit 2 at once
    log = read_log(args.log, allow_truncated=True)
    if not log.complete:
        print(f"warning: {args.log}: {truncation_advice(log.raw)}", file=sys.stderr)
    out = plot_run(log, args.out, dpi=args.dpi)
    print(out)
    return 0
