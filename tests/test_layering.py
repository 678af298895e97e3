"""Imports point one way: models <- planners <- controllers <- sim.

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
