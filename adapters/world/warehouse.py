"""The world adapter: generates the warehouse once and offers it to the other adapters."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from cosim.core.adapter import RunContext, ScenarioView
from cosim.core.hosts import BASE_HOST, HostKind
from cosim.core.rng import RngStreams
from cosim.core.summary import SummaryKey
from cosim.scenario.fields import model_problem
from cosim.scenario.sections import RobotsConfig, WorldConfig
from models.errors import ModelError
from models.world.layout import WarehouseSpec
from models.world.obstacles import DynamicObstacles
from models.world.warehouse import Warehouse, generate_warehouse

WORLD_STREAM = "world"
"""The random stream a scenario's warehouse is generated from."""


def spec_from_scenario(scenario: ScenarioView) -> WarehouseSpec:
    """The model parameters of a scenario's world and fleet placement (no run needed)."""
    world = scenario.section(WorldConfig)
    robots = scenario.section(RobotsConfig)
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


def scenario_warehouse(scenario: ScenarioView, rng: np.random.Generator | None = None) -> Warehouse:
    """The warehouse a run of ``scenario`` builds, also without running anything.

    The run, ``cosim world``, the stand-in launcher and the figures all build it here, from
    the scenario's ``world`` stream, so each sees the same world.

    Args:
        scenario: the validated scenario (its seed decides a random layout).
        rng: the run's ``world`` stream; by default the same stream made from the seed.

    Raises:
        ScenarioError: naming the scenario file and the key for impossible requests.
    """
    if rng is None:
        rng = RngStreams(scenario.seed).stream(WORLD_STREAM)
    try:
        return generate_warehouse(spec_from_scenario(scenario), rng)
    except ModelError as error:
        raise model_problem(scenario.source, error) from None


class WorldAdapter:
    """Builds the static world (walls, shelves, start poses) and the base-station host."""

    name: ClassVar[str] = "world"
    requires: ClassVar[tuple[str, ...]] = ()
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "shelves": SummaryKey("count", "shelves in the hall"),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        self.warehouse = scenario_warehouse(run.scenario, run.rng.stream(WORLD_STREAM))
        run.add_host(BASE_HOST, HostKind.BASE)
        run.provide(self.warehouse)
        run.provide(DynamicObstacles())

    def start(self, run: RunContext) -> None:
        """Record the world's size in the events table."""
        run.recorder.event(
            run.kernel.now_ns,
            "world",
            "built",
            f"{len(self.warehouse.shelves)} shelves, layout {run.settings(WorldConfig).layout}",
        )

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """World size and shelf count."""
        return {"shelves": len(self.warehouse.shelves)}
