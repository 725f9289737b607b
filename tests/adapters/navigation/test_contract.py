"""Navigation's pluggable parts: their groups, their contract checks, their contexts."""

from __future__ import annotations

from typing import Any, ClassVar

import pytest

from adapters.navigation.astar import AStar
from adapters.navigation.contract import (
    CONTROLLERS,
    PLANNERS,
    TRAFFIC_POLICIES,
    controller_contract,
    controller_registry,
    planner_contract,
    planner_registry,
    traffic_contract,
    traffic_registry,
)
from adapters.navigation.local_control import DwaControl
from adapters.navigation.traffic_policies import LaneTraffic, NoTraffic, PibtTraffic
from cosim.core.errors import RegistryError
from cosim.core.registry import Group, installed_groups


def test_the_built_in_controller_planner_and_policies_are_registered_and_pass_their_checks():
    assert controller_registry().load_all()["dwa"] is DwaControl
    assert planner_registry().load_all()["astar"] is AStar
    policies = traffic_registry().load_all()
    assert (policies["none"], policies["lanes"], policies["pibt"]) == (
        NoTraffic,
        LaneTraffic,
        PibtTraffic,
    )


def test_the_three_groups_are_registered_and_say_which_key_chooses_an_entry():
    registered = {g.entry_points: g for g in installed_groups()}
    for group, key in (
        (CONTROLLERS, "`navigation.controller`"),
        (PLANNERS, "`navigation.planner`"),
        (TRAFFIC_POLICIES, "`navigation.traffic`"),
    ):
        assert registered[group.entry_points] is group
        assert group.chosen_by == key


class _Commands:
    name: ClassVar[str] = "commands"

    def commands(self, inputs: Any) -> Any:
        return None


class _PlanOnly:
    name: ClassVar[str] = "planonly"

    def plan(self, request: Any) -> Any:
        return None


@pytest.mark.parametrize(
    ("check", "loaded", "says"),
    [
        (controller_contract, _Commands(), "is not a class (expected a class built with a "),
        (controller_contract, _PlanOnly, "has no commands(inputs) method"),
        (planner_contract, _Commands(), "is not a class (expected a class built with a Planner"),
        (planner_contract, _PlanOnly, "has no repair(request) method"),
        (traffic_contract, NoTraffic(None), "is not a class (expected a class built with a Traf"),  # type: ignore[arg-type]
    ],
)
def test_a_broken_entry_is_refused_naming_what_it_lacks(check, loaded, says):
    problem = check("x", loaded)
    assert problem is not None and problem.startswith(says)


def test_entries_with_what_the_contract_asks_are_accepted():
    assert controller_contract("commands", _Commands) is None
    assert planner_contract("astar", AStar) is None
    assert traffic_contract("lanes", LaneTraffic) is None


@pytest.mark.parametrize(
    ("group", "entry", "says"),
    [
        (CONTROLLERS, _PlanOnly, r"local controller 'planonly' .*has no commands\(inputs\)"),
        (PLANNERS, _PlanOnly, r"global planner 'planonly' .*has no repair\(request\)"),
    ],
)
def test_a_plugin_breaking_its_contract_is_refused_when_asked_for(group: Group, entry, says):
    registry = group.installed().with_entry("planonly", entry)
    with pytest.raises(RegistryError, match=says):
        registry.get("planonly")
    assert "planonly" not in registry.load_all()
