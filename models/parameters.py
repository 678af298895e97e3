"""Components registered by name and configured by a parameter table (planners, navigators).

A component is a dataclass registered under a name; its parameters are its
init fields.  A user's table (from a scenario file or ``--set``) is checked
against the fields' annotations, and every problem is a :class:`ConfigError`
naming ``<kind>.params.<key>`` (or ``<kind>.name``).
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from typing import Any

from swarmnav.models.errors import ConfigError


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
                    source: str | None = None) -> Any:
    """Build ``registry[name]`` from a parameter table, checking every value against its field's type.

    Args:
        kind: what the registry holds, for error fields (``"planner"``, ``"navigator"``).

    Raises:
        ConfigError: unknown name, unknown parameter, or a value of the wrong type.
    """
    if name not in registry:
        raise ConfigError(f"{kind}.name", f"unknown {kind} {name!r} (known: {', '.join(sorted(registry))})",
                          source)
    cls = registry[name]
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    hints = typing.get_type_hints(cls)
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
    try:
        return cls(**kwargs)
    except ConfigError as exc:
        raise ConfigError(exc.field, exc.problem, source) from None
    except (ValueError, TypeError) as exc:
        raise ConfigError(f"{kind}.params", str(exc), source) from None
