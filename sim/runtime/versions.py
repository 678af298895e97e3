"""The software versions a run records (in its log's metadata, in study rows)."""

from __future__ import annotations

import platform
from importlib import metadata

import mujoco


def software_versions(*packages: str) -> dict[str, str]:
    """swarmnav, MuJoCo and Python versions, plus those of the named distributions."""
    out = {}
    for name in ("swarmnav", *packages):
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "unknown"
    return {**out, "mujoco": mujoco.__version__, "python": platform.python_version()}
