"""Running a scenario from a test: plugins given in code, overrides, seed, duration, folder."""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import pytest

import cosim
from adapters.assignment.contract import PROTOCOLS, EpochView, ProtocolBase
from cosim.core.errors import ConfigError, RegistryError
from cosim.core.kernel import Stage
from cosim.scenario.fields import param
from cosim.testing.running import SMALL_WAREHOUSE, run_scenario


@dataclass(frozen=True)
class FirstFreeSettings:
    """``[first_free]``: which free task a robot takes."""

    skip: int = param(0, "free tasks passed over before the one taken", ge=0)


class FirstFreeAgent:
    """Takes the first free task of its row (after ``skip``), at once."""

    def __init__(self, epoch: EpochView, skip: int) -> None:
        free = [j for j in range(len(epoch.tasks)) if j not in epoch.taken]
        self.choice = free[min(skip, len(free) - 1)] if free else None
        self.robot = epoch.robot

    def round(self, inbox: list[Any], now_ns: int) -> tuple[None, bool]:
        return None, False

    decided = True
    rounds = 0

    def task(self) -> int | None:
        return self.choice

    def cost(self) -> float:
        return 0.0

    def view(self) -> dict[int, int]:
        return {self.robot: self.choice} if self.choice is not None else {}


class FirstFree(ProtocolBase):
    """Every robot takes the first task nobody holds."""

    name: ClassVar[str] = "first_free"

    def agent(self, epoch: EpochView) -> FirstFreeAgent:
        return FirstFreeAgent(epoch, self.fleet.run.settings(FirstFreeSettings).skip)


PLUGINS = {
    "cosim.protocols": {"first_free": FirstFree},
    "cosim.sections": {"first_free": FirstFreeSettings},
}
TASKS = {**SMALL_WAREHOUSE, "robots.driver": "tasks"}


def test_a_protocol_given_in_code_runs_by_name_with_its_settings_and_is_gone_afterwards():
    result = run_scenario(
        "warehouse-random",
        {**TASKS, "assignment.protocol": "first_free", "first_free.skip": 1},
        duration_s=5.0,
        seed=4,
        plugins=PLUGINS,
    )
    assert result.scenario.sections["first_free"] == FirstFreeSettings(skip=1)
    assert (result.scenario.seed, result.summary["sim_time_s"]) == (4, 5.0)
    assert result.tables["tasks"]["t_assigned_s"].notna().any()
    assert "first_free" not in PROTOCOLS.installed()
    with pytest.raises(ConfigError, match=r"\(registered: agent_bids, cbba, distributed_simplex, "
                       r"greedy, hungarian\)$"):  # fmt: skip
        cosim.load_scenario("warehouse-random", {"assignment.protocol": "first_free"})


def test_a_plugin_in_a_group_that_is_not_registered_is_refused_with_the_nearest_group():
    with pytest.raises(RegistryError, match=r"no registry 'cosim\.protocol'; did you mean "
                       r"'cosim\.protocols'"):  # fmt: skip
        run_scenario(plugins={"cosim.protocol": {"first_free": FirstFree}})


def test_overrides_go_with_a_name_or_a_file_not_with_a_loaded_scenario():
    loaded = cosim.load_scenario("warehouse-random")
    with pytest.raises(TypeError, match=r"overrides \['robots.count'\] given with a loaded"):
        run_scenario(loaded, {"robots.count": 2})


class Counter:
    """An adapter given in code: counts kernel ticks of 1 s."""

    name: ClassVar[str] = "tick_counter"
    requires: ClassVar[tuple[str, ...]] = ()

    def __init__(self, run: Any) -> None:
        self.ticks = 0

    def start(self, run: Any) -> None:
        run.kernel.every(1_000_000_000, self._tick, stage=Stage.RECORD)

    def _tick(self, now_ns: int) -> None:
        self.ticks += 1

    def finish(self, run: Any) -> Mapping[str, Any]:
        return {"ticks": self.ticks}


def test_an_adapter_class_runs_beside_the_scenarios_and_the_folder_is_written(tmp_path):
    small = {**SMALL_WAREHOUSE, "robots.driver": "wander"}
    result = run_scenario(small_scenario := cosim.load_scenario("warehouse-random", small),
                          duration_s=3.0, adapters=[Counter], out=tmp_path / "run")  # fmt: skip
    assert result.scenario.robots == small_scenario.robots
    assert result.summary["ticks"] == 3  # at 0, 1 and 2 s: the run ends before 3 s
    assert (
        json.loads((tmp_path / "run" / "summary.json").read_text())["ticks"]
        == (result.summary["ticks"])
    )
