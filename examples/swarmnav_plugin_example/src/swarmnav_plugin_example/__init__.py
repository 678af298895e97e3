"""An example swarmnav plugin (see its pyproject.toml for the entry points)."""
