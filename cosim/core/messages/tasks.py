"""Fleet coordination messages (``cosim_msgs``): tasks, claims and service.

Task ids are non-negative integers given by the task source; robots are named. Every
header is in ``map``.
"""

from __future__ import annotations

from cosim.core.messages.aliases import Header, Strings, bool_, float64, string, uint32
from cosim.core.messages.declare import Message, ros_message


@ros_message("cosim_msgs/msg/TaskInfo")
class TaskInfo(Message):
    """One open task inside a :class:`TaskSet` (``cosim_msgs/msg/TaskInfo``).

    Attributes:
        task_id: the task's id.
        x_m, y_m: where the task is served, in ``map`` (m).
        eligible: the robots that may serve it.
        holder: the robot committed to it (claim accepted or serving), or "".
    """

    task_id: uint32
    x_m: float64
    y_m: float64
    eligible: Strings
    holder: string = ""


@ros_message("cosim_msgs/msg/TaskSet")
class TaskSet(Message):
    """The open tasks of an epoch, broadcast by the task source (``cosim_msgs/msg/TaskSet``).

    Attributes:
        stamp_ns: send time, ns.
        epoch: increases whenever the set of open tasks or their claims change.
        tasks: the open tasks, by id.
    """

    stamp_ns: Header
    epoch: uint32
    tasks: tuple[TaskInfo, ...]


@ros_message("cosim_msgs/msg/TaskClaim")
class TaskClaim(Message):
    """A robot commits to a task, or gives it up (``cosim_msgs/msg/TaskClaim``).

    Attributes:
        stamp_ns: send time, ns.
        epoch: the epoch the claim was decided in.
        task_id: the task.
        robot: the claiming robot.
        cost_m: the robot's cost for the task (m); conflicts go to the lower cost.
        state: ``claim`` or ``release``.
    """

    stamp_ns: Header
    epoch: uint32
    task_id: uint32
    robot: string
    cost_m: float64
    state: string


@ros_message("cosim_msgs/msg/ServiceRequest")
class ServiceRequest(Message):
    """A robot at a task asks the task source for the right to serve it.

    ``cosim_msgs/msg/ServiceRequest``; the answer is a :class:`ServiceReply`.

    Attributes:
        stamp_ns: send time, ns.
        task_id: the task.
        robot: the robot asking.
    """

    stamp_ns: Header
    task_id: uint32
    robot: string


@ros_message("cosim_msgs/msg/ServiceReply")
class ServiceReply(Message):
    """The task source's answer to a :class:`ServiceRequest` (``cosim_msgs/msg/ServiceReply``).

    Attributes:
        stamp_ns: send time, ns.
        task_id: the task.
        robot: the robot that asked.
        granted: whether it may serve the task (exactly one robot ever is).
    """

    stamp_ns: Header
    task_id: uint32
    robot: string
    granted: bool_


@ros_message("cosim_msgs/msg/TaskDone")
class TaskDone(Message):
    """A robot has served a task (``cosim_msgs/msg/TaskDone``).

    Attributes:
        stamp_ns: send time, ns.
        task_id: the task.
        robot: the robot that served it.
    """

    stamp_ns: Header
    task_id: uint32
    robot: string
