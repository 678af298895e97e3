"""``python -m swarmnav.sim.cli``: the ``swarmnav`` command."""

import sys

from swarmnav.sim.cli.main import main

sys.exit(main())
