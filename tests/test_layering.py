"""The floors of the installed package: every import points down (or stays on its floor), no cycle, and every
file is importable under exactly one name.

The installed names come from ``pyproject.toml``'s ``package-dir`` (``sim/runtime`` is ``swarmnav.sim``,
``sim/api`` is ``swarmnav`` itself, ...), and are checked against the installed package's own finder.  Every
import of every module is read with ``ast`` (imports inside functions included), so a lazy import that climbs a
floor fails here too.
"""

import ast
import functools
import importlib.util
import re
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
PACKAGE_DIRS: dict[str, str] = PYPROJECT["package-dir"]  # installed name -> its folder
# The floors, from the bottom up: a module may import its own floor and the floors below, never one above.
FLOORS: tuple[tuple[str, ...], ...] = (
    ("swarmnav.models",),
    ("swarmnav.planners",),
    ("swarmnav.controllers",),
    ("swarmnav.sim",),  # the physics runtime (sim/runtime/): scene, stepper, simulation, episode, sensing, ...
    ("swarmnav.video",),  # what uses the runtime: rendering, the run log, studies and the dm_env task
    ("swarmnav.log",),
    ("swarmnav.study", "swarmnav.env"),
    ("swarmnav.benchmarks",),
    ("swarmnav",),  # the Python API (sim/api/: calls, results)
    ("swarmnav.cli",),  # the command line, on top
)
LAYERS = ("models", "planners", "controllers", "sim")  # the repository's source folders
# What each source folder may import from the project (itself included).
ALLOWED = {layer: set(LAYERS[:i + 1]) for i, layer in enumerate(LAYERS)}
SIM_ONLY = {"mujoco", "dm_control", "dm_env", "gymnasium", "foxglove", "mcap", "mcap_protobuf"}
# Loading code by name outside sim/: only the policy navigator, which loads the user's
# ``module:function`` policy (never project code) with pkgutil.resolve_name.
CODE_LOADERS = {"importlib", "pkgutil"}
USER_CODE_LOADER = ("controllers/navigators/policy.py", "pkgutil")


def floor_of(module: str) -> int:
    """The floor of an installed module: that of the longest package name it starts with."""
    best = max((package for floor in FLOORS for package in floor if in_package(module, package)), key=len)
    return next(index for index, floor in enumerate(FLOORS) if best in floor)


def imported_modules(source: str, package: str) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import in a module's source, at any depth."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found.extend((node.lineno, alias.name) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative: resolve against the module's package
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            found.append((node.lineno, name))
    return found


def violations(source: str, layer: str, relative_path: str = "") -> list[str]:
    """Imports in a module of ``layer`` that climb a floor, name an old top-level package, or use MuJoCo outside sim."""
    out = []
    for line, name in imported_modules(source, f"swarmnav.{layer}"):
        parts = name.split(".")
        if parts[0] in LAYERS:
            out.append(f"line {line}: {name} (import through the swarmnav namespace)")
        elif parts[0] == "swarmnav" and len(parts) > 1 and parts[1] in LAYERS and parts[1] not in ALLOWED[layer]:
            out.append(f"line {line}: {name} ({layer} may import only {sorted(ALLOWED[layer])})")
        elif parts[0] in SIM_ONLY and layer != "sim":
            out.append(f"line {line}: {name} (only sim/ touches MuJoCo and the log formats)")
        elif parts[0] in CODE_LOADERS and layer != "sim" and (relative_path, parts[0]) != USER_CODE_LOADER:
            out.append(f"line {line}: {parts[0]} outside sim")
    return out


def project_modules():
    for layer in LAYERS:
        for path in sorted((ROOT / layer).rglob("*.py")):
            yield layer, path


@pytest.mark.parametrize("layer,path", list(project_modules()), ids=lambda v: str(v).rsplit("/", 2)[-1])
def test_imports_point_one_way(layer, path):
    assert violations(path.read_text(encoding="utf-8"), layer, path.relative_to(ROOT).as_posix()) == []


def test_no_module_loads_project_code_by_string():
    for layer, path in project_modules():
        text = path.read_text(encoding="utf-8")
        assert "import_module(" not in text and "__import__(" not in text, path


def test_the_check_catches_an_import_inside_a_function():
    source = "import numpy\n\ndef f():\n    from swarmnav.sim.simulation import Simulation\n    return Simulation\n"
    assert violations(source, "planners") == ["line 4: swarmnav.sim.simulation (planners may import only "
                                              "['models', 'planners'])"]
    assert violations(source, "sim") == []
    assert violations("def g():\n    import mujoco\n", "controllers")
    assert violations("from planners.problem import Problem\n", "sim")
    assert violations("from ..sim import cli\n", "models")  # relative, resolved against swarmnav.models
    assert violations("import pkgutil\n", "controllers", "controllers/navigators/follow.py")
    assert violations("import pkgutil\n", "controllers", "controllers/navigators/policy.py") == []
    assert violations("import importlib\n", "controllers", "controllers/navigators/policy.py")


def test_no_grab_bag_utils_module():
    assert not list(ROOT.glob("*/utils.py"))


def installed_names(path: Path) -> list[str]:
    """Every name a project file is importable under: one per ``package-dir`` folder it sits in through a chain
    of packages (folders with ``__init__.py``)."""
    names = []
    for package, folder in PACKAGE_DIRS.items():
        base = ROOT / folder
        if not path.is_relative_to(base):
            continue
        relative = path.relative_to(base)
        folders = [base / Path(*relative.parts[:i]) for i in range(len(relative.parts))]
        if all((f / "__init__.py").is_file() for f in folders):
            parts = list(relative.with_suffix("").parts)
            names.append(".".join([package, *(parts[:-1] if parts[-1] == "__init__" else parts)]))
    return names


def module_name(layer: str, path: Path) -> str:
    """The one installed name of a project file (``sim/runtime/`` is ``swarmnav.sim``, ``sim/api/`` the top-level
    ``swarmnav`` package, ...; ``pyproject.toml``'s ``package-dir``)."""
    names = installed_names(path)
    assert len(names) == 1, f"{path.relative_to(ROOT)} is importable as {names}"
    return names[0]


@functools.cache
def parsed(path: Path) -> ast.Module:
    """A project file's syntax tree, parsed once per session (several checks read every file)."""
    return ast.parse(path.read_text(encoding="utf-8"))


@functools.cache
def import_graph() -> dict[str, set[str]]:
    """Project module -> the project modules it imports, at any depth (imports inside functions included)."""
    files = {module_name(layer, path): (layer, path) for layer, path in project_modules()}
    graph: dict[str, set[str]] = {name: set() for name in files}
    for name, (layer, path) in files.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in ast.walk(parsed(path)):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    base = ".".join(package.split(".")[:len(package.split(".")) - node.level + 1] + ([base] if base else []))
                targets = [base] + [f"{base}.{alias.name}" for alias in node.names]
            graph[name].update(t for t in targets if t in files and t != name)
    return graph


def import_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    cycles: list[list[str]] = []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    cycles.append(sorted(component))
    return cycles


def test_no_import_cycle_among_the_project_modules():
    assert import_cycles(import_graph()) == []


def test_the_cycle_check_finds_a_cycle():
    assert import_cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert import_cycles({"a": {"b"}, "b": set()}) == []


CLI = "swarmnav.cli"  # sim/cli/: the parser and the commands
BENCHMARKS = "swarmnav.benchmarks"  # sim/benchmarks/: run by `swarmnav bench` only


def in_package(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


def outside_importers(graph: dict[str, set[str]], package: str, allowed: tuple[str, ...] = ()) -> list[str]:
    """The modules outside ``package`` (and outside the ``allowed`` packages) that import a module of it."""
    return sorted(name for name, targets in graph.items()
                  if not any(in_package(name, home) for home in (package, *allowed))
                  and any(in_package(target, package) for target in targets))


def upward_imports(graph: dict[str, set[str]]) -> list[str]:
    """``importer -> imported`` for every import from a lower floor to a higher one."""
    return sorted(f"{name} -> {target}" for name, targets in graph.items() for target in targets
                  if floor_of(target) > floor_of(name))


def test_every_file_is_importable_under_exactly_one_name():
    files = [path for layer, path in project_modules()]
    assert len(files) > 200
    assert {path.relative_to(ROOT).as_posix(): names for path in files
            if len(names := installed_names(path)) != 1} == {}


def test_every_package_folder_is_installed_and_found_by_its_name():
    """Each folder with ``__init__.py`` is in ``packages`` (a wheel would leave it out otherwise), and the
    installed package's finder resolves each name to that very folder."""
    folders = sorted({path.parent for layer, path in project_modules() if path.name == "__init__.py"})
    names = {module_name("", folder / "__init__.py"): folder for folder in folders}
    assert sorted(set(names) - set(PYPROJECT["packages"])) == []
    for name, folder in names.items():
        spec = importlib.util.find_spec(name)
        assert spec is not None and Path(spec.origin).resolve() == (folder / "__init__.py").resolve(), name
    simulation = importlib.util.find_spec("swarmnav.sim.simulation")
    assert Path(simulation.origin).resolve() == ROOT / "sim" / "runtime" / "simulation.py"


def test_a_folder_of_one_floor_is_not_reachable_inside_another():
    """No second name: the folders above the runtime are not packages of ``swarmnav.sim``, nor the API's."""
    for package in ("api", "cli", "study", "log", "env", "video", "benchmarks", "runtime"):
        assert importlib.util.find_spec(f"swarmnav.sim.{package}") is None, package
    assert importlib.util.find_spec("swarmnav.api") is None and importlib.util.find_spec("swarmnav.runtime") is None


def test_every_installed_package_has_a_floor():
    assert sorted(name for name in PACKAGE_DIRS if not any(name in floor for floor in FLOORS)) == []


def test_no_import_climbs_a_floor():
    graph = import_graph()
    assert sum(len(targets) for targets in graph.values()) > 500  # the check sees the imports
    assert upward_imports(graph) == []


def test_the_floor_check_finds_an_import_that_climbs():
    graph = {"swarmnav.cli.main": {"swarmnav.calls", "swarmnav.sim.scene"},
             "swarmnav.benchmarks.paper_defaults": {"swarmnav", "swarmnav.sim.episode"},
             "swarmnav.sim.plot": {"swarmnav.log.reader"},
             "swarmnav.study.cell": {"swarmnav.env.task", "swarmnav.log.writer"},
             "swarmnav.results": {"swarmnav.sim.episode"}}
    assert upward_imports(graph) == ["swarmnav.benchmarks.paper_defaults -> swarmnav",
                                     "swarmnav.sim.plot -> swarmnav.log.reader"]
    assert floor_of("swarmnav.calls") == floor_of("swarmnav") > floor_of("swarmnav.benchmarks.sim")
    assert floor_of("swarmnav.simulation_like") == floor_of("swarmnav")  # a name that merely starts like a package


def test_only_the_command_line_imports_the_command_line():
    graph = import_graph()
    assert any(in_package(name, CLI) for name in graph)  # the check sees the package
    assert outside_importers(graph, CLI) == []


def test_no_runtime_module_imports_a_benchmark():
    """Benchmarks stay outside the runtime's import graph: only the command line (``bench``) imports them."""
    graph = import_graph()
    assert any(in_package(target, BENCHMARKS) for name, targets in graph.items() if in_package(name, CLI)
               for target in targets)  # the check sees the bench command's (lazy) imports
    assert outside_importers(graph, BENCHMARKS, allowed=(CLI,)) == []


def test_the_package_checks_find_an_importer():
    graph = {"swarmnav.cli.main": {"swarmnav.sim.simulation", "swarmnav.benchmarks.sim"},
             "swarmnav.sim.simulation": {"swarmnav.cli.commands"},
             "swarmnav.client": {"swarmnav.benchmarks"},  # a name that merely starts like the package
             "swarmnav.benchmarks.sim": {"swarmnav.sim.simulation"}}
    assert outside_importers(graph, CLI) == ["swarmnav.sim.simulation"]
    assert outside_importers(graph, BENCHMARKS, allowed=(CLI,)) == ["swarmnav.client"]
    assert outside_importers(graph, BENCHMARKS) == ["swarmnav.cli.main", "swarmnav.client"]


def test_the_deprecated_runner_name_warns_and_is_the_same_class():
    import sys
    sys.modules.pop("swarmnav.sim.runner", None)
    with pytest.warns(DeprecationWarning, match="swarmnav.sim.simulation"):
        from swarmnav.sim.runner import Simulation
    from swarmnav.sim.simulation import Simulation as Current
    assert Simulation is Current


def test_every_import_of_the_package_names_one_of_its_modules():
    """``from swarmnav.X import ...`` names an installed module (or a compiled extension of pyproject.toml), and
    ``from swarmnav.X import y`` a module of it or a name its ``__init__.py`` has: an old or second name
    (``swarmnav.sim.api.calls``, ``from swarmnav.sim import plot``) fails here."""
    modules = {module_name(layer, path): path for layer, path in project_modules()}
    known = set(modules) | {extension["name"] for extension in PYPROJECT["ext-modules"]}
    unknown = []
    for layer, path in [*project_modules(), *(("tests", p) for p in sorted((ROOT / "tests").glob("*.py")))]:
        for node in ast.walk(parsed(path)):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
                names = [node.module]
                if node.module in modules and modules[node.module].name == "__init__.py":
                    package_text = modules[node.module].read_text(encoding="utf-8")
                    names += [f"{node.module}.{alias.name}" for alias in node.names
                              if not re.search(rf"\b{alias.name}\b", package_text)]
            else:
                continue
            unknown += [f"{path.relative_to(ROOT)}:{node.lineno}: {name}" for name in names
                        if name.split(".")[0] == "swarmnav" and name not in known and name != "swarmnav.sim.runner"]
    assert unknown == []
