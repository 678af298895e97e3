"""Only sim/ may import MuJoCo; planners/ and controllers/ stay plain Python + NumPy."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
IMPORT_MUJOCO = re.compile(r"^\s*(import\s+mujoco|from\s+mujoco\b|import\s+dm_control|from\s+dm_control\b)", re.M)


def test_mujoco_is_imported_only_in_sim():
    offenders = []
    for folder in ("planners", "controllers", "models"):
        for path in (ROOT / folder).rglob("*.py"):
            if IMPORT_MUJOCO.search(path.read_text(encoding="utf-8")):
                offenders.append(str(path.relative_to(ROOT)))
    assert offenders == []


def test_the_check_would_catch_an_import(tmp_path):
    assert IMPORT_MUJOCO.search("x = 1\nimport mujoco\n")
    assert IMPORT_MUJOCO.search("from mujoco import MjModel\n")
    assert not IMPORT_MUJOCO.search("# mujoco is only in sim/\n")


def test_no_grab_bag_utils_module():
    assert not list(ROOT.glob("*/utils.py"))
