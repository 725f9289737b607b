"""``cosim world SCENARIO``: the scenario's world as a picture, a map_server map, an SDF world."""

from __future__ import annotations

from pathlib import Path

from adapters.world.files import DEFAULT_RESOLUTION_M, write_map, write_sdf
from adapters.world.warehouse import scenario_warehouse
from cosim.core.errors import ConfigError
from cosim.scenario.model import Scenario
from models.errors import ModelError
from models.world.warehouse import ground_truth_grid


def world_command(
    scenario: Scenario,
    *,
    png: Path | None = None,
    map_yaml: Path | None = None,
    sdf: Path | None = None,
    resolution_m: float = DEFAULT_RESOLUTION_M,
) -> list[Path]:
    """Build the scenario's world and write the requested files (``cosim world``).

    Args:
        scenario: the validated scenario (its seed decides a random layout).
        png: a figure of walls, shelves and robot starts, if given.
        map_yaml: a ``map_server`` map (this YAML plus a ``.pgm`` beside it), if given.
        sdf: a Gazebo SDF world, if given.
        resolution_m: map cell size (m/cell).

    Returns:
        Every file written, in the order png, map YAML, map image, SDF; empty if nothing
        was requested.

    Raises:
        ScenarioError: the world cannot be built.
        ConfigError: the resolution is not a finite number > 0 or gives a huge grid.
        ExportError: a file cannot be written.
    """
    warehouse = scenario_warehouse(scenario)
    grid = None
    if map_yaml is not None:  # rasterize first: a bad resolution writes no file at all
        try:
            grid = ground_truth_grid(warehouse, resolution_m)
        except ModelError as error:
            raise ConfigError(
                f"--resolution-m {error.value!r}: expected {error.expected}"
            ) from None
    written: list[Path] = []
    if png is not None:
        from cosim.plotting.world import world_figure  # matplotlib: only when drawing

        title = f"{scenario.name} (seed {scenario.seed})"
        written.append(
            world_figure(warehouse, Path(png), title=title, robot_radius_m=scenario.robots.radius_m)
        )
    if map_yaml is not None and grid is not None:
        written += write_map(grid, Path(map_yaml))
    if sdf is not None:
        written.append(write_sdf(warehouse, Path(sdf), world_name=scenario.name))
    return written
