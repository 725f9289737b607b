"""The static layer each robot plans on: the building's map, or the map the robot builds.

Without mapping every robot plans on the ground-truth map, inflated once and shared. With
``mapping.enabled`` each robot starts knowing nothing and plans on its own map as it
arrives on ``/robot_i/map`` (slam_toolbox's ``/map`` feeding Nav2's static layer):
resampled to the costmap's cell size keeping every obstacle, with unknown cells
traversable (Nav2's ``allow_unknown``: a robot plans into unexplored space and its lidar
and replanning take it from there), then inflated. Every robot's distance-to-obstacle
grid is kept in one stack so that the traffic rules stay one batched call.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from adapters.mapping.geometry import map_geometry, unknown_grid
from adapters.mapping.settings import MappingConfig
from adapters.navigation.settings import NavigationConfig
from cosim.core.adapter import RunContext
from cosim.core.messages import OccupancyGrid as GridMessage
from models.geometry.occupancy import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    OccupancyGrid,
    resample,
    resampled_obstacles,
)
from models.navigation.costmap import INSCRIBED, CostmapParams, StaticCostmap
from models.navigation.lanes import TWO_WAY, aisle_lanes
from models.world.warehouse import Warehouse, ground_truth_grid


class StaticLayer:
    """The static map navigation plans on; a later mapping adapter may provide its own.

    Attributes:
        grid: the occupancy grid (``map`` frame).
    """

    def __init__(self, grid: OccupancyGrid) -> None:
        self.grid = grid


class StaticLayers:
    """Each robot's static costmap and their distance grids.

    Args:
        layers: one costmap per robot (the same object for all when shared).
        stacked: keep a (robots, rows, cols) stack of distances (own maps), else the first
            layer's distances serve every robot.
    """

    def __init__(self, layers: list[StaticCostmap], *, stacked: bool) -> None:
        self.layers = layers
        first = layers[0]
        self.resolution_m = first.resolution_m
        self.origin_xy_m = first.origin_xy_m
        self.params = first.params
        self.distance: npt.NDArray[np.float32] = (
            np.stack([layer.distance_m for layer in layers]) if stacked else first.distance_m
        )
        self.updates = 0

    @classmethod
    def shared(cls, static: StaticCostmap, robots: int) -> StaticLayers:
        """Every robot plans on the same map."""
        return cls([static] * robots, stacked=False)

    @classmethod
    def unexplored(
        cls, grid: OccupancyGrid, robots: int, params: CostmapParams, resolution_m: float
    ) -> StaticLayers:
        """Each robot starts with an empty map covering ``grid``'s area."""
        empty = _traversable(resample(grid, resolution_m))
        layer = StaticCostmap.from_grid(empty, params)
        return cls([layer] * robots, stacked=True)

    def __getitem__(self, robot: int) -> StaticCostmap:
        return self.layers[robot]

    def update(self, robot: int, message: GridMessage) -> None:
        """A robot's new map: resample, make unknown traversable, inflate, restack."""
        self.set(robot, self.build(robot, message))

    def build(self, robot: int, message: GridMessage) -> StaticCostmap:
        """The costmap of robot ``robot``'s new map, not used yet (see :meth:`set`).

        Resampled, unknown cells traversable, inflated. It reads only the layers' settings,
        so the maps of several robots may be built at once on different threads.

        Raises:
            ValueError: the map does not cover the same area as the robot's costmap.
        """
        cells = np.frombuffer(message.data, dtype=np.int8).reshape(message.height, message.width)
        origin = (message.origin_x_m, message.origin_y_m)
        # with unknown cells traversable only the obstacles count: when the costmap's cells
        # are whole blocks of the map's, they are found without resampling the map
        obstacles = resampled_obstacles(cells, message.resolution_m, self.resolution_m)
        if obstacles is not None:
            layer = StaticCostmap.from_obstacles(obstacles, self.resolution_m, origin, self.params)
        else:
            grid = OccupancyGrid(message.resolution_m, origin, cells)
            layer = StaticCostmap.from_grid(
                _traversable(resample(grid, self.resolution_m)), self.params
            )
        if layer.cost.shape != self.layers[robot].cost.shape:
            raise ValueError(
                f"map of {message.width} x {message.height} cells does not cover the same "
                f"area as robot {robot}'s costmap"
            )
        return layer

    def set(self, robot: int, layer: StaticCostmap) -> None:
        """Robot ``robot`` plans on ``layer`` from now on (from :meth:`build`)."""
        self.layers[robot] = layer
        self.distance[robot] = layer.distance_m
        self.updates += 1


def _traversable(grid: OccupancyGrid) -> OccupancyGrid:
    """Unknown cells as free (Nav2's ``allow_unknown``)."""
    data = np.where(grid.data == UNKNOWN, FREE, grid.data).astype(np.int8)
    return OccupancyGrid(grid.resolution_m, grid.origin_xy_m, data)


def lanes_on(layer: StaticCostmap, truth: OccupancyGrid, width_m: float) -> npt.NDArray[np.uint8]:
    """The building's one-way lanes on a costmap's cells (two-way where the map reaches past it).

    A robot that maps plans on a grid with a margin around the building; the lanes are laid
    into it at the building's offset. Both grids share the cell size; aisles up to ``width_m``
    wide are one-way (:func:`models.navigation.lanes.aisle_lanes`).

    Raises:
        ValueError: when the costmap does not cover the building.
    """
    lanes = aisle_lanes(truth.data >= OCCUPIED, truth.resolution_m, width_m)
    offset = np.subtract(truth.origin_xy_m, layer.origin_xy_m) / layer.resolution_m
    ox, oy = (int(v) for v in np.rint(offset))
    rows, cols = lanes.shape
    if ox < 0 or oy < 0 or oy + rows > layer.height or ox + cols > layer.width:
        raise ValueError(
            f"the costmap {layer.cost.shape} does not cover the building {lanes.shape}"
        )
    placed = np.full(layer.cost.shape, TWO_WAY, dtype=np.uint8)
    placed[oy : oy + rows, ox : ox + cols] = lanes
    return placed


def static_costmap(run: RunContext, radius_m: float) -> StaticCostmap:
    """The building's static map, inflated for a footprint of ``radius_m`` (m).

    The :class:`StaticLayer` service if an adapter provides one, else the ground-truth
    map at ``navigation.resolution_m`` (provided from now on).
    """
    cfg = run.settings(NavigationConfig)
    if not run.has_service(StaticLayer):
        run.provide(StaticLayer(ground_truth_grid(run.service(Warehouse), cfg.resolution_m)))
    params = CostmapParams(radius_m, cfg.inflation_radius_m, cfg.cost_scaling)
    return StaticCostmap.from_grid(run.service(StaticLayer).grid, params)


def robot_layers(run: RunContext, static: StaticCostmap, robots: int) -> StaticLayers:
    """The static layer each robot plans on: the shared one, or its own map as it builds it."""
    mapping = run.settings(MappingConfig)
    if not mapping.enabled:
        return StaticLayers.shared(static, robots)
    area = map_geometry(run.service(Warehouse), mapping.resolution_m)
    resolution_m = run.settings(NavigationConfig).resolution_m
    return StaticLayers.unexplored(unknown_grid(area), robots, static.params, resolution_m)


def padded(static: StaticCostmap, padding_m: float) -> StaticCostmap:
    """``static`` with every cell nearer an obstacle than the footprint plus a padding blocked.

    Nav2's ``footprint_padding``, kept for the planner: the local controller keeps
    ``padding_m`` of clearance beyond the footprint and will not enter a gap narrower than
    the footprint plus that on both sides, so the global planner must not route through
    one (a robot sent into a 0.82 m gap by a plan that fits a 0.66 m footprint halts at its
    mouth, replanning the same way until it is stuck). The inflation costs outside that
    band are unchanged.

    Args:
        static: the costmap (its ``distance_m`` grid is used).
        padding_m: clearance beyond the footprint radius (m), >= 0.

    Returns:
        A costmap whose cells within ``robot_radius_m + padding_m`` of an obstacle are
        ``INSCRIBED`` (lethal and unknown cells kept), or ``static`` itself for no padding.
    """
    if padding_m <= 0:
        return static
    reach = static.params.robot_radius_m + padding_m
    cost = np.array(static.cost)
    band = (static.distance_m <= reach) & (cost < INSCRIBED)
    cost[band] = INSCRIBED
    return StaticCostmap(
        cost=cost,
        distance_m=static.distance_m,
        resolution_m=static.resolution_m,
        origin_xy_m=static.origin_xy_m,
        params=static.params,
    )


def open_goal(
    cost: npt.NDArray[np.uint8],
    plain: StaticCostmap,
    padded_layer: StaticCostmap,
    goal_xy_m: npt.NDArray[np.float64],
    radius_m: float,
) -> None:
    """Give back, round a goal, the cells only the padding blocked (in place on ``cost``).

    A goal nearer an obstacle than the footprint plus the padding is reached within the
    goal tolerance all the same; the planner needs a way into it.

    Args:
        cost: a per-plan cost grid made from ``padded_layer``.
        plain: the layer without padding.
        padded_layer: the padded layer.
        goal_xy_m: the goal in ``map`` (m).
        radius_m: cells whose centre is this near the goal are opened (m).
    """
    res = plain.resolution_m
    gx, gy = plain.world_to_cell(goal_xy_m)
    reach = int(np.ceil(radius_m / res))
    x0, x1 = max(gx - reach, 0), min(gx + reach + 1, plain.width)
    y0, y1 = max(gy - reach, 0), min(gy + reach + 1, plain.height)
    if x0 >= x1 or y0 >= y1:
        return
    dx = np.arange(x0, x1) - gx
    dy = np.arange(y0, y1) - gy
    disc = (dx[None, :] ** 2 + dy[:, None] ** 2) * res * res <= radius_m * radius_m
    window = cost[y0:y1, x0:x1]
    before = plain.cost[y0:y1, x0:x1]
    after = padded_layer.cost[y0:y1, x0:x1]
    band = disc & (after != before) & (window == after)
    window[band] = before[band]
