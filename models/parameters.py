"""Components registered by name and configured by a parameter table (planners, navigators).

A component is a dataclass registered under a name; its parameters are its
init fields.  A user's table (from a scenario file or ``--set``) is checked
against the fields' annotations, and every problem is a :class:`ConfigError`
naming ``<kind>.params.<key>`` (or ``<kind>.name``).

One declaration per parameter: the dataclass field itself, typed, with its range (a number) or its
choices (a string) beside its default, :func:`param`::

    iterations: int = param(100, within(1, 100_000))
    strategy: str = param("paper", choices=("paper", "wait"))

Everything takes its checks from there: the TOML reader and ``--set`` (both through
:func:`build_component`: a value of the wrong type, outside its range, NaN, infinite or not
among the choices is a :class:`ConfigError` naming the field, raised before the component is
built, so before anything of that size is allocated), ``planners --json`` / ``navigators --json``
and the docs (:func:`parameter_table`).  A component's ``__post_init__`` keeps only what one
field cannot say (a rule between two fields).  The older class-level form,
``parameter_ranges: ClassVar[dict[str, Range]]``, is still read (merged along the class
hierarchy, :func:`parameter_ranges`) for plugins written against it.

A parameter that names code (the ``policy`` navigator's ``module:function``) is
declared with :func:`code_parameter`.  Data is not code: such a value is taken
from the command line and the Python API, but from a data file (a scenario, a
study, a log) only when the user passes ``--trust-code`` for that invocation;
:func:`refuse_code` checks it before anything is imported.
"""

from __future__ import annotations

import dataclasses
import functools
import types
import typing
from typing import Any

from swarmnav.models.errors import ConfigError
# Components declare their parameters' ranges with the reader's (Range, above, within), imported from here.
from swarmnav.models.toml_table import Range, TomlTable, above, check_string, within  # noqa: F401

TRUST_OPTION = "--trust-code"  # the opt-in that lets a data file name code
_NAMES_CODE = "names_code"
_RANGE = "range"
_CHOICES = "choices"


def param(default: Any = dataclasses.MISSING, bounds: Range | None = None, *,
          choices: tuple[str, ...] | None = None) -> Any:
    """A component parameter: a dataclass field with its default and, beside it, the range a number must lie
    in (``bounds``) or the strings it may take (``choices``); see the module docstring."""
    metadata: dict[str, Any] = {}
    if bounds is not None:
        metadata[_RANGE] = bounds
    if choices is not None:
        metadata[_CHOICES] = tuple(choices)
    return dataclasses.field(default=default, metadata=metadata)


def _init_fields(cls: type) -> list[dataclasses.Field]:
    return [f for f in dataclasses.fields(cls) if f.init] if dataclasses.is_dataclass(cls) else []


def _declared(cls: type, key: str, older: str | None = None) -> dict[str, Any]:
    """What the fields (:func:`param`) declare under ``key``, a class's own over its bases' (a subclass that
    only changes a field's default keeps its base's declaration), over the older class-level dict ``older``."""
    merged: dict[str, Any] = {}
    for klass in reversed(cls.__mro__):
        if older is not None:
            merged.update(vars(klass).get(older, {}))
        own = vars(klass).get("__dataclass_fields__", {})
        merged.update({name: f.metadata[key] for name, f in own.items() if key in f.metadata})
    return merged


def parameter_ranges(cls: type) -> dict[str, Range]:
    """Every declared range of a component class: its fields' (:func:`param`), and the class-level
    ``parameter_ranges`` of the older form, its own over its bases'."""
    return _declared(cls, _RANGE, "parameter_ranges")


def parameter_choices(cls: type) -> dict[str, tuple[str, ...]]:
    """The strings each parameter declared with ``choices`` may take."""
    return _declared(cls, _CHOICES)


def check_declared(component: Any, kind: str) -> None:
    """``component``'s values held to its class's declared ranges and choices, for a component made directly
    in Python (:func:`build_component` checks a table before building); a ConfigError names
    ``<kind>.params.<key>`` as the reader's does."""
    cls = type(component)
    for key, bounds in parameter_ranges(cls).items():
        value = getattr(component, key)
        if isinstance(value, (int, float)) and not isinstance(value, bool) and not bounds.holds(value):
            raise ConfigError(f"{kind}.params.{key}", f"{bounds.requirement()}, got {value!r}")
    for key, allowed in parameter_choices(cls).items():
        value = getattr(component, key)
        if value is not None and value not in allowed:
            raise ConfigError(f"{kind}.params.{key}", f"must be one of {', '.join(allowed)}, got {value!r}")


def _shown_default(f: dataclasses.Field) -> Any:
    if f.default is not dataclasses.MISSING:
        return f.default
    return f.default_factory() if f.default_factory is not dataclasses.MISSING else None


def parameter_table(cls: type, extra: tuple[type, tuple[str, ...], dict[str, Any]] | None = None
                    ) -> list[dict[str, Any]]:
    """One row per parameter of a component: name, type, default, range and choices (None where it declares
    none), and whether it names code: what ``planners --json`` and ``navigators --json`` list.

    ``extra``: ``(cls2, names, defaults)``, rows of another declaration that the component takes as its
    own (a navigator's safety layer switches, :mod:`controllers.safety_layer`), with its defaults.
    """
    rows = []
    sources = [(cls, None, {})] + ([extra] if extra is not None else [])
    for klass, names, defaults in sources:
        try:
            hints = typing.get_type_hints(klass)
        except Exception:  # a plugin's annotation that does not resolve: shown as written
            hints = {}
        ranges, choices = parameter_ranges(klass), parameter_choices(klass)
        for f in _init_fields(klass):
            if names is not None and f.name not in names:
                continue
            annotation = hints.get(f.name, f.type)
            rows.append({"name": f.name, "type": getattr(annotation, "__name__", str(annotation)),
                         "default": defaults.get(f.name, _shown_default(f)),
                         "range": str(ranges[f.name]) if f.name in ranges else None,
                         "choices": list(choices[f.name]) if f.name in choices else None,
                         "names_code": bool(f.metadata.get(_NAMES_CODE))})
    return rows


def numeric_parameters(cls: type) -> tuple[str, ...]:
    """The init fields whose type admits an int or a float (bool excluded)."""
    hints = _type_hints(cls)
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


@functools.lru_cache(maxsize=None)
def _type_hints(cls: type) -> dict[str, Any]:
    """``typing.get_type_hints`` of a component class, once per class (it re-evaluates every annotation)."""
    return typing.get_type_hints(cls)


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
                    source: str | None = None, trust_code: bool = True, also_known: tuple[str, ...] = ()) -> Any:
    """Build ``registry[name]`` from a parameter table, checking every value against its field's type.

    Args:
        kind: what the registry holds, for error fields (``"planner"``, ``"navigator"``).
        trust_code: False when ``params`` come from a data file the user did not vouch for: a parameter
            that names code is then refused (:func:`refuse_code`) before the component is built.
        also_known: parameters the component takes through another declaration (named among the known
            ones when a key is unknown).

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
    hints = _type_hints(cls)
    ranges, choices = parameter_ranges(cls), parameter_choices(cls)
    table = TomlTable({} if params is None else params, f"{kind}.params", source)
    kwargs = {}
    for key in table.keys():
        if key not in fields:
            known = sorted(set(fields) | set(also_known))
            table.fail(key, f"unknown parameter for {name!r} (known: {', '.join(known) or 'none'})")
        kwargs[key] = table.typed(key, hints.get(key, typing.Any), ranges.get(key))
        if key in choices and kwargs[key] is not None:
            check_string(kwargs[key], table.path(key), source, choices[key])
    try:
        return cls(**kwargs)
    except ConfigError as exc:
        raise ConfigError(exc.field, exc.problem, source) from None
    except (ValueError, TypeError) as exc:
        raise ConfigError(f"{kind}.params", str(exc), source) from None
