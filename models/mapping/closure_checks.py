"""The acceptance tests of a loop closure, before and after it enters the pose graph.

A wrong closure bends the whole map, so a closure found by the search is checked against
the graph of map updates (:class:`~models.mapping.update_graph.UpdateGraph`):

1. *plausible*: the correction it asks for is one the path since could have drifted
   (the steps' covariances compounded along it, Smith, Self and Cheeseman 1990);
2. *needed*: the current estimate disagrees with it (else it adds only its own error);
3. *confirmed*: another closure of the same revisit agrees with it (pairwise
   consistency, Mangelson et al., ICRA 2018);
4. *consistent*: after the solve no closure's residual is beyond the chi-square gate, and
   the graph's whole cost is raised by no more than the closures added can explain
   (Graham, How and Gustafson, IROS 2015).

The fifth check, that the solve explains the recent scans better, is made on maps of
scans (:meth:`models.mapping.loop_search.LoopSearch.explains_better`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from scipy.stats import chi2 as chi_square

from models.arrays import FloatArray
from models.geometry.angles import wrap_angle
from models.geometry.se2 import compose, relative
from models.mapping.posegraph import Edge
from models.mapping.update_graph import UpdateGraph, in_frame

if TYPE_CHECKING:
    from models.mapping.loop_params import LoopParams


class ClosureChecks:
    """Whether a loop closure is plausible, needed, confirmed, and consistent after a solve.

    Args:
        updates: the graph of map updates the closures are checked against (read at each
            check: its current estimates).
        params: the loop settings (``max_innovation``, ``max_disagreement``, ``max_chi2``
            and ``max_cost_quantile`` are read here).
    """

    def __init__(self, updates: UpdateGraph, params: LoopParams) -> None:
        self.updates = updates
        self.params = params

    def plausible(self, edge: Edge) -> bool:
        """Whether the correction a closure asks for is one the path since could have drifted.

        The path from the old node to the new one is a chain of steps, each as sure as its
        odometry and scan match together; their covariances compound along the path
        (Smith, Self and Cheeseman's compounding of uncertain transformations). A closure
        that moves the new node further from where the chain puts it than the chain's and
        the closure's uncertainty allow (Mahalanobis, ``max_innovation``) asks for a drift
        that did not happen: it matched another place that looks the same.
        """
        chain = self.updates.chain_covariance(edge.a, edge.b)
        x = self.updates.graph.nodes
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

    def correction(self, edge: Edge) -> float:
        """How far (Mahalanobis, the closure's own covariance) the closure would move its node.

        A closure is needed only when this is at least ``min_correction``.
        """
        x = self.updates.graph.nodes
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

    def agree(self, first: Edge, second: Edge) -> bool:
        """Whether two closures imply the same pose of the newer one's node (pairwise consistent).

        The first closure and the estimated path from its node to the second's predict where
        the second's node is; the second closure says it directly. The two must agree within
        their uncertainties (Mahalanobis, ``max_disagreement``), as in pairwise consistency
        maximization (Mangelson et al., "Pairwise Consistent Measurement Set Maximization
        for Robust Multi-robot Map Merging", ICRA 2018).
        """
        updates = self.updates
        x = updates.graph.nodes
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
        first_cov = in_frame(_covariance(first), -x[first.a][2])
        second_cov = in_frame(_covariance(second), -x[second.a][2])
        chains = updates.chain_covariance_map(first.b, second.b) + updates.chain_covariance_map(
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

    def consistent(self, chi2: FloatArray, cost_before: float, added: int) -> bool:
        """Whether a solution's residuals (per edge, ``chi2``) accept the ``added`` closures.

        No closure's own residual beyond ``max_chi2``, and the graph's whole cost raised by
        at most the ``max_cost_quantile`` point of a chi-square with 3 per closure added.
        """
        p = self.params
        worst = float(chi2[np.array(self.updates.loop_edges)].max())
        raised = float(chi2.sum()) - cost_before
        return worst <= p.max_chi2 and raised <= _chi2_quantile(3 * added, p.max_cost_quantile)


def _chi2_quantile(dof: int, quantile: float) -> float:
    """The ``quantile`` point of a chi-square with ``dof`` degrees of freedom."""
    return float(chi_square.ppf(quantile, dof))


def _covariance(edge: Edge) -> FloatArray:
    """An edge's covariance (its frame), from its square-root information."""
    root = edge.whitening()
    covariance: FloatArray = np.asarray(np.linalg.inv(root.T @ root), dtype=np.float64)
    return covariance
