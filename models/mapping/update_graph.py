"""The pose graph of one robot's map updates, and how sure each part of it is.

Every scan that updates the map is a node (its ``map`` pose, its odometry pose and its
ranges), tied to the previous one by the relative pose matching found, as sure as the
odometry and the match together (their informations added). The covariance of a node
relative to an older one is compounded along the steps between them (Smith, Self and
Cheeseman 1990); a loop closure's edge carries its match's covariance in its old node's
frame, a direction the match could not tell (a corridor) made to constrain nothing. The
checks a closure passes are in :mod:`models.mapping.closure_checks`, the search for one
in :mod:`models.mapping.loop_search`, and :class:`~models.mapping.loops.LoopCloser`
composes them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.geometry.se2 import Pose, relative
from models.mapping.posegraph import Edge, PoseGraph, sqrt_information

if TYPE_CHECKING:
    from models.mapping.loop_params import LoopParams


@dataclass
class ScanNode:
    """What a node keeps of its map update besides its pose.

    Attributes:
        odom: the odometry pose the scan was taken at (``odom`` frame; m, rad).
        ranges: the scan's ranges (m), one per beam.
    """

    odom: Pose
    ranges: npt.NDArray[np.float32]


class UpdateGraph:
    """Every map update a node of a pose graph, with its scan, path length and step covariance.

    Args:
        params: the loop settings (``odometry_sigma``, ``ambiguous_m``,
            ``ambiguous_sigma_m`` are read here).

    Attributes:
        graph: the pose graph; its nodes are the updates' ``map`` poses (m, rad).
        nodes: each node's odometry pose and scan.
        path_m: the path length driven up to each node (m).
        loop_edges: per edge of ``graph``, whether it is a loop closure.
        steps: node ``k``'s step covariance, in node ``k - 1``'s frame (the first node's
            is zero).
    """

    def __init__(self, params: LoopParams) -> None:
        self.params = params
        self.graph = PoseGraph()
        self.nodes: list[ScanNode] = []
        self.path_m: list[float] = []
        self.loop_edges: list[bool] = []
        self.steps: list[FloatArray] = [np.zeros((3, 3))]  # node k's step covariance (its frame)

    def add(
        self,
        pose: Pose,
        odom: Pose,
        ranges: npt.NDArray[np.float32],
        covariance: FloatArray | None = None,
    ) -> None:
        """A map update at ``pose`` (``map``) with its odometry pose and scan.

        ``covariance`` is the scan match's (``map`` axes), when it was matched: the step
        from the previous node is trusted as much as the odometry and that match together.
        """
        k = self.graph.add_node(pose)
        self.nodes.append(ScanNode(odom, np.asarray(ranges, dtype=np.float32).copy()))
        if k == 0:
            self.path_m.append(0.0)
            return
        previous = self.graph.nodes[k - 1]
        step = relative(previous, pose)
        self.path_m.append(self.path_m[-1] + math.hypot(step[0], step[1]))
        # what odometry says of the step, and (when it was matched) what the match says
        moved = relative(self.nodes[k - 1].odom, odom)
        info = np.linalg.inv(self.odometry_covariance(moved))
        if covariance is not None:
            info = info + np.linalg.inv(in_frame(covariance, previous[2]))
        covariance_step = np.linalg.inv(info)
        self.steps.append(covariance_step)
        self.graph.add_edge(Edge(k - 1, k, step, 0.0, 0.0, sqrt_information(covariance_step)))
        self.loop_edges.append(False)

    def odometry_covariance(self, moved: Pose) -> FloatArray:
        """The covariance of an odometry step ``moved`` (its own frame), from ``odometry_sigma``."""
        per_m, floor_m, per_rad, rad_per_m, floor_rad = self.params.odometry_sigma
        d = math.hypot(moved[0], moved[1])
        sigma_m = per_m * d + floor_m
        sigma_rad = per_rad * abs(moved[2]) + rad_per_m * d + floor_rad
        return np.diag([sigma_m**2, sigma_m**2, sigma_rad**2])

    def chain_covariance(self, a: int, b: int) -> FloatArray:
        """The covariance of node ``b``'s pose relative to node ``a``'s, in ``a``'s frame.

        Compounded along the sequential steps ``a+1 .. b`` at the current estimates: each
        step's translation turned into ``map`` axes, and its rotation swinging the rest of
        the path about its node (a lever to node ``b``).
        """
        x = np.array(self.graph.nodes[a : b + 1])
        steps = np.array(self.steps[a + 1 : b + 1])
        yaw = x[:-1, 2]
        c, s = np.cos(yaw), np.sin(yaw)
        rot = np.zeros((len(yaw), 2, 2))
        rot[:, 0, 0], rot[:, 0, 1], rot[:, 1, 0], rot[:, 1, 1] = c, -s, s, c
        translation = np.einsum("kij,kjl,kml->im", rot, steps[:, :2, :2], rot)
        lever = x[-1, :2] - x[1:, :2]  # from each step's node to node b
        swing = np.stack([-lever[:, 1], lever[:, 0]], axis=1)
        translation += np.einsum("k,ki,kj->ij", steps[:, 2, 2], swing, swing)
        covariance = np.zeros((3, 3))
        covariance[:2, :2] = translation
        covariance[2, 2] = steps[:, 2, 2].sum()
        covariance[:2, 2] = covariance[2, :2] = np.einsum("k,ki->i", steps[:, 2, 2], swing)
        return in_frame(covariance, float(x[0, 2]))

    def chain_covariance_map(self, a: int, b: int) -> FloatArray:
        """The covariance of the later node's pose relative to the earlier one's, ``map`` axes."""
        first, last = min(a, b), max(a, b)
        if first == last:
            return np.zeros((3, 3))
        return in_frame(self.chain_covariance(first, last), -self.graph.nodes[first][2])

    def closure(self, a: int, b: int, pose: Pose, covariance: FloatArray) -> Edge:
        """The edge of a loop closure: node ``b`` matched at ``pose`` (``map``) near node ``a``.

        The match's covariance (``map`` axes) is turned into node ``a``'s frame, and a
        direction the match cannot tell (a corridor) is made to constrain nothing.
        """
        p = self.params
        local = in_frame(covariance, self.graph.nodes[a][2])
        values, vectors = np.linalg.eigh(local[:2, :2])
        values = np.where(np.sqrt(values) > p.ambiguous_m, p.ambiguous_sigma_m**2, values)
        local[:2, :2] = vectors @ np.diag(values) @ vectors.T
        local[:2, 2] = local[2, :2] = 0.0  # the spread's coupling is not trusted
        z = relative(self.graph.nodes[a], pose)
        return Edge(a, b, z, 0.0, 0.0, sqrt_information(local))

    def solve_with(self, closures: list[Edge]) -> list[Pose]:
        """The graph's solution with ``closures`` added (they stay until :meth:`drop`)."""
        for closure in closures:
            self.graph.add_edge(closure)
            self.loop_edges.append(True)
        return self.graph.optimize()

    def drop(self, closures: int) -> None:
        """Take the last ``closures`` edges out of the graph again."""
        del self.graph.edges[-closures:]
        del self.loop_edges[-closures:]


def in_frame(covariance: FloatArray, yaw: float) -> FloatArray:
    """A covariance in ``map`` axes turned into the axes of a node at heading ``yaw`` (rad)."""
    c, s = math.cos(yaw), math.sin(yaw)
    rotate = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    turned: FloatArray = rotate @ covariance @ rotate.T
    return turned
