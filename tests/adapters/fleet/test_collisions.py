from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
import pytest

import cosim
from adapters.naming import topic
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import Twist
from cosim.core.registry import AdapterRegistry
from cosim.runner.execute import execute
from models.fleet.kinematics import FleetState
from models.world.obstacles import DynamicObstacles


class DriveStraight:
    """Test driver: every robot is commanded 1 m/s forward, all the time."""

    name: ClassVar[str] = "drive_straight"
    requires: ClassVar[tuple[str, ...]] = ("fleet",)

    def __init__(self, run: RunContext) -> None:
        self.names = run.service(FleetState).names

    def start(self, run: RunContext) -> None:
        def command(now: int) -> None:
            for name in self.names:
                run.bus.publish(topic(name, "cmd_vel"), Twist(1.0, 0.0), HostId(name))

        run.kernel.every(50_000_000, command, stage=Stage.CONTROL)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {}


class StandingPerson:
    """Test obstacle: a person of radius 0.25 m standing at (5, 5)."""

    name: ClassVar[str] = "standing_person"
    requires: ClassVar[tuple[str, ...]] = ("world",)

    def __init__(self, run: RunContext) -> None:
        run.service(DynamicObstacles).update("people", np.array([[5.0, 5.0, 0.25]]), ["person_0"])

    def start(self, run: RunContext) -> None:
        pass

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {}


REGISTRY = (
    AdapterRegistry.from_entry_points().with_adapter(DriveStraight).with_adapter(StandingPerson)
)


def _run(positions, extra=(), **more):
    scenario = cosim.load_scenario(
        "warehouse-random",
        overrides={
            **more,
            "scenario.duration_s": 8.0,
            "world.size_m": [10.0, 10.0],
            "world.shelf_count": 0,
            "robots.count": len(positions),
            "robots.placement": "explicit",
            "robots.positions": positions,
            "lidar.beams": 0,
        },
    )
    names = ["world", "fleet", "collisions", "poses", "drive_straight", *extra]
    return execute(scenario, names=names, registry=REGISTRY)


def test_a_robot_driving_into_a_wall_stops_at_it_and_never_passes_through():
    result = _run([[5.0, 5.0, 0.0]])
    poses = result.tables["poses"]
    assert poses["x_m"].max() <= 10.0 - 0.33 + 1e-12
    assert poses["x_m"].iloc[-1] > 10.0 - 0.33 - 0.06  # held within one step of the wall
    assert poses["v_mps"].iloc[-1] == 0.0
    collisions = result.tables["collisions"]
    assert list(collisions["kind"]) == ["wall"]  # one contact, recorded once
    assert collisions["other"].iloc[0] == "wall_3"
    assert 0 < collisions["depth_m"].iloc[0] <= 0.05 + 1e-9
    assert result.summary["collisions"] == 1
    assert 0 <= result.summary["min_clearance_m"] < 0.06
    events = result.tables["events"]
    assert (events["kind"] == "collision").sum() == 1


def test_a_robot_driving_into_a_given_obstacle_is_held_and_the_obstacle_named():
    result = _run([[5.0, 5.0, 0.0]], **{"world.obstacles": [[7.0, 4.0, 8.0, 6.0]]})
    collisions = result.tables["collisions"]
    assert list(collisions["kind"]) == ["obstacle"]
    assert collisions["other"].iloc[0] == "obstacle_0"
    assert result.tables["poses"]["x_m"].max() <= 7.0 - 0.33 + 1e-12


def test_two_robots_head_on_both_stop_without_overlapping():
    result = _run([[3.0, 5.0, 0.0], [7.0, 5.0, np.pi]])
    poses = result.tables["poses"].pivot(index="t_s", columns="robot", values="x_m")
    gap = poses["robot_2"] - poses["robot_1"] - 0.66
    assert gap.min() >= 0
    assert gap.iloc[-1] < 0.11
    collisions = result.tables["collisions"]
    assert list(zip(collisions["robot"], collisions["other"], strict=True)) == [
        ("robot_1", "robot_2")
    ]
    assert result.summary["min_clearance_m"] >= 0


def test_a_robot_stops_at_a_dynamic_obstacle():
    result = _run([[2.0, 5.0, 0.0]], extra=["standing_person"])
    collisions = result.tables["collisions"]
    assert list(collisions["kind"]) == ["dynamic"]
    assert collisions["other"].iloc[0] == "person_0"
    assert result.tables["poses"]["x_m"].max() <= 5.0 - 0.25 - 0.33 + 1e-12


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_default_scenario_never_lets_robots_overlap(seed):
    scenario = cosim.load_scenario("warehouse-random", {"scenario.duration_s": 30.0})
    result = cosim.run(scenario, seed=seed)
    poses = result.tables["poses"]
    for _t, group in poses.groupby("t_s"):
        xy = group[["x_m", "y_m"]].to_numpy()
        d = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
        np.fill_diagonal(d, np.inf)
        assert d.min() >= 0.66 - 1e-9
    assert result.summary["min_clearance_m"] >= 0
