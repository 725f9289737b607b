"""Views of ROS 2's standard types: a planar message class bound onto a declared type.

A view binds its fields to paths of the type it is sent as (``"pose.pose"``,
``"header.stamp"``); what it does not bind is zero on the wire. The bindings are an
attribute's name, :class:`Const`, :class:`Planar`, :class:`Each` and :class:`Rows`; the
decoder inverts every binding but :class:`Const` and the one-way half of :class:`Rows`.
"""

from __future__ import annotations

import ast
import dataclasses
import math
import typing
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from cosim.core.errors import WireError
from cosim.core.messages.binding import ClassBinding, convert
from cosim.core.messages.cdr_layout import AsTuple, Expr, Fields, Items, Source
from cosim.core.messages.wire import Sequence, Struct, WireType


@dataclass(frozen=True)
class Const:
    """A fixed value on the wire (not read back)."""

    value: Any


@dataclass(frozen=True)
class Outer:
    """Inside :class:`Each`: an attribute of the message holding the sequence."""

    attr: str


@dataclass(frozen=True)
class Planar:
    """A ``geometry_msgs/Pose`` (or ``Transform``) from a planar pose.

    Position x, y (z from ``z``, else 0) and a rotation about z by ``yaw`` (rad); decoded
    back through the quaternion's yaw (as tf2 computes it).

    Attributes:
        x, y, yaw: the attributes holding them (m, m, rad).
        z: an attribute for z, or None (0).
        yaw_nan: the yaw written for a NaN yaw (None: write it as it is).
    """

    x: str
    y: str
    yaw: str
    z: str | None = None
    yaw_nan: float | None = None


@dataclass(frozen=True)
class Each:
    """A sequence of structs from a tuple of objects of a declared class ``element``.

    Attributes:
        attr: the attribute holding the tuple.
        element: the element's class (built back when decoding).
        wire: the element's bindings onto the sequence's struct, paths as in ``ros_message``;
            :class:`Outer` names an attribute of the enclosing message.
    """

    attr: str
    element: type[Any]
    wire: Mapping[str, Any]


@dataclass(frozen=True)
class Rows:
    """A sequence of structs made by a function of the message.

    ``encode`` gives each element as a tuple of the struct's fields in order (nested the
    same way, a time as ns); ``decode`` turns the decoded rows back into the attribute's
    value.
    """

    attr: str
    encode: Callable[[Any], Any]
    decode: Callable[[list[Any]], Any]


Binding = str | Const | Outer | Planar | Each | Rows


def view_binding(cls: Any, kind: Struct, wire: Mapping[str, Binding]) -> ClassBinding:
    """A class viewing a declared type through its bindings."""
    hints = typing.get_type_hints(cls, include_extras=True)
    attrs = {f.name for f in dataclasses.fields(cls)}
    helpers: dict[str, Any] = {}
    for path, binding in wire.items():
        _check_path(cls, kind, path)
        for attr in _attrs_of(binding):
            if not hasattr(cls, attr) and attr not in attrs:
                raise WireError(f"{cls.__name__}: wire[{path!r}] binds {attr!r}, no attribute")
    needed = {f.name for f in dataclasses.fields(cls) if _required(f)}
    bound = {a for b in wire.values() for a in _attrs_of(b) if a in attrs}
    if needed - bound:
        raise WireError(f"{cls.__name__}: fields {sorted(needed - bound)} are bound to no path")
    for k, binding in enumerate(wire.values()):
        if isinstance(binding, Rows):
            helpers[f"_rows{k}"] = binding.encode
    for binding in _all_bindings(wire):
        if isinstance(binding, Const) and _literal_code(binding.value) is None:
            helpers[_const_name(binding)] = binding.value

    def source(base: str, var: Callable[[], str]) -> Source:
        return _tree_source(kind, wire, base, var, base, list(wire))

    def build(tree: tuple[Any, ...]) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for path, binding in wire.items():
            value, node = _at(kind, tree, path)
            _unbind(binding, value, node, out, hints)
        return out

    return ClassBinding(source, build, helpers)


def _all_bindings(wire: Mapping[str, Binding]) -> list[Binding]:
    """Every binding, those inside :class:`Each` included."""
    found: list[Binding] = []
    for binding in wire.values():
        found.append(binding)
        if isinstance(binding, Each):
            found += _all_bindings(binding.wire)
    return found


def _literal_code(value: Any) -> str | None:
    """``repr(value)`` if it reads back as the same value (not NaN, not an object), or None."""
    code = repr(value)
    try:
        same = ast.literal_eval(code) == value and type(ast.literal_eval(code)) is type(value)
    except (ValueError, SyntaxError):
        return None
    return code if same else None


def _const_name(binding: Const) -> str:
    return f"_const{id(binding)}"


def _required(f: dataclasses.Field[Any]) -> bool:
    missing = dataclasses.MISSING
    return f.init and f.default is missing and f.default_factory is missing


def _attrs_of(binding: Binding) -> list[str]:
    if isinstance(binding, str):
        return [binding]
    if isinstance(binding, Planar):
        return [a for a in (binding.x, binding.y, binding.yaw, binding.z) if a]
    if isinstance(binding, Each):
        return [binding.attr, *(b.attr for b in binding.wire.values() if isinstance(b, Outer))]
    if isinstance(binding, Rows):
        return [binding.attr]
    return []


def _check_path(cls: Any, kind: Struct, path: str) -> None:
    node: WireType = kind
    for part in path.split("."):
        if not isinstance(node, Struct):
            raise WireError(f"{cls.__name__}: wire path {path!r} goes into {node!r}")
        try:
            node = node.field_type(part)
        except KeyError as error:
            raise WireError(f"{cls.__name__}: wire path {path!r}: {error.args[0]}") from None


def _tree_source(
    kind: Struct,
    wire: Mapping[str, Binding],
    base: str,
    var: Callable[[], str],
    outer: str,
    order: list[str],
    prefix: str = "",
) -> Source:
    """The Fields of ``kind`` (at ``prefix``) from the bindings under it."""
    found: dict[str, Source] = {}
    for name, field_kind in kind.fields:
        path = f"{prefix}{name}"
        if path in wire:
            found[name] = _bound_source(field_kind, wire[path], base, var, outer, order.index(path))
        elif any(p.startswith(path + ".") for p in wire) and isinstance(field_kind, Struct):
            found[name] = _tree_source(field_kind, wire, base, var, outer, order, path + ".")
    return Fields(found)


def _bound_source(
    kind: WireType, binding: Binding, base: str, var: Callable[[], str], outer: str, k: int
) -> Source:
    if isinstance(binding, str):
        if isinstance(kind, Struct) and not kind.nanoseconds:
            return AsTuple(f"{base}.{binding}")
        return Expr(f"{base}.{binding}")
    if isinstance(binding, Const):
        return Expr(_literal_code(binding.value) or _const_name(binding))
    if isinstance(binding, Outer):
        return Expr(f"{outer}.{binding.attr}")
    if isinstance(binding, Planar):
        yaw = f"{base}.{binding.yaw}"
        if binding.yaw_nan is not None:
            yaw = f"({yaw} if {yaw} == {yaw} else {binding.yaw_nan!r})"
        z = Expr(f"{base}.{binding.z}") if binding.z else None
        place = {"x": Expr(f"{base}.{binding.x}"), "y": Expr(f"{base}.{binding.y}")}
        if z is not None:
            place["z"] = z
        turn = {"z": Expr(f"_sin(0.5 * {yaw})"), "w": Expr(f"_cos(0.5 * {yaw})")}
        first, second = (n for n, _ in kind.fields) if isinstance(kind, Struct) else ("", "")
        return Fields({first: Fields(place), second: Fields(turn)})
    if isinstance(binding, Each):
        assert isinstance(kind, Sequence) and isinstance(kind.element, Struct)
        name = var()
        element = _tree_source(kind.element, binding.wire, name, var, base, list(binding.wire))
        return Items(f"{base}.{binding.attr}", name, element)
    if isinstance(binding, Rows):
        name = var()
        return Items(f"_rows{k}({base})", name, AsTuple(name))
    raise WireError(f"unknown binding {binding!r}")


def _at(kind: Struct, tree: tuple[Any, ...], path: str) -> tuple[Any, WireType]:
    """The decoded value at ``path`` of a ``kind`` tree, and its type."""
    node: WireType = kind
    value: Any = tree
    for part in path.split("."):
        assert isinstance(node, Struct)
        index = node.names().index(part)
        value = value[index]
        node = node.fields[index][1]
    return value, node


def _unbind(
    binding: Binding, value: Any, kind: WireType, out: dict[str, Any], hints: Mapping[str, Any]
) -> None:
    """Set the attributes a binding reads from the decoded ``value`` (of type ``kind``)."""
    if isinstance(binding, str):
        if binding in hints:
            out[binding] = convert(value, hints[binding], None)
    elif isinstance(binding, Planar):
        (x, y, z), (qx, qy, qz, qw) = value
        out[binding.x], out[binding.y] = x, y
        if binding.z:
            out[binding.z] = z
        out[binding.yaw] = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    elif isinstance(binding, Each):
        assert isinstance(kind, Sequence) and isinstance(kind.element, Struct)
        element = binding.element
        element_hints = typing.get_type_hints(element, include_extras=True)
        items = []
        for row in value:
            fields: dict[str, Any] = {}
            for path, sub in binding.wire.items():
                at, node = _at(kind.element, row, path)
                if isinstance(sub, Outer):
                    out.setdefault(sub.attr, at)  # the enclosing message's, from its first
                else:
                    _unbind(sub, at, node, fields, element_hints)
            items.append(element(**fields))
        for sub in binding.wire.values():  # no element: no value to take it from
            if isinstance(sub, Outer):
                out.setdefault(sub.attr, 0)
        out[binding.attr] = tuple(items)
    elif isinstance(binding, Rows):
        out[binding.attr] = binding.decode(value)
