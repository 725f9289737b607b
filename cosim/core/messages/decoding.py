"""CDR decoding of every declared message type into nested tuples.

A struct decodes to a tuple of its fields in order; a time (``builtin_interfaces``) to
integer ns; a string to ``str``; a numeric sequence to a NumPy array, a byte sequence to
``bytes``; a sequence of structs to a list. Bytes come from the network, a bag or a Unity
scene and are not trusted: whatever does not hold a message of the type (a wrong
encapsulation, too few bytes, a string without its NUL or not UTF-8, a count beyond the
bytes, more than 3 bytes left over after it) is refused with
:class:`~cosim.core.errors.WireError`, naming the type and the byte.
"""

from __future__ import annotations

import struct as _struct
from typing import Any

import numpy as np

from cosim.core.errors import WireError
from cosim.core.messages.wire import (
    HEADER,
    NS_PER_S,
    UINT32,
    Array,
    Primitive,
    Struct,
    Text,
    WireType,
)


class _Reader:
    """Reads values of declared types from CDR bytes (after the encapsulation header)."""

    def __init__(self, data: bytes | bytearray | memoryview) -> None:
        self.data = bytes(data)
        self.end = len(self.data)
        self.at = 4

    def fail(self, what: str) -> WireError:
        return WireError(f"{what} at byte {self.at} of {self.end}")

    def align(self, a: int) -> None:
        self.at += -(self.at - 4) % a

    def take(self, kind: Primitive, count: int = 1) -> Any:
        self.align(kind.size)
        end = self.at + kind.size * count
        if end > self.end:
            raise self.fail(f"{count} {kind.name} cut short")
        values = _struct.unpack_from(f"<{count}{kind.code}", self.data, self.at)
        self.at = end
        return values[0] if count == 1 else values

    def text(self) -> str:
        length = self.take(UINT32)
        end = self.at + length
        if length < 1 or end > self.end or self.data[end - 1] != 0:
            raise self.fail(f"a string of {length} bytes with its NUL")
        try:
            value = self.data[self.at : end - 1].decode("utf-8")
        except UnicodeDecodeError as error:
            raise self.fail(f"a string that is not UTF-8 ({error.reason})") from None
        self.at = end
        return value

    def value(self, kind: WireType) -> Any:
        if isinstance(kind, Primitive):
            return self.take(kind)
        if isinstance(kind, Text):
            return self.text()
        if isinstance(kind, Struct):
            if kind.nanoseconds:
                sec, nanosec = self.take(kind.fields[0][1]), self.take(kind.fields[1][1])  # type: ignore[arg-type]
                return sec * NS_PER_S + nanosec
            return tuple(self.value(k) for _, k in kind.fields)
        if isinstance(kind, Array):
            return self.items(kind.element, kind.length)
        count = self.take(UINT32)
        return self.items(kind.element, count)

    def items(self, element: Primitive | Text | Struct, count: int) -> Any:
        if isinstance(element, Primitive):
            if count and element.size > 1:
                self.align(element.size)
            end = self.at + element.size * count
            if end > self.end:
                raise self.fail(f"{count} {element.name} cut short")
            raw = self.data[self.at : end]
            self.at = end
            if element.size == 1 and element.name != "bool":
                return raw
            return np.frombuffer(raw, dtype=element.numpy).copy()
        if count > self.end - self.at:  # every element takes a byte at least
            raise self.fail(f"{count} elements in fewer bytes")
        return [self.value(element) for _ in range(count)]


def decode_tree(kind: Struct, data: bytes | bytearray | memoryview) -> tuple[Any, ...]:
    """The fields of a ``kind`` message in CDR ``data``, as nested tuples.

    Raises:
        WireError: for bytes that are not such a message (a wrong encapsulation, too
            short, a string without its NUL or not UTF-8, a count beyond the bytes).
    """
    reader = _Reader(data)
    if reader.data[:4] != HEADER:
        raise WireError(
            f"{kind.ros_type}: encapsulation {reader.data[:4].hex(' ') or 'missing'}; "
            "expected 00 01 00 00 (CDR, little endian)"
        )
    try:
        tree = reader.value(kind)
    except WireError as error:
        raise WireError(f"{kind.ros_type}: {error}") from None
    left = reader.end - reader.at
    if left > 3:  # a message may end in up to 3 bytes of padding, not more
        raise WireError(
            f"{kind.ros_type}: {left} bytes left over after the message at byte {reader.at} "
            f"of {reader.end}; expected its end"
        )
    return tree  # type: ignore[no-any-return]
