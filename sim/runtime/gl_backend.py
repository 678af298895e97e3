"""No OpenGL until something renders: MuJoCo is imported with its GL backend disabled, and a context made on demand.

With ``MUJOCO_GL=egl`` (which the README, the Makefile and the CLI set),
``import mujoco`` imports ``mujoco.egl`` and so PyOpenGL's EGL, which loads
Mesa's ``libEGL``; ``import dm_control.mujoco`` does the same through
``dm_control._render``.  A process that loads PyTorch's triton after Mesa's EGL
dies with a segfault (issue 25), and one that never renders has no use for a GL
library.  So swarmnav imports both with ``MUJOCO_GL=disable`` in the environment
(:func:`import_mujoco`, run by ``swarmnav.sim``'s ``__init__``, installs an import
hook that does so when either is first imported, so starting the CLI still imports no MuJoCo) and puts the user's value back right after; nothing
GL-related is loaded until :func:`new_renderer` makes the first renderer.

:func:`new_renderer` picks the backend then: the user's ``MUJOCO_GL`` if it names
one (``egl``, ``osmesa``, ``glfw``), else ``egl``, which it writes into the
environment before importing MuJoCo's context class (as the user would have).  Every
renderer it makes is closed at interpreter exit (``atexit``, which runs before
modules are torn down), so a script that renders and exits without ``close()``
prints no EGL traceback (the hook is registered after the first context is made, so it
runs before MuJoCo's own ``eglTerminate`` hook).

Loading no GL library at import is not enough: the first context loads Mesa's
software driver (``swrast_dri.so``) and with it ``libLLVM-15``, and importing triton
(PyTorch's compiler; its CUDA build installs it, and torch imports it when installed
on ``PPO(...)`` or ``PPO.load``) after that dies with a segfault (exit 139, nothing
on stderr; seen with triton 3.7.1, probably its bundled LLVM meeting Mesa's).  Triton
imported first, both work.  So :func:`new_renderer` imports triton before the first
context when it is installed and not yet imported (about 0.1 s of CPU), and a policy
that loads PyTorch lazily, on its first action after ``--video`` made its context, runs.

``dm_control``'s own renderer (``Physics.render``) stays disabled in a process
that imported it through swarmnav: the environment renders with
:class:`swarmnav.video.render.SceneRenderer`, never with ``Physics.render``.  A user who
imported ``mujoco`` or ``dm_control`` before swarmnav keeps what they loaded.
"""

from __future__ import annotations

import atexit
import importlib.abc
import importlib.util
import os
import sys
import weakref
from typing import Any

DISABLED = "disable"
DEFAULT_BACKEND = "egl"
BACKENDS = ("egl", "osmesa", "glfw")

_renderers: weakref.WeakSet = weakref.WeakSet()
_state = {"registered": False}


GL_READERS = ("mujoco", "dm_control._render")  # the modules that read MUJOCO_GL when they are executed


class _DisabledGLLoader(importlib.abc.Loader):
    """Runs a module's own loader with ``MUJOCO_GL=disable``, then puts the user's value back."""

    def __init__(self, loader: importlib.abc.Loader):
        self.loader = loader

    def create_module(self, spec):
        return self.loader.create_module(spec)

    def exec_module(self, module) -> None:
        saved = os.environ.get("MUJOCO_GL")
        os.environ["MUJOCO_GL"] = DISABLED
        try:
            self.loader.exec_module(module)
        finally:
            if saved is None:
                os.environ.pop("MUJOCO_GL", None)
            else:
                os.environ["MUJOCO_GL"] = saved


class _DisableGLOnImport(importlib.abc.MetaPathFinder):
    """Finds ``mujoco`` and ``dm_control._render`` as the other finders do, with :class:`_DisabledGLLoader`."""

    def __init__(self) -> None:
        self._finding = False

    def find_spec(self, name, path, target=None):
        if name not in GL_READERS or self._finding:
            return None
        self._finding = True
        try:
            spec = importlib.util.find_spec(name)
        finally:
            self._finding = False
        if spec is None or spec.loader is None:
            return None
        spec.loader = _DisabledGLLoader(spec.loader)
        return spec


def import_mujoco() -> None:
    """From now on, ``mujoco`` and ``dm_control._render`` import with the GL backend disabled (lazily: this imports
    neither; the CLI starts without MuJoCo).  A module already imported keeps what it loaded."""
    if not any(isinstance(finder, _DisableGLOnImport) for finder in sys.meta_path):
        sys.meta_path.insert(0, _DisableGLOnImport())


def backend() -> str:
    """The backend a renderer will use: the user's ``MUJOCO_GL`` when it names one, else ``egl``."""
    chosen = os.environ.get("MUJOCO_GL", "").lower().strip()
    return chosen if chosen in BACKENDS else DEFAULT_BACKEND


def _import_triton_first() -> None:
    """Import triton, if it is installed and not imported yet, before Mesa's LLVM is loaded (see above)."""
    if "triton" in sys.modules or importlib.util.find_spec("triton") is None:
        return
    try:
        import triton  # noqa: F401
    except Exception:  # a triton that cannot be imported cannot crash a later import of it either
        pass


def _context_class() -> Any:
    """MuJoCo's GL context class for :func:`backend`, installed where ``mujoco.Renderer`` looks for it."""
    from mujoco.rendering.classic import gl_context
    if getattr(gl_context, "GLContext", None) is not None:
        return gl_context.GLContext
    _import_triton_first()
    name = backend()
    os.environ["MUJOCO_GL"] = name
    if name == "egl":
        from mujoco.egl import GLContext
    elif name == "osmesa":
        from mujoco.osmesa import GLContext
    else:
        from mujoco.glfw import GLContext
    gl_context.GLContext = GLContext
    return GLContext


def new_renderer(model: Any, height: int, width: int) -> Any:
    """A ``mujoco.Renderer`` with a GL context made now, closed at exit if not before."""
    import mujoco
    _context_class()
    renderer = mujoco.Renderer(model, height, width)
    if not _renderers and not _state["registered"]:
        # after the first context: MuJoCo's EGL registers eglTerminate then, and atexit runs last-in first
        atexit.register(_close_renderers)
        _state["registered"] = True
    _renderers.add(renderer)
    return renderer


def _close_renderers() -> None:
    for renderer in list(_renderers):
        try:
            renderer.close()
        except Exception:  # the context may already be gone; exiting is not the place to report it
            pass
    _renderers.clear()
