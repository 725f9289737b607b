"""The project's own messages (``cosim_msgs``): navigation goals and fleet coordination."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from cosim.core.messages.base import Message
from cosim.core.messages.cdr import ENCAPSULATION, doubles, header, string, uint32
from cosim.core.messages.encoder import CdrWriter


@dataclass(frozen=True, slots=True)
class NavGoal(Message):
    """A "go to (x, y[, yaw])" goal for a robot's navigation (``cosim_msgs/msg/NavGoal``).

    Attributes:
        stamp_ns: when the goal was issued, ns.
        goal_id: the sender's id of this goal; statuses refer to it.
        x_m, y_m: goal position in ``map`` (m).
        yaw_rad: goal heading in ``map`` (rad), or ``nan`` for any heading.
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/NavGoal"
    stamp_ns: int
    goal_id: int
    x_m: float
    y_m: float
    yaw_rad: float = float("nan")

    def size_bytes(self) -> int:
        """Header in ``map``, uint32 id, three float64."""
        return ENCAPSULATION + doubles(uint32(header(0, "map")), 3)

    def to_cdr(self) -> bytes:
        """Header in ``map``, goal id, x, y, yaw."""
        w = CdrWriter()
        w.header(self.stamp_ns, "map")
        w.u32(self.goal_id)
        w.f64s((self.x_m, self.y_m, self.yaw_rad))
        return w.data()


@dataclass(frozen=True, slots=True)
class NavStatus(Message):
    """Progress of a navigation goal (``cosim_msgs/msg/NavStatus``).

    Attributes:
        stamp_ns: time of the report, ns.
        goal_id: the goal it is about.
        state: ``accepted`` | ``progress`` | ``arrived`` | ``stuck`` | ``unreachable`` |
            ``cancelled``.
        x_m, y_m: the robot's position in ``map`` (m).
        remaining_m: path length still to go (m), ``nan`` when unknown.
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/NavStatus"
    stamp_ns: int
    goal_id: int
    state: str
    x_m: float
    y_m: float
    remaining_m: float

    def size_bytes(self) -> int:
        """Header, uint32 id, state string, three float64."""
        offset = string(uint32(header(0, "map")), self.state)
        return ENCAPSULATION + doubles(offset, 3)

    def to_cdr(self) -> bytes:
        """Header in ``map``, goal id, state, x, y, remaining."""
        w = CdrWriter()
        w.header(self.stamp_ns, "map")
        w.u32(self.goal_id)
        w.string(self.state)
        w.f64s((self.x_m, self.y_m, self.remaining_m))
        return w.data()


@dataclass(frozen=True, slots=True)
class RobotState(Message):
    """A robot's pose, speed and footprint, broadcast to the others (robots layer).

    ``cosim_msgs/msg/RobotState``, as a Nav2 user's shared "robots layer" would send.

    Attributes:
        stamp_ns: time of the pose, ns.
        robot: the robot's name.
        x_m, y_m, yaw_rad: pose in ``map`` (m, m, rad).
        v_mps: forward speed (m/s).
        radius_m: footprint radius (m).
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/RobotState"
    stamp_ns: int
    robot: str
    x_m: float
    y_m: float
    yaw_rad: float
    v_mps: float
    radius_m: float

    def size_bytes(self) -> int:
        """Header, robot name, five float64."""
        return ENCAPSULATION + doubles(string(header(0, "map"), self.robot), 5)

    def to_cdr(self) -> bytes:
        """Header in ``map``, robot name, x, y, yaw, v, radius."""
        w = CdrWriter()
        w.header(self.stamp_ns, "map")
        w.string(self.robot)
        w.f64s((self.x_m, self.y_m, self.yaw_rad, self.v_mps, self.radius_m))
        return w.data()
