"""The ``swarmnav`` command line: the parser and the commands.

:mod:`.main` is the entry point (``swarmnav``, ``python -m swarmnav.cli``): the parser, the exit codes and
the commands that drive an episode (``plan``, ``run``, ``scenarios``, ``planners``, ``navigators``).
:mod:`.commands` holds the options of the subcommands implemented in modules below the CLI (``bench``,
``replay``, ``plot``, ``log``, ``foxglove-layout``, ``study``), each imported only when its subcommand runs;
:mod:`.log` is ``log info`` / ``log recover``, :mod:`.study` is ``study``, ``studies`` and ``report``, and
:mod:`.stop_signal` turns SIGTERM into a clean stop.

Nothing outside this package imports it: the defaults that the plot, the replay, the studies and the
benchmarks share with it are in :mod:`sim.defaults`, the option types in :mod:`sim.options`
(``tests/test_layering.py`` checks it).
"""
