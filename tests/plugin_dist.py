"""The example plugin (examples/swarmnav_plugin_example) made discoverable without a build: its package's
folder and a ``.dist-info`` folder holding its entry points, as an installed distribution has them, on the
path (``PYTHONPATH``), so a subprocess, a spawned study worker and a local Ray worker all find it."""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "swarmnav_plugin_example"
# A study of the plugin's planner and a bundled one over a bundled scenario and the plugin's: 8 plan-only cells.
PLUGIN_STUDY = ('name = "plugin-study"\nscenarios = ["gwo-scenario-3", "plugin-corridor"]\nmode = "plan"\n'
                'seeds = 2\n[[planners]]\nname = "random_detour"\n[[planners]]\nname = "astar"\n')


def dist_info(folder: Path, name: str, version: str, entry_points: dict[str, dict[str, str]]) -> Path:
    """A ``<name>-<version>.dist-info`` folder in ``folder`` with its METADATA and entry_points.txt."""
    info = folder / f"{name.replace('-', '_')}-{version}.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: {version}\n")
    (info / "entry_points.txt").write_text("".join(
        f"[{group}]\n" + "".join(f"{key} = {value}\n" for key, value in entries.items())
        for group, entries in entry_points.items()))
    return info


def example_plugin(folder: Path) -> list[str]:
    """The path entries that make the example plugin installed: ``folder`` (its dist-info) and its sources."""
    groups = tomllib.loads((EXAMPLE / "pyproject.toml").read_text())["project"]["entry-points"]
    dist_info(folder, "swarmnav-plugin-example", "0.1.0", groups)
    return [str(folder), str(EXAMPLE / "src")]


def python_path(*entries: str) -> dict[str, str]:
    """``{"PYTHONPATH": ...}`` with ``entries`` before what the environment has."""
    return {"PYTHONPATH": os.pathsep.join([*entries, os.environ.get("PYTHONPATH", "")])}
