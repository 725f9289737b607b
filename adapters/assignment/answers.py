"""What an assignment protocol answers, checked where it enters the task assignment.

A protocol's agents answer every round (:meth:`~adapters.assignment.contract.ProtocolAgent.round`,
``decided``, ``task()``, ``view()``), and a central protocol answers the task source's
:meth:`~adapters.assignment.contract.AssignmentProtocolType.orders`. An answer cosim cannot
act on ends the run with a :class:`~cosim.core.plugins.PluginError` naming the protocol,
the robot, the value and what was expected, instead of leaving robots standing:

- ``round()``: a pair ``(message or None, changed)``; the message exactly of the
  protocol's declared ``message`` type (a protocol that declares none sends nothing);
  ``changed`` a bool;
- ``decided``: a bool (a ``decided`` method without ``@property`` would read as always
  decided);
- ``task()``: None, or the index of one of the epoch's tasks (``0 <= index < len(tasks)``;
  a negative index is no task's);
- ``view()``: robot index -> task index, both in range, no task given to two robots;
- ``rounds``, ``cost()``: an int, a number (m);
- ``orders()``: robot name -> ``(task id, cost in m)``, only for the free robots asked
  about, each task id one of the open tasks offered (or -1: none) that the robot may serve,
  no task ordered to two robots, the cost a finite number.

Each check is a few comparisons per answer; an answer it accepts keeps its value (numpy
integers and booleans come back as Python's).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from numbers import Integral, Real
from typing import Any

import numpy as np

from adapters.assignment.contract import EpochView
from cosim.core.messages import Message, TaskInfo
from cosim.core.plugins import refuse


class CheckedAgent:
    """One robot's agent as the task assignment sees it: every answer checked on its way out.

    Args:
        agent: what the protocol's ``agent(epoch)`` returned.
        protocol: the run's protocol (named in errors).
        epoch: the robot's view of the epoch the agent is for.
        robots: how many robots the fleet has.
    """

    def __init__(self, agent: Any, protocol: Any, epoch: EpochView, robots: int) -> None:
        self.agent = agent
        self.protocol = protocol
        self.message: type[Message] | None = protocol.message
        self.name = epoch.name
        self.epoch = epoch.epoch
        self.tasks = len(epoch.tasks)
        self.robots = robots

    def round(self, inbox: list[Message], now_ns: int) -> tuple[Message | None, bool]:
        """The agent's round: the message to send (or None) and whether its state changed."""
        returned = self.agent.round(inbox, now_ns)
        if not isinstance(returned, tuple) or len(returned) != 2:
            raise self._refuse(
                f"returned {_brief(returned)} from round(); expected a tuple "
                "(message or None, changed)"
            )
        message, changed = returned
        declared = self.message
        if message is not None and type(message) is not declared:
            expected = (
                f"a {declared.__name__} (its declared message) or None"
                if declared is not None
                else "None (it declares no message)"
            )
            raise self._refuse(
                f"returned a {type(message).__name__} from round(); expected {expected}"
            )
        return message, self._flag("changed (from round())", changed)

    @property
    def decided(self) -> bool:
        """The agent's ``decided``."""
        return self._flag("decided", self.agent.decided)

    def task(self) -> int | None:
        """The agent's ``task()``: None, or an index into the epoch's tasks."""
        index = self.agent.task()
        if index is None:
            return None
        if not _index(index, self.tasks):
            kind = "task index " if isinstance(index, Integral) else ""
            raise self._refuse(
                f"task() returned {kind}{index!r}; expected None or {_indices(self.tasks)} "
                f"(the epoch has {self.tasks} tasks)"
            )
        return int(index)

    @property
    def rounds(self) -> int:
        """The agent's ``rounds``."""
        rounds = self.agent.rounds
        if not isinstance(rounds, Integral) or isinstance(rounds, bool):
            raise self._refuse(f"rounds is {_brief(rounds)}; expected an int")
        return int(rounds)

    def cost(self) -> float:
        """The agent's ``cost()`` (m)."""
        cost = self.agent.cost()
        if not isinstance(cost, Real) or isinstance(cost, bool):
            raise self._refuse(f"cost() returned {_brief(cost)}; expected a number (m)")
        return float(cost)

    def view(self) -> dict[int, int]:
        """The agent's ``view()``: robot index -> task index, each task at most once."""
        view = self.agent.view()
        if not isinstance(view, Mapping):
            raise self._refuse(
                f"view() returned {_brief(view)}; expected a dict robot index -> task index"
            )
        given: dict[int, int] = {}
        for who, task in view.items():
            if not _index(who, self.robots):
                raise self._refuse(
                    f"view() names robot {who!r}; expected {_indices(self.robots)} "
                    f"(the fleet has {self.robots} robots)"
                )
            if not _index(task, self.tasks):
                raise self._refuse(
                    f"view() gives robot {who} task {task!r}; expected {_indices(self.tasks)} "
                    f"(the epoch has {self.tasks} tasks)"
                )
            if task in given:
                raise self._refuse(
                    f"view() gives task {task} to robots {given[task]} and {who}; expected "
                    "each task to at most one robot"
                )
            given[task] = who
        return {int(who): int(task) for who, task in view.items()}

    def _flag(self, what: str, value: Any) -> bool:
        if type(value) is bool:
            return value
        if isinstance(value, np.bool_):  # as from (a == b).all()
            return bool(value)
        hint = " (a method: declare it with @property)" if callable(value) else ""
        raise self._refuse(f"{what} is {_brief(value)}{hint}; expected True or False")

    def _refuse(self, problem: str) -> Exception:
        """The error naming the protocol: ``problem`` follows ``robot_2's agent``."""
        return refuse(
            self.protocol,
            f"{self.name}'s agent {problem}",
            doing=f"running {self.name}'s round of epoch {self.epoch}",
        )


class CheckedOrders:
    """A central protocol's :meth:`orders`, checked before the task source acts on them.

    Args:
        protocol: the run's central protocol.
        names: the robots, in fleet order.
    """

    def __init__(self, protocol: Any, names: Sequence[str]) -> None:
        self.protocol = protocol
        self.names = frozenset(names)

    def orders(
        self, tasks: Sequence[TaskInfo], poses: Mapping[str, tuple[float, float]]
    ) -> dict[str, tuple[int, float]]:
        """The protocol's orders for the free robots in ``poses``, checked."""
        orders = self.protocol.orders(tasks, poses)
        doing = "ordering the free robots to tasks (a central protocol's orders())"

        def refused(problem: str) -> Exception:
            return refuse(self.protocol, f"returned from orders() {problem}", doing=doing)

        if not isinstance(orders, Mapping):
            raise refused(f"{_brief(orders)}; expected a dict robot -> (task id, cost in m)")
        offered = {task.task_id: task for task in tasks}
        ordered: dict[int, str] = {}
        for robot, order in orders.items():
            if robot not in self.names:
                raise refused(f"an order for {robot!r}; expected robots of the fleet")
            if robot not in poses:
                raise refused(
                    f"an order for {robot!r}, which is not free; expected orders for the free "
                    f"robots asked about only ({', '.join(poses) or 'none'})"
                )
            if not (isinstance(order, tuple) and len(order) == 2):
                raise refused(f"{robot!r}: {_brief(order)}; expected (task id, cost in m)")
            task_id, cost = order
            if not isinstance(task_id, Integral) or isinstance(task_id, bool):
                raise refused(f"{robot!r}: task id {task_id!r}; expected an int")
            if not isinstance(cost, Real) or not math.isfinite(cost):
                raise refused(f"{robot!r}: cost {cost!r}; expected a finite number (m)")
            task_id = int(task_id)
            if task_id == -1:
                continue
            task = offered.get(task_id)
            if task is None:
                ids = ", ".join(str(t) for t in offered) or "none"
                raise refused(
                    f"{robot!r}: task id {task_id}; expected -1 (none) or an open task's id ({ids})"
                )
            if robot not in task.eligible:
                raise refused(
                    f"{robot!r}: task {task_id}, which it may not serve; expected one of the "
                    "tasks it is eligible for"
                )
            if task_id in ordered:
                raise refused(
                    f"task {task_id} for both {ordered[task_id]!r} and {robot!r}; expected "
                    "each task for at most one robot"
                )
            ordered[task_id] = robot
        return dict(orders)


def _index(value: Any, size: int) -> bool:
    return isinstance(value, Integral) and not isinstance(value, bool) and 0 <= int(value) < size


def _indices(size: int) -> str:
    return f"an index 0 to {size - 1}" if size else "no index"


def _brief(value: Any) -> str:
    """What a value is, briefly: ``None``, ``a list of 2``, ``3.5``."""
    if value is None or isinstance(value, bool | int | float | str):
        return repr(value)
    name = type(value).__name__
    article = "an" if name[0] in "aeiou" else "a"
    try:
        return f"{article} {name} of {len(value)}"
    except TypeError:
        return f"{article} {name}"
