"""The world as ROS 2 tools draw it: ``nav_msgs/OccupancyGrid`` and ``visualization_msgs`` markers.

Both are in ``map`` (metres, REP 103) unless a marker names a robot frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

from cosim.core.messages import std
from cosim.core.messages.declare import Message, ros_message
from cosim.core.messages.views import Const, Each, Outer, Planar

RGBA = tuple[float, float, float, float]
"""A colour: red, green, blue, alpha in [0, 1]."""


@ros_message(
    std.OCCUPANCY_GRID,
    wire={
        "header.stamp": "stamp_ns",
        "header.frame_id": "frame_id",
        "info.map_load_time": "stamp_ns",
        "info.resolution": "resolution_m",
        "info.width": "width",
        "info.height": "height",
        "info.origin.position.x": "origin_x_m",
        "info.origin.position.y": "origin_y_m",
        "info.origin.orientation.w": Const(1.0),
        "data": "data",
    },
)
class OccupancyGrid(Message):
    """A 2D occupancy map (``nav_msgs/msg/OccupancyGrid``), as map_server publishes on ``/map``.

    Its metadata's load time is its stamp; the origin has no rotation.

    Attributes:
        stamp_ns: time of the map, ns.
        frame_id: frame of the map (``map``).
        resolution_m: cell size (m).
        width, height: cells along x and y.
        origin_x_m, origin_y_m: position of cell (0, 0)'s outer corner in ``frame_id`` (m).
        data: ``width * height`` int8 values as bytes, row-major from the origin (0 free,
            100 occupied, -1 unknown).
    """

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


@ros_message(
    std.MARKER_ARRAY,
    wire={
        "markers": Each(
            "markers",
            Marker,
            {
                "header.stamp": Outer("stamp_ns"),
                "header.frame_id": "frame_id",
                "ns": "ns",
                "id": "marker_id",
                "type": "kind",
                "action": "action",
                "pose": Planar("x_m", "y_m", "yaw_rad", z="z_m"),
                "scale": "scale_m",
                "color": "color",
                "frame_locked": "frame_locked",
                "text": "text",
            },
        )
    },
)
class MarkerArray(Message):
    """Shapes for RViz and Foxglove (``visualization_msgs/msg/MarkerArray``).

    Every marker carries the array's stamp; lifetime 0 (forever); no points, colours,
    texture or mesh.

    Attributes:
        stamp_ns: time of every marker, ns.
        markers: the markers, applied in order.
    """

    stamp_ns: int
    markers: tuple[Marker, ...]
