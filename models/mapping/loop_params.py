"""When and how a robot searches, verifies and accepts loop closures (the parameters)."""

from __future__ import annotations

from dataclasses import dataclass, field

from models.mapping.matcher import MatcherParams
from models.mapping.uncertainty import ResponseWindow


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
