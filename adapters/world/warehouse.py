"""The world adapter: generates the warehouse once and offers it to the other adapters."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from cosim.adapter import RunContext
from cosim.errors import ScenarioError
from cosim.hosts import BASE_HOST, HostKind
from cosim.scenario.model import Scenario
from models.errors import ModelError
from models.layout import WarehouseSpec
from models.obstacles import DynamicObstacles
from models.world import Warehouse, generate_warehouse


def warehouse_spec(run: RunContext) -> WarehouseSpec:
    """The model parameters of the scenario's world and fleet placement."""
    return spec_from_scenario(run.scenario)


def spec_from_scenario(scenario: Scenario) -> WarehouseSpec:
    """The model parameters of a scenario's world and fleet placement (no run needed)."""
    world = scenario.world
    robots = scenario.robots
    return WarehouseSpec(
        size_m=world.size_m,
        layout=world.layout,
        shelf_size_m=world.shelf_size_m,
        shelf_count=world.shelf_count,
        shelves_per_rack=world.shelves_per_rack,
        aisle_width_m=world.aisle_width_m,
        wall_thickness_m=world.wall_thickness_m,
        robot_count=robots.count,
        robot_radius_m=robots.radius_m,
        placement=robots.placement,
        positions=robots.positions,
        obstacles=world.obstacles,
    )


def build_warehouse(run: RunContext) -> Warehouse:
    """Generate the scenario's warehouse from the ``world`` random stream.

    Raises:
        ScenarioError: naming the scenario file and the key for impossible requests.
    """
    try:
        return generate_warehouse(warehouse_spec(run), run.rng.stream("world"))
    except ModelError as error:
        raise ScenarioError(
            f"{run.scenario.source}: {error.key} = {error.value!r}: expected {error.expected}"
        ) from None


class WorldAdapter:
    """Builds the static world (walls, shelves, start poses) and the base-station host."""

    name: ClassVar[str] = "world"
    requires: ClassVar[tuple[str, ...]] = ()

    def __init__(self, run: RunContext) -> None:
        self.warehouse = build_warehouse(run)
        run.add_host(BASE_HOST, HostKind.BASE)
        run.provide(self.warehouse)
        run.provide(DynamicObstacles())

    def start(self, run: RunContext) -> None:
        """Record the world's size in the events table."""
        run.recorder.event(
            run.kernel.now_ns,
            "world",
            "built",
            f"{len(self.warehouse.shelves)} shelves, layout {run.scenario.world.layout}",
        )

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """World size and shelf count."""
        return {"shelves": len(self.warehouse.shelves)}
