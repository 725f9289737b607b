"""The types of ROS 2 messages on the wire: primitives, nested types, sequences, arrays.

A :class:`Struct` is a ROS 2 message type as its ``.msg`` file declares it: a name
(``geometry_msgs/msg/Pose``) and typed fields in order. From it come the ``.msg`` text that
bags embed (:meth:`Struct.msg_text`), the CDR layout every encoder and decoder follows
(:mod:`cosim.core.messages.codec`) and the DDS type (``adapters.ros2dds.types``). ROS 2's
standard types are declared once, in :mod:`cosim.core.messages.std`; cosim's own and a
plugin's come from their message classes (:func:`cosim.core.messages.declare.message`).

``builtin_interfaces/msg/Time`` and ``Duration`` are structs of two integers on the wire;
their values are integer nanoseconds everywhere in cosim (:attr:`Struct.nanoseconds`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

HEADER = b"\x00\x01\x00\x00"
"""CDR encapsulation in front of every message: XCDR1, little endian, no options."""
NS_PER_S = 1_000_000_000
"""A time's nanoseconds per second."""


@dataclass(frozen=True)
class Primitive:
    """A fixed-size ROS 2 primitive type.

    Attributes:
        name: its ``.msg`` name (``float64``).
        code: its :mod:`struct` format character (little endian).
        size: its size in bytes, which is also its CDR alignment.
        zero: the value of a field left unset.
        numpy: its NumPy dtype (little endian).
    """

    name: str
    code: str
    size: int
    zero: Any
    numpy: str

    def __repr__(self) -> str:
        return self.name


@dataclass(frozen=True)
class Text:
    """The ROS 2 ``string`` type: UTF-8, a uint32 length counting the terminating NUL."""

    name: str = "string"
    zero: str = ""

    def __repr__(self) -> str:
        return self.name


BOOL = Primitive("bool", "?", 1, False, "?")
BYTE = Primitive("byte", "B", 1, 0, "u1")
CHAR = Primitive("char", "B", 1, 0, "u1")
INT8 = Primitive("int8", "b", 1, 0, "i1")
UINT8 = Primitive("uint8", "B", 1, 0, "u1")
INT16 = Primitive("int16", "h", 2, 0, "<i2")
UINT16 = Primitive("uint16", "H", 2, 0, "<u2")
INT32 = Primitive("int32", "i", 4, 0, "<i4")
UINT32 = Primitive("uint32", "I", 4, 0, "<u4")
INT64 = Primitive("int64", "q", 8, 0, "<i8")
UINT64 = Primitive("uint64", "Q", 8, 0, "<u8")
FLOAT32 = Primitive("float32", "f", 4, 0.0, "<f4")
FLOAT64 = Primitive("float64", "d", 8, 0.0, "<f8")
STRING = Text()

_ALL = (BOOL, BYTE, CHAR, INT8, UINT8, INT16, UINT16, INT32, UINT32, INT64, UINT64, FLOAT32)
PRIMITIVES: dict[str, Primitive] = {p.name: p for p in (*_ALL, FLOAT64)}
"""Every primitive by its ``.msg`` name."""


@dataclass(frozen=True)
class Sequence:
    """An unbounded sequence (``float64[]``): a uint32 count, then the elements."""

    element: Primitive | Text | Struct

    def __repr__(self) -> str:
        return f"{self.element!r}[]"


@dataclass(frozen=True)
class Array:
    """A fixed-size array (``float64[36]``): the elements alone, no count."""

    element: Primitive | Text | Struct
    length: int

    def __repr__(self) -> str:
        return f"{self.element!r}[{self.length}]"


@dataclass(frozen=True, eq=False)
class Struct:
    """A ROS 2 message type: its name and its fields, in wire order.

    Compared by identity: each type is declared once.

    Attributes:
        ros_type: ``pkg/msg/Name``.
        fields: (name, type) of every field, in order.
        nanoseconds: a time (``builtin_interfaces/msg/Time`` or ``Duration``) whose values
            are integer nanoseconds rather than a (sec, nanosec) pair.
        defaults: the ``.msg`` defaults of fields that have one other than zero (a
            quaternion's ``w`` is 1), for types built field by field (DDS samples).
    """

    ros_type: str
    fields: tuple[tuple[str, WireType], ...]
    nanoseconds: bool = False
    defaults: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self) -> None:
        parts = self.ros_type.split("/")
        if len(parts) != 3 or parts[1] != "msg" or not all(parts):
            raise ValueError(f"message type {self.ros_type!r}: expected 'package/msg/Name'")
        names = [name for name, _ in self.fields]
        if len(set(names)) != len(names):
            raise ValueError(f"message type {self.ros_type!r} names a field twice: {names}")

    def __repr__(self) -> str:
        return self.ros_type

    @property
    def short(self) -> str:
        """``pkg/Name``, as a ``.msg`` file names a nested type."""
        package, _, name = self.ros_type.split("/")
        return f"{package}/{name}"

    def field_type(self, name: str) -> WireType:
        """The type of field ``name``.

        Raises:
            KeyError: for a field this type does not have.
        """
        for field_name, kind in self.fields:
            if field_name == name:
                return kind
        raise KeyError(f"{self.ros_type} has no field {name!r} (fields: {self.names()})")

    def names(self) -> list[str]:
        """The field names, in order."""
        return [name for name, _ in self.fields]

    def msg_text(self) -> str:
        """The ``.msg`` text of this type (one field a line)."""
        return "".join(f"{type_name(kind)} {name}\n" for name, kind in self.fields)

    def dependencies(self) -> list[Struct]:
        """Every type it nests, depth first, each once (itself not included)."""
        found: list[Struct] = []

        def visit(struct: Struct) -> None:
            for nested in _nested(struct):
                if nested not in found:
                    visit(nested)
                    found.append(nested)

        visit(self)
        return found


WireType = Primitive | Text | Sequence | Array | Struct
"""Anything a field may be."""


def struct(
    ros_type: str,
    *,
    nanoseconds: bool = False,
    defaults: dict[str, Any] | None = None,
    **fields: WireType,
) -> Struct:
    """Declare a message type: ``struct("geometry_msgs/msg/Point", x=FLOAT64, ...)``."""
    return Struct(ros_type, tuple(fields.items()), nanoseconds, tuple((defaults or {}).items()))


def type_name(kind: WireType) -> str:
    """How a ``.msg`` file names a field's type (``float64[36]``, ``std_msgs/Header``)."""
    if isinstance(kind, Struct):
        return kind.short
    if isinstance(kind, Sequence):
        return f"{type_name(kind.element)}[]"
    if isinstance(kind, Array):
        return f"{type_name(kind.element)}[{kind.length}]"
    return kind.name


def _nested(struct: Struct) -> Iterator[Struct]:
    for _, kind in struct.fields:
        element = kind.element if isinstance(kind, Sequence | Array) else kind
        if isinstance(element, Struct):
            yield element
