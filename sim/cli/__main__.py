"""``python -m swarmnav.cli``: the ``swarmnav`` command."""

import sys

from swarmnav.cli.main import main

sys.exit(main())
