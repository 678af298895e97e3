"""What the API's calls return: a plan and a run, each with ``to_dict()`` (the CLI's JSON) and ``plot()``."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np
    from matplotlib.figure import Figure

    from swarmnav.planners.problem import Path, PlanStats, Problem
    from swarmnav.sim.episode import Episode
    from swarmnav.sim.run_result import RunResult


class PlanResult:
    """A planned episode: ``path`` (waypoints ``(N, 2)`` metres and ``stats``), ``problem`` and the resolved
    ``spec``; ``to_dict()`` is what ``swarmnav plan --json`` prints."""

    def __init__(self, episode: Episode):
        self.episode = episode

    @property
    def path(self) -> Path:
        return self.episode.path

    @property
    def waypoints(self) -> np.ndarray:
        return self.episode.path.waypoints

    @property
    def stats(self) -> PlanStats:
        return self.episode.path.stats

    @property
    def problem(self) -> Problem:
        return self.episode.problem

    @property
    def length_m(self) -> float:
        return float(self.episode.path.stats.length_m)

    def to_dict(self) -> dict[str, Any]:
        return self.episode.plan_summary()

    def plot(self, ax: Any = None) -> Figure:
        """The scenario at t = 0 and the planned path; returns the Matplotlib figure."""
        return _plot(self.episode, None, ax)

    def __repr__(self) -> str:
        return (f"PlanResult({self.episode.spec.scenario.name!r}, {_source(self.episode)}, "
                f"length_m={self.length_m:.4f}, waypoints={len(self.waypoints)})")


class RunOutcome(PlanResult):
    """A driven episode: ``outcome`` (``goal_reached``, ``collision``, ``timeout``, ``left_arena``), ``reached``,
    ``success`` (reached with no collision, inside the arena), ``result`` (the full :class:`swarmnav.sim.simulation.RunResult` with its arrays),
    ``log`` and ``video`` paths; ``to_dict()`` is what ``swarmnav run --json`` prints."""

    def __init__(self, episode: Episode, log: str | None = None, video: str | None = None):
        super().__init__(episode)
        self.log = log
        self.video = video

    @property
    def result(self) -> RunResult:
        assert self.episode.result is not None  # a RunOutcome is made of a driven episode
        return self.episode.result

    @property
    def outcome(self) -> str:
        return self.result.outcome

    @property
    def reached(self) -> bool:
        return bool(self.result.reached)

    @property
    def success(self) -> bool:
        return bool(self.result.success)

    def to_dict(self) -> dict[str, Any]:
        return {**self.episode.summary(), "log": self.log, "video": self.video}

    def plot(self, ax: Any = None) -> Figure:
        """The scenario at t = 0, the planned path, the driven trajectory and the collisions."""
        return _plot(self.episode, self.episode.result, ax)

    def __repr__(self) -> str:
        r = self.result
        return (f"RunOutcome({self.episode.spec.scenario.name!r}, {_source(self.episode)}, "
                f"navigator={self.episode.spec.navigator!r}, outcome={r.outcome!r}, collisions={r.collisions}, "
                f"sim_time_s={r.sim_time_s:.2f})")


def _source(episode: Any) -> str:
    """Where the path came from: ``planner='astar'``, or ``given='plan.csv'`` for a given path."""
    given = episode.path.stats.extra.get("given")
    return f"given={given!r}" if given else f"planner={episode.spec.planner!r}"


def _plot(episode: Episode, result: RunResult | None, ax: Any) -> Figure:
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Rectangle

    if ax is None:
        fig, ax = plt.subplots(figsize=(6, 6), layout="constrained")
    else:
        fig = ax.figure
    problem, scenario = episode.problem, episode.spec.scenario
    bounds = scenario.planning_bounds(0.0)
    ax.add_patch(Rectangle((bounds.x_min_m, bounds.y_min_m), bounds.x_max_m - bounds.x_min_m,
                           bounds.y_max_m - bounds.y_min_m,
                           fill=False, ec="black", lw=1.0))
    for disc in scenario.discs_at(0.0):
        ax.add_patch(Circle((disc.x_m, disc.y_m), disc.radius_m, color="0.55", alpha=0.8, lw=0))
    for box in problem.boxes:
        ax.add_patch(Rectangle((box.x_min_m, box.y_min_m), box.x_max_m - box.x_min_m, box.y_max_m - box.y_min_m,
                               color="0.55", alpha=0.8, lw=0))
    waypoints = episode.path.waypoints
    ax.plot(waypoints[:, 0], waypoints[:, 1], color="tab:green", lw=1.5, marker=".", ms=3, label="planned path")
    if result is not None and len(result.poses):
        ax.plot(result.poses[:, 0], result.poses[:, 1], color="tab:blue", lw=1.3, label="driven")
        if len(result.collision_points_m):
            points = result.collision_points_m
            ax.plot(points[:, 0], points[:, 1], "x", color="red", ms=9, mew=2, label="collisions")
    ax.plot(scenario.start.x_m, scenario.start.y_m, "o", color="tab:blue", ms=6, label="start")
    ax.plot(scenario.goal.x_m, scenario.goal.y_m, "*", color="tab:green", mec="black", ms=13, label="goal")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    given = episode.path.stats.extra.get("given")
    title = f"{scenario.name}: {'given path' if given else episode.spec.planner}"
    if result is not None:
        title += f" + {episode.spec.navigator}, {result.outcome}"
    ax.set_title(title, fontsize=10)
    ax.legend(loc="best", fontsize=8)
    return fig
