"""One robot's mapping: drifting odometry corrected by scan-to-map matching (slam_toolbox's role).

Each scan comes with the odometry pose it was taken at (frame ``odom``). A scan updates
the map only once the robot has moved far enough, turned far enough, and some time has
passed since the last update (slam_toolbox's ``minimum_travel_distance``,
``minimum_travel_heading``, ``minimum_time_interval``, 0.5 m, 0.5 rad, 0.5 s by default).
The pose of an updating scan is predicted from the last estimate and the odometry moved
since, matched against the map (:mod:`models.mapping.matcher`), and the scan is added at
the matched pose. The estimate between updates is that pose moved by the odometry:
``map -> odom`` is held as a correction, exactly the transform slam_toolbox publishes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.errors import ModelError
from models.geometry.se2 import Pose, compose, inverse, relative
from models.mapping.grid import LogOddsMap
from models.mapping.loop_params import LoopParams
from models.mapping.loops import LoopCloser
from models.mapping.matcher import MatcherParams, match, scan_points
from models.mapping.uncertainty import match_covariance


@dataclass(frozen=True)
class UpdateGate:
    """When a scan updates the map (slam_toolbox's defaults).

    Attributes:
        min_travel_m: distance driven since the last update (m); either this or the
            heading must be reached.
        min_heading_rad: rotation since the last update (rad).
        min_interval_s: time since the last update (s), in any case.
    """

    min_travel_m: float = 0.5
    min_heading_rad: float = 0.5
    min_interval_s: float = 0.5

    def __post_init__(self) -> None:
        for name in ("min_travel_m", "min_heading_rad", "min_interval_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ModelError(f"mapping.{name}", value, "a finite value >= 0")

    def due(self, motion: Pose, elapsed_s: float) -> bool:
        """Whether a scan after ``motion`` (since the last update) and ``elapsed_s`` updates."""
        if elapsed_s < self.min_interval_s:
            return False
        moved = math.hypot(motion[0], motion[1]) >= self.min_travel_m
        return moved or abs(motion[2]) >= self.min_heading_rad


@dataclass(frozen=True)
class MapperParams:
    """A robot's mapping settings.

    Attributes:
        gate: when scans update the map.
        matcher: the scan matcher's window and thresholds.
        scan_matching: correct the odometry by matching (False: odometry only).
        range_min_m, range_max_m: the lidar's valid ranges (m).
        clear_no_return_m: how far a beam without a return clears (m).
        loop_closure: close loops (:mod:`models.mapping.loops`), or None.
    """

    gate: UpdateGate = field(default_factory=UpdateGate)
    matcher: MatcherParams = field(default_factory=MatcherParams)
    scan_matching: bool = True
    range_min_m: float = 0.1
    range_max_m: float = 10.0
    clear_no_return_m: float = 3.0
    loop_closure: LoopParams | None = None


class Update(NamedTuple):
    """A scan that updated the map.

    Attributes:
        t_ns: its time (ns).
        pose: the estimated sensor pose it was added at (``map``).
        prior: the pose odometry alone predicted for it (``map``).
        score: the match score (0 without matching).
        matched: whether matching moved the pose.
        flipped: cells whose occupied state changed.
    """

    t_ns: int
    pose: Pose
    prior: Pose
    score: float
    matched: bool
    flipped: int


class ScanMapper:
    """Builds one robot's map and pose estimate from its scans and odometry.

    Args:
        grid: the robot's map (it may also receive other robots' evidence).
        start: the robot's known start pose in ``map`` (the common frame).
        params: mapping settings.
        angles_rad: the lidar's beam angles in the sensor frame.
    """

    def __init__(
        self, grid: LogOddsMap, start: Pose, params: MapperParams, angles_rad: FloatArray
    ) -> None:
        self.grid = grid
        self.params = params
        self.angles = np.asarray(angles_rad, dtype=np.float64)
        self.start = start
        self.correction: Pose = (0.0, 0.0, 0.0)
        """``map -> odom``: the estimate is ``correction * odometry``."""
        self._odom_ref: Pose | None = None
        self._estimate_ref: Pose = start
        self._last_ns = 0
        self.updates = 0
        self.matched = 0
        self.loops = (
            LoopCloser(
                params.loop_closure,
                self.angles,
                range_min_m=params.range_min_m,
                range_max_m=params.range_max_m,
                clear_no_return_m=params.clear_no_return_m,
            )
            if params.loop_closure is not None
            else None
        )

    def estimate(self, odom: Pose) -> Pose:
        """The ``map`` pose estimated for the odometry pose ``odom``.

        Before the first scan the correction is the identity (the simulation's odometry
        starts aligned with ``map``); the first scan anchors it to the start pose.
        """
        return compose(self.correction, odom)

    def due(self, t_ns: int, odom: Pose) -> bool:
        """Whether a scan at ``t_ns`` taken at odometry pose ``odom`` would update the map."""
        if self._odom_ref is None:
            return True
        return self.params.gate.due(relative(self._odom_ref, odom), (t_ns - self._last_ns) / 1e9)

    def process(
        self,
        t_ns: int,
        odom: Pose,
        ranges_m: npt.NDArray[np.floating[Any]],
    ) -> Update | None:
        """Take one scan with the odometry pose it was taken at; an :class:`Update` if it mapped."""
        p = self.params
        if self._odom_ref is None:
            # the first scan anchors odometry to the known start pose
            self._odom_ref = odom
            self.correction = compose(self.start, inverse(odom))
            return self._add(t_ns, odom, self.start, self.start, 0.0, False, ranges_m)
        motion = relative(self._odom_ref, odom)
        if not p.gate.due(motion, (t_ns - self._last_ns) / 1e9):
            return None
        prior = compose(self._estimate_ref, motion)
        pose, score, matched = prior, 0.0, False
        covariance = None
        if p.scan_matching and not self.grid.empty:
            points = scan_points(
                self.angles,
                ranges_m,
                p.range_min_m,
                min(p.range_max_m, p.matcher.max_range_m),
                p.matcher.max_points,
            )
            result = match(self.grid, prior, points, p.matcher)
            pose, score, matched = result.pose, result.score, result.matched
            if matched and p.loop_closure is not None:
                # how sure the match is: the pose graph's trust in this step
                window = p.loop_closure.sequential_response
                covariance = match_covariance(self.grid, pose, points, window)
        return self._add(t_ns, odom, pose, prior, score, matched, ranges_m, covariance)

    def _add(
        self,
        t_ns: int,
        odom: Pose,
        pose: Pose,
        prior: Pose,
        score: float,
        matched: bool,
        ranges_m: npt.NDArray[np.floating[Any]],
        covariance: FloatArray | None = None,
    ) -> Update:
        p = self.params
        flipped = self.grid.integrate(
            pose,
            self.angles,
            ranges_m,
            range_min_m=p.range_min_m,
            range_max_m=p.range_max_m,
            clear_no_return_m=p.clear_no_return_m,
        )
        if self.loops is not None:
            ranges = np.asarray(ranges_m, dtype=np.float32)
            self.loops.add(pose, odom, ranges, matched, covariance)
            closed = self.loops.close(self.grid)
            if closed is not None:
                pose = closed
        self._odom_ref = odom
        self._estimate_ref = pose
        self._last_ns = t_ns
        self.correction = compose(pose, inverse(odom))
        self.updates += 1
        self.matched += int(matched)
        return Update(t_ns, pose, prior, score, matched, flipped)
