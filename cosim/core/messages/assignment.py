"""Assignment-protocol messages (``cosim_msgs``): rounds, central orders and decisions.

Every header is in ``map``.
"""

from __future__ import annotations

from typing import Annotated

from cosim.core.messages.aliases import Float64s, Header, Int32s, float64, int32, string, uint32
from cosim.core.messages.declare import Message, ros_message
from cosim.core.messages.wire import FLOAT64, INT32, UINT8, Sequence, struct

Column = tuple[int, int, int, float]
"""A column of the assignment LP: (kind, robot index, task index, cost)."""

SIMPLEX_COLUMN = struct(
    "cosim_msgs/msg/SimplexColumn", kind=UINT8, robot=INT32, task=INT32, cost=FLOAT64
)
"""A basis column on the wire (a :data:`Column` tuple in the message)."""


@ros_message("cosim_msgs/msg/SimplexBasis")
class SimplexBasis(Message):
    """A robot's current basis in a distributed-simplex round (``cosim_msgs/msg/SimplexBasis``).

    Attributes:
        stamp_ns: send time, ns.
        epoch: the assignment problem it belongs to.
        robot: the sender.
        round: the sender's round number in the epoch.
        columns: the basis columns (kind, robot index, task index, cost).
    """

    stamp_ns: Header
    epoch: uint32
    robot: string
    round: uint32
    columns: Annotated[tuple[Column, ...], Sequence(SIMPLEX_COLUMN)]


@ros_message("cosim_msgs/msg/CbbaBids")
class CbbaBids(Message):
    """A robot's view of the winning bids (CBBA consensus; ``cosim_msgs/msg/CbbaBids``).

    Attributes:
        stamp_ns: send time, ns.
        epoch: the assignment problem it belongs to.
        robot: the sender.
        bids: winning bid known per task index.
        winners: winning robot index known per task index (-1: none).
    """

    stamp_ns: Header
    epoch: uint32
    robot: string
    bids: Float64s
    winners: Int32s


@ros_message("cosim_msgs/msg/TaskOrder")
class TaskOrder(Message):
    """The base station tells a robot its task (centralized baseline; ``cosim_msgs/msg/TaskOrder``).

    Attributes:
        stamp_ns: send time, ns.
        epoch: the epoch the order was computed in.
        robot: the robot.
        task_id: its task, or -1 for none.
        cost_m: the robot's cost for it (m).
    """

    stamp_ns: Header
    epoch: uint32
    robot: string
    task_id: int32
    cost_m: float64


@ros_message("cosim_msgs/msg/TaskAssignment")
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

    stamp_ns: Header
    epoch: uint32
    robot: string
    task_id: int32
    cost_m: float64
    rounds: uint32


__all__ = [
    "SIMPLEX_COLUMN",
    "CbbaBids",
    "Column",
    "SimplexBasis",
    "TaskAssignment",
    "TaskOrder",
]
