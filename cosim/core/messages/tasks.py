"""Fleet coordination messages (``cosim_msgs``): tasks, claims and service.

Task ids are non-negative integers given by the task source; robots are named. Sizes are
those of the CDR encoding of the documented field layout.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from cosim.core.messages.base import Message
from cosim.core.messages.cdr import ENCAPSULATION, doubles, header, string, uint32
from cosim.core.messages.encoder import CdrWriter


@dataclass(frozen=True, slots=True)
class TaskInfo:
    """One open task inside a :class:`TaskSet` (``cosim_msgs/msg/TaskInfo``).

    Attributes:
        task_id: the task's id.
        x_m, y_m: where the task is served, in ``map`` (m).
        eligible: the robots that may serve it.
        holder: the robot committed to it (claim accepted or serving), or "".
    """

    task_id: int
    x_m: float
    y_m: float
    eligible: tuple[str, ...]
    holder: str = ""

    def end(self, offset: int) -> int:
        """CDR offset after this element: uint32 id, two float64, strings, holder."""
        offset = doubles(uint32(offset), 2)
        offset = uint32(offset)
        for name in self.eligible:
            offset = string(offset, name)
        return string(offset, self.holder)

    def write(self, w: CdrWriter) -> None:
        """Append this element to a message being encoded."""
        w.u32(self.task_id)
        w.f64s((self.x_m, self.y_m))
        w.strings(self.eligible)
        w.string(self.holder)


@dataclass(frozen=True, slots=True)
class TaskSet(Message):
    """The open tasks of an epoch, broadcast by the task source (``cosim_msgs/msg/TaskSet``).

    Attributes:
        stamp_ns: send time, ns.
        epoch: increases whenever the set of open tasks or their claims change.
        tasks: the open tasks, by id.
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/TaskSet"
    stamp_ns: int
    epoch: int
    tasks: tuple[TaskInfo, ...]

    def size_bytes(self) -> int:
        """Header, uint32 epoch, sequence of TaskInfo."""
        offset = uint32(uint32(header(0, "map")))
        for task in self.tasks:
            offset = task.end(offset)
        return ENCAPSULATION + offset

    def to_cdr(self) -> bytes:
        """Header in ``map``, epoch, the tasks."""
        w = CdrWriter()
        w.header(self.stamp_ns, "map")
        w.u32(self.epoch)
        w.u32(len(self.tasks))
        for task in self.tasks:
            task.write(w)
        return w.data()


@dataclass(frozen=True, slots=True)
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

    ros_type: ClassVar[str] = "cosim_msgs/msg/TaskClaim"
    stamp_ns: int
    epoch: int
    task_id: int
    robot: str
    cost_m: float
    state: str

    def size_bytes(self) -> int:
        """Header, two uint32, robot name, float64, state string."""
        offset = string(uint32(uint32(header(0, "map"))), self.robot)
        return ENCAPSULATION + string(doubles(offset, 1), self.state)

    def to_cdr(self) -> bytes:
        """Header in ``map``, epoch, task id, robot, cost, state."""
        w = CdrWriter()
        w.header(self.stamp_ns, "map")
        w.u32(self.epoch)
        w.u32(self.task_id)
        w.string(self.robot)
        w.f64(self.cost_m)
        w.string(self.state)
        return w.data()


@dataclass(frozen=True, slots=True)
class ServiceRequest(Message):
    """A robot at a task asks the task source for the right to serve it.

    ``cosim_msgs/msg/ServiceRequest``; the answer is a :class:`ServiceReply`.

    Attributes:
        stamp_ns: send time, ns.
        task_id: the task.
        robot: the robot asking.
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/ServiceRequest"
    stamp_ns: int
    task_id: int
    robot: str

    def size_bytes(self) -> int:
        """Header, uint32, robot name."""
        return ENCAPSULATION + string(uint32(header(0, "map")), self.robot)

    def to_cdr(self) -> bytes:
        """Header in ``map``, task id, robot."""
        return _task_robot(self.stamp_ns, self.task_id, self.robot).data()


@dataclass(frozen=True, slots=True)
class ServiceReply(Message):
    """The task source's answer to a :class:`ServiceRequest` (``cosim_msgs/msg/ServiceReply``).

    Attributes:
        stamp_ns: send time, ns.
        task_id: the task.
        robot: the robot that asked.
        granted: whether it may serve the task (exactly one robot ever is).
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/ServiceReply"
    stamp_ns: int
    task_id: int
    robot: str
    granted: bool

    def size_bytes(self) -> int:
        """Header, uint32, robot name, bool."""
        return ENCAPSULATION + string(uint32(header(0, "map")), self.robot) + 1

    def to_cdr(self) -> bytes:
        """Header in ``map``, task id, robot, granted."""
        w = _task_robot(self.stamp_ns, self.task_id, self.robot)
        w.boolean(self.granted)
        return w.data()


@dataclass(frozen=True, slots=True)
class TaskDone(Message):
    """A robot has served a task (``cosim_msgs/msg/TaskDone``).

    Attributes:
        stamp_ns: send time, ns.
        task_id: the task.
        robot: the robot that served it.
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/TaskDone"
    stamp_ns: int
    task_id: int
    robot: str

    def size_bytes(self) -> int:
        """Header, uint32, robot name."""
        return ENCAPSULATION + string(uint32(header(0, "map")), self.robot)

    def to_cdr(self) -> bytes:
        """Header in ``map``, task id, robot."""
        return _task_robot(self.stamp_ns, self.task_id, self.robot).data()


def _task_robot(stamp_ns: int, task_id: int, robot: str) -> CdrWriter:
    """A writer holding the header, task id and robot shared by the service messages."""
    w = CdrWriter()
    w.header(stamp_ns, "map")
    w.u32(task_id)
    w.string(robot)
    return w


__all__ = [
    "ServiceReply",
    "ServiceRequest",
    "TaskClaim",
    "TaskDone",
    "TaskInfo",
    "TaskSet",
]
