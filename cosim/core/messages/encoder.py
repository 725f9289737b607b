"""CDR encoding: the bytes of a message as ROS 2 puts it on the wire and rosbag2 stores it.

XCDR1, little endian, behind the 4-byte encapsulation header ``00 01 00 00``; a primitive
is aligned to its own size counted from the end of that header, a string is a uint32
length (counting the NUL), its UTF-8 bytes and the NUL, a sequence is a uint32 count and
its elements, a fixed array only its elements. The layouts are those of the ``.msg``
definitions (standard ROS 2 Humble types and :mod:`cosim.core.messages.definitions`); the tests
check every message byte for byte against rosbags' serializer and against ``size_bytes``.

Hand-written rather than rosbags' generic serializer because recording runs on the hot
path: the bag of a 50-robot run takes a few thousand messages per simulated second
(``make bench`` compares both).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence
from functools import lru_cache

import numpy as np
import numpy.typing as npt

HEADER = b"\x00\x01\x00\x00"
"""CDR encapsulation: XCDR1, little endian, no options."""
NS_PER_S = 1_000_000_000

_PAD = tuple(bytes(n) for n in range(8))
_I32 = struct.Struct("<i")
_U32 = struct.Struct("<I")
_TIME = struct.Struct("<iI")
_F64 = struct.Struct("<d")
_F32 = struct.Struct("<f")


class CdrWriter:
    """Appends CDR fields to a buffer, aligning each as ROS 2's serializer does.

    Usage: ``w = CdrWriter(); w.header(stamp_ns, "map"); w.f64s((x, y)); data = w.data()``.
    """

    __slots__ = ("buf",)

    def __init__(self) -> None:
        self.buf = bytearray(HEADER)

    def align(self, size: int) -> None:
        """Pad with zeros to a multiple of ``size`` bytes after the encapsulation header."""
        pad = -(len(self.buf) - 4) % size
        if pad:
            self.buf += _PAD[pad]

    def u8(self, value: int) -> None:
        """A uint8 (also a bool or an int8 written as its unsigned byte)."""
        self.buf.append(value & 0xFF)

    def boolean(self, value: bool) -> None:
        """A bool: one byte, 0 or 1."""
        self.buf.append(1 if value else 0)

    def i32(self, value: int) -> None:
        """An int32."""
        self.align(4)
        self.buf += _I32.pack(value)

    def u32(self, value: int) -> None:
        """A uint32 (also a sequence length)."""
        self.align(4)
        self.buf += _U32.pack(value)

    def f32(self, value: float) -> None:
        """A float32."""
        self.align(4)
        self.buf += _F32.pack(value)

    def f32s(self, values: Sequence[float]) -> None:
        """Consecutive float32 fields (or a fixed float32 array)."""
        self.align(4)
        self.buf += struct.pack(f"<{len(values)}f", *values)

    def f64(self, value: float) -> None:
        """A float64."""
        self.align(8)
        self.buf += _F64.pack(value)

    def f64s(self, values: Sequence[float]) -> None:
        """Consecutive float64 fields (or a fixed float64 array)."""
        self.align(8)
        self.buf += struct.pack(f"<{len(values)}d", *values)

    def zeros(self, count: int, size: int) -> None:
        """``count`` zero-valued primitives of ``size`` bytes (e.g. a covariance of zeros)."""
        self.align(size)
        self.buf += bytes(count * size)

    def time(self, stamp_ns: int) -> None:
        """A builtin_interfaces/Time (int32 sec, uint32 nanosec) from integer ns."""
        self.align(4)
        sec, nanosec = divmod(stamp_ns, NS_PER_S)
        self.buf += _TIME.pack(sec, nanosec)

    def string(self, text: str) -> None:
        """A string: uint32 length with the NUL, UTF-8 bytes, NUL."""
        raw = text.encode("utf-8")
        self.align(4)
        self.buf += _U32.pack(len(raw) + 1)
        self.buf += raw
        self.buf.append(0)

    def strings(self, texts: Sequence[str]) -> None:
        """A sequence of strings."""
        self.u32(len(texts))
        for text in texts:
            self.string(text)

    def header(self, stamp_ns: int, frame_id: str) -> None:
        """A std_msgs/Header."""
        self.time(stamp_ns)
        self.string(frame_id)

    def f32_seq(self, values: npt.NDArray[np.float32]) -> None:
        """A sequence of float32 from an array (copied as little-endian float32)."""
        self.u32(len(values))
        self.buf += np.ascontiguousarray(values, dtype="<f4").tobytes()

    def f64_seq(self, values: Sequence[float]) -> None:
        """A sequence of float64."""
        self.u32(len(values))
        if values:
            self.f64s(values)

    def i32_seq(self, values: Sequence[int]) -> None:
        """A sequence of int32."""
        self.u32(len(values))
        self.buf += struct.pack(f"<{len(values)}i", *values)

    def u8_seq(self, data: bytes) -> None:
        """A sequence of uint8 or int8, from raw bytes."""
        self.u32(len(data))
        self.buf += data

    def pose2d(self, x_m: float, y_m: float, yaw_rad: float, z_m: float = 0.0) -> None:
        """A geometry_msgs/Pose of a planar pose: Point and a yaw-only Quaternion."""
        half = 0.5 * yaw_rad
        self.f64s((x_m, y_m, z_m, 0.0, 0.0, math.sin(half), math.cos(half)))

    def data(self) -> bytes:
        """The encoded message, encapsulation header included."""
        return bytes(self.buf)


TIME = _TIME
"""builtin_interfaces/Time: int32 sec, uint32 nanosec."""


def time_bytes(stamp_ns: int) -> bytes:
    """A builtin_interfaces/Time from integer ns (needs 4-byte alignment)."""
    sec, nanosec = divmod(stamp_ns, NS_PER_S)
    return _TIME.pack(sec, nanosec)


@lru_cache(maxsize=4096)
def strings_block(offset: int, texts: tuple[str, ...], then_align: int) -> bytes:
    """The bytes of consecutive string fields starting at data offset ``offset``.

    For the fast paths of hot messages whose strings (frame ids) repeat: the strings with
    their alignment, then the padding that aligns the next field to ``then_align``. Only
    ``offset % 8`` matters, so callers pass that and the cache stays small.
    """
    w = CdrWriter()
    w.buf += bytes(offset)
    for text in texts:
        w.string(text)
    w.align(then_align)
    return bytes(w.buf[4 + offset :])
