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

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.geometry.se2 import Pose
from models.mapping.closure_checks import ClosureChecks
from models.mapping.grid import LogOddsMap
from models.mapping.loop_params import LoopParams
from models.mapping.loop_search import LoopSearch
from models.mapping.posegraph import Edge
from models.mapping.update_graph import UpdateGraph


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
