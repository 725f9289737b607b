"""What robots share to map together (``cosim_msgs``): localized scans and map updates."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import numpy.typing as npt

from cosim.core.messages.base import Message
from cosim.core.messages.cdr import ENCAPSULATION, doubles, float_seq, header, string, uint32
from cosim.core.messages.encoder import CdrWriter


@dataclass(frozen=True, slots=True)
class LocalizedScan(Message):
    """A scan with the pose its robot estimated for it (``cosim_msgs/msg/LocalizedScan``).

    What slam_toolbox's multi-robot mode exchanges: a neighbour adds the scan to its own
    map at that pose.

    Attributes:
        stamp_ns: when the scan was taken, ns.
        robot: the robot that took it.
        x_m, y_m, yaw_rad: estimated sensor pose in ``map``.
        angle_min_rad, angle_increment_rad: beam angles in the sensor frame (rad).
        range_min_m, range_max_m: valid ranges (m).
        ranges_m: float32 ranges (REP 117), read-only.
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/LocalizedScan"
    stamp_ns: int
    robot: str
    x_m: float
    y_m: float
    yaw_rad: float
    angle_min_rad: float
    angle_increment_rad: float
    range_min_m: float
    range_max_m: float
    ranges_m: npt.NDArray[np.float32] = field(repr=False)

    def __post_init__(self) -> None:
        self.ranges_m.flags.writeable = False

    def size_bytes(self) -> int:
        """Header, robot, three float64, four float32, float32 ranges."""
        offset = doubles(string(header(0, "map"), self.robot), 3)
        offset = float_seq(uint32(uint32(uint32(offset))) + 4, len(self.ranges_m))
        return ENCAPSULATION + offset

    def to_cdr(self) -> bytes:
        """Header in ``map``, robot, pose, beam geometry, ranges."""
        w = CdrWriter()
        w.header(self.stamp_ns, "map")
        w.string(self.robot)
        w.f64s((self.x_m, self.y_m, self.yaw_rad))
        w.f32s((self.angle_min_rad, self.angle_increment_rad, self.range_min_m, self.range_max_m))
        w.f32_seq(self.ranges_m)
        return w.data()


@dataclass(frozen=True, slots=True)
class MapUpdate(Message):
    """A block of a robot's new map evidence (``cosim_msgs/msg/MapUpdate``).

    The log-odds its own scans added to the cells of a rectangle since its last update,
    quantized to int8 steps of ``scale`` and zlib-compressed (``encoding``
    ``"zlib-int8"``), rows from the lowest y. A neighbour adds it to its own map.

    Attributes:
        stamp_ns: send time, ns.
        robot: the sender.
        seq: the sender's update number (a receiver sees what it missed).
        ix0, iy0: the rectangle's lower-left cell in the common map grid.
        width, height: its size in cells.
        scale: log-odds per int8 step.
        data: the compressed cells.
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/MapUpdate"
    stamp_ns: int
    robot: str
    seq: int
    ix0: int
    iy0: int
    width: int
    height: int
    scale: float
    data: bytes = field(repr=False)

    def size_bytes(self) -> int:
        """Header, robot, five uint32/int32, float32, encoding string, byte sequence."""
        offset = uint32(string(header(0, "map"), self.robot))
        offset = uint32(uint32(uint32(uint32(uint32(offset)))))
        offset = string(offset, "zlib-int8")
        return ENCAPSULATION + uint32(offset) + len(self.data)

    def to_cdr(self) -> bytes:
        """Header in ``map``, robot, rectangle, scale, encoding, data."""
        w = CdrWriter()
        w.header(self.stamp_ns, "map")
        w.string(self.robot)
        w.u32(self.seq)
        w.i32(self.ix0)
        w.i32(self.iy0)
        w.u32(self.width)
        w.u32(self.height)
        w.f32(self.scale)
        w.string("zlib-int8")
        w.u8_seq(self.data)
        return w.data()
