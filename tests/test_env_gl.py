"""No GL library is loaded until something renders (issue 25): checked in fresh interpreters, via /proc/self/maps."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

pytest.importorskip("dm_control")

GL_LIBRARIES = ("libEGL", "libGL", "libOSMesa", "libglfw", "libgbm")

MAPPED = """
def mapped():
    with open("/proc/self/maps") as maps:
        return sorted({line.split()[-1] for line in maps if any(lib in line for lib in %r)})
""" % (GL_LIBRARIES,)


def run_python(code: str, mujoco_gl: str | None = "egl") -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    if mujoco_gl is not None:
        env["MUJOCO_GL"] = mujoco_gl
    return subprocess.run([sys.executable, "-c", textwrap.dedent(MAPPED + code)], capture_output=True, text=True,
                          env=env, timeout=300)


@pytest.mark.parametrize("mujoco_gl", ["egl", None])
def test_making_and_stepping_an_environment_maps_no_gl_library(mujoco_gl):
    done = run_python("""
import os
import swarmnav
import swarmnav.env
env = swarmnav.env.NavigateEnv("gwo-scenario-2")
env.reset(seed=1)
for _ in range(5):
    env.step(env.action_space.sample())
print(mapped(), os.environ.get("MUJOCO_GL"))
""", mujoco_gl)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("]")[0] + "]" == "[]", done.stdout
    assert done.stdout.strip().endswith(str(mujoco_gl)), "the user's MUJOCO_GL is left as it was"


def test_render_makes_the_context_on_demand_and_exit_without_close_is_clean():
    done = run_python("""
import os
import swarmnav.env
env = swarmnav.env.NavigateEnv("gwo-scenario-2", render_mode="rgb_array", width=64, height=48)
env.reset(seed=1)
assert mapped() == [], mapped()
frame = env.render()
print(frame.shape, frame.std() > 0, any("libEGL" in lib for lib in mapped()), os.environ["MUJOCO_GL"])
""", mujoco_gl=None)  # no close(): the exit hook releases the context
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["(48,", "64,", "3)", "True", "True", "egl"], done.stdout
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr, done.stderr


def test_triton_imports_beside_the_environment_and_after_a_render():
    """Issue 25's 'done when': ``MUJOCO_GL=egl python -c "import swarmnav.env, triton"`` exits 0; and triton
    (which PyTorch imports when it is installed, e.g. on ``PPO.load``) imported after a render, as a policy loaded
    lazily under ``--video`` does, no longer dies with a segfault (exit -11 before the first context imported it)."""
    pytest.importorskip("triton")  # the test extra installs it on Linux
    done = run_python("import swarmnav.env, triton")
    assert done.returncode == 0, (done.returncode, done.stderr)
    done = run_python("""
import swarmnav.env
env = swarmnav.env.NavigateEnv("gwo-scenario-2", render_mode="rgb_array", width=64, height=48)
env.reset(seed=1)
first = env.render()
import triton
env.step(env.action_space.sample())
second = env.render()
print(first.std() > 0, second.std() > 0, any("libEGL" in lib for lib in mapped()))
""")
    assert done.returncode == 0, (done.returncode, done.stderr)
    assert done.stdout.split() == ["True", "True", "True"], done.stdout
