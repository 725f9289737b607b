"""What the mapper keeps between a scan's arrival and the instant's batch, and per thread.

Every robot's scans of one instant are matched and mapped together on the run's threads
(:class:`cosim.core.batches.InstantBatch`): a :class:`Pending` holds one
scan with what was known when it arrived, and :class:`ThreadScratch` gives each thread its
own map-update working memory (the maps share one otherwise; see
:class:`models.mapping.grid.Scratch`).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cosim.core.messages import LaserScan
from models.mapping.grid import MapGeometry, Scratch

Pose = tuple[float, float, float]


@dataclass(frozen=True)
class Pending:
    """A scan that will update robot ``robot``'s map at this instant.

    Attributes:
        robot: the robot's index in the fleet.
        now_ns: when it arrived (ns).
        odom: its odometry pose when the scan arrived (x m, y m, yaw rad; ``odom``).
        ranges: the ranges to map (m), returns off other robots already NaN.
        scan: the scan message (for map sharing).
    """

    robot: int
    now_ns: int
    odom: Pose
    ranges: npt.NDArray[np.float32]
    scan: LaserScan


class ThreadScratch:
    """One :class:`~models.mapping.grid.Scratch` per thread, made on first use.

    Args:
        geometry: the maps' geometry (every robot's map has the same).
    """

    def __init__(self, geometry: MapGeometry) -> None:
        self.geometry = geometry
        self._local = threading.local()

    def mine(self) -> Scratch:
        """The calling thread's scratch."""
        scratch: Scratch | None = getattr(self._local, "scratch", None)
        if scratch is None:
            scratch = Scratch(self.geometry)
            self._local.scratch = scratch
        return scratch


__all__ = ["Pending", "ThreadScratch"]
