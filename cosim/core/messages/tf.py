"""Time and frames as ROS 2 tools expect them: ``/clock`` and ``/tf`` (tf2_msgs).

Frames follow REP 105 with a prefix per robot: ``map`` -> ``robot_i/odom`` ->
``robot_i/base_link`` -> ``robot_i/laser``. Transforms are planar (z = 0, yaw only).
"""

from __future__ import annotations

from typing import NamedTuple

from cosim.core.messages import std
from cosim.core.messages.declare import Message, ros_message
from cosim.core.messages.views import Each, Outer, Planar


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


@ros_message(
    std.TF_MESSAGE,
    wire={
        "transforms": Each(
            "transforms",
            Transform,
            {
                "header.stamp": Outer("stamp_ns"),
                "header.frame_id": "parent",
                "child_frame_id": "child",
                "transform": Planar("x_m", "y_m", "yaw_rad"),
            },
        )
    },
)
class TFMessage(Message):
    """Transforms sharing one stamp (``tf2_msgs/msg/TFMessage`` on ``/tf`` and ``/tf_static``).

    Each transform goes as a TransformStamped with the message's stamp.

    Attributes:
        stamp_ns: time of every transform, ns.
        transforms: the transforms.
    """

    stamp_ns: int
    transforms: tuple[Transform, ...]


@ros_message(std.CLOCK, wire={"clock": "stamp_ns"})
class Clock(Message):
    """The simulation time (``rosgraph_msgs/msg/Clock`` on ``/clock``).

    Attributes:
        stamp_ns: simulation time, ns.
    """

    stamp_ns: int
