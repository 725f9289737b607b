"""Message classes of a type of their own: the class's fields are the type's fields.

A field's wire type comes from its annotation (:mod:`cosim.core.messages.aliases`, a
declared class, a ``tuple[X, ...]`` of either, or plain ``float``, ``str``, ``bool``,
``bytes``); its name on the wire is its name without a unit suffix.
"""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Callable, Mapping
from typing import Annotated, Any, get_args, get_origin

from cosim.core.errors import WireError
from cosim.core.messages import std
from cosim.core.messages.aliases import HeaderFrame, HeaderStamp
from cosim.core.messages.binding import ClassBinding, convert, element_class
from cosim.core.messages.cdr_layout import AsTuple, Expr, Fields, Items, Source
from cosim.core.messages.wire import (
    BOOL,
    FLOAT64,
    STRING,
    UINT8,
    Array,
    Primitive,
    Sequence,
    Struct,
    Text,
    WireType,
)

UNIT_SUFFIXES = (
    "_ns", "_ms", "_s", "_m", "_mps", "_mps2", "_rad", "_radps", "_radps2", "_deg", "_hz",
    "_m2", "_bytes", "_dbm", "_db",
)  # fmt: skip
"""Unit suffixes a field name drops on the wire (REP 103: ROS messages are in SI)."""


_PLAIN: dict[Any, WireType] = {float: FLOAT64, str: STRING, bool: BOOL, bytes: Sequence(UINT8)}


def wire_name(name: str, meta: Mapping[str, Any]) -> str:
    """The name of a field on the wire: its ``wire`` metadata, or its name without units."""
    given = meta.get("wire")
    if isinstance(given, str):
        return given
    for suffix in UNIT_SUFFIXES:
        if name.endswith(suffix) and len(name) > len(suffix):
            return name[: -len(suffix)]
    return name


def own_binding(cls: Any, ros_type: str, frame_id: str) -> tuple[Struct, ClassBinding]:
    """A class of one's own: its fields are the type's."""
    hints = typing.get_type_hints(cls, include_extras=True)
    fields = [f for f in dataclasses.fields(cls) if f.metadata.get("wire", True) is not False]
    stamp = next((f.name for f in fields if _marker(hints[f.name], HeaderStamp)), None)
    frame = next((f.name for f in fields if _marker(hints[f.name], HeaderFrame)), None)
    layout: list[tuple[str, WireType]] = []
    parts: list[tuple[str, str, WireType]] = []  # (wire name, attribute, type)
    for f in fields:
        if f.name == frame:
            continue
        if f.name == stamp:
            layout.append(("header", std.HEADER))
            continue
        kind = _wire_type(cls, f.name, hints[f.name])
        layout.append((wire_name(f.name, f.metadata), kind))
        parts.append((wire_name(f.name, f.metadata), f.name, kind))
    try:
        kind = Struct(ros_type, tuple(layout))
    except ValueError as error:
        raise WireError(f"{cls.__name__}: {error}") from None
    element_of = {name: element_class(hints[attr]) for name, attr, _ in parts}

    def source(base: str, var: Callable[[], str]) -> Source:
        found: dict[str, Source] = {}
        if stamp is not None:
            frame_source = Expr(f"{base}.{frame}") if frame else Expr(repr(frame_id))
            found["header"] = Fields({"stamp": Expr(f"{base}.{stamp}"), "frame_id": frame_source})
        for name, attr, wire_kind in parts:
            found[name] = _attr_source(f"{base}.{attr}", wire_kind, element_of[name], var)
        return Fields(found)

    def build(tree: tuple[Any, ...]) -> dict[str, Any]:
        values = dict(zip(kind.names(), tree, strict=True))
        out: dict[str, Any] = {}
        if stamp is not None:
            out[stamp] = values["header"][0]
            if frame is not None:
                out[frame] = values["header"][1]
        for name, attr, _ in parts:
            out[attr] = convert(values[name], hints[attr], element_of[name])
        return out

    return kind, ClassBinding(source, build, {})


def _attr_source(code: str, kind: WireType, element: Any, var: Callable[[], str]) -> Source:
    """How a field holding an attribute's value is found."""
    if isinstance(kind, Struct) and not kind.nanoseconds:
        if element is not None:
            return element._binding.source(code, var)  # type: ignore[no-any-return]
        return AsTuple(code)
    if isinstance(kind, Sequence) and isinstance(kind.element, Struct) and element is not None:
        name = var()
        return Items(code, name, element._binding.source(name, var))
    return Expr(code)


def _marker(hint: Any, marker: type[Any]) -> bool:
    return get_origin(hint) is Annotated and any(isinstance(a, marker) for a in get_args(hint))


def _wire_type(cls: Any, name: str, hint: Any) -> WireType:
    """The wire type of a field's annotation."""
    if get_origin(hint) is Annotated:
        for extra in get_args(hint)[1:]:
            if isinstance(extra, Primitive | Text | Sequence | Array | Struct):
                return extra
        hint = get_args(hint)[0]
    if hint in _PLAIN:
        return _PLAIN[hint]
    declared = getattr(hint, "wire", None)
    if isinstance(declared, Struct):
        return declared
    if get_origin(hint) is tuple:
        args = get_args(hint)
        if len(args) == 2 and args[1] is Ellipsis:
            element = _wire_type(cls, name, args[0])
            if isinstance(element, Primitive | Text | Struct):
                return Sequence(element)
    raise WireError(
        f"{cls.__name__}.{name}: annotation {hint!r} has no wire type; expected one of "
        "cosim.core.messages' wire types (uint32, int32, float64, string, Header, Time, "
        "Float32s, ...), float, str, bool, bytes, a declared message class, or a tuple[X, ...] "
        "of one"
    )
