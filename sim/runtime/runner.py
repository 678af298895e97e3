"""Deprecated name of :mod:`swarmnav.sim.simulation` (the module that holds :class:`Simulation`), kept for one
release: importing it warns; import ``swarmnav.sim.simulation`` instead."""

import warnings

from swarmnav.sim.simulation import MAP_LOG_PERIOD_S, Simulation

warnings.warn("swarmnav.sim.runner is renamed swarmnav.sim.simulation; the old name goes in the next release",
              DeprecationWarning, stacklevel=2)

__all__ = ["MAP_LOG_PERIOD_S", "Simulation"]
