"""What the robots' maps take at ``mapping.resolution_m``, checked before they are built.

Every robot holds its own map over the common grid (:func:`~adapters.mapping.geometry.map_geometry`:
the building, its walls and a margin), so the memory grows with the number of robots and
the inverse square of the cell size: 50 robots at 1 cm on the 30 m hall are 50 maps of
10.5 million cells. :func:`check_mapping_memory` estimates it from the settings alone and
refuses a cell size that does not fit in the memory the process has left
(:func:`cosim.core.memory.available`), in one line naming the key, the value, the estimate
and a cell size that fits.

Bytes per cell, as :mod:`models.mapping.grid` and the adapter allocate them:

- each robot: log-odds (float32, 4), fine and coarse matching scores (uint8, 1 + 1), the
  map rendered for ``/robot_i/map`` and kept latched on the bus (int8, 1 + 1) and the final
  map the run keeps (int8, 1): 9; with a sharing mode that tracks changes
  (``share = "maps"``), the log-odds not yet sent (float32, 4) more; refining on walls
  (``refine = "walls"``), where its returns fell in each cell (uint8 mean offsets x, y
  and a uint8 count: 3) more;
- shared: the update's scratch (int32 stamp, uint8 dirty flag: 5), the fleet map and the
  ground truth the map quality is measured against, with its masks (about 11): 16;
- each thread of the run that maps (``--threads``, at most the cores available): its own
  scratch (5).
"""

from __future__ import annotations

import math

from adapters.mapping.contract import MAP_SHARING
from adapters.mapping.geometry import MARGIN_M
from adapters.mapping.settings import MappingConfig
from cosim.core.errors import ConfigError
from cosim.core.memory import Room, available, size_text, smallest_fitting
from cosim.core.workers import MAX_THREADS, available_cores
from cosim.scenario.fields import format_problem, key_bounds
from cosim.scenario.model import Scenario
from cosim.scenario.sections import RobotsConfig, WorldConfig

ROBOT_BYTES_PER_CELL = 9
"""Each robot's map, matching scores and rendered copies (bytes per cell)."""
CHANGES_BYTES_PER_CELL = 4
"""Each robot's unsent log-odds, with a sharing mode that tracks changes (bytes per cell)."""
CENTROID_BYTES_PER_CELL = 3
"""Each robot's hit means and counts, when scan matching refines on walls (bytes per cell)."""
SHARED_BYTES_PER_CELL = 16
"""The scratch, fleet map and ground truth every robot's map shares (bytes per cell)."""
THREAD_BYTES_PER_CELL = 5
"""Each mapping thread's own scratch (bytes per cell)."""


def map_shape(world: WorldConfig, resolution_m: float) -> tuple[int, int]:
    """Columns and rows of the common map grid at ``resolution_m`` (as ``MapGeometry.covering``)."""
    extent = [size + 2 * world.wall_thickness_m + 2 * MARGIN_M for size in world.size_m]
    return math.ceil(extent[0] / resolution_m), math.ceil(extent[1] / resolution_m)


def mapping_bytes(scenario: Scenario, resolution_m: float | None = None) -> int:
    """Bytes the robots' maps take at ``resolution_m`` (m; the scenario's when None); 0 when off."""
    cfg = scenario.section(MappingConfig)
    if not cfg.enabled:
        return 0
    cols, rows = map_shape(scenario.section(WorldConfig), resolution_m or cfg.resolution_m)
    per_robot = ROBOT_BYTES_PER_CELL
    if MAP_SHARING.installed().get(cfg.share).tracks_changes:
        per_robot += CHANGES_BYTES_PER_CELL
    if cfg.refine == "walls":
        per_robot += CENTROID_BYTES_PER_CELL
    robots = scenario.section(RobotsConfig).count
    # a run takes the cores available unless told fewer threads: count a scratch for each
    threads = THREAD_BYTES_PER_CELL * min(available_cores(), MAX_THREADS)
    return cols * rows * (robots * per_robot + SHARED_BYTES_PER_CELL + threads)


def check_mapping_memory(scenario: Scenario, room: Room | None = None) -> None:
    """Refuse a ``mapping.resolution_m`` whose maps would not fit in memory.

    Args:
        scenario: the scenario (its world, robot count and mapping settings).
        room: the memory available; :func:`cosim.core.memory.available` when None.

    Raises:
        ConfigError: naming the key, the value, the estimate, the memory available and
            the smallest cell size that fits (or that none does).
    """
    cfg = scenario.section(MappingConfig)
    room = room or available()
    need = mapping_bytes(scenario)
    if room is None or need <= room.bytes:
        return
    cols, rows = map_shape(scenario.section(WorldConfig), cfg.resolution_m)
    robots = scenario.section(RobotsConfig).count
    high = key_bounds(MappingConfig, "resolution_m").le or 1.0
    fits = smallest_fitting(
        lambda r: mapping_bytes(scenario, r), cfg.resolution_m, high, room.bytes
    )
    takes = (
        f"{robots:,} robots' maps of {cols:,} x {rows:,} cells would take about "
        f"{size_text(need)}, more than the {size_text(room.bytes)} of memory this process "
        f"has left ({room.source})"
    )
    expected = (
        f"a cell size of at least {fits:g} m on this machine: {takes}"
        if fits is not None
        else f"fewer robots or a smaller world: {takes}, and even {high:g} m cells would not fit"
    )
    raise ConfigError(
        format_problem(scenario.source, "mapping", "resolution_m", cfg.resolution_m, expected)
    )


__all__ = ["check_mapping_memory", "map_shape", "mapping_bytes"]
