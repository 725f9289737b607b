"""A protocol's answers at the boundary: what cosim cannot act on is refused naming the
protocol, the robot, the value and what was expected, instead of leaving robots standing."""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.assignment.answers import CheckedAgent, CheckedOrders
from adapters.assignment.contract import EpochView, ProtocolAgent, ProtocolBase
from adapters.assignment.protocols import GreedyProtocol, Hungarian
from cosim.core.messages import CbbaBids, Message, SimplexBasis, TaskClaim, TaskInfo
from cosim.core.plugins import PluginError
from cosim.core.registry import registered
from models.assignment.problem import AssignmentProblem
from tests.conftest import SMALL

TASKS = {**SMALL, "robots.driver": "tasks", "scenario.duration_s": 3.0, "tasks.initial": 3}


def _run(protocol: type[ProtocolBase]) -> cosim.RunResult:
    overrides = {**TASKS, "assignment.protocol": protocol.name}
    with registered("cosim.protocols", protocol.name, protocol):
        return cosim.run(cosim.load_scenario("warehouse-random", overrides))


def _refusal(protocol: type[ProtocolBase]) -> str:
    with pytest.raises(PluginError) as caught:
        _run(protocol)
    error = caught.value
    assert error.plugin is not None and error.plugin.name == protocol.name
    line = str(error)
    assert line.startswith(f"assignment protocol {protocol.name!r} (")
    return line


class Nearest:
    """An agent like greedy's, with one answer to spoil in each case below."""

    def __init__(self, epoch: EpochView) -> None:
        self.greedy = GreedyProtocol(epoch.problem, epoch.robot, set(epoch.taken))
        self.epoch = epoch

    def round(self, inbox: list[Message], now_ns: int) -> Any:
        return None, False

    @property
    def decided(self) -> Any:
        return True

    def task(self) -> Any:
        return self.greedy.task()

    @property
    def rounds(self) -> Any:
        return 0

    def cost(self) -> Any:
        return 0.0

    def view(self) -> Any:
        return self.greedy.view()


def _protocol(name: str, agent: type[Nearest], **attributes: Any) -> type[ProtocolBase]:
    def make(self: ProtocolBase, epoch: EpochView) -> ProtocolAgent:
        return agent(epoch)  # type: ignore[return-value]

    return type(name.title(), (ProtocolBase,), {"name": name, "agent": make, **attributes})


class Beyond(Nearest):
    def task(self) -> Any:
        return len(self.epoch.tasks) + 4


class Negative(Nearest):
    def task(self) -> Any:
        return -1


class FloatIndex(Nearest):
    def task(self) -> Any:
        return 0.0


class DecidedMethod(Nearest):
    def decided(self) -> Any:  # type: ignore[override]  # forgot @property
        return True


class Claims(Nearest):
    def round(self, inbox: list[Message], now_ns: int) -> Any:
        return TaskClaim(now_ns, self.epoch.epoch, 0, self.epoch.name, 1.0, "claim"), True


class Bare(Nearest):
    def round(self, inbox: list[Message], now_ns: int) -> Any:
        return SimplexBasis(now_ns, self.epoch.epoch, self.epoch.name, 0, ())


class TwiceInView(Nearest):
    def view(self) -> Any:
        return {0: 0, 1: 0}


def test_a_task_index_beyond_the_epochs_tasks_is_refused_instead_of_leaving_the_robot_idle():
    line = _refusal(_protocol("beyond", Beyond))
    said = (
        r"\) (robot_\d)'s agent task\(\) returned task index 7; expected None or an index 0 to 2 "
        r"\(the epoch has 3 tasks\) while running \1's round of epoch 1 at t = [0-9.]+ s simulated$"
    )
    assert re.search(said, line), line


@pytest.mark.parametrize(
    ("agent", "said"),
    [
        (Negative, "task() returned task index -1; expected None or an index 0 to 2"),
        (FloatIndex, "task() returned 0.0; expected None or an index 0 to 2"),
        (
            DecidedMethod,
            "decided is a method (a method: declare it with @property); expected True or False",
        ),
        (Bare, "returned a SimplexBasis from round(); expected a tuple (message or None, changed)"),
        (TwiceInView, "view() gives task 0 to robots 0 and 1; expected each task to at most one"),
    ],
)
def test_an_agents_answer_of_the_wrong_type_or_range_is_refused_naming_it(agent, said):
    assert said in _refusal(_protocol(agent.__name__.lower(), agent))


def test_a_message_of_another_type_than_the_declared_one_is_refused_before_it_is_sent():
    protocol = _protocol("claims", Claims, message=CbbaBids, topic="/fleet/dta/claims_bids")
    line = _refusal(protocol)
    assert re.search(
        r"robot_\d's agent returned a TaskClaim from round\(\); expected a CbbaBids", line
    )


def test_a_protocol_declaring_no_message_may_send_none():
    line = _refusal(_protocol("sends_undeclared", Claims))
    assert "returned a TaskClaim from round(); expected None (it declares no message)" in line


def test_a_well_behaved_plugin_agent_serves_tasks():
    result = _run(_protocol("nearest", Nearest))
    assert result.summary["tasks_created"] >= 3


# -- central orders --------------------------------------------------------------------------
class Orders(Hungarian):
    """The Hungarian orders, spoilt by ``spoil``."""

    name: ClassVar[str] = "orders"

    def orders(
        self, tasks: Sequence[TaskInfo], poses: Mapping[str, tuple[float, float]]
    ) -> dict[str, tuple[int, float]]:
        return self.spoil(super().orders(tasks, poses), tasks)

    def spoil(self, orders: dict[str, Any], tasks: Sequence[TaskInfo]) -> Any:
        return orders


def _central(name: str, spoil: Any) -> type[Orders]:
    return type(name.title(), (Orders,), {"name": name, "spoil": spoil})


@pytest.mark.parametrize(
    ("spoil", "said"),
    [
        (
            lambda self, orders, tasks: {**orders, "robot_9": (tasks[0].task_id, 1.0)},
            "returned from orders() an order for 'robot_9'; expected robots of the fleet",
        ),
        (
            lambda self, orders, tasks: {r: (99, 1.0) for r in orders},
            "returned from orders() 'robot_1': task id 99; expected -1 (none) or an open task's",
        ),
        (
            lambda self, orders, tasks: {r: (tasks[0].task_id, 1.0) for r in orders},
            "returned from orders() task 0 for both 'robot_1' and 'robot_2'; expected each task "
            "for at most one robot",
        ),
        (
            lambda self, orders, tasks: {r: (str(t), c) for r, (t, c) in orders.items()},
            "returned from orders() 'robot_1': task id '",
        ),
        (
            lambda self, orders, tasks: {r: (t, float("nan")) for r, (t, c) in orders.items()},
            "returned from orders() 'robot_1': cost nan; expected a finite number (m)",
        ),
        (
            lambda self, orders, tasks: ["robot_1", 3],
            "returned from orders() a list of 2; expected a dict robot -> (task id, cost in m)",
        ),
    ],
)
def test_central_orders_cosim_cannot_act_on_are_refused_naming_the_protocol(spoil, said):
    line = _refusal(_central("spoilt", spoil))
    assert said in line
    assert "while ordering the free robots to tasks" in line


# -- the checks themselves -------------------------------------------------------------------
def _epoch(tasks: int = 3, robots: int = 2) -> EpochView:
    infos = tuple(TaskInfo(10 + j, float(j), 0.0, ("robot_1", "robot_2")) for j in range(tasks))
    problem = AssignmentProblem(
        ("robot_1", "robot_2")[:robots], tuple(10 + j for j in range(tasks)),
        np.ones((robots, tasks)),
    )  # fmt: skip
    return EpochView(problem, 0, "robot_1", 4, infos, frozenset())


class Fixed:
    """An agent answering what it was given."""

    def __init__(self, **answers: Any) -> None:
        self.answers = {"task": None, "view": {}, "decided": True, "rounds": 1, "cost": 0.0}
        self.answers.update(answers)
        self.decided = self.answers["decided"]
        self.rounds = self.answers["rounds"]

    def task(self) -> Any:
        return self.answers["task"]

    def view(self) -> Any:
        return self.answers["view"]

    def cost(self) -> Any:
        return self.answers["cost"]

    def round(self, inbox: list[Message], now_ns: int) -> Any:
        return self.answers["round"]


def _checked(**answers: Any) -> CheckedAgent:
    protocol = _protocol("fixed", Nearest, message=SimplexBasis, topic="/fleet/dta/bases")
    return CheckedAgent(Fixed(**answers), protocol, _epoch(), robots=2)


@settings(max_examples=50, deadline=None)
@given(st.integers(-5, 10))
def test_a_task_index_is_taken_only_within_the_epochs_tasks(index):
    agent = _checked(task=index)
    if 0 <= index < 3:
        assert agent.task() == index
    else:
        with pytest.raises(PluginError, match=f"task index {index}; expected None or an index"):
            agent.task()


def test_numpy_integers_and_booleans_are_taken_as_ints_and_bools():
    agent = _checked(task=np.int64(2), decided=np.bool_(True), view={np.int64(1): np.int64(0)})
    assert agent.task() == 2 and type(agent.task()) is int
    assert agent.decided is True
    assert agent.view() == {1: 0}


@pytest.mark.parametrize(
    ("answers", "ask", "said"),
    [
        ({"rounds": 1.5}, "rounds", "rounds is 1.5; expected an int"),
        ({"cost": "far"}, "cost", "cost() returned 'far'; expected a number (m)"),
        ({"view": {5: 0}}, "view", "view() names robot 5; expected an index 0 to 1"),
        ({"view": {0: 3}}, "view", "view() gives robot 0 task 3; expected an index 0 to 2"),
        ({"view": [0]}, "view", "view() returned a list of 1; expected a dict"),
        ({"round": (None, 1)}, "round", "changed (from round()) is 1; expected True or False"),
        ({"decided": None}, "decided", "decided is None; expected True or False"),
    ],
)
def test_each_answer_of_an_agent_is_checked_when_asked(answers, ask, said):
    agent = _checked(**answers)
    with pytest.raises(PluginError) as caught:
        value = getattr(agent, ask)
        if callable(value):
            value([], 0) if ask == "round" else value()
    assert said in str(caught.value)
    assert "while running robot_1's round of epoch 4" in str(caught.value)


def test_orders_for_a_busy_robot_or_a_task_it_may_not_serve_are_refused():
    tasks = [TaskInfo(3, 1.0, 1.0, ("robot_1",)), TaskInfo(4, 2.0, 1.0, ("robot_1", "robot_2"))]
    poses = {"robot_1": (0.0, 0.0)}
    fleet = ["robot_1", "robot_2"]

    def checked(orders: dict[str, tuple[int, float]]) -> dict[str, tuple[int, float]]:
        protocol = _central("fixed_orders", lambda self, _orders, _tasks: orders)
        return CheckedOrders(protocol.__new__(protocol), fleet).orders(tasks, poses)

    assert checked({"robot_1": (4, 2.0)}) == {"robot_1": (4, 2.0)}
    assert checked({"robot_1": (-1, 0.0)}) == {"robot_1": (-1, 0.0)}
    with pytest.raises(PluginError, match="'robot_2', which is not free"):
        checked({"robot_2": (4, 2.0)})
    poses["robot_2"] = (1.0, 1.0)
    with pytest.raises(PluginError, match="'robot_2': task 3, which it may not serve"):
        checked({"robot_2": (3, 2.0)})
