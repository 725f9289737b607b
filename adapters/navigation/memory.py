"""What the costmaps take at ``navigation.resolution_m``, checked before they are built.

The navigation inflates the building's map at ``navigation.resolution_m`` once, and on
layers of :data:`~models.navigation.landmarks.ALT_MIN_CELLS` cells or more builds landmark
fields for A* on it; a robot that maps plans on a costmap of its own. At 3.4 mm on the 30 m
hall the building's layer alone has 80 million cells, and numpy refused one of the landmark
build's arrays (611 MiB) in the middle of a run. :func:`check_navigation_memory` estimates
the memory from the settings alone and refuses, in one line, a cell size that does not fit
in the memory the process has left (:func:`cosim.core.memory.available`), besides the
robots' maps (:mod:`adapters.mapping.memory`), naming a cell size that fits.

Bytes per cell of the building's layer, as :mod:`models.navigation.costmap` and
:mod:`models.navigation.landmarks` allocate them:

- the ground-truth grid and its copy (int8, 2), the obstacle mask (1), the squared distance
  transform and its column pass (int64, 8 + 8), the distances (float32, 4) and costs
  (uint8, 1): 24;
- landmark fields on large layers: 8 landmarks of int32 for each of the two cost weights
  planned with (64), and the build's working arrays (labels, the region's cells, two
  distance fields of float64, the fixed-point conversion): 96 in all.

Measured on these machines (``warehouse-random``, 4 robots, resident memory at its peak):
102 bytes a cell between 5.9 and 9.2 million cells with the landmarks, 23 below them.

With ``mapping.enabled`` each robot plans on its own map resampled to the costmap's cells
(the building, its walls and the maps' margin): its costs and distances (uint8 + float32)
and its row of the stacked distances (float32): 9 bytes a cell per robot.
"""

from __future__ import annotations

import math

from adapters.mapping.memory import check_mapping_memory, map_shape, mapping_bytes
from adapters.mapping.settings import MappingConfig
from adapters.navigation.settings import NavigationConfig
from cosim.core.errors import ConfigError
from cosim.core.memory import Room, available, size_text, smallest_fitting
from cosim.scenario.fields import format_problem, key_bounds
from cosim.scenario.model import Scenario
from cosim.scenario.sections import RobotsConfig, WorldConfig
from models.navigation.landmarks import ALT_MIN_CELLS

STATIC_BYTES_PER_CELL = 24
"""The building's costmap, built once (bytes per cell)."""
LANDMARK_BYTES_PER_CELL = 96
"""The landmark fields of a layer of ``ALT_MIN_CELLS`` cells or more, with their build."""
OWN_MAP_BYTES_PER_CELL = 9
"""Each mapping robot's own costmap and its row of the stacked distances (bytes per cell)."""
SNAP_CELLS = 1e-6
"""As the rasterizer: an extent within this many cells of a whole number is that number."""


def static_shape(world: WorldConfig, resolution_m: float) -> tuple[int, int]:
    """Columns and rows of the building's layer (walls included) at ``resolution_m`` (m)."""
    extent = [size + 2 * world.wall_thickness_m for size in world.size_m]
    return (
        max(1, math.ceil(extent[0] / resolution_m - SNAP_CELLS)),
        max(1, math.ceil(extent[1] / resolution_m - SNAP_CELLS)),
    )


def navigation_bytes(scenario: Scenario, resolution_m: float | None = None) -> int:
    """Bytes the costmaps take at ``resolution_m`` (m; the scenario's when None)."""
    resolution_m = resolution_m or scenario.section(NavigationConfig).resolution_m
    world = scenario.section(WorldConfig)
    cols, rows = static_shape(world, resolution_m)
    cells = cols * rows
    per_cell = STATIC_BYTES_PER_CELL + (LANDMARK_BYTES_PER_CELL if cells >= ALT_MIN_CELLS else 0)
    need = cells * per_cell
    mapping = scenario.section(MappingConfig)
    if mapping.enabled:
        map_cols, map_rows = map_shape(world, mapping.resolution_m)
        own = math.ceil(map_cols * mapping.resolution_m / resolution_m - SNAP_CELLS) * math.ceil(
            map_rows * mapping.resolution_m / resolution_m - SNAP_CELLS
        )
        need += own * scenario.section(RobotsConfig).count * OWN_MAP_BYTES_PER_CELL
    return need


def check_navigation_memory(scenario: Scenario, room: Room | None = None) -> None:
    """Refuse a ``navigation.resolution_m`` whose costmaps would not fit in memory.

    The robots' maps come first (:func:`~adapters.mapping.memory.check_mapping_memory`):
    the costmaps must fit in what they leave.

    Args:
        scenario: the scenario (its world, robot count, navigation and mapping settings).
        room: the memory available; :func:`cosim.core.memory.available` when None.

    Raises:
        ConfigError: naming the key, the value, the estimate, the memory available and
            the smallest cell size that fits (or that none does).
    """
    room = room or available()
    if room is None:
        return
    check_mapping_memory(scenario, room)
    maps = mapping_bytes(scenario)
    left = Room(room.bytes - maps, room.source)
    resolution_m = scenario.section(NavigationConfig).resolution_m
    need = navigation_bytes(scenario)
    if need <= left.bytes:
        return
    cols, rows = static_shape(scenario.section(WorldConfig), resolution_m)
    high = key_bounds(NavigationConfig, "resolution_m").le or 1.0
    fits = smallest_fitting(lambda r: navigation_bytes(scenario, r), resolution_m, high, left.bytes)
    besides = f" besides the robots' maps ({size_text(maps)})" if maps else ""
    takes = (
        f"the costmaps of the {cols:,} x {rows:,} cell building would take about "
        f"{size_text(need)}, more than the {size_text(left.bytes)} of memory this process has "
        f"left{besides} ({room.source})"
    )
    expected = (
        f"a cell size of at least {fits:g} m on this machine: {takes}"
        if fits is not None
        else f"fewer robots or a smaller world: {takes}, and even {high:g} m cells would not fit"
    )
    raise ConfigError(
        format_problem(scenario.source, "navigation", "resolution_m", resolution_m, expected)
    )


__all__ = ["check_navigation_memory", "navigation_bytes", "static_shape"]
