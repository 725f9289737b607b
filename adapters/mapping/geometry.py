"""The grid every robot's map shares: the warehouse and a margin, at ``mapping.resolution_m``."""

from __future__ import annotations

import numpy as np

from models.geometry.occupancy import UNKNOWN, OccupancyGrid
from models.mapping.grid import MapGeometry
from models.world.warehouse import Warehouse

MARGIN_M = 1.0
"""The maps reach this far beyond the walls' outer faces (m)."""


def map_geometry(world: Warehouse, resolution_m: float) -> MapGeometry:
    """The common map grid (frame ``map``) of a warehouse."""
    return MapGeometry.covering(world.bounds, resolution_m, MARGIN_M)


def unknown_grid(geometry: MapGeometry) -> OccupancyGrid:
    """A map of that grid with every cell unknown (a robot that has seen nothing)."""
    data = np.full((geometry.height, geometry.width), UNKNOWN, dtype=np.int8)
    return OccupancyGrid(geometry.resolution_m, geometry.origin_xy_m, data)
