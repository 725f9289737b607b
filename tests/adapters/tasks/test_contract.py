"""What the task source needs from whoever assigns its tasks: claim rules, a central solver."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence

import pytest

import cosim
from adapters.tasks.contract import (
    CentralOrders,
    CentralSolver,
    ClaimRules,
    ClaimRulesSection,
    claim_rules,
)
from cosim.core.messages import TaskInfo


@dataclasses.dataclass(frozen=True)
class Plain:
    """A section that says nothing about claims."""

    period_s: float = 1.0


@dataclasses.dataclass(frozen=True)
class Strict:
    """A section that keeps claims briefly, with preemption."""

    def claim_rules(self) -> ClaimRules:
        return ClaimRules(claim_timeout_s=0.5, rebroadcast_s=0.25, preemption=True)


def test_without_a_section_declaring_them_the_book_keeps_the_default_rules():
    rules = claim_rules({"plain": Plain()})
    assert rules == ClaimRules()
    assert (rules.claim_timeout_s, rules.rebroadcast_s) == (5.0, 1.0)
    assert not rules.preemption and not rules.central


def test_the_rules_are_the_first_section_that_declares_them():
    assert claim_rules({"plain": Plain(), "strict": Strict()}) == ClaimRules(0.5, 0.25, True)
    assert isinstance(Strict(), ClaimRulesSection)
    assert not isinstance(Plain(), ClaimRulesSection)


def test_the_assignment_section_declares_the_rules_of_its_keys_and_protocol():
    scenario = cosim.load_scenario(
        "warehouse-random",
        {
            "robots.driver": "tasks",
            "assignment.claim_timeout_s": 2.0,
            "assignment.rebroadcast_s": 0.5,
            "assignment.preemption": True,
        },
    )
    assert claim_rules(scenario.sections) == ClaimRules(2.0, 0.5, True, central=False)


@pytest.mark.parametrize(("protocol", "central"), [("hungarian", True), ("cbba", False)])
def test_a_protocol_solved_on_the_base_station_makes_the_rules_central(protocol, central):
    scenario = cosim.load_scenario("warehouse-random", {"assignment.protocol": protocol})
    assert claim_rules(scenario.sections).central is central


def test_central_orders_hold_the_solver_the_task_source_asks():
    class First:
        def orders(
            self, tasks: Sequence[TaskInfo], poses: Mapping[str, tuple[float, float]]
        ) -> dict[str, tuple[int, float]]:
            return {robot: (tasks[0].task_id, 0.0) for robot in poses}

    solver: CentralSolver = First()
    service = CentralOrders(solver)
    asked = service.solver.orders([TaskInfo(4, 1.0, 2.0, ("robot_1",))], {"robot_1": (0.0, 0.0)})
    assert asked == {"robot_1": (4, 0.0)}
    with pytest.raises(dataclasses.FrozenInstanceError):
        service.solver = First()  # type: ignore[misc]
