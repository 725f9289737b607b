"""Time and frames as ROS 2 tools expect them: ``/clock`` and ``/tf`` (tf2_msgs).

Frames follow REP 105 with a prefix per robot: ``map`` -> ``robot_i/odom`` ->
``robot_i/base_link`` -> ``robot_i/laser``. Transforms are planar (z = 0, yaw only).
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from typing import ClassVar, NamedTuple

from cosim.core.messages.base import Message
from cosim.core.messages.cdr import ENCAPSULATION, doubles, header, string, uint32
from cosim.core.messages.encoder import HEADER, CdrWriter, strings_block, time_bytes

_COUNT = struct.Struct("<I")
_TRANSFORM = struct.Struct("<2d24x2d")
"""A planar Transform: x, y, (z, qx, qy = 0), qz, qw."""


class Transform(NamedTuple):
    """A planar transform: the pose of ``child`` in ``parent`` (m, m, rad).

    Attributes:
        parent: the parent frame (the header's frame_id).
        child: the child frame.
        x_m, y_m: translation of the child's origin in the parent frame (m).
        yaw_rad: rotation of the child about z (rad, counter-clockwise).
    """

    parent: str
    child: str
    x_m: float
    y_m: float
    yaw_rad: float


@dataclass(frozen=True, slots=True)
class TFMessage(Message):
    """Transforms sharing one stamp (``tf2_msgs/msg/TFMessage`` on ``/tf`` and ``/tf_static``).

    Attributes:
        stamp_ns: time of every transform, ns.
        transforms: the transforms.
    """

    ros_type: ClassVar[str] = "tf2_msgs/msg/TFMessage"
    stamp_ns: int
    transforms: tuple[Transform, ...]

    def size_bytes(self) -> int:
        """A sequence of TransformStamped: header, child frame, Vector3, Quaternion."""
        offset = uint32(0)
        for t in self.transforms:
            offset = doubles(string(header(offset, t.parent), t.child), 7)
        return ENCAPSULATION + offset

    def to_cdr(self) -> bytes:
        """Each transform as a TransformStamped with the message's stamp."""
        stamp = time_bytes(self.stamp_ns)
        parts = [HEADER, _COUNT.pack(len(self.transforms))]
        offset = 4
        pack = _TRANSFORM.pack
        for t in self.transforms:
            # after a transform's doubles (or the count) the offset is a multiple of 4 and
            # only its remainder modulo 8 shapes the padding
            block = strings_block((offset + 8) % 8, (t.parent, t.child), 8)
            half = 0.5 * t.yaw_rad
            parts += (stamp, block, pack(t.x_m, t.y_m, math.sin(half), math.cos(half)))
            offset += 8 + len(block) + _TRANSFORM.size
        return b"".join(parts)


@dataclass(frozen=True, slots=True)
class Clock(Message):
    """The simulation time (``rosgraph_msgs/msg/Clock`` on ``/clock``).

    Attributes:
        stamp_ns: simulation time, ns.
    """

    ros_type: ClassVar[str] = "rosgraph_msgs/msg/Clock"
    stamp_ns: int

    def size_bytes(self) -> int:
        """One builtin_interfaces/Time."""
        return ENCAPSULATION + 8

    def to_cdr(self) -> bytes:
        """The time as (int32 sec, uint32 nanosec)."""
        w = CdrWriter()
        w.time(self.stamp_ns)
        return w.data()
