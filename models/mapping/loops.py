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
close loops this way; what a wrong closure costs (a bent map) makes the loop closer check a
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
:class:`LoopCloser` composes the parts: the graph of map updates
(:mod:`models.mapping.update_graph`), the search and the check on the scans
(:mod:`models.mapping.loop_search`) and the checks 1-4 (:mod:`models.mapping.closure_checks`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.geometry.se2 import Pose
from models.mapping.closure_checks import ClosureChecks
from models.mapping.grid import LogOddsMap
from models.mapping.loop_search import LoopSearch
from models.mapping.matcher import MatcherParams
from models.mapping.posegraph import Edge
from models.mapping.uncertainty import ResponseWindow
from models.mapping.update_graph import UpdateGraph


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


class LoopCloser:
    """The pose graph of one robot's map updates, and its loop closures.

    Args:
        params: search settings.
        angles_rad: the lidar's beam angles.
        range_min_m, range_max_m, clear_no_return_m: how scans are added to maps (range
            limits, clearing), as for the robot's map.

    Attributes:
        updates: the graph of map updates (:class:`~models.mapping.update_graph.UpdateGraph`).
        graph: its pose graph (the nodes' ``map`` poses after the last solve kept).
        nodes: its nodes' odometry poses and scans.
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
        self.updates = UpdateGraph(params)
        self.graph = self.updates.graph
        self.nodes = self.updates.nodes
        limits = (range_min_m, range_max_m, clear_no_return_m)
        self.search = LoopSearch(params, angles_rad, self.updates, limits)
        self.checks = ClosureChecks(self.updates, params)
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
        self.updates.add(pose, odom, ranges, covariance)

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
        candidates = self.search.candidates(poses, k)
        if candidates is None:
            return None
        nearest, chosen = candidates
        found = self.search.match(grid.geometry, poses, chosen, k)
        if found is None:
            return None
        pose, covariance = found
        edge = self.updates.closure(nearest, k, pose, covariance)
        checks = self.checks
        if not checks.plausible(edge):  # more than the path since can have drifted
            self.implausible += 1
            return None
        recent = [c for c in self.recent if c.b >= k - p.agreement_nodes]
        partners = [c for c in recent if checks.agree(c, edge)]
        self.recent = [*recent, edge]  # a partner for the revisit's next closures
        if checks.correction(edge) < p.min_correction:
            self.not_needed += 1  # the estimate agrees already: nothing to correct
            return None
        if not partners:  # it enters only once another closure of the revisit agrees
            self.waiting += 1
            return None
        new = [edge, *(c for c in partners if all(c is not a for a in self.accepted))]
        cost_before = float(self.graph.residuals().sum())
        solved = self.updates.solve_with(new)
        consistent = checks.consistent(self.graph.residuals(solved), cost_before, len(new))
        if not consistent or not self.search.explains_better(grid.geometry, edge, poses, solved):
            self.updates.drop(len(new))  # they disagree with the rest of the graph
            self.recent = [c for c in self.recent if c is not edge]
            self.rejected += 1
            return None
        self.accepted.extend(new)
        self.closures += len(new)
        shift = np.hypot(*(np.array(solved)[:, :2] - poses[:, :2]).T).max()
        self.graph.nodes = solved
        if shift > p.rebuild_shift_m:
            self.search.rebuild(grid)
        return solved[k]
