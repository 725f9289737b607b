"""The world adapter: a scenario's warehouse, the same for a run and for every tool."""

from __future__ import annotations

import numpy as np
import pytest

import cosim
from adapters.world.warehouse import (
    WORLD_STREAM,
    WorldAdapter,
    scenario_warehouse,
    spec_from_scenario,
)
from cosim.core.errors import ScenarioError
from cosim.core.hosts import BASE_HOST, HostKind
from cosim.core.rng import RngStreams
from cosim.runner.assembly import assemble
from models.world.layout import WarehouseSpec
from models.world.obstacles import DynamicObstacles
from models.world.warehouse import Warehouse
from tests.conftest import SMALL


def _scenario(**overrides: object) -> cosim.Scenario:
    return cosim.load_scenario("warehouse-random", {**SMALL, **overrides})


def test_the_spec_takes_every_world_and_fleet_key_of_the_scenario():
    scenario = _scenario(
        **{
            "world.layout": "all_rows",
            "world.shelf_size_m": [1.5, 0.6],
            "world.shelves_per_rack": 2,
            "world.aisle_width_m": 1.8,
            "world.wall_thickness_m": 0.3,
            "world.obstacles": [[5.0, 5.0, 5.5, 5.5]],
            "robots.radius_m": 0.25,
            "robots.placement": "explicit",
            "robots.positions": [[2.0, 2.0, 0.0], [3.0, 2.0, 0.0], [4.0, 2.0, 1.0]],
        }
    )
    assert spec_from_scenario(scenario) == WarehouseSpec(
        size_m=(12.0, 12.0),
        layout="all_rows",
        shelf_size_m=(1.5, 0.6),
        shelf_count=4,
        shelves_per_rack=2,
        aisle_width_m=1.8,
        wall_thickness_m=0.3,
        robot_count=3,
        robot_radius_m=0.25,
        placement="explicit",
        positions=((2.0, 2.0, 0.0), (3.0, 2.0, 0.0), (4.0, 2.0, 1.0)),
        obstacles=((5.0, 5.0, 5.5, 5.5),),
    )


def _same(a: Warehouse, b: Warehouse) -> bool:
    return all(
        np.array_equal(getattr(a, key), getattr(b, key)) for key in ("walls", "shelves", "starts")
    )


def test_a_scenarios_world_comes_from_its_seeds_world_stream():
    scenario = _scenario()
    world = scenario_warehouse(scenario)
    assert _same(
        world, scenario_warehouse(scenario, RngStreams(scenario.seed).stream(WORLD_STREAM))
    )
    assert _same(world, scenario_warehouse(scenario))
    assert not _same(world, scenario_warehouse(scenario.with_seed(scenario.seed + 1)))
    assert len(world.shelves) == 4 and world.starts.shape == (3, 3)


def test_the_run_builds_the_world_every_tool_builds_and_offers_it():
    scenario = _scenario(**{"scenario.seed": 5})
    run = assemble(scenario, names=["world"]).run
    assert _same(run.service(Warehouse), scenario_warehouse(scenario))
    assert isinstance(run.service(DynamicObstacles), DynamicObstacles)


def test_the_world_adapter_creates_the_base_station_host():
    run = assemble(_scenario(), names=["world"]).run
    assert run.hosts[BASE_HOST].kind is HostKind.BASE


def test_an_impossible_world_is_refused_naming_the_scenario_and_the_key():
    with pytest.raises(ScenarioError) as refused:
        scenario_warehouse(_scenario(**{"world.shelf_count": 40}))
    message = str(refused.value)
    assert message.startswith("preset warehouse-random: world.shelf_count = 40: expected at most")
    assert "\n" not in message


def test_the_world_is_recorded_as_built_and_its_shelves_summed_up():
    assembly = assemble(_scenario(), names=["world"])
    run = assembly.run
    [(name, adapter)] = assembly.adapters
    assert name == "world" and isinstance(adapter, WorldAdapter)
    adapter.start(run)
    events = run.recorder.events.columns()
    assert list(events["kind"]) == ["built"]
    assert list(events["detail"]) == ["4 shelves, layout random"]
    assert adapter.finish(run) == {"shelves": 4}
