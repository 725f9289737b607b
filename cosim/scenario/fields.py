"""Typed configuration fields: declaration (:func:`param`) and validation (:func:`build`).

Sections of a scenario are frozen dataclasses whose fields are declared with
:func:`param`. :func:`build` turns a TOML table into such a dataclass, checking every
key against the annotations and the declared bounds; a problem becomes a
:class:`~cosim.core.errors.ConfigError` naming the file, the section, the key, the value and
what was expected. Unknown keys get a "did you mean" suggestion.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import types
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal, TypeVar, Union, get_args, get_origin, get_type_hints

from cosim.core.errors import ConfigError, ScenarioError
from cosim.core.registry import group_named, suggest_names
from models.errors import ModelError


@dataclass(frozen=True, slots=True)
class Bounds:
    """Numeric bounds of a field (applied to every element of a list)."""

    ge: float | None = None
    gt: float | None = None
    le: float | None = None
    lt: float | None = None

    def violation(self, value: float) -> str | None:
        """Return a description of the violated bound, or ``None``."""
        if self.gt is not None and not value > self.gt:
            return f"> {self.gt:g}"
        if self.ge is not None and not value >= self.ge:
            return f">= {self.ge:g}"
        if self.lt is not None and not value < self.lt:
            return f"< {self.lt:g}"
        if self.le is not None and not value <= self.le:
            return f"<= {self.le:g}"
        return None

    def describe(self) -> str:
        """Describe all bounds, e.g. ``>= 0 and <= 1``."""
        parts = []
        if self.gt is not None:
            parts.append(f"> {self.gt:g}")
        if self.ge is not None:
            parts.append(f">= {self.ge:g}")
        if self.lt is not None:
            parts.append(f"< {self.lt:g}")
        if self.le is not None:
            parts.append(f"<= {self.le:g}")
        return " and ".join(parts)


def param(
    default: Any,
    doc: str,
    *,
    ge: float | None = None,
    gt: float | None = None,
    le: float | None = None,
    lt: float | None = None,
    path: bool = False,
    registry: str | None = None,
    off: str | None = None,
    unit: str | None = None,
) -> Any:
    """Declare a configuration field with a default, a one-line doc and numeric bounds.

    ``path=True`` marks a file name: a relative one is resolved against the folder of the
    scenario file when the scenario is loaded (against the working folder for presets and
    ``--set``), so the resolved scenario names an absolute file.

    ``registry`` names the entry-point group of a registry (``"cosim.controllers"``: a
    :class:`~cosim.core.registry.Group` registered in ``cosim.registries``): the value (or
    every element of a list) must be a name registered there; an unknown one is refused
    with the registered names. ``off`` is a value that chooses nothing (``"none"``: no
    motion-capture source at all), accepted without being registered.

    ``unit`` is for a number whose name cannot carry its unit (a Nav2 name kept, such
    as ``cost_scaling`` in ``1/m``), or that has none: it says what the number is
    instead (``count``, ``probability``, ``ratio``, ``id``). By default a key's unit is
    the one its name's suffix carries (:func:`unit_of`); the scenario key reference
    shows it in a column of its own (:func:`key_unit`).
    """
    metadata = {
        "doc": doc,
        "bounds": Bounds(ge, gt, le, lt),
        "path": path,
        "registry": registry,
        "off": off,
        "unit": unit,
    }
    return field(default=default, metadata=metadata)


@dataclass(frozen=True, slots=True)
class Problem:
    """A cross-field problem found by a section's ``problems()`` method."""

    key: str
    value: Any
    expected: str


class _MismatchError(Exception):
    def __init__(self, expected: str) -> None:
        super().__init__(expected)
        self.expected = expected


def describe(hint: Any) -> str:
    """Say in words what a type annotation accepts."""
    origin = get_origin(hint)
    if hint is bool:
        return "true or false"
    if hint is int:
        return "an integer"
    if hint is float:
        return "a number"
    if hint is str:
        return "a string"
    if origin is Literal:
        return "one of " + ", ".join(repr(a) for a in get_args(hint))
    if origin is tuple:
        args = get_args(hint)
        if len(args) == 2 and args[1] is Ellipsis:
            inner = describe(args[0])
            return f"a list of {_plural(inner)}"
        return f"a list of {len(args)} {_plural(describe(args[0]))}"
    if origin in (Union, types.UnionType):
        return " or ".join(describe(a) for a in get_args(hint))
    return str(hint)


def _plural(phrase: str) -> str:
    for article in ("an ", "a "):
        if phrase.startswith(article):
            phrase = phrase[len(article) :]
            break
    if phrase == "true or false":
        return "booleans"
    if phrase.startswith("one of "):
        return "values " + phrase
    if phrase.startswith("list of "):
        return "lists of " + phrase[len("list of ") :]
    return phrase + "s"


def coerce(value: Any, hint: Any) -> Any:
    """Convert a TOML value to the annotated type, or raise ``_MismatchError``."""
    origin = get_origin(hint)
    if hint is bool:
        if isinstance(value, bool):
            return value
    elif hint is int:
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        if isinstance(value, float) and value.is_integer():
            return int(value)
    elif hint is float:
        if isinstance(value, int | float) and not isinstance(value, bool):
            if math.isfinite(value):
                return float(value)
            raise _MismatchError("a finite number")
    elif hint is str:
        if isinstance(value, str):
            return value
    elif origin is Literal:
        if value in get_args(hint) and type(value) in {type(a) for a in get_args(hint)}:
            return value
    elif origin is tuple:
        if isinstance(value, list | tuple):
            args = get_args(hint)
            if len(args) == 2 and args[1] is Ellipsis:
                return tuple(coerce(item, args[0]) for item in value)
            if len(value) == len(args):
                return tuple(coerce(item, arg) for item, arg in zip(value, args, strict=True))
    elif origin in (Union, types.UnionType):
        for arg in get_args(hint):
            try:
                return coerce(value, arg)
            except _MismatchError:
                continue
    raise _MismatchError(describe(hint))


def _numbers(value: Any) -> Iterator[float]:
    if isinstance(value, bool):
        return
    if isinstance(value, int | float):
        yield value
    elif isinstance(value, tuple):
        for item in value:
            yield from _numbers(item)


def format_problem(origin: str, section: str, key: str, value: Any, expected: str) -> str:
    """Format the one-line message used for every configuration error."""
    return f"{origin}: [{section}] {key} = {show_value(value)}: expected {expected}"


def model_problem(source: str, error: ModelError, *, value: Any = None) -> ScenarioError:
    """The one-line error for a model that refuses the scenario's parameters.

    Args:
        source: the scenario file or preset the parameters came from.
        error: the model's refusal, naming the parameter as ``section.key``.
        value: the value to show instead of the model's (when the model was given a
            value derived from the user's, such as a radius plus a margin).
    """
    shown = error.value if value is None else value
    # a file name is shown whole: its end names the file
    text = repr(shown) if isinstance(shown, str) and len(shown) <= 4096 else show_value(shown)
    return ScenarioError(f"{source}: {error.key} = {text}: expected {error.expected}")


SHOWN_CHARS = 80
"""Longest value a message shows; longer ones end in an ellipsis."""


def show_value(value: Any) -> str:
    """A value as TOML-like text on one line, at most :data:`SHOWN_CHARS` long."""
    text = _show(value)
    return text if len(text) <= SHOWN_CHARS else text[: SHOWN_CHARS - 3] + "..."


def _show(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_show(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_key(k)} = {_show(v)}" for k, v in value.items()) + "}"
    return repr(value)  # repr escapes newlines and control characters


def show_name(name: str) -> str:
    """A section or key name as written, quoted when it holds spaces or control characters."""
    shown = name if name and name.isprintable() and name.strip() == name else repr(name)
    return shown if len(shown) <= SHOWN_CHARS else shown[: SHOWN_CHARS - 3] + "..."


def _key(key: Any) -> str:
    text = str(key)
    return text if text.isidentifier() else repr(text)


def suggest(name: str, options: list[str]) -> str:
    """Return "; did you mean 'x'?" for the closest option, or a list of the valid ones."""
    close = difflib.get_close_matches(name, options, n=1, cutoff=0.6)
    if close:
        return f"; did you mean {close[0]!r}?"
    return "; valid: " + ", ".join(options)


T = TypeVar("T")

UNITS = {
    "_mps2": "m/s²",
    "_radps2": "rad/s²",
    "_mps": "m/s",
    "_radps": "rad/s",
    "_mbps": "Mbit/s",
    "_dbm": "dBm",
    "_db": "dB",
    "_wh": "Wh",
    "_w": "W",
    "_hz": "Hz",
    "_ms": "ms",
    "_ns": "ns",
    "_s": "s",
    "_m": "m",
    "_deg": "deg",
    "_rad": "rad",
    "_prob": "probability",
}
"""Unit by key suffix (the project's naming rule: units in names)."""


def unit_of(key: str) -> str:
    """The unit a key's name carries, or an empty string.

    ``X_per_<unit>`` carries X's unit per that unit: ``drive_wh_per_m`` is in Wh/m,
    ``cost_per_m`` in 1/m.
    """
    for suffix, unit in UNITS.items():
        per = "_per" + suffix
        if key.endswith(per) and len(key) > len(per):
            return f"{unit_of('_' + key[: -len(per)]) or '1'}/{unit}"
    return next((unit for suffix, unit in UNITS.items() if key.endswith(suffix)), "")


def key_unit(field: dataclasses.Field[Any]) -> str:
    """A section key's unit: declared with ``param(..., unit=...)``, else its name's.

    An empty string for a key with none (a name, a flag, a choice).
    """
    declared = field.metadata.get("unit")
    return declared if isinstance(declared, str) else unit_of(field.name)


SMALLEST = {"_hz": 1e-3, "_ms": 1e-3, "_s": 1e-6}
"""Smallest positive value of a rate or time (by unit suffix) where only ``> 0`` is declared:
a rate of 1e-308 Hz is a period no clock can hold."""
LARGEST = {"_hz": 1e6, "_ms": 1e12, "_s": 1e9}
"""Largest rate or time (by unit suffix) where none is declared: a MHz tick is already a
billion events a run; 1e9 s (32 years) is near the kernel's int64 nanosecond clock."""


def implicit_bounds(key: str, bounds: Bounds) -> Bounds:
    """The declared bounds, plus the limits every rate and time keeps (by the key's unit)."""
    for suffix, smallest in SMALLEST.items():
        if key.endswith(suffix) and bounds.gt == 0 and bounds.ge is None:
            bounds = dataclasses.replace(bounds, gt=None, ge=smallest)
    for suffix, largest in LARGEST.items():
        if key.endswith(suffix) and bounds.le is None and bounds.lt is None:
            bounds = dataclasses.replace(bounds, le=largest)
    return bounds


def key_bounds(cls: type[Any], key: str) -> Bounds:
    """The bounds a section's key is checked against when loaded (declared and implicit).

    A command-line flag that overrides a key (``cosim run --duration-s``) checks the same.
    """
    found = {f.name: f for f in dataclasses.fields(cls)}[key]
    return implicit_bounds(key, found.metadata.get("bounds", Bounds()))


def field_names(cls: type[Any]) -> list[str]:
    """Names of a section's fields in declaration order."""
    return [f.name for f in dataclasses.fields(cls)]


def build(
    cls: type[T],
    table: Mapping[str, Any],
    *,
    section: str,
    origins: Mapping[str, str],
    default_origin: str,
    unregistered: list[tuple[str, Any]] | None = None,
) -> T:
    """Validate a TOML table and build the section dataclass ``cls`` from it.

    Args:
        cls: the section dataclass.
        table: the TOML table (key -> value).
        section: the section's name, for messages.
        origins: where each key came from (a file, or ``--set``), for messages.
        default_origin: the origin reported for cross-field problems of defaults.
        unregistered: when given, a key naming what no installed package registers is
            taken as it is and listed here as (key, value), not refused (a finished run's
            scenario read for its results, a plugin it used uninstalled since).

    Raises:
        ConfigError: naming the origin, the section, the key, the value and what was
            expected, for an unknown key, a wrong type or a value out of bounds.
    """
    hints = get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    values: dict[str, Any] = {}
    for key, raw in table.items():
        origin = origins.get(key, default_origin)
        if key not in fields:
            raise ConfigError(
                f"{origin}: [{section}] unknown key {key!r}" + suggest(key, list(fields))
            )
        hint = hints[key]
        nested = _table_item_type(hint)
        if nested is not None:
            values[key] = _build_tables(nested, raw, section=f"{section}.{key}", origin=origin)
            continue
        bounds = implicit_bounds(key, fields[key].metadata.get("bounds", Bounds()))
        bound_text = bounds.describe()
        try:
            value = coerce(raw, hint)
        except _MismatchError as mismatch:
            expected = mismatch.expected + (f" {bound_text}" if bound_text else "")
            raise ConfigError(format_problem(origin, section, key, raw, expected)) from None
        for number in _numbers(value):
            if bounds.violation(number) is not None:
                expected = describe(hint) + f" {bound_text}"
                if isinstance(value, tuple):
                    expected += " (every element)"
                raise ConfigError(format_problem(origin, section, key, raw, expected))
        group = fields[key].metadata.get("registry")
        if group is not None and value != fields[key].metadata.get("off"):
            try:
                _check_registered(group, value, origin, section, key, raw)
            except ConfigError:
                if unregistered is None:
                    raise
                unregistered.append((key, value))
        values[key] = value
    instance = cls(**values)
    problems = getattr(instance, "problems", None)
    if problems is not None:
        for problem in problems():
            origin = origins.get(problem.key, default_origin)
            raise ConfigError(
                format_problem(origin, section, problem.key, problem.value, problem.expected)
            )
    return instance


def _check_registered(
    group: str, value: Any, origin: str, section: str, key: str, raw: Any
) -> None:
    """Refuse a name (or a list's name) that is not registered in the ``group`` registry."""
    registry = group_named(group).installed()
    for name in value if isinstance(value, tuple) else (value,):
        if name not in registry:
            expected = f"a registered {registry.words}" + suggest_names(name, registry.names())
            raise ConfigError(format_problem(origin, section, key, raw, expected))


def _table_item_type(hint: Any) -> type[Any] | None:
    """The dataclass ``X`` of a ``tuple[X, ...]`` annotation (an array of tables), or None."""
    if get_origin(hint) is tuple:
        args = get_args(hint)
        if len(args) == 2 and args[1] is Ellipsis and dataclasses.is_dataclass(args[0]):
            return args[0]  # type: ignore[return-value]
    return None


def _build_tables(cls: type[T], raw: Any, *, section: str, origin: str) -> tuple[T, ...]:
    """Validate an array of tables (``[[section.key]]``) into a tuple of dataclasses."""
    if not isinstance(raw, list | tuple) or not all(isinstance(item, dict) for item in raw):
        raise ConfigError(
            f"{origin}: [{section}] = {_show(raw)}: expected a list of tables "
            f"({', '.join(field_names(cls))})"
        )
    return tuple(
        build(cls, item, section=f"{section}[{i}]", origins={}, default_origin=origin)
        for i, item in enumerate(raw)
    )


def docs(cls: type[Any]) -> dict[str, str]:
    """The one-line doc of every field of a section."""
    return {f.name: f.metadata.get("doc", "") for f in dataclasses.fields(cls)}


__all__ = [
    "UNITS",
    "Bounds",
    "Problem",
    "build",
    "coerce",
    "describe",
    "docs",
    "field_names",
    "format_problem",
    "key_bounds",
    "key_unit",
    "model_problem",
    "param",
    "suggest",
    "unit_of",
]
