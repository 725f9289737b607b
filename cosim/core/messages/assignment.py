"""Assignment-protocol messages (``cosim_msgs``): rounds, central orders and decisions.

Sizes are those of the CDR encoding of the documented field layout.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar

from cosim.core.messages.base import Message
from cosim.core.messages.cdr import ENCAPSULATION, doubles, header, string, uint32
from cosim.core.messages.encoder import CdrWriter

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

    def to_cdr(self) -> bytes:
        """Header in ``map``, epoch, robot, round, the columns."""
        w = CdrWriter()
        w.header(self.stamp_ns, "map")
        w.u32(self.epoch)
        w.string(self.robot)
        w.u32(self.round)
        w.u32(len(self.columns))
        for kind, robot, task, cost in self.columns:
            w.u8(kind)
            w.i32(robot)
            w.i32(task)
            w.f64(cost)
        return w.data()


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

    def to_cdr(self) -> bytes:
        """Header in ``map``, epoch, robot, bids, winners."""
        w = CdrWriter()
        w.header(self.stamp_ns, "map")
        w.u32(self.epoch)
        w.string(self.robot)
        w.f64_seq(self.bids)
        w.i32_seq(self.winners)
        return w.data()


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

    def to_cdr(self) -> bytes:
        """Header in ``map``, epoch, robot, task id, cost."""
        w = CdrWriter()
        w.header(self.stamp_ns, "map")
        w.u32(self.epoch)
        w.string(self.robot)
        w.i32(self.task_id)
        w.f64(self.cost_m)
        return w.data()


@dataclass(frozen=True, slots=True)
class TaskAssignment(Message):
    """What a robot's assignment protocol decided in an epoch (``cosim_msgs/msg/TaskAssignment``).

    Published on ``/fleet/assignment`` for tools and recordings, as a ChoiRbot node reports
    its result; no robot depends on it.

    Attributes:
        stamp_ns: when the protocol decided, ns.
        epoch: the epoch decided.
        robot: the deciding robot.
        task_id: the task it chose, or -1 for none.
        cost_m: its cost for that task (m), ``nan`` for none.
        rounds: protocol rounds the robot ran in the epoch before deciding.
    """

    ros_type: ClassVar[str] = "cosim_msgs/msg/TaskAssignment"
    stamp_ns: int
    epoch: int
    robot: str
    task_id: int
    cost_m: float
    rounds: int

    def size_bytes(self) -> int:
        """Header, uint32 epoch, robot name, int32 task, float64 cost, uint32 rounds."""
        offset = uint32(string(uint32(header(0, "map")), self.robot))
        return ENCAPSULATION + uint32(doubles(offset, 1))

    def to_cdr(self) -> bytes:
        """Header in ``map``, epoch, robot, task id, cost, rounds."""
        w = CdrWriter()
        w.header(self.stamp_ns, "map")
        w.u32(self.epoch)
        w.string(self.robot)
        w.i32(self.task_id)
        w.f64(self.cost_m)
        w.u32(self.rounds)
        return w.data()


__all__ = ["AuctionBids", "Column", "SimplexBasis", "TaskAssignment", "TaskOrder"]
