"""Records of mapping: pose errors per update, merges, map quality over time, final maps.

Tables:

- ``map_quality``: every ``mapping.quality_period_s``, per robot and for the ``fleet``:
  coverage, iou, accuracy, iou_strict (:mod:`models.mapping.quality`) against the world's ground
  truth on the same grid, and ``ate_m`` / ``ate_odom_m``, the RMS position error of the
  estimate / of odometry alone over the updates so far (m; one common ``map`` frame, so
  no alignment). The fleet's map is every robot's map fused (log-odds summed,
  :func:`models.mapping.grid.merged`): bookkeeping, no robot sees it.
- ``scan_matches``: one row per map update: the estimated pose, its error and the error
  of odometry alone against ground truth (m), the match score and whether it matched.
- ``map_merges``: one row per scan or map update a robot added from a neighbour: its
  size, its delay from the sender's stamp (s) and the cells it changed.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from cosim.core.recorder import Recorder
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S
from cosim.core.workers import Spread, in_turn
from models.geometry.occupancy import OccupancyGrid, rasterize_boxes
from models.mapping.grid import LogOddsMap, MapGeometry
from models.mapping.quality import MapScores, map_scores, observable
from models.world.warehouse import Warehouse

MAPPING_SUMMARY: Mapping[str, SummaryKey] = {
    "map_coverage": SummaryKey(
        "fraction", "the fleet's map at the end: share of the observable cells it knows"
    ),
    "map_iou": SummaryKey(
        "fraction",
        "the fleet's map at the end: occupied cells against the truth over the explored "
        "area, one cell of tolerance (intersection over union)",
    ),
    "map_accuracy": SummaryKey(
        "fraction", "the fleet's map at the end: share of the known cells right"
    ),
    "map_iou_strict": SummaryKey("fraction", "map_iou without the cell of tolerance"),
    "map_ate_m": SummaryKey(
        "m", "RMS position error of the robots' estimated poses over every map update"
    ),
    "map_ate_odom_m": SummaryKey("m", "RMS position error of odometry alone over the same updates"),
    "map_updates": SummaryKey("count", "scans integrated into the robots' maps"),
    "map_matched_share": SummaryKey(
        "fraction", "of the map updates, those whose scan match was accepted (null: none)"
    ),
    "map_share_messages": SummaryKey("count", "scans or map updates sent to neighbours"),
    "map_share_bytes": SummaryKey("bytes", "wire size of those messages, summed"),
    "map_merges": SummaryKey("count", "scans or map updates a robot added from a neighbour"),
    "map_merge_delay_s_mean": SummaryKey(
        "s", "time from the sender's stamp to the merge, mean (null: no merge)"
    ),
}
"""The summary keys :meth:`MappingRecords.summary` writes (the fleet's map scores are null
before its first quality sample)."""

MAP_QUALITY = TableSpec(
    "map_quality",
    "Every robot's map against the ground truth, and the fleet's (its maps fused), over time.",
    {
        "t_s": "when (s)",
        "robot": "the robot, or fleet",
        "coverage": "share of the observable cells the map knows (0-1)",
        "iou": "occupied cells against the truth over the explored area, one cell of tolerance",
        "accuracy": "share of the known cells right about free or occupied (0-1)",
        "ate_m": "RMS of the pose estimate's position error so far (m)",
        "ate_odom_m": "the same for odometry alone (m)",
        "iou_strict": "iou without the cell of tolerance",
    },
    categorical=("robot",),
    units={
        "coverage": "fraction",
        "iou": "fraction",
        "accuracy": "fraction",
        "iou_strict": "fraction",
    },
)
QUALITY_COLUMNS = tuple(MAP_QUALITY.columns)
SCAN_MATCHES = TableSpec(
    "scan_matches",
    "One row per map update of a robot: where scan matching put it, and how wrong that is.",
    {
        "t_s": "when (s)",
        "robot": "the robot",
        "x_m": "the pose estimate's x in map (m)",
        "y_m": "its y in map (m)",
        "yaw_rad": "its heading (rad)",
        "error_m": "distance of the estimate from the true position (m)",
        "odom_error_m": "distance of odometry alone from the true position (m)",
        "score": "the match's score (share of the scan's points on occupied cells)",
        "matched": "whether the match was accepted (else odometry was kept)",
    },
    categorical=("robot",),
    units={"score": "fraction"},
)
MATCH_COLUMNS = tuple(SCAN_MATCHES.columns)
MAP_MERGES = TableSpec(
    "map_merges",
    "One row per neighbour's scan or map a robot added to its own (mapping.share).",
    {
        "t_s": "when it was added (s)",
        "robot": "the robot that added it",
        "source": "the neighbour that sent it",
        "kind": "scan or map",
        "bytes": "its size on the wire (bytes)",
        "delay_s": "time from sending to adding (s)",
        "cells": "cells of the robot's map it changed",
    },
    categorical=("robot", "source", "kind"),
    units={"bytes": "bytes", "cells": "count"},
)
MERGE_COLUMNS = tuple(MAP_MERGES.columns)
FLEET = "fleet"


def _rms(values: list[float]) -> float:
    return math.sqrt(float(np.mean(np.square(values)))) if values else math.nan


class MappingRecords:
    """The mapping tables and the statistics behind the mapping summary.

    Args:
        recorder: the run's recorder.
        names: robot names, by index.
        world: the warehouse (its boxes are the ground truth).
        geometry: the maps' common grid.
    """

    def __init__(
        self, recorder: Recorder, names: list[str], world: Warehouse, geometry: MapGeometry
    ) -> None:
        self.names = names
        self.quality = recorder.table(MAP_QUALITY)
        self.matches = recorder.table(SCAN_MATCHES)
        self.merges = recorder.table(MAP_MERGES)
        x0, y0 = geometry.origin_xy_m
        r = geometry.resolution_m
        extent = (x0, y0, x0 + geometry.width * r, y0 + geometry.height * r)
        self.truth = rasterize_boxes(world.boxes, extent, r).data
        xs = x0 + (np.arange(geometry.width) + 0.5) * r
        ys = y0 + (np.arange(geometry.height) + 0.5) * r
        wx, wy = world.size_m
        room = ((ys >= 0) & (ys <= wy))[:, None] & ((xs >= 0) & (xs <= wx))[None, :]
        self.seen = observable(self.truth, room)
        self.errors: list[list[float]] = [[] for _ in names]
        self.odom_errors: list[list[float]] = [[] for _ in names]
        self.updates = 0
        self.matched = 0
        self.merged = 0
        self.merge_delays: list[float] = []
        self.shared_messages = 0
        self.shared_bytes = 0
        self.last: dict[str, MapScores] = {}

    def update(
        self,
        t_ns: int,
        robot: int,
        pose: tuple[float, float, float],
        truth: tuple[float, float],
        odom: tuple[float, float],
        score: float,
        matched: bool,
    ) -> None:
        """A robot's map update at ``pose``; ``truth`` and ``odom`` are positions in ``map``."""
        error = math.hypot(pose[0] - truth[0], pose[1] - truth[1])
        odom_error = math.hypot(odom[0] - truth[0], odom[1] - truth[1])
        self.errors[robot].append(error)
        self.odom_errors[robot].append(odom_error)
        self.updates += 1
        self.matched += int(matched)
        self.matches.append(
            t_s=t_ns / NS_PER_S,
            robot=self.names[robot],
            x_m=pose[0],
            y_m=pose[1],
            yaw_rad=pose[2],
            error_m=error,
            odom_error_m=odom_error,
            score=score,
            matched=matched,
        )

    def merge(
        self, t_ns: int, robot: int, source: str, kind: str, nbytes: int, sent_ns: int, cells: int
    ) -> None:
        """A robot added a neighbour's ``kind`` ("scan" or "map") sent at ``sent_ns``."""
        delay = (t_ns - sent_ns) / NS_PER_S
        self.merged += 1
        self.merge_delays.append(delay)
        self.merges.append(
            t_s=t_ns / NS_PER_S,
            robot=self.names[robot],
            source=source,
            kind=kind,
            bytes=nbytes,
            delay_s=delay,
            cells=cells,
        )

    def shared(self, nbytes: int) -> None:
        """A robot published ``nbytes`` of mapping data to its neighbours."""
        self.shared_messages += 1
        self.shared_bytes += nbytes

    def sample(
        self,
        t_ns: int,
        maps: list[LogOddsMap],
        fleet: OccupancyGrid,
        spread: Spread = in_turn,
    ) -> None:
        """A row per robot and one for the fleet (its maps fused): quality now.

        Args:
            t_ns: now (ns).
            maps: every robot's map.
            fleet: the fleet's fused map.
            spread: runs the maps' scoring (``spread(fn, items)``, results in order), e.g.
                on the run's threads; the rows are the same.
        """
        t_s = t_ns / NS_PER_S
        every: list[float] = []
        every_odom: list[float] = []

        def score(k: int) -> MapScores:
            cells = maps[k].occupancy() if k < len(maps) else fleet.data
            return map_scores(cells, self.truth, self.seen)

        scores = spread(score, range(len(maps) + 1))
        for i in range(len(maps)):
            self._row(t_s, self.names[i], scores[i], self.errors[i], self.odom_errors[i])
            every += self.errors[i]
            every_odom += self.odom_errors[i]
        self._row(t_s, FLEET, scores[-1], every, every_odom)

    def _row(
        self, t_s: float, robot: str, scores: MapScores, errors: list[float], odom: list[float]
    ) -> None:
        self.last[robot] = scores
        self.quality.append(
            t_s=t_s,
            robot=robot,
            coverage=scores.coverage,
            iou=scores.iou,
            accuracy=scores.accuracy,
            ate_m=_rms(errors),
            ate_odom_m=_rms(odom),
            iou_strict=scores.iou_strict,
        )

    def summary(self) -> dict[str, Any]:
        """Final map quality of the fleet, trajectory errors, updates and sharing."""
        fleet = self.last.get(FLEET)
        every = [e for errors in self.errors for e in errors]
        every_odom = [e for errors in self.odom_errors for e in errors]

        def rounded(value: float) -> float | None:
            return round(value, 6) if math.isfinite(value) else None

        return {
            "map_coverage": rounded(fleet.coverage) if fleet else None,
            "map_iou": rounded(fleet.iou) if fleet else None,
            "map_accuracy": rounded(fleet.accuracy) if fleet else None,
            "map_iou_strict": rounded(fleet.iou_strict) if fleet else None,
            "map_ate_m": rounded(_rms(every)),
            "map_ate_odom_m": rounded(_rms(every_odom)),
            "map_updates": self.updates,
            "map_matched_share": rounded(self.matched / self.updates) if self.updates else None,
            "map_share_messages": self.shared_messages,
            "map_share_bytes": self.shared_bytes,
            "map_merges": self.merged,
            "map_merge_delay_s_mean": rounded(float(np.mean(self.merge_delays)))
            if self.merge_delays
            else None,
        }
