from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from adapters.agents.bidding import AgentBids
from adapters.assignment.contract import (
    PROTOCOLS,
    EpochView,
    ProtocolBase,
    ProtocolFleet,
    protocol_contract,
    protocol_registry,
)
from adapters.assignment.protocols import Cbba, DistributedSimplex, Greedy, Hungarian
from adapters.assignment.topics import BASES
from cosim.core.errors import RegistryError
from cosim.core.messages import Message, SimplexBasis, TaskInfo
from cosim.core.registry import Registry
from models.assignment.problem import AssignmentProblem

BUILT_IN = {
    "distributed_simplex": DistributedSimplex,
    "cbba": Cbba,
    "greedy": Greedy,
    "hungarian": Hungarian,
}


def test_the_built_in_protocols_are_registered_and_keep_the_contract():
    # and the learning agents' (adapters.agents.bidding), tested with them
    assert protocol_registry().load_all() == {**BUILT_IN, "agent_bids": AgentBids}
    assert protocol_registry().group is PROTOCOLS
    for name, protocol in BUILT_IN.items():
        assert protocol.name == name
        assert protocol_contract(name, protocol) is None


@pytest.mark.parametrize(
    ("name", "exchanges", "central", "compared"),
    [
        ("distributed_simplex", True, False, True),
        ("cbba", True, False, True),
        ("greedy", False, False, False),
        ("hungarian", False, True, False),
    ],
)
def test_each_protocol_says_what_it_exchanges_who_decides_and_whether_it_is_compared(
    name, exchanges, central, compared
):
    protocol = BUILT_IN[name]
    assert (protocol.message is not None, protocol.topic is not None) == (exchanges, exchanges)
    assert (protocol.central, protocol.compare_to_optimum) == (central, compared)


class _Plain(ProtocolBase):
    name = "plain"

    def agent(self, epoch: EpochView) -> Any:
        return None


class _Undeclared(Message):
    """A message class that was never declared with ros_message."""


def _subclass(**attributes: Any) -> type:
    return type("Broken", (_Plain,), {"name": "broken", **attributes})


@pytest.mark.parametrize(
    ("entry", "problem"),
    [
        (
            SimpleNamespace(name="broken"),
            "is not a class (expected a class built with a ProtocolFleet)",
        ),
        (_subclass(orders=None), "has no orders() method (see adapters.assignment.contract)"),
        (_subclass(agent=3), "has no agent() method (see adapters.assignment.contract)"),
        (
            _subclass(message=SimplexBasis),
            "message = <class 'cosim.core.messages.assignment.SimplexBasis'> and topic = None: "
            "expected both or neither",
        ),
        (_subclass(topic=BASES), f"message = None and topic = {BASES!r}: expected both or neither"),
        (
            _subclass(message=dict, topic=BASES),
            "message = <class 'dict'>: expected a cosim.core.messages.Message subclass",
        ),
        (
            _subclass(message=_Undeclared, topic=BASES),
            "message = _Undeclared: expected a message declared with "
            "cosim.core.messages.ros_message (its wire type, size and encoding come from it)",
        ),
        (_subclass(central="no"), "central = 'no': expected True or False"),
        (_subclass(compare_to_optimum=None), "compare_to_optimum = None: expected True or False"),
    ],
)
def test_a_protocol_breaking_the_contract_is_refused_naming_itself_and_what_is_wrong(
    entry, problem
):
    assert protocol_contract("broken", entry) == problem
    with pytest.raises(RegistryError) as refused:
        Registry(PROTOCOLS, {"broken": entry}).get("broken")
    message = str(refused.value)
    assert message.startswith("assignment protocol 'broken' (")
    assert message.endswith(f": {problem}")


def test_a_subclass_of_the_base_with_an_agent_keeps_the_contract():
    assert protocol_contract("plain", _Plain) is None
    assert Registry(PROTOCOLS, {"plain": _Plain}).get("plain") is _Plain


def _fleet() -> ProtocolFleet:
    return ProtocolFleet(SimpleNamespace(), ("robot_1", "robot_2"), 1, (10.0, 8.0))  # type: ignore[arg-type]


def test_the_base_exchanges_nothing_orders_nothing_and_reports_nothing():
    protocol = _Plain(_fleet())
    assert protocol.fleet.names == ("robot_1", "robot_2")
    assert (_Plain.message, _Plain.topic, _Plain.central, _Plain.compare_to_optimum) == (
        None,
        None,
        False,
        False,
    )
    tasks = [TaskInfo(7, 1.0, 2.0, ("robot_1",))]
    assert protocol.orders(tasks, {"robot_1": (0.0, 0.0)}) == {}
    assert protocol.summary() == {}


def test_a_protocol_that_forgot_its_agent_says_which_class():
    class Forgetful(ProtocolBase):
        name = "forgetful"

    problem = AssignmentProblem(("robot_1",), (7,), np.array([[1.0]]))
    epoch = EpochView(problem, 0, "robot_1", 1, (), frozenset())
    with pytest.raises(NotImplementedError, match=r"Forgetful\.agent"):
        Forgetful(_fleet()).agent(epoch)
