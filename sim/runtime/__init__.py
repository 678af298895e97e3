"""The physics runtime (``sim/runtime/``, installed as ``swarmnav.sim``): the floor that steps MuJoCo (with no GL
library loaded; see :mod:`swarmnav.sim.gl_backend`).  Video, logs, studies, the environment, benchmarks, the API
and the CLI stand on it (``pyproject.toml``'s ``package-dir``).

A folder named ``swarmnav`` on the import path ahead of the installed package (a clone of the repository in the
working directory, with an editable install whose folders Python finds by an import hook) makes ``swarmnav`` a
namespace package without ``run``; it is stopped here, at the first import of the runtime, with one line naming
the folder (exit 2), instead of an ``AttributeError`` later.
"""

import sys as _sys

_top = _sys.modules.get("swarmnav")
if _top is not None and getattr(_top, "__file__", None) is None:  # a namespace package: a folder shadows it
    _folder = next(iter(getattr(_top, "__path__", [])), "swarmnav")
    print(f"swarmnav: error: the folder {_folder} shadows the installed swarmnav package (a folder named swarmnav "
          "on the import path, e.g. a clone in the working directory): run from another folder, or rename it",
          file=_sys.stderr)
    raise SystemExit(2)

from swarmnav.sim.gl_backend import import_mujoco  # noqa: E402

import_mujoco()
