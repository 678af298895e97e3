"""One reader for the project's TOML: scenarios, studies, suites and component parameter tables.

A :class:`TomlTable` is one table of a document that knows its file (``source``) and its key path
(``where``, e.g. ``obstacles[3].motion``).  Its typed getters (:meth:`~TomlTable.string`,
:meth:`~TomlTable.number` with a :class:`Range`, :meth:`~TomlTable.integer`, :meth:`~TomlTable.boolean`,
:meth:`~TomlTable.array`, :meth:`~TomlTable.table`, :meth:`~TomlTable.tables`) return the checked value, and
unknown keys are found by :meth:`~TomlTable.close` (every key never read) or :meth:`~TomlTable.only`.
Every problem is one :class:`~swarmnav.models.errors.ConfigError`: the file, the field's dotted path and what
is wrong, printed on one line (``scenario.toml: obstacles[3].radius_m: must be positive, got 0``), which the
CLI maps to exit code 2.

The checks of a single value (:func:`check_number`, ...) are public too, for values that do not sit in a
table of the file (a ``--set`` value, a planner's own consistency check).
"""

from __future__ import annotations

import math
import types
import typing
from dataclasses import dataclass
from pathlib import Path as FilePath
from typing import Any, Iterable, NoReturn

from swarmnav.models.contained_files import loads_toml, read_input_text
from swarmnav.models.errors import ConfigError

#: The default of a required key: reading it when it is absent is an error ("is required").
REQUIRED: Any = ...


@dataclass(frozen=True)
class Range:
    """The values a number may take: ``low``..``high``, ``low`` (``high``) itself excluded when ``low_open``
    (``high_open``)."""

    low: float
    high: float
    low_open: bool = False
    high_open: bool = False

    def holds(self, value: float) -> bool:
        try:
            if not math.isfinite(value):
                return False
        except OverflowError:  # an integer beyond any float
            return False
        return (self.low < value if self.low_open else self.low <= value) and \
            (value < self.high if self.high_open else value <= self.high)

    def requirement(self) -> str:
        """What a value outside the range must be, in words (``must be positive``, ``must be in [0, 1]``)."""
        if self.high == math.inf and not self.high_open:
            if self.low == 0.0:
                return "must be positive" if self.low_open else "must not be negative"
            if not self.low_open:
                return f"must be at least {_shown_number(self.low)}"
        if self.low == -math.inf and not self.low_open and not self.high_open:
            return f"must be at most {_shown_number(self.high)}"
        return f"must be in {self}"

    def __str__(self) -> str:
        return (f"{'(' if self.low_open else '['}{_shown_number(self.low)}, {_shown_number(self.high)}"
                f"{')' if self.high_open else ']'}")


def _shown_number(value: float) -> str:
    """An integer in full (a seed's 2**63 - 1), a float short (``1e+06``)."""
    return str(value) if isinstance(value, int) else f"{value:g}"


def within(low: float, high: float = math.inf) -> Range:
    """[low, high] (an integer bound is kept exact: it compares exactly with integers)."""
    return Range(low, high)


def above(low: float, high: float = math.inf) -> Range:
    """(low, high]: e.g. a positive length, ``above(0, 100)``."""
    return Range(low, high, low_open=True)


POSITIVE = above(0)
NON_NEGATIVE = within(0)


def fail(field: str, problem: str, source: str | None = None) -> NoReturn:
    """Raise the one error of bad input: ``source: field: problem``."""
    raise ConfigError(field, problem, source)


def check_number(value: Any, field: str, source: str | None = None, bounds: Range | None = None) -> float:
    """A finite number (an integer or a float, not a bool) within ``bounds``, as a float."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        fail(field, f"expected a number, got {value!r}", source)
    try:
        number = float(value)
    except OverflowError:  # an integer beyond any float
        fail(field, f"must be finite, got {value!r}", source)
    if not math.isfinite(number):
        fail(field, f"must be finite, got {value!r}", source)
    if bounds is not None and not bounds.holds(number):
        fail(field, f"{bounds.requirement()}, got {number:g}", source)
    return number


def check_integer(value: Any, field: str, source: str | None = None, bounds: Range | None = None,
                  integral_float: bool = False) -> int:
    """An integer (not a bool; with ``integral_float``, also a float with no fraction) within ``bounds``."""
    if integral_float and isinstance(value, float) and math.isfinite(value) and value == int(value):
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, int):
        fail(field, f"expected an integer, got {value!r}", source)
    if bounds is not None and not bounds.holds(value):
        fail(field, f"{bounds.requirement()}, got {value}", source)
    return value


def check_boolean(value: Any, field: str, source: str | None = None) -> bool:
    if not isinstance(value, bool):
        fail(field, f"expected true or false, got {value!r}", source)
    return value


def check_string(value: Any, field: str, source: str | None = None, choices: Iterable[str] | None = None,
                 non_empty: bool = False) -> str:
    """A string; with ``non_empty``, not blank; with ``choices``, one of them."""
    if not isinstance(value, str):
        fail(field, f"expected {'a non-empty' if non_empty else 'a'} string, got {value!r}", source)
    if non_empty and not value.strip():
        fail(field, f"expected a non-empty string, got {value!r}", source)
    if choices is not None and value not in choices:
        fail(field, f"unknown value {value!r} (expected one of: {', '.join(choices)})", source)
    return value


def check_array(value: Any, field: str, source: str | None = None, what: str = "an array",
                non_empty: bool = False) -> list:
    """A list (``what`` names what it should hold, for the error); with ``non_empty``, not empty."""
    if not isinstance(value, list) or (non_empty and not value):
        fail(field, f"expected {what}, got {_brief(value)}", source)
    return value


def read_text(path: FilePath, field: str) -> str:
    """A regular file's UTF-8 text, bounded (:func:`~swarmnav.models.contained_files.read_input_text`);
    anything else is a ConfigError naming ``field`` (``scenario``, ``study``) and the file."""
    return read_input_text(path, field)


def parse_toml(text: str, source: str) -> "TomlTable":
    """The top table of a TOML document; malformed or too deeply nested TOML is a ConfigError naming ``toml``."""
    return TomlTable(loads_toml(text, source), "", source)


def _brief(value: Any, limit: int = 60) -> str:
    """A value as an error shows it: its repr, cut short (a wrong array may be long)."""
    text = repr(value)
    return text if len(text) <= limit else f"{text[:limit - 5]}...{text[-1]}"


def _shown(key: str) -> str:
    """A key as an error names it: one that would not read as one (empty, control characters) is quoted."""
    return key if key.isprintable() and key.strip() else repr(key)


class TomlTable:
    """Typed access to one table of a document that remembers where it is, for error messages.

    Args:
        data: the table's mapping (anything else is an error naming ``where``).
        where: the table's dotted path in the document (``""`` for the top table).
        source: the file (or other origin) it was read from.
    """

    def __init__(self, data: Any, where: str, source: str | None):
        self.where = where
        self.source = source
        if not isinstance(data, dict):
            fail(where or "toml", f"expected a table, got {_brief(data)}", source)
        self.data: dict[str, Any] = data
        self.used: set[str] = set()

    def path(self, key: str) -> str:
        """The dotted path of a key of this table."""
        return f"{self.where}.{key}" if self.where and key else (self.where or key)

    def fail(self, key: str, problem: str) -> NoReturn:
        fail(self.path(key), problem, self.source)

    def has(self, key: str) -> bool:
        return key in self.data

    def keys(self) -> list[str]:
        return list(self.data)

    def raw(self, key: str, default: Any = REQUIRED) -> Any:
        """The value as read, unchecked (``default`` when absent; absent and required is an error)."""
        self.used.add(key)
        if key not in self.data:
            if default is REQUIRED:
                self.fail(key, "is required")
            return default
        return self.data[key]

    def number(self, key: str, default: Any = REQUIRED, bounds: Range | None = None) -> float:
        if key not in self.data and default is not REQUIRED:
            self.used.add(key)
            return default
        return check_number(self.raw(key), self.path(key), self.source, bounds)

    def integer(self, key: str, default: Any = REQUIRED, bounds: Range | None = None) -> int:
        if key not in self.data and default is not REQUIRED:
            self.used.add(key)
            return default
        return check_integer(self.raw(key), self.path(key), self.source, bounds)

    def boolean(self, key: str, default: Any = REQUIRED) -> bool:
        if key not in self.data and default is not REQUIRED:
            self.used.add(key)
            return default
        return check_boolean(self.raw(key), self.path(key), self.source)

    def string(self, key: str, default: Any = REQUIRED, choices: Iterable[str] | None = None,
               non_empty: bool = False) -> str:
        if key not in self.data and default is not REQUIRED:
            self.used.add(key)
            return default
        return check_string(self.raw(key), self.path(key), self.source, choices, non_empty)

    def array(self, key: str, default: Any = REQUIRED, what: str = "an array", non_empty: bool = False) -> list:
        """A list (``what`` names what it should hold, for the error); with ``non_empty``, not empty."""
        return check_array(self.raw(key, default), self.path(key), self.source, what, non_empty)

    def table(self, key: str, default: Any = REQUIRED) -> "TomlTable":
        return TomlTable(self.raw(key, default), self.path(key), self.source)

    def tables(self, key: str, default: Any = REQUIRED, non_empty: bool = False) -> list["TomlTable"]:
        """An array of tables (``[[key]]``), each a :class:`TomlTable` at ``key[i]``."""
        value = self.array(key, default, f"{'a non-empty' if non_empty else 'an'} array of [[{key}]] tables",
                           non_empty)
        return [TomlTable(entry, f"{self.path(key)}[{i}]", self.source) for i, entry in enumerate(value)]

    def only(self, allowed: Iterable[str], hint: str = "") -> None:
        """Reject the first key (in sorted order) not in ``allowed``; ``hint`` is added to the problem."""
        unknown = sorted(set(self.data) - set(allowed))
        if unknown:
            self.fail(_shown(unknown[0]), f"unknown key{hint}")

    def typed(self, key: str, annotation: Any, bounds: Range | None = None) -> Any:
        """A present key's value checked against a Python annotation (:func:`check_typed`)."""
        return check_typed(self.raw(key), annotation, self.path(key), self.source, bounds)

    def close(self) -> None:
        """Reject keys that were never read."""
        self.only(self.used)


def check_typed(value: Any, annotation: Any, field: str, source: str | None = None,
                bounds: Range | None = None) -> Any:
    """A value checked against a Python annotation (``bool``, ``int``, ``float``, ``str``, a union of them with
    ``None``; any other annotation takes the value as it is), then a number against ``bounds``.

    An ``int`` also takes a float with no fraction (``50.0``).  For a union, the first member that takes the
    value wins; if none does, the problem lists each member's.
    """
    value = _typed(value, annotation, field, source)
    if bounds is not None and isinstance(value, (int, float)) and not isinstance(value, bool):
        if isinstance(value, int):
            check_integer(value, field, source, bounds)
        else:
            check_number(value, field, source, bounds)
    return value


def _typed(value: Any, annotation: Any, field: str, source: str | None) -> Any:
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        members = typing.get_args(annotation)
        if value is None and type(None) in members:
            return None
        problems = []
        for member in members:
            if member is type(None):
                continue
            try:
                return _typed(value, member, field, source)
            except ConfigError as exc:
                problems.append(exc.problem)
        fail(field, "; ".join(problems), source)
    if annotation is bool:
        return check_boolean(value, field, source)
    if annotation is int:
        return check_integer(value, field, source, integral_float=True)
    if annotation is float:
        return check_number(value, field, source)
    if annotation is str:
        return check_string(value, field, source)
    return value
