"""What an assignment protocol is: the contract a plugin's protocol fulfils.

A protocol is a class registered by name in the ``cosim.protocols`` entry-point group and
chosen with ``assignment.protocol``. The task assignment adapter builds one instance per run
(:class:`ProtocolFleet` tells it the fleet) and asks it, every time a robot hears a new
epoch (the open tasks), for that robot's :class:`ProtocolAgent`. Every
``assignment.period_ms`` the agent runs a round on the protocol messages the robot received
(only messages of the protocol's own :attr:`~AssignmentProtocolType.message` type, of this
epoch, from other robots) and returns what to broadcast on the protocol's
:attr:`~AssignmentProtocolType.topic`, over the network model. Once the agent has
*decided*, the robot claims its :meth:`~ProtocolAgent.task`, drives there and serves it;
claims, service and conflicts are the adapter's, the same for every protocol.

A *central* protocol decides on the base station instead: robots report their poses, and
at every announcement the task source asks :meth:`~AssignmentProtocolType.orders` for each
free robot's task.

The messages a protocol exchanges are :class:`~cosim.core.messages.Message` subclasses with
``epoch`` (int) and ``robot`` (the sender's name) attributes, a ROS 2 type name and a CDR
encoding (so the network model sizes them and bags record them).

Every answer is checked where it enters the task assignment
(:mod:`adapters.assignment.answers`): one cosim cannot act on (a task index out of the
epoch's range, a message of another type than :attr:`~AssignmentProtocolType.message`, a
``decided`` that is no bool, orders for robots that are not free or tasks not offered, a
task ordered twice, ...) ends the run with a :class:`~cosim.core.plugins.PluginError`
naming the protocol, the robot, the value and what was expected.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

from cosim.core.adapter import RunContext
from cosim.core.messages import Message, TaskInfo
from cosim.core.registry import Group, Registry
from models.assignment.problem import AssignmentProblem


@dataclass(frozen=True)
class ProtocolFleet:
    """What a protocol knows of the run when it is built.

    Attributes:
        run: the run (settings by section type: ``run.settings(MyProtocolSettings)``,
            named random streams: ``run.rng.stream("my_protocol")``).
        names: the robots, in fleet order (agent ``i`` is robot ``names[i]``).
        diameter: hops across the robots' communication graph (or
            ``assignment.diameter_bound``): how long a protocol must wait for news from
            the farthest robot.
        hall_size_m: the hall's inner size (x, y) in metres (a bound on any travel cost).
    """

    run: RunContext
    names: tuple[str, ...]
    diameter: int
    hall_size_m: tuple[float, float]


@dataclass(frozen=True)
class EpochView:
    """One robot's view of one epoch, from which its agent is built.

    Attributes:
        problem: the assignment problem of the epoch; only this robot's cost row is known
            (the other rows are ``inf``): travel costs in metres, ``inf`` where the robot
            may not or cannot serve a task.
        robot: this robot's index (its row).
        name: this robot's name.
        epoch: the epoch number (messages of other epochs are dropped before the agent).
        tasks: the open tasks of the epoch (columns of ``problem``, in order).
        taken: indices of tasks another robot holds or has claimed, as far as this robot
            has heard.
    """

    problem: AssignmentProblem
    robot: int
    name: str
    epoch: int
    tasks: tuple[TaskInfo, ...]
    taken: frozenset[int]


class ProtocolAgent(Protocol):
    """One robot's side of an assignment protocol in one epoch."""

    def round(self, inbox: list[Message], now_ns: int) -> tuple[Message | None, bool]:
        """Run one round on the messages received since the last one.

        Returns:
            The message to broadcast (None: nothing), exactly of the protocol's
            ``message`` type, and whether this robot's state changed (a bool; a changed
            state is broadcast at once, an unchanged one every
            ``assignment.rebroadcast_s``).
        """
        ...

    @property
    def decided(self) -> bool:
        """Whether the robot may act on :meth:`task` (it may still change its mind): a bool."""
        ...

    def task(self) -> int | None:
        """The index of the task this robot should serve in the epoch's tasks, or None.

        An index is ``0 <= index < len(epoch.tasks)`` (an int; a negative one is refused).
        """
        ...

    @property
    def rounds(self) -> int:
        """Rounds run so far."""
        ...

    def cost(self) -> float:
        """This robot's view of the assignment's objective (m; for the assignments table)."""
        ...

    def view(self) -> dict[int, int]:
        """This robot's view of the whole assignment (robot index -> task index).

        Indices in range, and no task given to two robots.
        """
        ...


class AssignmentProtocolType(Protocol):
    """What a ``cosim.protocols`` entry point names: a class built once per run.

    Attributes:
        name: the registered name (``assignment.protocol``).
        message: the message type robots exchange (None: they exchange nothing).
        topic: the topic they exchange it on (e.g. ``/fleet/dta/bids``).
        central: the base station decides (robots report poses, :meth:`orders` assigns).
        compare_to_optimum: each epoch's decisions are compared with the central optimum
            of the same instance (the ``optimality_gap`` of the summary).
    """

    name: ClassVar[str]
    message: ClassVar[type[Message] | None]
    topic: ClassVar[str | None]
    central: ClassVar[bool]
    compare_to_optimum: ClassVar[bool]

    def __init__(self, fleet: ProtocolFleet) -> None: ...

    def agent(self, epoch: EpochView) -> ProtocolAgent | None:
        """This robot's agent for the epoch (None for a central protocol)."""
        ...

    def orders(
        self, tasks: Sequence[TaskInfo], poses: Mapping[str, tuple[float, float]]
    ) -> dict[str, tuple[int, float]]:
        """Central protocols: each free robot's task id and cost (-1: none), from poses (m).

        Only robots of ``poses`` (the free ones), each ordered to one of ``tasks`` it is
        eligible for (or -1), no task to two robots, the cost a finite number (m).
        """
        ...

    def summary(self) -> Mapping[str, Any]:
        """Extra summary metrics of the run (flat, JSON-serializable).

        Each key is declared, with its unit and meaning, in the class's ``summary_keys``
        (a mapping of key to :class:`cosim.core.summary.SummaryKey`), which the summary
        reference shows.
        """
        ...


def protocol_contract(name: str, loaded: Any) -> str | None:
    """What a protocol class lacks (see :class:`AssignmentProtocolType`), or None."""
    if not isinstance(loaded, type):
        return "is not a class (expected a class built with a ProtocolFleet)"
    for method in ("agent", "orders", "summary"):
        if not callable(getattr(loaded, method, None)):
            return f"has no {method}() method (see adapters.assignment.contract)"
    message, topic = getattr(loaded, "message", None), getattr(loaded, "topic", None)
    if (message is None) != (topic is None):
        return f"message = {message!r} and topic = {topic!r}: expected both or neither"
    if message is not None and not (isinstance(message, type) and issubclass(message, Message)):
        return f"message = {message!r}: expected a cosim.core.messages.Message subclass"
    if message is not None and not hasattr(message, "wire"):
        return (
            f"message = {message.__name__}: expected a message declared with "
            "cosim.core.messages.ros_message (its wire type, size and encoding come from it)"
        )
    for flag in ("central", "compare_to_optimum"):
        if not isinstance(getattr(loaded, flag, None), bool):
            return f"{flag} = {getattr(loaded, flag, None)!r}: expected True or False"
    return None


class ProtocolBase:
    """Defaults for a protocol class: no messages, not central, nothing extra to report.

    Subclass it and override what your protocol needs (at least :meth:`agent`).
    """

    name: ClassVar[str] = ""
    message: ClassVar[type[Message] | None] = None
    topic: ClassVar[str | None] = None
    central: ClassVar[bool] = False
    compare_to_optimum: ClassVar[bool] = False

    def __init__(self, fleet: ProtocolFleet) -> None:
        self.fleet = fleet

    def agent(self, epoch: EpochView) -> ProtocolAgent | None:
        """This robot's agent for the epoch."""
        raise NotImplementedError(f"{type(self).__name__}.agent")

    def orders(
        self, tasks: Sequence[TaskInfo], poses: Mapping[str, tuple[float, float]]
    ) -> dict[str, tuple[int, float]]:
        """Not central: no orders."""
        return {}

    def summary(self) -> Mapping[str, Any]:
        """Nothing extra."""
        return {}


PROTOCOLS = Group(
    "cosim.protocols",
    "assignment protocol",
    "assignment protocols",
    "`adapters.assignment.contract` (`AssignmentProtocolType`, `ProtocolAgent`)",
    "`assignment.protocol`",
    check=protocol_contract,
)
"""Task assignment protocols (``assignment.protocol``)."""


def protocol_registry() -> Registry[type[AssignmentProtocolType]]:
    """The assignment protocols installed packages register (``cosim.protocols``)."""
    return PROTOCOLS.installed()
