"""What produced a study's verdicts, and whether today's code would still produce them.

:func:`study_inputs` records, when a study runs (``study.json``'s ``inputs``, copied into ``claims.json``):

* ``study_file``: the study file (path relative to the repository, SHA-256 of its bytes);
* ``sources``: the SHA-256 of every source file of the components the study ran: each planner's module,
  each navigator's module and the safety layer the stepper applies after it (physics studies only; a
  plan-only study never drives), and every project module
  they import from ``planners/`` and ``controllers/``, followed transitively (a compiled helper is hashed by
  its C source beside it).  Modules elsewhere (``sim/``, ``models/``) are not followed: the inputs are the
  components, not the harness;
* ``scenarios``: the SHA-256 of every scenario file the study ran, and of the map file each names;
* ``versions``: swarmnav's version and those of its key dependencies (:data:`KEY_DEPENDENCIES`).

:func:`stale_inputs` compares a recorded ``inputs`` with today's: a study is *stale* when its study file, a
source or a scenario changed (or appeared or disappeared), or swarmnav's version changed; a dependency whose
version differs is a note only (CI installs what the version ranges of ``pyproject.toml`` resolve to).
``swarmnav report --check-fresh DIR`` runs it over every ``claims.json`` under DIR.
"""

from __future__ import annotations

import hashlib
import inspect
import re
from importlib import metadata
from pathlib import Path as FilePath
from typing import Any, Iterable

ROOT = FilePath(__file__).resolve().parents[2]
#: The project folders whose modules count as a component's sources (imports are followed only inside them).
COMPONENT_PACKAGES = ("planners", "controllers")
KEY_DEPENDENCIES = ("numpy", "scipy", "mujoco", "ompl")
#: Component modules a physics run uses whatever its navigator imports: the safety layer the stepper applies
#: after every navigator's step.
PHYSICS_LAYERS = (ROOT / "controllers" / "safety_layer.py",)


def _sha256(path: FilePath) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _relative(path: FilePath) -> str:
    try:
        return path.resolve().relative_to(ROOT).as_posix()
    except ValueError:
        return path.resolve().as_posix()  # a plugin's module outside the repository


def _module_file(module: str) -> FilePath | None:
    """The source file of ``swarmnav.<package>.<...>`` inside :data:`COMPONENT_PACKAGES` (None otherwise)."""
    parts = module.split(".")
    if len(parts) < 2 or parts[0] != "swarmnav" or parts[1] not in COMPONENT_PACKAGES:
        return None
    base = ROOT.joinpath(*parts[1:])
    for candidate in (base.with_suffix(".py"), base / "__init__.py", base.with_suffix(".c")):
        if candidate.is_file():
            return candidate
    return None


_FROM_IMPORT = re.compile(r"^[ \t]*from[ \t]+([\w.]+)[ \t]+import[ \t]+(\([^)]*\)|[^\n#]*)", re.M)
_IMPORT = re.compile(r"^[ \t]*import[ \t]+([^\n#]+)", re.M)


def _imports(path: FilePath) -> set[str]:
    """The absolute module names a Python file imports (``from a.b import c`` gives ``a.b`` and ``a.b.c``).

    Read from the import statements' text, not with :func:`ast.parse`: CPython 3.11.7's AST constructor raises
    ``SystemError: AST constructor recursion depth mismatch`` in a process that has met a RecursionError before
    (a 5,000-deep array refused earlier in the same process). A line of a docstring that reads like an import
    only adds a file to hash.
    """
    if path.suffix != ".py":
        return set()
    # continuation lines joined and comments dropped (a '#' inside a string only cuts that line short)
    text = re.sub(r"#[^\n]*", "", path.read_text(encoding="utf-8").replace("\\\n", " "))
    names: set[str] = set()
    for module, imported in _FROM_IMPORT.findall(text):
        if module.startswith("."):
            continue
        names.add(module)
        for alias in imported.strip("()").split(","):
            words = alias.split()
            if words and words[0].isidentifier():
                names.add(f"{module}.{words[0]}")
    for imported in _IMPORT.findall(text):
        for alias in imported.split(","):
            words = alias.split()
            if words:
                names.add(words[0])
    return names


def source_closure(files: Iterable[FilePath]) -> list[FilePath]:
    """``files`` and every project module of :data:`COMPONENT_PACKAGES` they import, transitively, sorted."""
    seen: set[FilePath] = set()
    todo = [f.resolve() for f in files]
    while todo:
        path = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        for name in _imports(path):
            found = _module_file(name)
            if found is not None and found.resolve() not in seen:
                todo.append(found.resolve())
    return sorted(seen)


def _class_file(cls: type) -> FilePath:
    path = FilePath(inspect.getfile(cls))
    source = path.with_name(path.name.split(".")[0] + ".c") if path.suffix == ".so" else path
    return source if source.is_file() else path


def component_files(study) -> list[FilePath]:
    """The module of each planner (and, for a physics study, each navigator) the study runs (with
    ``--claims-only``: those of the arms its claims compare)."""
    from swarmnav.controllers.navigators import NAVIGATORS
    from swarmnav.planners.registry import PLANNERS
    from swarmnav.study.claim_spec import arm_labels
    wanted = None if study.claim_arms is None else {label for _, label, _ in study.claim_arms}
    planners = [p for p in study.planners if wanted is None or set(arm_labels([p])) & wanted]
    files = [_class_file(PLANNERS[p.name]) for p in planners if p.name in PLANNERS]
    if study.mode != "plan":
        claimed = None if study.claim_arms is None else {nav for _, _, nav in study.claim_arms}
        navs = None if claimed is None or None in claimed else claimed
        navigators = [n for n in study.navigators if navs is None or set(arm_labels([n])) & navs]
        files += [_class_file(NAVIGATORS[n.name]) for n in navigators if n.name in NAVIGATORS]
        files += [f for f in PHYSICS_LAYERS if f.is_file()]
    return files


def versions() -> dict[str, str | None]:
    out: dict[str, str | None] = {}
    for name in ("swarmnav",) + KEY_DEPENDENCIES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


def scenario_files(refs: Iterable[str]) -> list[FilePath]:
    """The scenario files of ``refs`` (bundled names or paths) and the map file each names (``[map] file``,
    beside the scenario or under ``models/maps/``)."""
    import tomllib

    from swarmnav.models.scenario import resolve_scenario_path
    files: set[FilePath] = set()
    for ref in refs:
        path = FilePath(resolve_scenario_path(ref)).resolve()
        files.add(path)
        name = (tomllib.loads(path.read_text(encoding="utf-8")).get("map") or {}).get("file")
        if isinstance(name, str):
            found = next((c for c in (path.parent / name, ROOT / "models" / "maps" / name) if c.is_file()), None)
            if found is not None:
                files.add(found.resolve())
    return sorted(files)


def study_inputs(study) -> dict[str, Any]:
    """What a run of ``study`` depends on (see the module docstring)."""
    study_file = FilePath(study.source) if study.source else None
    return {
        "claims_only": study.claim_arms is not None,
        "study_file": ({"path": _relative(study_file), "sha256": _sha256(study_file)}
                       if study_file is not None and study_file.is_file() else None),
        "sources": {_relative(f): _sha256(f) for f in source_closure(component_files(study))},
        "scenarios": {_relative(f): _sha256(f) for f in scenario_files(study.scenarios)},
        "versions": versions(),
    }


def stale_inputs(recorded: dict[str, Any], current: dict[str, Any]) -> tuple[list[str], list[str]]:
    """(what changed, notes): each change a short phrase naming the file or version; notes for dependency
    versions that differ (not a change of the study's inputs)."""
    changes: list[str] = []
    old_file, new_file = recorded.get("study_file") or {}, current.get("study_file") or {}
    if old_file.get("sha256") != new_file.get("sha256"):
        changes.append(f"study file {new_file.get('path') or old_file.get('path')} changed")
    for key, what in (("sources", "source"), ("scenarios", "scenario")):
        old, new = recorded.get(key) or {}, current.get(key) or {}
        for path in sorted(set(old) | set(new)):
            if path not in new:
                changes.append(f"{what} {path} no longer used")
            elif path not in old:
                changes.append(f"{what} {path} newly used")
            elif old[path] != new[path]:
                changes.append(f"{what} {path} changed")
    old_versions, new_versions = recorded.get("versions") or {}, current.get("versions") or {}
    notes = []
    for name in sorted(set(old_versions) | set(new_versions)):
        if old_versions.get(name) != new_versions.get(name):
            phrase = f"{name} {old_versions.get(name)} -> {new_versions.get(name)}"
            (changes if name == "swarmnav" else notes).append(phrase)
    return changes, notes


def check_fresh(paths: list[str]) -> tuple[list[str], list[str], list[str]]:
    """Every ``claims.json`` under ``paths`` (as ``--readme-table`` reads them) against today's inputs of its
    study: (one line per stale study naming its claims and what changed, the stale studies' names, notes)."""
    from swarmnav.models.errors import ConfigError
    from swarmnav.study.readme_table import read_documents
    from swarmnav.study.spec import load_study
    lines, stale, notes = [], [], []
    for document in read_documents(paths):
        name = document.get("study", "?")
        claims = ", ".join(c["id"] for c in document.get("claims", []))
        recorded = document.get("inputs")
        if not recorded:
            changes = ["its claims.json records no inputs (run before provenance was recorded)"]
        else:
            try:
                study = load_study(name)
                changes, study_notes = stale_inputs(recorded, study_inputs(
                    study.claims_only() if recorded.get("claims_only") else study))
            except ConfigError as exc:
                changes, study_notes = [f"its study cannot be loaded today ({exc})"], []
            notes += [f"{name}: {n}" for n in study_notes]
        if changes:
            stale.append(name)
            lines.append(f"stale: {name} (claims {claims}): {'; '.join(changes)}")
    return lines, stale, notes
