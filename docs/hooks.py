"""MkDocs hook: the source tree as it installs, for mkdocstrings to read.

swarmnav installs its folders under one name (``pyproject.toml``'s ``package-dir``: ``sim/api`` is
``swarmnav``, ``planners`` is ``swarmnav.planners``, ``sim/runtime`` is ``swarmnav.sim``, ...), which no static
reader can follow from the repository.  Before the build this links them, as they install, into ``build/docs-src/swarmnav/`` (``build/``
is git-ignored), the folder mkdocs.yml's python handler searches.
"""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

from mkdocs.plugins import event_priority

REPO = Path(__file__).resolve().parent.parent
TREE = REPO / "build" / "docs-src" / "swarmnav"
# swarmnav.X -> its folder, as pyproject.toml maps it (the package swarmnav itself, sim/api, is linked file by file)
SUBPACKAGES = {name.split(".", 1)[1]: folder for name, folder in tomllib.loads(
    (REPO / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]["package-dir"].items()
    if name != "swarmnav"}


def _link(link: Path, target: Path) -> None:
    """``link`` -> ``target``, replaced atomically: two builds at once (the test suite's workers) never see it
    missing or trip over each other's link."""
    if link.is_symlink() and link.resolve() == target.resolve():
        return
    fresh = link.with_name(f".{link.name}.{os.getpid()}")
    fresh.unlink(missing_ok=True)
    fresh.symlink_to(target, target_is_directory=target.is_dir())
    os.replace(fresh, link)


@event_priority(100)  # before mkdocstrings' on_config, which keeps only search paths that exist
def on_config(config):
    TREE.mkdir(parents=True, exist_ok=True)
    for source in (REPO / "sim" / "api").glob("*.py"):
        _link(TREE / source.name, source)
    for name, folder in SUBPACKAGES.items():
        _link(TREE / name, REPO / folder)
    return config
