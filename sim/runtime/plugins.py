"""Planners, navigators and scenario folders from installed packages, by entry points.

An installed distribution declares, in its ``pyproject.toml``::

    [project.entry-points."swarmnav.planners"]
    my_planner = "my_lab.planning:MyPlanner"        # a planner class (the seam of swarmnav.planners.problem)

    [project.entry-points."swarmnav.navigators"]
    my_navigator = "my_lab.driving:MyNavigator"     # a navigator class (swarmnav.controllers.navigator)

    [project.entry-points."swarmnav.scenarios"]
    my_scenarios = "my_lab.scenarios"               # a package whose folder holds scenario .toml files

and every command then knows those names as it knows the bundled ones (``run --planner``, studies,
``bench planners``).  Only what the user installed is loaded, and only by the group's name: a scenario or
study file that names a plugin selects an installed class by its registered name, never a module of the
file's choosing.

A plugin that fails to import, is not a class, or takes a name already registered (a bundled one or another
plugin's) is one warning line on stderr naming the distribution, and is skipped; the rest works.

Every place that looks a component up by name loads the plugins first (:func:`load_plugins`): the command line,
the API's calls, a study's validation, each study cell in a local worker or a Ray task
(:func:`swarmnav.study.cell.run_cell`) and the environment.  A process scans the entry points again when
its ``sys.path`` changed since the last scan (a script that put a plugin's folder on it), loading only the
entries it has not seen.
"""

from __future__ import annotations

import importlib.metadata
import importlib.resources
import sys
from pathlib import Path as FilePath
from typing import Any, Callable

GROUPS = ("swarmnav.planners", "swarmnav.navigators", "swarmnav.scenarios")

#: ``(kind, name) -> "distribution version"`` of every component a plugin registered.
ORIGINS: dict[tuple[str, str], str] = {}
#: ``distribution name -> version`` of every plugin whose components (or scenario folder) were registered.
DISTRIBUTIONS: dict[str, str] = {}
_scanned_path: tuple[str, ...] | None = None  # sys.path at the last scan
_seen: set[tuple[str, str, str]] = set()  # (group, name, value) of every entry point already handled


def _distribution(entry: importlib.metadata.EntryPoint) -> str:
    dist = getattr(entry, "dist", None)
    return f"{dist.name} {dist.version}" if dist is not None else "an unknown distribution"


def _warn(entry: importlib.metadata.EntryPoint, problem: str) -> None:
    print(f"swarmnav: warning: plugin {entry.name!r} of {_distribution(entry)} ({entry.group}): {problem}; "
          "skipped", file=sys.stderr)


def _register(entry: importlib.metadata.EntryPoint, kind: str, registry: dict[str, type],
              register: Callable[[type], type]) -> None:
    try:
        cls = entry.load()
    except Exception as exc:  # a broken plugin must not stop the bundled components
        _warn(entry, f"cannot be imported ({type(exc).__name__}: {exc})".replace("\n", " "))
        return
    name = getattr(cls, "name", None)
    if not isinstance(cls, type):
        _warn(entry, f"{entry.value} is not a class")
    elif name != entry.name:
        _warn(entry, f"the class's name is {name!r}, not the entry point's {entry.name!r}")
    elif name in registry:
        owner = ORIGINS.get((kind, name), "swarmnav")
        _warn(entry, f"the {kind} name {name!r} is taken by {owner}")
    else:
        try:
            register(cls)
        except (TypeError, ValueError) as exc:
            _warn(entry, str(exc))
            return
        ORIGINS[(kind, cls.name)] = _distribution(entry)
        _record_distribution(entry)


def _record_distribution(entry: importlib.metadata.EntryPoint) -> None:
    dist = getattr(entry, "dist", None)
    if dist is not None:
        DISTRIBUTIONS[dist.name] = dist.version


def _scenario_folder(entry: importlib.metadata.EntryPoint) -> FilePath | None:
    try:
        folder = importlib.resources.files(entry.value)
    except Exception as exc:
        _warn(entry, f"cannot be found ({type(exc).__name__}: {exc})".replace("\n", " "))
        return None
    path = FilePath(str(folder))
    if not path.is_dir():
        _warn(entry, f"{entry.value} is not a folder")
        return None
    return path


def _new_entries(group: str) -> list[importlib.metadata.EntryPoint]:
    """The entry points of ``group`` not handled by an earlier scan (each distribution's first of a name)."""
    out = []
    for entry in importlib.metadata.entry_points(group=group):
        key = (group, entry.name, entry.value)
        if key not in _seen:
            _seen.add(key)
            out.append(entry)
    return out


def load_plugins() -> None:
    """Register every installed plugin; again only when ``sys.path`` changed since the last call (then only
    the entry points not seen before), so it costs nothing where it is called on every lookup."""
    global _scanned_path
    path = tuple(sys.path)
    if path == _scanned_path:
        return
    _scanned_path = path
    from swarmnav.controllers import navigators
    from swarmnav.models import scenario
    from swarmnav.planners import registry

    for entry in _new_entries("swarmnav.planners"):
        _register(entry, "planner", registry.PLANNERS, registry.register)
    for entry in _new_entries("swarmnav.navigators"):
        _register(entry, "navigator", navigators.NAVIGATORS, navigators.register)
    for entry in _new_entries("swarmnav.scenarios"):
        folder = _scenario_folder(entry)
        if folder is not None and folder not in scenario.EXTRA_SCENARIO_DIRS:
            scenario.EXTRA_SCENARIO_DIRS.append(folder)
            _record_distribution(entry)


def distributions() -> dict[str, str]:
    """``name -> version`` of the plugin distributions this process loaded (for a Ray node's check)."""
    load_plugins()
    return dict(sorted(DISTRIBUTIONS.items()))


def origin(kind: str, name: str) -> str:
    """The distribution a component comes from (``swarmnav`` for the bundled ones)."""
    return ORIGINS.get((kind, name), "swarmnav")


def describe_components(kind: str) -> list[dict[str, Any]]:
    """Every registered planner or navigator with its parameters (name, type, default, and its range or choices
    where it declares them: :func:`models.parameters.parameter_table`, a navigator's safety layer switches
    included), its one-line description and its package: what ``swarmnav planners`` lists."""
    from swarmnav.models.parameters import parameter_table
    load_plugins()
    if kind == "planner":
        from swarmnav.planners.registry import PLANNERS as registry_map
        table = lambda name: parameter_table(registry_map[name])  # noqa: E731
    else:
        from swarmnav.controllers.navigators import NAVIGATORS as registry_map
        from swarmnav.controllers.navigators import navigator_table as table
    out = []
    for name in sorted(registry_map):
        cls = registry_map[name]
        doc = (cls.__doc__ or "").strip().splitlines()
        params = [{"name": row["name"], "type": row["type"], "default": _json_value(row["default"]),
                   **{key: _json_value(row[key]) for key in ("range", "choices") if row[key] is not None}}
                  for row in table(name)]
        out.append({"name": name, "description": doc[0] if doc else "", "package": origin(kind, name),
                    "parameters": params})
    return out


def _json_value(value: Any) -> Any:
    if isinstance(value, (bool, int, str)) or value is None:
        return value
    if isinstance(value, float):
        return value if value == value and abs(value) != float("inf") else str(value)
    if isinstance(value, (list, tuple)):
        return [_json_value(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _json_value(v) for k, v in value.items()}
    return repr(value)
