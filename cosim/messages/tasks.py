"""Fleet coordination messages (``cosim_msgs``): tasks, claims, service, protocol rounds.

Task ids are non-negative integers given by the task source; robots are named. Sizes are
those of the CDR encoding of the documented field layout.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar

from cosim.messages.base import Message
from cosim.messages.cdr import ENCAPSULATION, doubles, header, string, uint32


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


Column = tuple[int, int, int, float]
"""A column of the assignment LP: (kind, robot index, task index, cost)."""


@lru_cache(maxsize=1024)
def _columns_end(offset: int, count: int) -> int:
    # per column: uint8 kind, int32 robot, int32 task, float64 cost
    offset = uint32(offset)
    for _ in range(count):
        offset = doubles(uint32(uint32(offset + 1)), 1)
    return offset


@dataclass(frozen=True, slots=True)
class SimplexBasis(Message):
    """A robot's current basis in a distributed-simplex round (``cosim_msgs/msg/SimplexBasis``).

    Attributes:
        stamp_ns: send time, ns.
        epoch: the assignment problem it belongs to.
        robot: the sender.
        round: the sender's round number in the epoch.
        columns: the basis columns (kind, robot index, task index, cost).
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/SimplexBasis"
    stamp_ns: int
    epoch: int
    robot: str
    round: int
    columns: tuple[Column, ...]

    def size_bytes(self) -> int:
        """Header, uint32 epoch, robot name, uint32 round, sequence of columns."""
        offset = uint32(string(uint32(header(0, "map")), self.robot))
        return ENCAPSULATION + _columns_end(offset, len(self.columns))


@dataclass(frozen=True, slots=True)
class AuctionBids(Message):
    """A robot's view of the winning bids (CBBA consensus; ``cosim_msgs/msg/AuctionBids``).

    Attributes:
        stamp_ns: send time, ns.
        epoch: the assignment problem it belongs to.
        robot: the sender.
        bids: winning bid known per task index.
        winners: winning robot index known per task index (-1: none).
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/AuctionBids"
    stamp_ns: int
    epoch: int
    robot: str
    bids: tuple[float, ...]
    winners: tuple[int, ...]

    def size_bytes(self) -> int:
        """Header, uint32 epoch, robot name, float64 sequence, int32 sequence."""
        offset = string(uint32(header(0, "map")), self.robot)
        offset = doubles(uint32(offset), len(self.bids))
        return ENCAPSULATION + uint32(offset) + 4 * len(self.winners)


@dataclass(frozen=True, slots=True)
class TaskOrder(Message):
    """The base station tells a robot its task (centralized baseline; ``cosim_msgs/msg/TaskOrder``).

    Attributes:
        stamp_ns: send time, ns.
        epoch: the epoch the order was computed in.
        robot: the robot.
        task_id: its task, or -1 for none.
        cost_m: the robot's cost for it (m).
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/TaskOrder"
    stamp_ns: int
    epoch: int
    robot: str
    task_id: int
    cost_m: float

    def size_bytes(self) -> int:
        """Header, uint32 epoch, robot name, int32, float64."""
        offset = uint32(string(uint32(header(0, "map")), self.robot))
        return ENCAPSULATION + doubles(offset, 1)


__all__ = [
    "AuctionBids",
    "Column",
    "ServiceReply",
    "ServiceRequest",
    "SimplexBasis",
    "TaskClaim",
    "TaskDone",
    "TaskInfo",
    "TaskOrder",
    "TaskSet",
]
