"""What robots share to map together (``cosim_msgs``): localized scans and map updates.

Every header is in ``map``.
"""

from __future__ import annotations

from dataclasses import field

from cosim.core.messages.aliases import (
    Bytes,
    Float32s,
    Header,
    float32,
    float64,
    int32,
    string,
    uint32,
)
from cosim.core.messages.declare import Message, ros_message


@ros_message("cosim_msgs/msg/LocalizedScan")
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

    stamp_ns: Header
    robot: string
    x_m: float64
    y_m: float64
    yaw_rad: float64
    angle_min_rad: float32
    angle_increment_rad: float32
    range_min_m: float32
    range_max_m: float32
    ranges_m: Float32s = field(repr=False)

    def __post_init__(self) -> None:
        self.ranges_m.flags.writeable = False


@ros_message("cosim_msgs/msg/MapUpdate")
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
        encoding: how ``data`` is packed.
        data: the compressed cells.
    """

    stamp_ns: Header
    robot: string
    seq: uint32
    ix0: int32
    iy0: int32
    width: uint32
    height: uint32
    scale: float32
    encoding: string = field(default="zlib-int8", kw_only=True)
    data: Bytes = field(repr=False)
