"""One robot's lidar beams, recomputed from the run's world and poses.

The run does not store its scans; they are cast again with the project's batched caster
(:func:`models.sensing.raycast.cast_batch`, as :mod:`adapters.sensing.lidar` calls it) against the
static world, the other robots and the people (``tables/humans``, the latest sample at
or before the pose) at each pose sample: the exact ranges, before the sensor model's
noise and dropout.
"""

from __future__ import annotations

import math

import numpy as np

from cosim.plotting.people import PeopleSamples
from cosim.plotting.rundata import RunData
from models.arrays import BoolArray, FloatArray
from models.sensing.lidar import ScanGeometry
from models.sensing.raycast import StaticScene, cast_batch, scene_cell_m


class LidarRays:
    """The beams of robot ``robot`` (fleet index) at any pose sample, every k-th beam."""

    def __init__(self, run: RunData, robot: int, *, max_rays: int = 120) -> None:
        """Index the world's static edges once.

        Args:
            run: the run (its ``[lidar]`` section and world).
            robot: fleet index of the robot whose lidar is drawn.
            max_rays: most beams drawn (every k-th beam of the scan, k >= 1).
        """
        cfg = run.scenario.lidar
        geometry = ScanGeometry(
            beams=cfg.beams,
            fov_rad=math.radians(cfg.fov_deg),
            range_min_m=cfg.range_min_m,
            range_max_m=cfg.range_max_m,
        )
        step = max(1, math.ceil(cfg.beams / max_rays)) if cfg.beams else 1
        self.angles: FloatArray = geometry.angles()[::step] if cfg.beams else np.zeros(0)
        self.range_max_m = cfg.range_max_m
        self.radius_m = run.scenario.robots.radius_m
        segments = run.warehouse.segments()
        self.scene = StaticScene(segments, cell_m=scene_cell_m(segments))
        self.track = run.track
        self.robot = robot
        self.people = PeopleSamples(run)

    def cast(self, i: int) -> tuple[FloatArray, FloatArray, BoolArray]:
        """The beams at pose sample ``i``.

        Returns:
            The sensor's origin (2,) in ``map`` (m), each beam's end (b, 2) in ``map`` (m)
            (the hit, or ``range_max`` away if nothing is hit), and whether it hit (b,).
            No beam if the lidar is disabled or the robot has no pose at ``i``.
        """
        x, y, yaw = self.track.x_m[i], self.track.y_m[i], self.track.yaw_rad[i]
        origin = np.array([x[self.robot], y[self.robot]])
        if not len(self.angles) or not np.isfinite(origin).all():
            return origin, np.zeros((0, 2)), np.zeros(0, dtype=bool)
        present = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
        circles = np.vstack(
            [
                np.column_stack([x[present], y[present], np.full(len(present), self.radius_m)]),
                self.people.discs(float(self.track.t_s[i])),
            ]
        )
        own = np.array([int(np.searchsorted(present, self.robot))], dtype=np.int64)
        heading = float(yaw[self.robot])
        ranges = cast_batch(
            self.scene,
            origin.reshape(1, 2),
            np.array([heading]),
            self.angles,
            circles,
            own,
            self.range_max_m,
        )[0]
        hit = np.isfinite(ranges)
        reach = np.where(hit, ranges, self.range_max_m)
        directions = heading + self.angles
        ends = origin + reach[:, None] * np.column_stack([np.cos(directions), np.sin(directions)])
        return origin, ends, hit
