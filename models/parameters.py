"""Components registered by name and configured by a parameter table (planners, navigators).

A component is a dataclass registered under a name; its parameters are its
init fields.  A user's table (from a scenario file or ``--set``) is checked
against the fields' annotations, and every problem is a :class:`ConfigError`
naming ``<kind>.params.<key>`` (or ``<kind>.name``).

Every numeric parameter declares its range in the component's class:
``parameter_ranges: ClassVar[dict[str, Range]] = {"iterations": within(0, 100_000), ...}``
(merged along the class hierarchy, :func:`parameter_ranges`).  A value outside its
range, NaN or infinite is a :class:`ConfigError` naming the field and the range,
raised by :func:`build_component` before the component is built, so before anything
of that size is allocated; :func:`parameter_table` lists them.

A parameter that names code (the ``policy`` navigator's ``module:function``) is
declared with :func:`code_parameter`.  Data is not code: such a value is taken
from the command line and the Python API, but from a data file (a scenario, a
study, a log) only when the user passes ``--trust-code`` for that invocation;
:func:`refuse_code` checks it before anything is imported.
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from dataclasses import dataclass
from typing import Any

from swarmnav.models.errors import ConfigError

TRUST_OPTION = "--trust-code"  # the opt-in that lets a data file name code
_NAMES_CODE = "names_code"


@dataclass(frozen=True)
class Range:
    """The values a numeric parameter may take: ``low``..``high``, ``low`` itself excluded when ``low_open``."""

    low: float
    high: float
    low_open: bool = False

    def holds(self, value: float) -> bool:
        try:
            if not math.isfinite(value):
                return False
        except OverflowError:  # an integer beyond any float
            return False
        return (self.low < value if self.low_open else self.low <= value) and value <= self.high

    def __str__(self) -> str:
        return f"{'(' if self.low_open else '['}{self.low:g}, {self.high:g}]"


def within(low: float, high: float) -> Range:
    """[low, high]."""
    return Range(float(low), float(high))


def above(low: float, high: float) -> Range:
    """(low, high]: e.g. a positive length, ``above(0, 100)``."""
    return Range(float(low), float(high), low_open=True)


def parameter_ranges(cls: type) -> dict[str, Range]:
    """Every declared range of a component class, its own over its bases'."""
    merged: dict[str, Range] = {}
    for klass in reversed(cls.__mro__):
        merged.update(vars(klass).get("parameter_ranges", {}))
    return merged


def parameter_table(cls: type) -> list[dict[str, Any]]:
    """One row per parameter of a component: name, type, default and range (None: not numeric)."""
    hints = typing.get_type_hints(cls)
    ranges = parameter_ranges(cls)
    rows = []
    for f in dataclasses.fields(cls):
        if not f.init:
            continue
        default = f.default if f.default is not dataclasses.MISSING else None
        annotation = hints.get(f.name, Any)
        rows.append({"name": f.name, "type": getattr(annotation, "__name__", str(annotation)), "default": default,
                     "range": str(ranges[f.name]) if f.name in ranges else None,
                     "names_code": bool(f.metadata.get(_NAMES_CODE))})
    return rows


def numeric_parameters(cls: type) -> tuple[str, ...]:
    """The init fields whose type admits an int or a float (bool excluded)."""
    hints = typing.get_type_hints(cls)
    out = []
    for f in dataclasses.fields(cls):
        annotation = hints.get(f.name, Any)
        args = typing.get_args(annotation) if typing.get_origin(annotation) in (typing.Union, types.UnionType) \
            else (annotation,)
        if f.init and any(a in (int, float) for a in args):
            out.append(f.name)
    return tuple(out)


def code_parameter(default: str = "") -> Any:
    """A dataclass field whose value names code to import and call (``"module:function"``)."""
    return dataclasses.field(default=default, metadata={_NAMES_CODE: True})


def code_parameters(cls: type) -> tuple[str, ...]:
    """The init fields of a component class that name code."""
    return tuple(f.name for f in dataclasses.fields(cls) if f.init and f.metadata.get(_NAMES_CODE))


def refuse_code(registry: dict[str, type], kind: str, name: str, params: dict[str, Any] | None,
                source: str | None, field_prefix: str | None = None) -> None:
    """Raise a :class:`ConfigError` if ``params`` (read from a data file) give a parameter that names code.

    Nothing is imported: only the component's declaration is read.  An unknown
    component name passes here (the registry's own check reports it).
    """
    cls = registry.get(name)
    if cls is None or not params:
        return
    option = "--set" if kind == "planner" else f"--{kind}-set"
    for key in code_parameters(cls):
        if key in params:
            raise ConfigError(f"{field_prefix or kind}.params.{key}",
                              f"names code ({params[key]!r}); a data file's code runs only with {TRUST_OPTION} "
                              f"(or give it on the command line: {option} {key}=...)", source)


def _coerce(value: Any, annotation: Any, field: str) -> Any:
    """Check a user-given parameter against a dataclass field's annotation."""
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(annotation)
        if value is None and type(None) in args:
            return None
        errors = []
        for arg in args:
            if arg is type(None):
                continue
            try:
                return _coerce(value, arg, field)
            except ConfigError as exc:
                errors.append(exc.problem)
        raise ConfigError(field, "; ".join(errors))
    if annotation is bool:
        if isinstance(value, bool):
            return value
        raise ConfigError(field, f"expected true or false, got {value!r}")
    if annotation is int:
        if isinstance(value, float) and not math.isfinite(value):
            raise ConfigError(field, f"expected an integer, got {value!r}")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or float(value) != int(value):
            raise ConfigError(field, f"expected an integer, got {value!r}")
        return int(value)
    if annotation is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(field, f"expected a number, got {value!r}")
        if not math.isfinite(float(value)):
            raise ConfigError(field, f"must be finite, got {value!r}")
        return float(value)
    if annotation is str:
        if not isinstance(value, str):
            raise ConfigError(field, f"expected a string, got {value!r}")
        return value
    return value


def register_component(registry: dict[str, type], kind: str, cls: type) -> type:
    """Add a component class to a registry under its ``name``; a missing or taken name is an error."""
    name = getattr(cls, "name", None)
    if not isinstance(name, str) or not name:
        raise TypeError(f"{cls.__name__} has no {kind} name")
    if name in registry:
        raise ValueError(f"{kind} name {name!r} is registered twice ({registry[name].__name__} and {cls.__name__})")
    registry[name] = cls
    return cls


def build_component(registry: dict[str, type], kind: str, name: str, params: dict[str, Any] | None = None,
                    source: str | None = None, trust_code: bool = True) -> Any:
    """Build ``registry[name]`` from a parameter table, checking every value against its field's type.

    Args:
        kind: what the registry holds, for error fields (``"planner"``, ``"navigator"``).
        trust_code: False when ``params`` come from a data file the user did not vouch for: a parameter
            that names code is then refused (:func:`refuse_code`) before the component is built.

    Raises:
        ConfigError: unknown name, unknown parameter, or a value of the wrong type.
    """
    if name not in registry:
        raise ConfigError(f"{kind}.name", f"unknown {kind} {name!r} (known: {', '.join(sorted(registry))})",
                          source)
    if not trust_code:
        refuse_code(registry, kind, name, params, source)
    cls = registry[name]
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    hints = typing.get_type_hints(cls)
    ranges = parameter_ranges(cls)
    kwargs = {}
    for key, value in (params or {}).items():
        if key not in fields:
            raise ConfigError(f"{kind}.params.{key}",
                              f"unknown parameter for {name!r} (known: {', '.join(sorted(fields)) or 'none'})",
                              source)
        try:
            kwargs[key] = _coerce(value, hints.get(key, typing.Any), f"{kind}.params.{key}")
        except ConfigError as exc:
            raise ConfigError(exc.field, exc.problem, source) from None
        allowed = ranges.get(key)
        if allowed is not None and isinstance(kwargs[key], (int, float)) and not isinstance(kwargs[key], bool) \
                and not allowed.holds(kwargs[key]):
            raise ConfigError(f"{kind}.params.{key}", f"must be in {allowed}, got {kwargs[key]!r}", source)
    try:
        return cls(**kwargs)
    except ConfigError as exc:
        raise ConfigError(exc.field, exc.problem, source) from None
    except (ValueError, TypeError) as exc:
        raise ConfigError(f"{kind}.params", str(exc), source) from None
