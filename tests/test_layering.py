"""Imports point one way: models <- planners <- controllers <- sim; no cycle; nothing below the CLI imports it
and no runtime module imports a benchmark.

Every import of every module is read with ``ast`` (imports inside functions
included), so a lazy import that climbs a floor fails here too.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
LAYERS = ("models", "planners", "controllers", "sim")
# What each layer may import from the project (itself included).
ALLOWED = {layer: set(LAYERS[:i + 1]) for i, layer in enumerate(LAYERS)}
SIM_ONLY = {"mujoco", "dm_control", "dm_env", "gymnasium", "foxglove", "mcap", "mcap_protobuf"}
# Loading code by name outside sim/: only the policy navigator, which loads the user's
# ``module:function`` policy (never project code) with pkgutil.resolve_name.
CODE_LOADERS = {"importlib", "pkgutil"}
USER_CODE_LOADER = ("controllers/navigators/policy.py", "pkgutil")


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
    source = "import numpy\n\ndef f():\n    from swarmnav.sim.runner import Simulation\n    return Simulation\n"
    assert violations(source, "planners") == ["line 4: swarmnav.sim.runner (planners may import only "
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


def module_name(layer: str, path: Path) -> str:
    """The installed name of a project file (``sim/api/`` is the top-level ``swarmnav`` package)."""
    parts = list(path.relative_to(ROOT / layer).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    if layer == "sim" and parts[:1] == ["api"]:
        return ".".join(["swarmnav", *parts[1:]])
    return ".".join(["swarmnav", layer, *parts])


def import_graph() -> dict[str, set[str]]:
    """Project module -> the project modules it imports, at any depth (imports inside functions included)."""
    files = {module_name(layer, path): (layer, path) for layer, path in project_modules()}
    graph: dict[str, set[str]] = {name: set() for name in files}
    for name, (layer, path) in files.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
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


CLI = "swarmnav.sim.cli"  # sim/cli/: the parser and the commands
BENCHMARKS = "swarmnav.sim.benchmarks"  # sim/benchmarks/: run by `swarmnav bench` only


def in_package(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


def outside_importers(graph: dict[str, set[str]], package: str, allowed: tuple[str, ...] = ()) -> list[str]:
    """The modules outside ``package`` (and outside the ``allowed`` packages) that import a module of it."""
    return sorted(name for name, targets in graph.items()
                  if not any(in_package(name, home) for home in (package, *allowed))
                  and any(in_package(target, package) for target in targets))


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
    graph = {"swarmnav.sim.cli.main": {"swarmnav.sim.runner", "swarmnav.sim.benchmarks.sim"},
             "swarmnav.sim.runner": {"swarmnav.sim.cli.commands"},
             "swarmnav.sim.client": {"swarmnav.sim.benchmarks"},  # a name that merely starts like the package
             "swarmnav.sim.benchmarks.sim": {"swarmnav.sim.runner"}}
    assert outside_importers(graph, CLI) == ["swarmnav.sim.runner"]
    assert outside_importers(graph, BENCHMARKS, allowed=(CLI,)) == ["swarmnav.sim.client"]
    assert outside_importers(graph, BENCHMARKS) == ["swarmnav.sim.cli.main", "swarmnav.sim.client"]
