"""What a study's physics rows on dynamic scenarios are measured against: the clairvoyant oracle's verdict and the
scene's difficulty metrics, computed once per scene per study.

For every physics row whose scenario has a moving obstacle, the study's driver adds (:meth:`Yardstick.annotate`):

* ``oracle_verdict``: ``solvable`` (the oracle, :mod:`controllers.oracle_search`, found a collision-free
  arrival on its lattice within the time limit), ``unsolvable`` (it proved none at its resolution:
  ``oracle_reason`` says why, e.g. ``time_limit``) or ``undecided`` (the search raised: ``oracle_reason`` holds
  the error; the row is kept, as every failure is) or ``none`` (the scene's agents see the robot and react to
  it: no clairvoyant yardstick exists, and nothing is counted against a navigator there);
* ``oracle_t_star_s`` (T*, the earliest arrival) and ``oracle_cell_m`` (the resolution it decided at);
* ``time_score``: BARN's (Perille et al. 2020), on rows of a solvable scene only: 0 when the run failed, else
  T* / T clipped to [0, 1], T the run's ``time_to_goal_s``; null on unsolvable and undecided scenes, so that a
  scene no robot could solve never counts against a navigator;
* the difficulty metrics of :mod:`sim.difficulty`: ``static_density``, ``dispersion``, ``survivability``,
  ``dynamic_traversability`` and ``t_star_ratio`` (T* over the static shortest arrival); ``difficulty_error``
  when they could not be computed.

A scene is the scenario file's content (SHA-256 of its bytes, so a renamed copy is the same scene and an
edited file a new one), the world seed and the study's simulated-time limit (the oracle searches up to it).
Each scene is computed the first time one of its rows arrives, on the driver (never once per row, and never
once per worker), and kept in ``DIR/difficulty.json`` so that a resumed study computes nothing again.  Plan-only
rows and static scenarios get nulls.  The oracle runs at its default settings (those of the ``oracle``
navigator), clairvoyant by design: it is the yardstick, not a contender.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path as FilePath
from typing import Any

from swarmnav.models.contained_files import check_no_link, loads_json, replace_file

FILE = "difficulty.json"
METRICS = ("static_density", "dispersion", "survivability", "dynamic_traversability", "t_star_ratio")
COLUMNS = ("oracle_verdict", "oracle_reason", "oracle_t_star_s", "oracle_cell_m", "time_score", *METRICS,
           "difficulty_error")


def time_score(success: bool, time_to_goal_s: float | None, t_star_s: float) -> float:
    """BARN's time score (Perille et al. 2020): 0 on failure, else T* / T clipped to [0, 1]."""
    if not success or time_to_goal_s is None:
        return 0.0
    if time_to_goal_s <= 0.0:
        return 1.0
    return min(1.0, max(0.0, t_star_s / time_to_goal_s))


def _failure(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}".splitlines()[0]


def measure(scenario, time_limit_s: float | None) -> dict[str, Any]:
    """One scene's entry: ``dynamic`` and, for a dynamic scene, the oracle's verdict and the metrics, each part
    caught on its own (an oracle that raises is ``undecided``; metrics that raise leave ``difficulty_error``)."""
    from swarmnav.sim.difficulty import oracle_metrics, scene_metrics
    entry: dict[str, Any] = {"scenario": scenario.name, "world_seed": scenario.world_seed,
                             "time_limit_s": time_limit_s, "dynamic": any(ob.moving for ob in scenario.obstacles)}
    if not entry["dynamic"]:
        return entry
    from swarmnav.controllers.oracle_search import reactive_agents
    if reactive_agents(scenario):
        entry.update(oracle_verdict="none", oracle_reason="the agents react to the robot: no clairvoyant yardstick")
        return entry
    try:
        found = oracle_metrics(scenario, None, time_limit_s)
        verdict = found["oracle"]
        entry.update(oracle_verdict="solvable" if verdict["solvable"] else "unsolvable",
                     oracle_reason=verdict["reason"] or None, oracle_t_star_s=verdict["arrival_s"],
                     oracle_cell_m=verdict["cell_m"], t_star_ratio=found["t_star_ratio"])
    except Exception as exc:  # noqa: BLE001 - the oracle could not decide: the rows say so
        entry.update(oracle_verdict="undecided", oracle_reason=_failure(exc))
    try:
        metrics = scene_metrics(scenario)
        entry.update({k: metrics[k] for k in METRICS if k in metrics})
    except Exception as exc:  # noqa: BLE001 - a metric that cannot be computed is a null with its reason
        entry["difficulty_error"] = _failure(exc)
    return entry


class Yardstick:
    """The scenes of one study folder, each measured once (see the module docstring)."""

    def __init__(self, out_dir: str | os.PathLike, time_limit_s: float | None = None, trust_code: bool = False):
        self.path = FilePath(out_dir) / FILE
        self.time_limit_s, self.trust_code = time_limit_s, trust_code
        self.scenes: dict[str, dict[str, Any]] = {}
        self.digests: dict[str, str] = {}
        self.computed = 0  # scenes measured by this instance (not read from the file)
        try:
            check_no_link(self.path, "--out")  # a link planted in the folder is neither read nor written through
            self.scenes = loads_json(self.path.read_text(encoding="utf-8"), str(self.path)).get("scenes", {})
        except (OSError, AttributeError):
            self.scenes = {}
        except ValueError as exc:  # unreadable JSON: measured again; a planted link: refused
            if "symbolic link" in str(exc):
                raise
            self.scenes = {}
        self.scenes = self.scenes if isinstance(self.scenes, dict) else {}

    def _digest(self, ref: str) -> str:
        if ref not in self.digests:
            from swarmnav.models.scenario import resolve_scenario_path
            self.digests[ref] = hashlib.sha256(resolve_scenario_path(ref).read_bytes()).hexdigest()
        return self.digests[ref]

    def scene(self, ref: str, world_seed: int | None) -> dict[str, Any]:
        """The entry of scenario ``ref`` with ``world_seed`` (None: the scenario's), measured if new."""
        from swarmnav.models.scenario import load_scenario
        try:
            digest = self._digest(ref)
        except Exception as exc:  # noqa: BLE001 - an unreadable file: its rows say so
            return {"dynamic": True, "oracle_verdict": "undecided", "oracle_reason": _failure(exc)}
        key = f"{digest[:16]} world_seed={world_seed} time_limit_s={self.time_limit_s}"
        if key not in self.scenes:
            try:
                scenario = load_scenario(ref, trust_code=self.trust_code)
                if world_seed is not None:
                    scenario = scenario.with_world_seed(world_seed)
                entry = measure(scenario, self.time_limit_s)
            except Exception as exc:  # noqa: BLE001 - a scenario that does not load: its rows say so
                entry = {"dynamic": True, "oracle_verdict": "undecided", "oracle_reason": _failure(exc)}
            self.scenes[key] = entry
            self.computed += 1
            self._save()
        return self.scenes[key]

    def _save(self) -> None:
        replace_file(self.path, json.dumps({"scenes": self.scenes}, indent=1, sort_keys=True) + "\n", "--out")

    def annotate(self, row: dict[str, Any]) -> dict[str, Any]:
        """``row`` with the columns of the module docstring (left alone for plan-only rows)."""
        if row.get("mode") != "physics":
            return row
        entry = self.scene(row["scenario_ref"], row["world_seed"])
        if not entry.get("dynamic"):
            return row
        row.update({k: entry.get(k) for k in COLUMNS if k != "time_score"})
        if entry.get("oracle_verdict") == "solvable":
            row["time_score"] = time_score(bool(row.get("success")), row.get("time_to_goal_s"),
                                           entry["oracle_t_star_s"])
        return row
