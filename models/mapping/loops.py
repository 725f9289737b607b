"""Loop closure: recognise a place seen long ago, and bend the trajectory to agree.

Scan-to-map matching corrects drift only while the map around the robot is its own
recent work; back in a place mapped long ago, the robot's estimate has drifted from the
map made then, and the two disagree by more than the matcher's window. Every scan that
updates the map becomes a node of a :class:`~models.mapping.posegraph.PoseGraph`, tied to
the previous one by the relative pose matching found, as sure as the odometry and the
match together. When a scan lies near nodes that are far back along the path, a map of
those nodes alone is built and the scan is matched against it over a wide window (branch
and bound keeps that exact and affordable); the spread of the match's response is its
covariance (Olson 2009; a corridor constrains nothing along it). Karto and slam_toolbox
close loops this way; what a wrong closure costs (a bent map) makes this module check a
candidate before and after it enters the graph:

1. *plausible*: the correction it asks for is one the path since could have drifted
   (its covariance compounded along the path, Smith, Self and Cheeseman 1990);
2. *needed*: the current estimate disagrees with it (else it adds only its own error);
3. *confirmed*: another closure of the same revisit agrees with it (pairwise
   consistency, Mangelson et al., ICRA 2018);
4. *consistent*: after the solve (Levenberg-Marquardt) no closure's residual is beyond
   the chi-square gate;
5. *explains the scans better*: the recent scans fit the old place's map at least as
   well where the solve puts them as before.

Only then is the solution kept and the robot's map rebuilt from every scan at its new pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from scipy.stats import chi2 as chi_square

from models.arrays import FloatArray
from models.geometry.angles import wrap_angle
from models.geometry.se2 import Pose, compose, relative
from models.mapping.grid import LogOddsMap, MapGeometry
from models.mapping.matcher import MatcherParams, match, scan_points
from models.mapping.posegraph import Edge, PoseGraph, sqrt_information
from models.mapping.uncertainty import ResponseWindow, match_covariance


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
        odometry_sigma: how far odometry may be off over a step: translation
            ``a d + b`` (m) and rotation ``c |turn| + e d + f`` (rad) for a step of length
            ``d`` (m) and turn (rad), as (a, b, c, e, f). Generous (10 % of the distance,
            5 % of the turn, 0.01 rad per metre): a step is the odometry's and the scan
            match's measurements fused (their informations added).
        sequential_response: where a matched step's covariance is read.
        response: where a closure's match covariance is read
            (:mod:`models.mapping.uncertainty`): its inverse is the closure's information.
            Its floors (5 cm, 0.02 rad) are what closures on Freiburg 079 were off by
            (against the reference: median 4 cm, 90th percentile 10 cm): a single scan
            matched on an old map is less sure than its response says.
        ambiguous_m: a closure whose match spreads further than this along one direction
            (a corridor) constrains nothing along it: that direction's standard deviation
            becomes ``ambiguous_sigma_m``. The response window (0.6 m each way) truncates
            a corridor's spread: 0.14 m measured there hid a 0.53 m error on ACES.
        ambiguous_sigma_m: (m) see ``ambiguous_m``.
        max_chi2: a new closure after which some closure's whitened residual exceeds this
            (chi-square, 3 degrees of freedom; 16.27 is the 99.9 % point) disagrees with
            the rest of the graph: it is dropped and the graph kept as it was.
        max_cost_quantile: the closures added together may raise the graph's whole cost
            (the sum of every edge's squared whitened residual) by at most this quantile
            of a chi-square with three degrees of freedom per closure: a wrong closure the
            path bends to meet raises no single residual far, but all of them together
            (Graham, How and Gustafson, "Robust incremental SLAM with consistency-checking",
            IROS 2015).
        agreement_nodes: a closure waits for another within this many nodes that agrees
            with it (a revisit is matched by several scans; an aliased place rarely twice
            the same way).
        max_disagreement: two closures agree when the Mahalanobis distance between the
            poses they imply is at most this (chi-square, 3 degrees of freedom, 99 %).
        max_innovation: a closure is plausible when the correction it asks for is at most
            this far (Mahalanobis) from where the path since puts the node (99.9 %).
        fit_tolerance: a solve is kept only if the recent scans fit the old place's map at
            least this much worse than before at most (mean score, 0-1).
        min_correction: a closure the current estimate already agrees with (it would move
            its node less than this, Mahalanobis with the closure's own covariance;
            chi-square, 3 degrees of freedom, 7.81 is the 95 % point) is not added: where
            scan-to-map matching has kept the map consistent, closures only add their own
            small errors (on Freiburg 079 they made the trajectory 0.5-1.2 cm worse).
        rebuild_shift_m: rebuild the map when optimisation moves a node more than this (m).
    """

    search_radius_m: float = 4.0
    min_path_m: float = 10.0
    local_nodes: int = 15
    every_nodes: int = 2
    matcher: MatcherParams = field(
        default_factory=lambda: MatcherParams(
            window_m=1.5, window_rad=0.3, max_points=180, min_score=0.55, margin=0.0
        )
    )
    odometry_sigma: tuple[float, float, float, float, float] = (0.1, 0.02, 0.05, 0.01, 0.005)
    response: ResponseWindow = field(
        default_factory=lambda: ResponseWindow(floor_m=0.05, floor_rad=0.02)
    )
    sequential_response: ResponseWindow = field(
        default_factory=lambda: ResponseWindow(half_cells=6, rotation_steps=4)
    )
    ambiguous_m: float = 0.10
    ambiguous_sigma_m: float = 2.0
    max_chi2: float = 16.27
    max_cost_quantile: float = 0.999
    agreement_nodes: int = 12
    max_disagreement: float = 11.34
    max_innovation: float = 16.27
    fit_tolerance: float = 0.0
    min_correction: float = 7.81
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
        range_min_m, range_max_m, clear_no_return_m: how scans are added to maps (range
            limits, clearing), as for the robot's map.

    Attributes:
        closures: closures added to the graph.
        not_needed: closures found that the estimate already agreed with.
        waiting: closures found that no other of their revisit confirmed (yet).
        implausible: closures asking for more drift than the path allows.
        rejected: closures confirmed but dropped after the solve (inconsistent, or
            explaining the scans worse).
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
        self.loop_edges: list[bool] = []
        self.steps: list[FloatArray] = [np.zeros((3, 3))]  # node k's step covariance (its frame)
        self.recent: list[Edge] = []
        self.accepted: list[Edge] = []
        self.closures = 0
        self.rejected = 0
        self.waiting = 0
        self.implausible = 0
        self.not_needed = 0
        self._since_search = 0

    def add(
        self,
        pose: Pose,
        odom: Pose,
        ranges: npt.NDArray[np.float32],
        matched: bool,
        covariance: FloatArray | None = None,
    ) -> None:
        """A map update at ``pose`` (after matching) with its odometry and scan.

        ``covariance`` is the scan match's (``map`` axes), when it was matched: the step
        from the previous node is trusted as much as that match.
        """
        k = self.graph.add_node(pose)
        self.nodes.append(_Node(odom, np.asarray(ranges, dtype=np.float32).copy()))
        if k == 0:
            self.path_m.append(0.0)
            return
        previous = self.graph.nodes[k - 1]
        step = relative(previous, pose)
        self.path_m.append(self.path_m[-1] + math.hypot(step[0], step[1]))
        # what odometry says of the step, and (when it was matched) what the match says
        moved = relative(self.nodes[k - 1].odom, odom)
        info = np.linalg.inv(self._odometry_covariance(moved))
        if covariance is not None:
            info = info + np.linalg.inv(_in_frame(covariance, previous[2]))
        covariance_step = np.linalg.inv(info)
        self.steps.append(covariance_step)
        self.graph.add_edge(Edge(k - 1, k, step, 0.0, 0.0, sqrt_information(covariance_step)))
        self.loop_edges.append(False)

    def _odometry_covariance(self, moved: Pose) -> FloatArray:
        """The covariance of an odometry step ``moved`` (its own frame), from ``odometry_sigma``."""
        per_m, floor_m, per_rad, rad_per_m, floor_rad = self.params.odometry_sigma
        d = math.hypot(moved[0], moved[1])
        sigma_m = per_m * d + floor_m
        sigma_rad = per_rad * abs(moved[2]) + rad_per_m * d + floor_rad
        return np.diag([sigma_m**2, sigma_m**2, sigma_rad**2])

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
        pose, covariance = found
        edge = self._closure(nearest, k, pose, covariance)
        if not self._plausible(edge):  # more than the path since can have drifted
            self.implausible += 1
            return None
        recent = [c for c in self.recent if c.b >= k - p.agreement_nodes]
        partners = [c for c in recent if self._agree(c, edge)]
        self.recent = [*recent, edge]  # a partner for the revisit's next closures
        if self._correction(edge) < p.min_correction:
            self.not_needed += 1  # the estimate agrees already: nothing to correct
            return None
        if not partners:  # it enters only once another closure of the revisit agrees
            self.waiting += 1
            return None
        new = [edge, *(c for c in partners if all(c is not a for a in self.accepted))]
        cost_before = float(self.graph.residuals().sum())
        for closure in new:
            self.graph.add_edge(closure)
            self.loop_edges.append(True)
        solved = self.graph.optimize()
        consistent = self._consistent(self.graph.residuals(solved), cost_before, len(new))
        if not consistent or not self._explains_better(grid.geometry, edge, poses, solved):
            del self.graph.edges[-len(new) :]  # they disagree with the rest of the graph
            del self.loop_edges[-len(new) :]
            self.recent = [c for c in self.recent if c is not edge]
            self.rejected += 1
            return None
        self.accepted.extend(new)
        self.closures += len(new)
        shift = np.hypot(*(np.array(solved)[:, :2] - poses[:, :2]).T).max()
        self.graph.nodes = solved
        if shift > p.rebuild_shift_m:
            self._rebuild(grid)
        return solved[k]

    def _consistent(self, chi2: FloatArray, cost_before: float, added: int) -> bool:
        """Whether a solution's residuals (per edge, ``chi2``) accept the ``added`` closures.

        No closure's own residual beyond ``max_chi2``, and the graph's whole cost raised by
        at most the ``max_cost_quantile`` point of a chi-square with 3 per closure added.
        """
        p = self.params
        worst = float(chi2[np.array(self.loop_edges)].max())
        raised = float(chi2.sum()) - cost_before
        return worst <= p.max_chi2 and raised <= _chi2_quantile(3 * added, p.max_cost_quantile)

    def _explains_better(
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
        local = self._local_map(geometry, poses, old)
        reach = min(self.limits[1], self.params.matcher.max_range_m)
        total, count = 0.0, 0
        for j in recent:
            points = scan_points(self.angles, self.nodes[j].ranges, self.limits[0], reach, 120)
            total += local.fit(tuple(poses[j]), points) * len(points)
            count += len(points)
        return total / count if count else 0.0

    def _local_map(self, geometry: MapGeometry, poses: FloatArray, nodes: list[int]) -> LogOddsMap:
        """A map of ``nodes``' scans at ``poses``, reaching as far as they see."""
        r = geometry.resolution_m
        reach = min(self.limits[1], self.params.matcher.max_range_m)
        lo = poses[nodes, :2].min(axis=0) - reach
        hi = poses[nodes, :2].max(axis=0) + reach
        local = LogOddsMap(MapGeometry.covering((lo[0], lo[1], hi[0], hi[1]), r, 1.0))
        for j in nodes:
            self._integrate(local, tuple(poses[j]), self.nodes[j].ranges)
        return local

    def _plausible(self, edge: Edge) -> bool:
        """Whether the correction a closure asks for is one the path since could have drifted.

        The path from the old node to the new one is a chain of steps, each as sure as its
        odometry and scan match together; their covariances compound along the path
        (Smith, Self and Cheeseman's compounding of uncertain transformations). A closure
        that moves the new node further from where the chain puts it than the chain's and
        the closure's uncertainty allow (Mahalanobis, ``max_innovation``) asks for a drift
        that did not happen: it matched another place that looks the same.
        """
        chain = self._chain_covariance(edge.a, edge.b)
        x = self.graph.nodes
        predicted = relative(x[edge.a], x[edge.b])
        innovation = np.array(
            [
                edge.z[0] - predicted[0],
                edge.z[1] - predicted[1],
                wrap_angle(edge.z[2] - predicted[2]),
            ]
        )
        total = chain + _covariance(edge)
        return float(innovation @ np.linalg.solve(total, innovation)) <= self.params.max_innovation

    def _correction(self, edge: Edge) -> float:
        """How far (Mahalanobis, the closure's own covariance) the closure would move its node."""
        x = self.graph.nodes
        predicted = relative(x[edge.a], x[edge.b])
        innovation = np.array(
            [
                edge.z[0] - predicted[0],
                edge.z[1] - predicted[1],
                wrap_angle(edge.z[2] - predicted[2]),
            ]
        )
        w = edge.whitening() @ innovation
        return float(w @ w)

    def _chain_covariance_map(self, a: int, b: int) -> FloatArray:
        """The covariance of the later node's pose relative to the earlier one's, ``map`` axes."""
        first, last = min(a, b), max(a, b)
        if first == last:
            return np.zeros((3, 3))
        return _in_frame(self._chain_covariance(first, last), -self.graph.nodes[first][2])

    def _chain_covariance(self, a: int, b: int) -> FloatArray:
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
        return _in_frame(covariance, float(x[0, 2]))

    def _agree(self, first: Edge, second: Edge) -> bool:
        """Whether two closures imply the same pose of the newer one's node (pairwise consistent).

        The first closure and the estimated path from its node to the second's predict where
        the second's node is; the second closure says it directly. The two must agree within
        their uncertainties (Mahalanobis, ``max_disagreement``), as in pairwise consistency
        maximization (Mangelson et al., "Pairwise Consistent Measurement Set Maximization
        for Robust Multi-robot Map Merging", ICRA 2018).
        """
        x = self.graph.nodes
        path = relative(x[first.b], x[second.b])
        implied_first = compose(x[first.a], first.z)
        via_first = compose(implied_first, path)
        via_second = compose(x[second.a], second.z)
        yaw = implied_first[2]
        lever = np.array(
            [
                -math.sin(yaw) * path[0] - math.cos(yaw) * path[1],
                math.cos(yaw) * path[0] - math.sin(yaw) * path[1],
            ]
        )
        jac = np.eye(3)
        jac[:2, 2] = lever
        first_cov = _in_frame(_covariance(first), -x[first.a][2])
        second_cov = _in_frame(_covariance(second), -x[second.a][2])
        chains = self._chain_covariance_map(first.b, second.b) + self._chain_covariance_map(
            first.a, second.a
        )
        total = jac @ first_cov @ jac.T + second_cov + chains
        e = np.array(
            [
                via_first[0] - via_second[0],
                via_first[1] - via_second[1],
                wrap_angle(via_first[2] - via_second[2]),
            ]
        )
        return float(e @ np.linalg.solve(total, e)) <= self.params.max_disagreement

    def _closure(self, a: int, b: int, pose: Pose, covariance: FloatArray) -> Edge:
        """The edge of a loop closure: node ``b`` matched at ``pose`` (``map``) near node ``a``.

        The match's covariance (``map`` axes) is turned into node ``a``'s frame, and a
        direction the match cannot tell (a corridor) is made to constrain nothing.
        """
        p = self.params
        local = _in_frame(covariance, self.graph.nodes[a][2])
        values, vectors = np.linalg.eigh(local[:2, :2])
        values = np.where(np.sqrt(values) > p.ambiguous_m, p.ambiguous_sigma_m**2, values)
        local[:2, :2] = vectors @ np.diag(values) @ vectors.T
        local[:2, 2] = local[2, :2] = 0.0  # the spread's coupling is not trusted
        z = relative(self.graph.nodes[a], pose)
        return Edge(a, b, z, 0.0, 0.0, sqrt_information(local))

    def _match(
        self, geometry: MapGeometry, poses: FloatArray, chosen: list[int], k: int
    ) -> tuple[Pose, FloatArray] | None:
        """Node ``k``'s pose in a map of the chosen old nodes and its covariance, if it matches."""
        reach = min(self.limits[1], self.params.matcher.max_range_m)
        local = self._local_map(geometry, poses, chosen)
        points = scan_points(
            self.angles, self.nodes[k].ranges, self.limits[0], reach, self.params.matcher.max_points
        )
        result = match(local, tuple(poses[k]), points, self.params.matcher)
        if not result.matched:
            return None
        return result.pose, match_covariance(local, result.pose, points, self.params.response)

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


def _chi2_quantile(dof: int, quantile: float) -> float:
    """The ``quantile`` point of a chi-square with ``dof`` degrees of freedom."""
    return float(chi_square.ppf(quantile, dof))


def _in_frame(covariance: FloatArray, yaw: float) -> FloatArray:
    """A covariance in ``map`` axes turned into the axes of a node at heading ``yaw``."""
    c, s = math.cos(yaw), math.sin(yaw)
    rotate = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    turned: FloatArray = rotate @ covariance @ rotate.T
    return turned


def _covariance(edge: Edge) -> FloatArray:
    """An edge's covariance (its frame), from its square-root information."""
    root = edge.whitening()
    covariance: FloatArray = np.asarray(np.linalg.inv(root.T @ root), dtype=np.float64)
    return covariance
