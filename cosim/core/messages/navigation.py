"""The project's own navigation messages (``cosim_msgs``): goals, their progress, robot states."""

from __future__ import annotations

from cosim.core.messages.aliases import Header, float64, string, uint32
from cosim.core.messages.declare import Message, ros_message


@ros_message("cosim_msgs/msg/NavGoal")
class NavGoal(Message):
    """A "go to (x, y[, yaw])" goal for a robot's navigation (``cosim_msgs/msg/NavGoal``).

    Attributes:
        stamp_ns: when the goal was issued, ns (header in ``map``).
        goal_id: the sender's id of this goal; statuses refer to it.
        x_m, y_m: goal position in ``map`` (m).
        yaw_rad: goal heading in ``map`` (rad), or ``nan`` for any heading.
    """

    stamp_ns: Header
    goal_id: uint32
    x_m: float64
    y_m: float64
    yaw_rad: float64 = float("nan")


@ros_message("cosim_msgs/msg/NavStatus")
class NavStatus(Message):
    """Progress of a navigation goal (``cosim_msgs/msg/NavStatus``).

    Attributes:
        stamp_ns: time of the report, ns (header in ``map``).
        goal_id: the goal it is about.
        state: ``accepted`` | ``progress`` | ``arrived`` | ``stuck`` | ``unreachable`` |
            ``cancelled``.
        x_m, y_m: the robot's position in ``map`` (m).
        remaining_m: path length still to go (m), ``nan`` when unknown.
    """

    stamp_ns: Header
    goal_id: uint32
    state: string
    x_m: float64
    y_m: float64
    remaining_m: float64


@ros_message("cosim_msgs/msg/RobotState")
class RobotState(Message):
    """A robot's pose, speed and footprint, broadcast to the others (robots layer).

    ``cosim_msgs/msg/RobotState``, as a Nav2 user's shared "robots layer" would send.

    Attributes:
        stamp_ns: time of the pose, ns (header in ``map``).
        robot: the robot's name.
        x_m, y_m, yaw_rad: pose in ``map`` (m, m, rad).
        v_mps: forward speed (m/s).
        radius_m: footprint radius (m).
    """

    stamp_ns: Header
    robot: string
    x_m: float64
    y_m: float64
    yaw_rad: float64
    v_mps: float64
    radius_m: float64
