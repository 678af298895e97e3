"""The report's figures, drawn from the rows with matplotlib (Agg), in the shared palette (:mod:`sim.palette`).

Each function returns a Matplotlib figure (or None when there is nothing to draw); the report writes it as
SVG (embedded, so it scales to any width and prints sharp) and as PNG at ``PNG_DPI``.  Figures are at most
``MAX_WIDTH_IN`` inches wide; a figure with many panels wraps them onto rows.
"""

from __future__ import annotations

import io
import json
import math
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PatchCollection  # noqa: E402
from matplotlib.ticker import NullFormatter  # noqa: E402

from swarmnav.sim import palette  # noqa: E402
from swarmnav.study import anytime  # noqa: E402
from swarmnav.study.statistics import OUTCOME_CLASSES, outcome_class, values  # noqa: E402

PNG_DPI = 200
MAX_WIDTH_IN = 10.0
OUTCOME_COLOURS = {"success": palette.START, "collision": palette.COLLISION, "timeout": "#e69f00",
                   "left arena": "#cc79a7",
                   "no path": "#7a7f87", "error": "#1b1b1b"}
METRIC_LABELS = {"plan_length_m": "plan length (m)", "plan_time_s": "plan time (s)",
                 "path_length_m": "driven length (m)", "sim_time_s": "simulated time (s)",
                 "min_clearance_m": "min clearance (m)"}
plt.rcParams.update({"font.size": 9, "axes.titlesize": 10, "legend.fontsize": 8, "svg.fonttype": "none",
                     "svg.hashsalt": "swarmnav"})


def encode(fig, formats: tuple[str, ...] = ("svg", "png")) -> list[bytes]:
    """The figure in each format ("svg", "png"), cropped to what it draws (measured once for all formats);
    reproducible (no date in the SVG)."""
    box = fig.get_tightbbox(fig.canvas.get_renderer()).padded(0.1)
    out = []
    for fmt in formats:
        buffer = io.BytesIO()
        fig.savefig(buffer, format=fmt, dpi=PNG_DPI, bbox_inches=box, metadata={"Date": None} if fmt == "svg" else {})
        out.append(buffer.getvalue())
    return out


def colours(names: list[str]) -> dict[str, str]:
    """One palette colour per arm, by the arm's planner label (an arm with a navigator keeps its planner's)."""
    planners: list[str] = []
    for name in names:
        base = name.split(" + ", 1)[0]
        if base not in planners:
            planners.append(base)
    return {name: palette.planner_colour(planners.index(name.split(" + ", 1)[0])) for name in names}


def _style(name: str):
    return palette.navigator_style(name.split(" + ", 1)[1] if " + " in name else "follow")


def box_plots(arms: dict[str, list[dict[str, Any]]], metrics: list[str]):
    if not metrics:  # every run failed: nothing to draw
        return None
    names = list(arms)
    columns = min(len(metrics), 3)
    rows = math.ceil(len(metrics) / columns)
    width = min(MAX_WIDTH_IN, 3.4 * columns)
    fig, axes = plt.subplots(rows, columns, figsize=(width, (2.4 + 0.12 * max(len(n) for n in names)) * rows),
                             squeeze=False)
    colour = colours(names)
    for ax, metric in zip(axes.flat, metrics):
        data = [values(arms[n], metric) for n in names]
        parts = ax.boxplot([d if d.size else [np.nan] for d in data], showmeans=True, patch_artist=True)
        for patch, n in zip(parts["boxes"], names):
            patch.set(facecolor=colour[n], alpha=0.45)
        ax.set_xticks(range(1, len(names) + 1), names, rotation=35, ha="right", fontsize=7)
        ax.set_ylabel(METRIC_LABELS.get(metric, metric))
        ax.grid(axis="y", alpha=0.3)
    for ax in list(axes.flat)[len(metrics):]:
        ax.set_visible(False)
    fig.tight_layout()
    return fig


def outcome_bars(arms: dict[str, list[dict[str, Any]]]):
    """Stacked shares of each outcome class per arm (success: reached with no collision)."""
    names = list(arms)
    fig, ax = plt.subplots(figsize=(min(MAX_WIDTH_IN, max(4.0, 0.6 * len(names) + 2.5)), 3.4))
    bottom = np.zeros(len(names))
    for c in OUTCOME_CLASSES:
        share = np.array([100.0 * sum(outcome_class(r) == c for r in arms[n]) / len(arms[n]) for n in names])
        if share.any():
            ax.bar(range(len(names)), share, bottom=bottom, color=OUTCOME_COLOURS[c], label=c)
            bottom += share
    for i, n in enumerate(names):
        failed = sum(outcome_class(r) != "success" for r in arms[n])
        ax.text(i, 101, f"{failed}/{len(arms[n])}\nfailed", ha="center", va="bottom", fontsize=6)
    ax.set_xticks(range(len(names)), names, rotation=35, ha="right", fontsize=7)
    ax.set_ylim(0, 118)
    ax.set_ylabel("runs (%)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), frameon=False)
    fig.tight_layout()
    return fig


def anytime_figure(arms: dict[str, list[dict[str, Any]]], history: dict[str, anytime.History],
                   optimum_m: float | None):
    """Fixed-budget curves (top) and fixed-target ECDFs (bottom), against evaluations (left) and wall time
    (right).  Returns (figure or None, the caption's sentence about the reference and missing histories)."""
    runs = {name: [history[r["config_hash"]] for r in rows if r["config_hash"] in history]
            for name, rows in arms.items()}
    recorded = {name: h for name, h in runs.items() if any(x.cost.size > 1 for x in h)}
    failed = [name for name in arms if name not in recorded and all(r["outcome"] != "ok" for r in arms[name])]
    silent = [name for name in arms if name not in recorded and name not in failed]
    absent = "; ".join(part for part in (
        "no best-cost history recorded: " + ", ".join(silent) if silent else "",
        "every run failed (no history): " + ", ".join(failed) if failed else "") if part)
    if not recorded:
        return None, f"No anytime figure for this scenario ({absent})."
    reference, said = anytime.reference_cost(optimum_m, [h for hs in recorded.values() for h in hs])
    fig, axes = plt.subplots(2, 2, figsize=(MAX_WIDTH_IN, 7.2))
    colour = colours(list(arms))
    for column, axis in enumerate(("evaluations", "wall_s")):
        for name, hs in recorded.items():
            curve = anytime.fixed_budget(hs, axis)
            if curve is not None:
                grid, (q1, med, q3) = curve
                axes[0, column].plot(grid, med, color=colour[name], linestyle=_style(name), label=name)
                axes[0, column].fill_between(grid, q1, q3, color=colour[name], alpha=0.18, linewidth=0)
            if reference is not None:
                ecdf = anytime.fixed_target(hs, len(arms[name]), reference, axis)
                if ecdf is not None:
                    axes[1, column].step(ecdf[0], ecdf[1], where="post", color=colour[name],
                                         linestyle=_style(name), label=name)
        what = "objective evaluations" if axis == "evaluations" else "wall time (s)"
        for row in (0, 1):
            ax = axes[row, column]
            ax.set_xscale("log")
            ax.xaxis.set_minor_formatter(NullFormatter())
            ax.set_xlabel(what)
            ax.grid(alpha=0.3)
            if not ax.lines:
                ax.text(0.5, 0.5, "no " + ("wall times" if axis == "wall_s" else "evaluations") + " recorded",
                        transform=ax.transAxes, ha="center", va="center")
        axes[0, column].set_ylabel("best cost (median, IQR)")
        if optimum_m is not None:
            axes[0, column].axhline(optimum_m, color=palette.DRIVEN, linewidth=0.8, linestyle=":",
                                    label="exact optimum")
        axes[1, column].set_ylabel("share of (run, target) pairs reached")
        axes[1, column].set_ylim(-0.02, 1.02)
    axes[0, 0].set_title("fixed budget")
    axes[1, 0].set_title("fixed target: " + ", ".join(f"{f:g}" for f in anytime.TARGET_FACTORS) + " × reference")
    if any(x.estimated for hs in recorded.values() for x in hs):
        estimated = sorted(n for n, hs in recorded.items() if any(x.estimated for x in hs))
        axes[0, 0].set_xlabel(f"objective evaluations (spread evenly for {', '.join(estimated)})")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    footer = absent
    fig.legend(handles, labels, loc="lower center", ncol=min(4, len(labels)), frameon=False,
               bbox_to_anchor=(0.5, -0.02 - 0.03 * math.ceil(len(labels) / 4)))
    if footer:
        fig.text(0.5, 1.0, footer, ha="center", va="bottom", fontsize=8, style="italic")
    fig.tight_layout()
    below = [n for n, hs in recorded.items() if reference is not None and optimum_m is not None
             and any(np.nanmin(x.cost) < optimum_m - 1e-6 for x in hs if x.cost.size)]
    sentence = f"Targets relative to {said}." + (f" {footer[0].upper() + footer[1:]}." if footer else "")
    if below:
        sentence += (f" Best costs below the optimum ({', '.join(below)}): that planner's objective is not the "
                     "path length alone (e.g. a penalty that an infeasible path pays less than the detour).")
    return fig, sentence


def _obstacles(ax, geometry: dict[str, Any], end_s: float | None):
    """Arena, static obstacles, moving obstacles' tracks coloured by time up to ``end_s`` (None: as recorded);
    the tracks' collection if one was drawn."""
    width_m, height_m = geometry["arena_m"]
    ax.add_patch(plt.Rectangle((0, 0), width_m, height_m, fill=False, edgecolor=palette.ARENA, linewidth=1.0))
    tracks = geometry.get("disc_tracks", [])
    moving_t0 = {(round(t["t_x_y"][0][1], 4), round(t["t_x_y"][0][2], 4)) for t in tracks if t["t_x_y"]}
    for x, y, r in geometry.get("discs_t0", []):
        moving = (round(x, 4), round(y, 4)) in moving_t0
        ax.add_patch(plt.Circle((x, y), r, facecolor=palette.MOVING_OBSTACLE if moving else palette.OBSTACLE,
                                edgecolor=palette.ARENA if moving else "none", linestyle="--", linewidth=0.6,
                                alpha=0.6 if moving else 1.0))
    ax.add_collection(PatchCollection([plt.Rectangle((x0, y0), x1 - x0, y1 - y0)
                                       for x0, y0, x1, y1 in geometry.get("boxes", [])], color=palette.OBSTACLE))
    drawn = None
    end_s = end_s or max((t["t_x_y"][-1][0] for t in tracks if t["t_x_y"]), default=1.0) or 1.0
    for track in tracks:
        txy = np.array(track["t_x_y"], dtype=float)
        txy = txy[txy[:, 0] <= end_s + 1e-9] if len(txy) else txy
        if len(txy) < 2:
            continue
        segments = np.stack([txy[:-1, 1:], txy[1:, 1:]], axis=1)
        lines = LineCollection(segments, cmap=palette.TIME_COLORMAP, linewidths=2.0, alpha=0.8)
        lines.set_array(txy[:-1, 0])
        lines.set_clim(0.0, end_s)
        drawn = ax.add_collection(lines)
    ax.plot(*geometry["start"], "^", color=palette.START, markersize=8, label="start", zorder=6)
    ax.plot(*geometry["goal"], "*", color=palette.GOAL, markersize=11, label="goal", zorder=6)
    ax.set_xlim(0.0, width_m)
    ax.set_ylim(0.0, height_m)
    return drawn


def paths(arms: dict[str, list[dict[str, Any]]], geometry: dict[str, Any] | None,
          driven: dict[str, tuple[np.ndarray, np.ndarray]] | None = None):
    """The plan of the lowest seed of each arm over the scenario as ``study.json`` recorded it at run time
    (arena, start, goal, obstacles at t = 0, moving obstacles' tracks coloured by time), and, where given, the
    trajectory that run drove with the points where collisions began (``driven``: arm -> (xy, collisions))."""
    driven = driven or {}
    fig, ax = plt.subplots(figsize=(7.0, 6.0))
    times = [r["sim_time_s"] for rows in arms.values() for r in rows if r.get("sim_time_s") is not None]
    tracks = _obstacles(ax, geometry, max(times) if times else None) if geometry else None
    collision_label = "collision began"
    colour = colours(list(arms))
    drawn = False
    for name, rows in arms.items():
        ok = sorted((r for r in rows if r.get("plan_waypoints")), key=lambda r: (r["seed"], str(r["world_seed"])))
        if not ok:
            continue
        points = np.array(json.loads(ok[0]["plan_waypoints"]))
        ax.plot(points[:, 0], points[:, 1], color=colour[name], linestyle=_style(name), linewidth=1.4,
                label=f"{name} plan (seed {ok[0]['seed']})")
        drawn = True
        if name in driven:
            xy, collisions = driven[name]
            ax.plot(xy[:, 0], xy[:, 1], color=colour[name], linewidth=3.0, alpha=0.35, solid_capstyle="round",
                    label=f"{name} driven")
            if len(collisions):
                ax.plot(collisions[:, 0], collisions[:, 1], "x", color=palette.COLLISION, markersize=9, mew=2,
                        zorder=7, label=collision_label)
                collision_label = "_nolegend_"
    if not drawn:
        plt.close(fig)
        return None
    if tracks is not None:
        fig.colorbar(tracks, ax=ax, fraction=0.04, pad=0.02, label="moving obstacles: time (s)")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.25 if tracks is not None else 1.02, 1.0), frameon=False)
    fig.tight_layout()
    return fig


def close(fig) -> None:
    plt.close(fig)
