"""The search for a loop closure, its check on the scans, and the maps both are made on.

When the newest map update lies near nodes far back along the path, a map of those old
nodes alone is built from their scans and the newest scan is matched against it over a
wide window (:func:`models.mapping.matcher.match`; branch and bound keeps that exact and
affordable); the spread of the match's response is its covariance (Olson 2009). After a
solve, the recent scans must fit the old place's map at least as well where the solve puts
them as before (a true closure brings them onto the old walls, a false one pulls them off).
When a solve moves the graph, the robot's map is rebuilt from every scan at its new pose.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.geometry.se2 import Pose
from models.mapping.grid import LogOddsMap, MapGeometry
from models.mapping.matcher import match, scan_points
from models.mapping.posegraph import Edge
from models.mapping.uncertainty import match_covariance
from models.mapping.update_graph import UpdateGraph

if TYPE_CHECKING:
    from models.mapping.loop_params import LoopParams


class LoopSearch:
    """Candidates for a loop closure, the match against their map, and maps of the scans.

    Args:
        params: the loop settings (``search_radius_m``, ``min_path_m``, ``local_nodes``,
            ``matcher``, ``response`` and ``fit_tolerance`` are read here).
        angles_rad: the lidar's beam angles (rad, sensor frame).
        updates: the graph of map updates whose scans are searched and mapped.
        limits: ``(range_min_m, range_max_m, clear_no_return_m)``: how scans are added to
            maps (range limits, clearing; m), as for the robot's map.
    """

    def __init__(
        self,
        params: LoopParams,
        angles_rad: FloatArray,
        updates: UpdateGraph,
        limits: tuple[float, float, float],
    ) -> None:
        self.params = params
        self.angles = angles_rad
        self.updates = updates
        self.limits = limits

    def candidates(self, poses: FloatArray, k: int) -> tuple[int, list[int]] | None:
        """The old nodes node ``k`` may close a loop with, at ``poses`` (``map``; m, rad).

        Old nodes are within ``search_radius_m`` of node ``k`` and at least ``min_path_m``
        back along the path.

        Returns:
            The nearest of them, and the nodes within ``local_nodes`` of it that are among
            them (the map the scan is matched on); None when there is none.
        """
        p = self.params
        path_m = self.updates.path_m
        here = poses[k, :2]
        far_back = np.asarray(path_m) <= path_m[k] - p.min_path_m
        near = np.hypot(*(poses[:, :2] - here).T) <= p.search_radius_m
        candidates = np.flatnonzero(far_back & near)
        if not len(candidates):
            return None
        nearest = int(candidates[np.argmin(np.hypot(*(poses[candidates, :2] - here).T))])
        chosen = [int(j) for j in candidates if abs(j - nearest) <= p.local_nodes]
        return nearest, chosen

    def match(
        self, geometry: MapGeometry, poses: FloatArray, chosen: list[int], k: int
    ) -> tuple[Pose, FloatArray] | None:
        """Node ``k``'s pose in a map of the chosen old nodes and its covariance, if it matches.

        Args:
            geometry: the robot's map (its resolution is the local map's).
            poses: every node's pose (``map``; m, rad).
            chosen: the old nodes whose scans make the map.
            k: the node whose scan is matched, from its pose in ``poses``.

        Returns:
            The matched pose (``map``) and its covariance (``map`` axes), or None.
        """
        reach = min(self.limits[1], self.params.matcher.max_range_m)
        local = self.local_map(geometry, poses, chosen)
        points = scan_points(
            self.angles,
            self.updates.nodes[k].ranges,
            self.limits[0],
            reach,
            self.params.matcher.max_points,
        )
        result = match(local, tuple(poses[k]), points, self.params.matcher)
        if not result.matched:
            return None
        return result.pose, match_covariance(local, result.pose, points, self.params.response)

    def explains_better(
        self, geometry: MapGeometry, edge: Edge, before: FloatArray, after: list[Pose]
    ) -> bool:
        """Whether the recent scans fit the old place's map better after the solve than before.

        A map of the old nodes around the closure is made at each solution, and the scans
        of the recent nodes (not among them) are scored on it where each solution puts
        them: a true closure brings them onto the old walls, a false one pulls them off.
        """
        p = self.params
        old = [j for j in range(max(0, edge.a - p.local_nodes), edge.a + p.local_nodes + 1)]
        recent = [j for j in range(max(0, edge.b - p.local_nodes), edge.b + 1) if j not in old]
        if not recent:
            return True
        solved = np.array(after)
        scores = [self._fit(geometry, poses, old, recent) for poses in (np.asarray(before), solved)]
        return scores[1] >= scores[0] - p.fit_tolerance

    def _fit(
        self, geometry: MapGeometry, poses: FloatArray, old: list[int], recent: list[int]
    ) -> float:
        """The mean score of the recent nodes' scans on a map of the old nodes, at ``poses``."""
        local = self.local_map(geometry, poses, old)
        reach = min(self.limits[1], self.params.matcher.max_range_m)
        total, count = 0.0, 0
        for j in recent:
            ranges = self.updates.nodes[j].ranges
            points = scan_points(self.angles, ranges, self.limits[0], reach, 120)
            total += local.fit(tuple(poses[j]), points) * len(points)
            count += len(points)
        return total / count if count else 0.0

    def local_map(self, geometry: MapGeometry, poses: FloatArray, nodes: list[int]) -> LogOddsMap:
        """A map of ``nodes``' scans at ``poses`` (``map``), reaching as far as they see."""
        r = geometry.resolution_m
        reach = min(self.limits[1], self.params.matcher.max_range_m)
        lo = poses[nodes, :2].min(axis=0) - reach
        hi = poses[nodes, :2].max(axis=0) + reach
        local = LogOddsMap(
            MapGeometry.covering((lo[0], lo[1], hi[0], hi[1]), r, 1.0),
            hit_centroids=self.params.matcher.refine_against == "walls",
        )
        for j in nodes:
            self._integrate(local, tuple(poses[j]), self.updates.nodes[j].ranges)
        return local

    def rebuild(self, grid: LogOddsMap) -> None:
        """``grid`` again from every node's scan at its pose in the graph (``map``)."""
        grid.clear()
        updates = self.updates
        for pose, node in zip(updates.graph.nodes, updates.nodes, strict=True):
            self._integrate(grid, pose, node.ranges)

    def _integrate(self, grid: LogOddsMap, pose: Pose, ranges: npt.NDArray[np.float32]) -> None:
        range_min, range_max, clear = self.limits
        grid.integrate(
            pose, self.angles, ranges, range_min_m=range_min, range_max_m=range_max,
            clear_no_return_m=clear,
        )  # fmt: skip
