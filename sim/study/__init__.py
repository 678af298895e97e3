"""Studies: scenario x planner x navigator x seed grids, one Parquet row per run, statistics, a report.

``spec`` reads a study file, ``grid`` expands it into cells, ``cell`` runs one cell
through the one episode function, ``engines`` runs many (local processes or Ray),
``rows`` writes and reads the Parquet tables, ``statistics`` and ``report`` turn the
rows into tables, tests and plots.  The ``study``, ``studies`` and ``report``
subcommands are in :mod:`swarmnav.cli.study`.
"""
