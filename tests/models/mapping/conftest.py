"""Small worlds of boxes and exact scans of them, to build and match maps against."""

from __future__ import annotations

import math

import numpy as np
import pytest

from models.mapping.grid import LogOddsMap, MapGeometry
from models.sensing.lidar import ScanGeometry
from models.sensing.raycast import StaticScene, cast_batch
from models.world.warehouse import box_segments

ROOM = np.array(
    [
        [-0.2, -0.2, 12.2, 0.0],  # walls of a 12 m x 8 m room
        [-0.2, 8.0, 12.2, 8.2],
        [-0.2, 0.0, 0.0, 8.0],
        [12.0, 0.0, 12.2, 8.0],
        [3.0, 2.0, 3.8, 4.0],  # and a few boxes in it
        [7.0, 5.0, 9.0, 5.6],
        [9.5, 1.0, 10.1, 1.6],
    ]
)
GEOMETRY = ScanGeometry(beams=360, fov_rad=2 * math.pi, range_min_m=0.1, range_max_m=10.0)


class Lidar:
    """Exact scans of a world of boxes."""

    def __init__(self, boxes: np.ndarray, geometry: ScanGeometry = GEOMETRY) -> None:
        self.scene = StaticScene(box_segments(boxes), cell_m=1.0)
        self.geometry = geometry
        self.angles = geometry.angles()

    def scan(self, pose: tuple[float, float, float]) -> np.ndarray:
        ranges = cast_batch(
            self.scene,
            np.array([pose[:2]], dtype=float),
            np.array([pose[2]], dtype=float),
            self.angles,
            np.zeros((0, 3)),
            np.zeros(0, dtype=np.int64),
            self.geometry.range_max_m,
        )[0]
        return ranges.astype(np.float32)


@pytest.fixture
def lidar() -> Lidar:
    return Lidar(ROOM)


def room_map() -> LogOddsMap:
    return LogOddsMap(MapGeometry.covering((-0.2, -0.2, 12.2, 8.2), 0.05, 1.0))


def integrate(grid: LogOddsMap, lidar: Lidar, pose: tuple[float, float, float]) -> int:
    return grid.integrate(
        pose,
        lidar.angles,
        lidar.scan(pose),
        range_min_m=0.1,
        range_max_m=10.0,
        clear_no_return_m=3.0,
    )
