"""Bad input: the one error type for a scenario field, a planner parameter or a command-line value.

It lives on the ground floor (``models``) because every layer validates input;
the CLI maps it to exit code 2.  Planning failures are ``planners.errors``.
"""

from __future__ import annotations


class ConfigError(ValueError):
    """Invalid user input: a scenario field, a planner parameter, a CLI option.

    Attributes:
        source: the file (or other origin) the value came from, if known.
        field: dotted path of the offending field, e.g. ``obstacles[2].radius_m``.
        problem: what is wrong with it, in a few words.
    """

    def __init__(self, field: str, problem: str, source: str | None = None):
        self.source = source
        self.field = field
        self.problem = problem
        where = f"{source}: " if source else ""
        super().__init__(f"{where}{field}: {problem}")
