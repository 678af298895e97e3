"""The simulation layer: the only one that imports MuJoCo (with no GL library loaded; see :mod:`sim.gl_backend`)."""

from swarmnav.sim.gl_backend import import_mujoco

import_mujoco()
