import os

# Offscreen rendering on CPU machines: Mesa's EGL.
os.environ.setdefault("MUJOCO_GL", "egl")
