"""The rows of ``swarmnav bench navigation`` on scenes among agents (``--suite crowdnav``): one set per setting.

CrowdNav (Chen et al. 2019) reports the robot invisible to the humans and visible to them apart; so does this.
"""

from __future__ import annotations

from typing import Any

from swarmnav.models.crowd_agents import AgentMotion
from swarmnav.models.scenario import load_scenario


def mean(values: list[float]) -> float | None:
    return sum(values) / len(values) if values else None


def crowd_rows(runs, visible, verdicts, shipped, sensing, settings, row_of, oracle: str) -> list[dict[str, Any]]:
    """The rows among agents, one set per setting (``robot_visible`` false, then true): each navigator's
    :func:`_row` over that setting's runs with the crowd metrics (``discomfort_frequency`` over all control steps
    of the runs that drove, as CrowdNav counts it; mean ``min_separation_m`` and ``path_irregularity_rad_m``).
    With the robot visible there is no clairvoyant yardstick: no oracle row, no verdicts, ``yardstick`` says so."""
    table = []
    for seen in sorted(set(visible.values())):
        for nav, arm in runs.items():
            if seen and nav == oracle:
                continue
            part = [r for r in arm if visible.get(r["scenario"]) == seen]
            drove = [r for r in part if r["outcome"] == "ok" and r.get("discomfort_frequency") is not None]
            steps = sum(r["control_steps"] for r in drove)
            row = {"scenario": None, **row_of(nav, part, {} if seen else verdicts, shipped), "sensor_model": sensing,
                   **settings.get(nav, {}), "robot_visible": seen,
                   "yardstick": "none: the humans react to the robot" if seen else "oracle",
                   "discomfort_frequency": (sum(r["discomfort_frequency"] * r["control_steps"] for r in drove)
                                            / steps if steps else None),
                   "mean_min_separation_m": mean([r["min_separation_m"] for r in drove]),
                   "mean_path_irregularity_rad_m": mean([r["path_irregularity_rad_m"] for r in drove])}
            table.append(row)
    return table


def robot_visible(names: list[str]) -> dict[str, bool]:
    """Scene name -> whether its agents see the robot, for the scenes with agents (empty: no scene has any)."""
    out = {}
    for name in names:
        scenario = load_scenario(name)
        crowd = next((ob.motion.crowd for ob in scenario.obstacles if isinstance(ob.motion, AgentMotion)), None)
        if crowd is not None:
            out[scenario.name] = crowd.sees_robot
    return out


def print_crowd_lines(rows: list[dict[str, Any]]) -> None:
    """The crowd metrics of each row, under its table."""
    for r in rows:
        def shown(key: str, spec: str) -> str:
            return "-" if r.get(key) is None else format(r[key], spec)
        print(f"  {r['navigator']}: discomfort_frequency {shown('discomfort_frequency', '.3f')}, "
              f"min separation {shown('mean_min_separation_m', '.3f')} m (mean), "
              f"path irregularity {shown('mean_path_irregularity_rad_m', '.3f')} rad/m")
