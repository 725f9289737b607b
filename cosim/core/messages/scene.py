"""The world as ROS 2 tools draw it: ``nav_msgs/OccupancyGrid`` and ``visualization_msgs`` markers.

Both are in ``map`` (metres, REP 103) unless a marker names a robot frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import ClassVar

from cosim.core.messages.base import Message
from cosim.core.messages.cdr import ENCAPSULATION, align, doubles, header, string, uint32
from cosim.core.messages.encoder import CdrWriter

RGBA = tuple[float, float, float, float]
"""A colour: red, green, blue, alpha in [0, 1]."""


@dataclass(frozen=True, slots=True)
class OccupancyGrid(Message):
    """A 2D occupancy map (``nav_msgs/msg/OccupancyGrid``), as map_server publishes on ``/map``.

    Attributes:
        stamp_ns: time of the map, ns.
        frame_id: frame of the map (``map``).
        resolution_m: cell size (m).
        width, height: cells along x and y.
        origin_x_m, origin_y_m: position of cell (0, 0)'s outer corner in ``frame_id`` (m).
        data: ``width * height`` int8 values as bytes, row-major from the origin (0 free,
            100 occupied, -1 unknown).
    """

    ros_type: ClassVar[str] = "nav_msgs/msg/OccupancyGrid"
    stamp_ns: int
    frame_id: str
    resolution_m: float
    width: int
    height: int
    origin_x_m: float
    origin_y_m: float
    data: bytes

    def __post_init__(self) -> None:
        if len(self.data) != self.width * self.height:
            raise ValueError(
                f"occupancy grid of {self.width} x {self.height} cells got {len(self.data)} values"
            )

    def size_bytes(self) -> int:
        """Header, MapMetaData (time, float32, two uint32, Pose), int8 sequence."""
        offset = header(0, self.frame_id)
        offset = doubles(uint32(uint32(uint32(align(offset, 4) + 8))), 7)
        return ENCAPSULATION + uint32(offset) + len(self.data)

    def to_cdr(self) -> bytes:
        """Header, metadata (load time = stamp), cells."""
        w = CdrWriter()
        w.header(self.stamp_ns, self.frame_id)
        w.time(self.stamp_ns)
        w.f32(self.resolution_m)
        w.u32(self.width)
        w.u32(self.height)
        w.pose2d(self.origin_x_m, self.origin_y_m, 0.0)
        w.u8_seq(self.data)
        return w.data()


class MarkerType(IntEnum):
    """The marker shapes used here (values of ``visualization_msgs/msg/Marker``)."""

    CUBE = 1
    SPHERE = 2
    CYLINDER = 3
    TEXT_VIEW_FACING = 9


class MarkerAction(IntEnum):
    """What a marker does to the display (values of ``visualization_msgs/msg/Marker``)."""

    ADD = 0
    DELETE = 2
    DELETEALL = 3


@dataclass(frozen=True, slots=True)
class Marker:
    """One shape of a :class:`MarkerArray`, planar pose, no lifetime (stays until replaced).

    Attributes:
        ns, marker_id: the marker's namespace and id (a later marker with both replaces it).
        kind: shape.
        action: add, delete, or delete all markers of ``ns``.
        frame_id: frame of the pose (``map``, or ``robot_i/base_link`` to ride along).
        x_m, y_m, z_m, yaw_rad: pose of the shape's centre.
        scale_m: size along x, y, z (m).
        color: RGBA in [0, 1].
        frame_locked: re-transform the marker every frame (for markers on robots).
        text: the text of a text marker.
    """

    ns: str
    marker_id: int
    kind: MarkerType
    frame_id: str = "map"
    x_m: float = 0.0
    y_m: float = 0.0
    z_m: float = 0.0
    yaw_rad: float = 0.0
    scale_m: tuple[float, float, float] = (1.0, 1.0, 1.0)
    color: RGBA = (1.0, 1.0, 1.0, 1.0)
    action: MarkerAction = MarkerAction.ADD
    frame_locked: bool = False
    text: str = ""

    def end(self, offset: int) -> int:
        """CDR offset after this marker (Humble/Jazzy layout, empty optional fields)."""
        offset = string(header(offset, self.frame_id), self.ns)
        offset = uint32(uint32(uint32(offset)))  # id, type, action
        offset = doubles(offset, 7 + 3)  # pose, scale
        offset = uint32(uint32(align(offset, 4) + 16))  # color, lifetime (int32, uint32)
        offset = uint32(uint32(offset + 1))  # frame_locked, empty points, empty colors
        offset = string(offset, "")  # texture_resource
        offset = uint32(string(header(offset, ""), ""))  # texture: header, format, data
        offset = uint32(offset)  # uv_coordinates
        offset = string(string(offset, self.text), "")  # text, mesh_resource
        offset = uint32(string(offset, ""))  # mesh_file: filename, data
        return offset + 1  # mesh_use_embedded_materials

    def write(self, w: CdrWriter, stamp_ns: int) -> None:
        """Append this marker to a message being encoded."""
        w.header(stamp_ns, self.frame_id)
        w.string(self.ns)
        w.i32(self.marker_id)
        w.i32(int(self.kind))
        w.i32(int(self.action))
        w.pose2d(self.x_m, self.y_m, self.yaw_rad, self.z_m)
        w.f64s(self.scale_m)
        w.f32s(self.color)
        w.time(0)  # lifetime 0: forever
        w.boolean(self.frame_locked)
        w.u32(0)  # points
        w.u32(0)  # colors
        w.string("")  # texture_resource
        w.header(0, "")  # texture (sensor_msgs/CompressedImage), empty
        w.string("")
        w.u32(0)
        w.u32(0)  # uv_coordinates
        w.string(self.text)
        w.string("")  # mesh_resource
        w.string("")  # mesh_file.filename
        w.u32(0)  # mesh_file.data
        w.boolean(False)  # mesh_use_embedded_materials


@dataclass(frozen=True, slots=True)
class MarkerArray(Message):
    """Shapes for RViz and Foxglove (``visualization_msgs/msg/MarkerArray``).

    Attributes:
        stamp_ns: time of every marker, ns.
        markers: the markers, applied in order.
    """

    ros_type: ClassVar[str] = "visualization_msgs/msg/MarkerArray"
    stamp_ns: int
    markers: tuple[Marker, ...]

    def size_bytes(self) -> int:
        """A sequence of Marker."""
        offset = uint32(0)
        for marker in self.markers:
            offset = marker.end(offset)
        return ENCAPSULATION + offset

    def to_cdr(self) -> bytes:
        """Every marker with the array's stamp."""
        w = CdrWriter()
        w.u32(len(self.markers))
        for marker in self.markers:
            marker.write(w, self.stamp_ns)
        return w.data()
