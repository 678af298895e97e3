"""Argument types for the command line: numbers checked where argparse reads them; ``KEY=VALUE`` settings;
the shared ``--trust-code`` option.

Each raises ``argparse.ArgumentTypeError``, which argparse reports against the
option's name with exit code 2.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from swarmnav.models.contained_files import check_output_target, loads_toml
from swarmnav.models.errors import ConfigError
from swarmnav.models.scenario_limits import MAX_SETTING_CHARS

MAX_SEED = 2**63 - 1  # the largest integer a TOML scenario can hold, so --seed and ``seed`` agree


def seed(text: str) -> int:
    """A random seed: an integer from 0 to 2**63 - 1, as ``seed`` in a scenario file."""
    value = _integer(text)
    if not 0 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"must be an integer from 0 to {MAX_SEED}, got {text}")
    return value


def positive_int(text: str) -> int:
    """An integer of at least 1."""
    value = _integer(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {text}")
    return value


def non_negative_int(text: str) -> int:
    """An integer of at least 0."""
    value = _integer(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must not be negative, got {text}")
    return value


def positive_float(text: str) -> float:
    """A finite number above 0."""
    value = _number(text)
    if value <= 0.0:
        raise argparse.ArgumentTypeError(f"must be positive, got {text}")
    return value


def non_negative_float(text: str) -> float:
    """A finite number of at least 0."""
    value = _number(text)
    if value < 0.0:
        raise argparse.ArgumentTypeError(f"must not be negative, got {text}")
    return value


def int_in(low: int, high: int):
    """An argument type: an integer from ``low`` to ``high`` (a count with its stated maximum)."""
    def count(text: str) -> int:
        value = _integer(text)
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"must be an integer from {low:,} to {high:,}, got {text[:40]}")
        return value
    count.__name__ = "integer"
    return count


def float_in(low: float, high: float, low_open: bool = True):
    """An argument type: a finite number above ``low`` (or from it, without ``low_open``) up to ``high``."""
    def number(text: str) -> float:
        value = _number(text)
        if not ((value > low if low_open else value >= low) and value <= high):
            raise argparse.ArgumentTypeError(f"must be {'above' if low_open else 'at least'} {low:g} and at most "
                                             f"{high:g}, got {text[:40]}")
        return value
    number.__name__ = "number"
    return number


MAX_PATH_CHARS = 4_096  # Linux's PATH_MAX


def output_path(text: str) -> str:
    """An argument type: a file or folder to write, named (never empty: an empty --out is not "the default")."""
    if not text.strip():
        raise argparse.ArgumentTypeError("must name a file or folder, got an empty path")
    if len(text) > MAX_PATH_CHARS or "\x00" in text:
        raise argparse.ArgumentTypeError(f"not a usable path ({len(text):,} characters)")
    try:
        check_output_target(text, "path")
    except ConfigError as exc:  # a device, a FIFO or a socket where the output would go
        raise argparse.ArgumentTypeError(f"{text}: {exc.problem}") from None
    return text


def _integer(text: str) -> int:
    try:
        return int(text)
    except ValueError:  # also a string of more than 4,300 digits
        raise argparse.ArgumentTypeError(f"expected an integer, got {text[:40]!r}") from None


def _number(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text[:40]!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite, got {text}")
    return value


def add_trust_code_argument(parser: argparse.ArgumentParser) -> None:
    """``--trust-code``: this invocation may run code that a file it reads names (a ``policy``)."""
    parser.add_argument("--trust-code", action="store_true",
                        help="let the files this command reads name code to run (the policy navigator's "
                             "policy = 'module:function'); without it such a value is an error")


def parse_settings(pairs: list[str] | None, option: str = "--set") -> dict[str, Any]:
    """``KEY=VALUE`` pairs of an option; values are read as TOML (numbers, booleans, arrays) or else strings."""
    params: dict[str, Any] = {}
    for pair in pairs or []:
        key, sep, text = pair.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ConfigError(option, f"expected key=value, got {pair[:60]!r}")
        if len(pair) > MAX_SETTING_CHARS:
            raise ConfigError(f"{option} {key[:40]}", f"{len(pair):,} characters, more than the maximum "
                                                      f"{MAX_SETTING_CHARS:,} (MAX_SETTING_CHARS)")
        try:
            value = loads_toml(f"v = {text}", None, f"{option} {key}")["v"]
        except ConfigError as exc:
            if "malformed TOML" not in exc.problem:
                raise
            value = text
        params[key] = value
    return params


def check_output_file(path: str | None, option: str) -> None:
    """An output file option that names a folder is refused before any work (the work's results would be lost
    to a one-line error at the end)."""
    import os
    if path is not None and os.path.isdir(path):
        raise ConfigError(option, "Is a directory (give a file path)", path)
