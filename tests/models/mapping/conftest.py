"""Small worlds of boxes and exact scans of them, to build and match maps against, and a
graph of map updates driven out and back, to check loop closures on."""

from __future__ import annotations

import math

import numpy as np
import pytest

from models.geometry.se2 import compose, relative
from models.mapping.grid import LogOddsMap, MapGeometry
from models.mapping.loop_params import LoopParams
from models.mapping.posegraph import Edge, sqrt_information
from models.mapping.update_graph import UpdateGraph
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
LAP = [
    (6.0 + 4.5 * math.cos(a), 4.0 + 2.8 * math.sin(a), a + math.pi / 2)
    for a in np.linspace(0.0, 2 * math.pi, 41)[:-1]
]
"""A lap of the room round its boxes: 40 poses on an ellipse (25 m), anticlockwise."""
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


OUT_AND_BACK_ANGLES = np.linspace(-math.pi, math.pi, 8, endpoint=False)
MATCHED = np.diag([0.02**2, 0.02**2, 0.005**2])
"""A scan match's covariance (``map`` axes)."""


def out_and_back() -> UpdateGraph:
    """40 matched updates: 10 m east in 0.5 m steps, a U-turn, and back west 2 m to the north."""
    updates = UpdateGraph(LoopParams())
    poses = [(0.5 * k, 0.0, 0.0) for k in range(20)] + [
        (9.5 - 0.5 * k, 2.0, math.pi) for k in range(20)
    ]
    for pose in poses:
        updates.add(pose, pose, np.full(len(OUT_AND_BACK_ANGLES), 5.0, np.float32), MATCHED)
    return updates


def closure(
    updates: UpdateGraph,
    a: int,
    b: int,
    error: tuple[float, float, float] = (0.0, 0.0, 0.0),
    sigma_m: float = 0.05,
) -> Edge:
    """Node ``b`` seen from node ``a``, off from where the graph has it by ``error``."""
    z = compose(relative(updates.graph.nodes[a], updates.graph.nodes[b]), error)
    cov = np.diag([sigma_m**2, sigma_m**2, 0.02**2])
    return Edge(a, b, z, 0.0, 0.0, sqrt_information(cov))
