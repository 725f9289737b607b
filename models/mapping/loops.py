"""Loop closure: recognise a place seen long ago, and bend the trajectory to agree.

Scan-to-map matching corrects drift only while the map around the robot is its own
recent work; back in a place mapped long ago, the robot's estimate has drifted from the
map made then, and the two disagree by more than the matcher's window. Every scan that
updates the map becomes a node of a :class:`~models.mapping.posegraph.PoseGraph`, tied to
the previous one by the relative pose matching found. When a scan lies near nodes that
are far back along the path, a map of those nodes alone is built and the scan is matched
against it over a wide window (branch and bound keeps that exact and affordable); a
confident match is a loop-closure edge, the graph is solved, and the robot's map is
rebuilt from every scan at its new pose (Karto and slam_toolbox close loops the same
way).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.mapping.grid import LogOddsMap, MapGeometry
from models.mapping.matcher import MatcherParams, match, scan_points
from models.mapping.posegraph import Edge, PoseGraph
from models.mapping.se2 import Pose, relative


@dataclass(frozen=True)
class LoopParams:
    """When and how loops are searched.

    Attributes:
        search_radius_m: old nodes within this of the current estimate are candidates (m).
        min_path_m: and only if the robot travelled at least this since them (m).
        local_nodes: nodes on each side of the nearest candidate that make the local map.
        every_nodes: search at most every this many nodes.
        matcher: the wide window of the loop match, and the score it needs; no margin
            (keeping the prior would assert the drifted estimate as a closure).
        sequential_sigma: (m, rad) trust in consecutive scan matches.
        loop_sigma: (m, rad) trust in a loop closure.
        rebuild_shift_m: rebuild the map when optimisation moves a node more than this (m).
    """

    search_radius_m: float = 4.0
    min_path_m: float = 10.0
    local_nodes: int = 15
    every_nodes: int = 3
    matcher: MatcherParams = field(
        default_factory=lambda: MatcherParams(
            window_m=1.5, window_rad=0.3, max_points=180, min_score=0.55, margin=0.0
        )
    )
    sequential_sigma: tuple[float, float] = (0.05, 0.02)
    loop_sigma: tuple[float, float] = (0.05, 0.02)
    rebuild_shift_m: float = 0.1


@dataclass
class _Node:
    odom: Pose
    ranges: npt.NDArray[np.float32]


class LoopCloser:
    """The pose graph of one robot's map updates, and its loop closures.

    Args:
        params: search settings.
        angles_rad: the lidar's beam angles.
        scan: how scans are added to maps (range limits, clearing), as for the robot's map.
    """

    def __init__(
        self,
        params: LoopParams,
        angles_rad: FloatArray,
        *,
        range_min_m: float,
        range_max_m: float,
        clear_no_return_m: float,
    ) -> None:
        self.params = params
        self.angles = angles_rad
        self.limits = (range_min_m, range_max_m, clear_no_return_m)
        self.graph = PoseGraph()
        self.nodes: list[_Node] = []
        self.path_m: list[float] = []
        self.closures = 0
        self._since_search = 0

    def add(self, pose: Pose, odom: Pose, ranges: npt.NDArray[np.float32], matched: bool) -> None:
        """A map update at ``pose`` (after matching) with its odometry and scan."""
        k = self.graph.add_node(pose)
        self.nodes.append(_Node(odom, np.asarray(ranges, dtype=np.float32).copy()))
        if k == 0:
            self.path_m.append(0.0)
            return
        previous = self.graph.nodes[k - 1]
        step = relative(previous, pose)
        self.path_m.append(self.path_m[-1] + math.hypot(step[0], step[1]))
        sigma_m, sigma_rad = self.params.sequential_sigma
        if not matched:  # odometry alone: trusted less
            sigma_m, sigma_rad = 4 * sigma_m, 4 * sigma_rad
        self.graph.add_edge(Edge(k - 1, k, step, sigma_m, sigma_rad))

    def close(self, grid: LogOddsMap) -> Pose | None:
        """Search a loop for the newest node; if one closes, re-solve and rebuild ``grid``.

        Returns:
            The newest node's new pose when the graph was re-solved, else None.
        """
        p = self.params
        self._since_search += 1
        k = len(self.nodes) - 1
        if k < 1 or self._since_search < p.every_nodes:
            return None
        self._since_search = 0
        poses = np.array(self.graph.nodes)
        here = poses[k, :2]
        far_back = np.asarray(self.path_m) <= self.path_m[k] - p.min_path_m
        near = np.hypot(*(poses[:, :2] - here).T) <= p.search_radius_m
        candidates = np.flatnonzero(far_back & near)
        if not len(candidates):
            return None
        nearest = int(candidates[np.argmin(np.hypot(*(poses[candidates, :2] - here).T))])
        chosen = [int(j) for j in candidates if abs(j - nearest) <= p.local_nodes]
        found = self._match(grid.geometry, poses, chosen, k)
        if found is None:
            return None
        sigma_m, sigma_rad = p.loop_sigma
        self.graph.add_edge(
            Edge(nearest, k, relative(self.graph.nodes[nearest], found), sigma_m, sigma_rad)
        )
        self.closures += 1
        solved = self.graph.optimize()
        shift = np.hypot(*(np.array(solved)[:, :2] - poses[:, :2]).T).max()
        self.graph.nodes = solved
        if shift > p.rebuild_shift_m:
            self._rebuild(grid)
        return solved[k]

    def _match(
        self, geometry: MapGeometry, poses: FloatArray, chosen: list[int], k: int
    ) -> Pose | None:
        """Node ``k``'s pose in a map of the chosen old nodes, if its scan matches it."""
        r = geometry.resolution_m
        reach = min(self.limits[1], self.params.matcher.max_range_m)
        lo = poses[chosen, :2].min(axis=0) - reach
        hi = poses[chosen, :2].max(axis=0) + reach
        local = LogOddsMap(MapGeometry.covering((lo[0], lo[1], hi[0], hi[1]), r, 1.0))
        for j in chosen:
            self._integrate(local, tuple(poses[j]), self.nodes[j].ranges)
        points = scan_points(
            self.angles, self.nodes[k].ranges, self.limits[0], reach, self.params.matcher.max_points
        )
        result = match(local, tuple(poses[k]), points, self.params.matcher)
        return result.pose if result.matched else None

    def _integrate(self, grid: LogOddsMap, pose: Pose, ranges: npt.NDArray[np.float32]) -> None:
        range_min, range_max, clear = self.limits
        grid.integrate(
            pose, self.angles, ranges, range_min_m=range_min, range_max_m=range_max,
            clear_no_return_m=clear,
        )  # fmt: skip

    def _rebuild(self, grid: LogOddsMap) -> None:
        """The map again from every node's scan at its solved pose."""
        grid.clear()
        for pose, node in zip(self.graph.nodes, self.nodes, strict=True):
            self._integrate(grid, pose, node.ranges)
