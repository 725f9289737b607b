"""The robots' mapping run on a recording (a user's own robot, a dataset): ``cosim map``.

The same models as in the simulation (:mod:`models.mapping`): each scan is paired with
the odometry interpolated at its stamp, gated, matched against the map built so far,
and added. The map frame is the odometry frame at the first scan. With a reference
topic, the absolute trajectory error (RMS after rigid SE(2) alignment) of odometry and
of the estimate is measured. :mod:`cosim.cli.bagmap` writes the results into a folder.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd

from adapters.mapping.recording import (
    Recording,
    read_recording,
)
from cosim.core.errors import BagError
from cosim.core.summary import SummaryKey
from models.geometry.se2 import compose, relative
from models.mapping.grid import MAX_CELLS, LogOddsMap, MapGeometry
from models.mapping.loop_params import LoopParams
from models.mapping.loops import LoopCloser
from models.mapping.matcher import MatcherParams
from models.mapping.quality import align_se2, ate_rmse
from models.mapping.slam import MapperParams, ScanMapper, UpdateGate

MAP_REACH_M = 30.0
"""The map reaches this far beyond the odometry's extent (m); returns beyond fall off."""
RESOLUTION_M = (0.01, 1.0)
"""The cell sizes ``cosim map`` takes (m): finer than a 2D lidar's centimetre noise maps
nothing more, and a cell coarser than the matcher's 0.3 m window leaves nothing to match."""
Progress = Callable[[float, float, float], None]
"""(recording time processed s, recording duration s, wall s)."""
_WITH_REFERENCE = "a reference topic is given (--reference) with 2 poses or more"
SUMMARY_KEYS: Mapping[str, SummaryKey] = {
    "bag": SummaryKey("text", "the recording mapped"),
    "scans": SummaryKey("count", "scans mapped"),
    "scans_outside_odometry": SummaryKey(
        "count", "scans outside the odometry's time span, left out"
    ),
    "map_updates": SummaryKey("count", "scans that updated the map"),
    "matched": SummaryKey("count", "of those, updates whose scan match moved the pose"),
    "loop_closures": SummaryKey("count", "loop closures added to the pose graph"),
    "loop_closures_not_needed": SummaryKey(
        "count", "verified loop closures left out: the estimate agreed already"
    ),
    "recording_s": SummaryKey("s", "time the recording's scans span"),
    "wall_time_s": SummaryKey("s", "wall-clock time the mapping took", volatile=True),
    "real_time_factor": SummaryKey(
        "ratio", "recording seconds mapped per wall-clock second", volatile=True
    ),
    "ate_m": SummaryKey(
        "m",
        "RMS position error of the estimate against the reference, aligned",
        when=_WITH_REFERENCE,
    ),
    "ate_odom_m": SummaryKey("m", "the same of the odometry alone", when=_WITH_REFERENCE),
    "reference_poses": SummaryKey(
        "count", "reference poses the errors are measured at", when=_WITH_REFERENCE
    ),
}
"""The keys of the ``summary.json`` that ``cosim map`` writes (:attr:`RecordingMap.summary`)."""


@dataclass
class RecordingMap:
    """A recording mapped.

    Attributes:
        grid: the map built (frame ``map``: the odometry frame at the first scan).
        summary: counts, timings and trajectory errors.
        trajectory: t_s, x_m, y_m, yaw_rad per scan (the estimate, frame ``map``).
        estimate_xy_m: (scans, 2) the estimated positions (m, ``map``).
        odometry_xy_m: (scans, 2) the odometry's positions (m, ``map``).
        reference_xy_m: (poses, 2) the reference aligned onto the estimate, if one was given.
    """

    grid: LogOddsMap = field(repr=False)
    summary: dict[str, Any]
    trajectory: pd.DataFrame = field(repr=False)
    estimate_xy_m: npt.NDArray[np.float64] = field(repr=False)
    odometry_xy_m: npt.NDArray[np.float64] = field(repr=False)
    reference_xy_m: npt.NDArray[np.float64] | None = field(default=None, repr=False)


def map_recording(
    bag: Path,
    *,
    scan_topic: str = "/scan",
    odom_topic: str = "/odom",
    reference_topic: str | None = None,
    resolution_m: float = 0.05,
    gate: UpdateGate | None = None,
    matcher: MatcherParams | None = None,
    scan_matching: bool = True,
    loop_closure: bool = True,
    clear_no_return_m: float = 3.0,
    progress: Progress | None = None,
) -> RecordingMap:
    """Map a recorded bag: :func:`read_recording`, then :func:`map_scans`.

    Raises:
        BagError: as :func:`read_recording`, or odometry spanning more than a map of
            :data:`~models.mapping.grid.MAX_CELLS` cells at ``resolution_m`` (one line
            naming the topic, the extent and the cell size that would fit).
        ValueError: ``resolution_m`` outside :data:`RESOLUTION_M`.
    """
    low, high = RESOLUTION_M
    if not low <= resolution_m <= high:
        raise ValueError(f"resolution_m {resolution_m!r}: expected {low:g} to {high:g} m")
    recording = read_recording(
        bag, scan_topic=scan_topic, odom_topic=odom_topic, reference_topic=reference_topic
    )
    reach = min(recording.range_max_m, MAP_REACH_M)
    if too_large := _oversize(recording.odometry, reach, resolution_m, "--resolution-m"):
        raise BagError(f"{recording.bag}: --odom {odom_topic} {too_large}")
    mapped = map_scans(
        recording.stamps_ns,
        recording.ranges_m,
        recording.odometry,
        recording.angles_rad,
        range_min_m=recording.range_min_m,
        range_max_m=recording.range_max_m,
        resolution_m=resolution_m,
        gate=gate,
        matcher=matcher,
        scan_matching=scan_matching,
        loop_closure=loop_closure,
        clear_no_return_m=clear_no_return_m,
        progress=progress,
    )
    return _result(recording, mapped)


@dataclass
class MappedScans:
    """Scans mapped, before any reference is compared.

    Attributes:
        grid: the map built (frame ``map``: the odometry frame at the first scan).
        rows: per scan (t_ns, estimated x m, y m, yaw rad, odometry x m, y m, yaw rad,
            the pose graph's node it belongs to or -1); after loop closure, the estimate
            is the final graph's.
        mapper: the mapper, with its counts and pose graph.
        wall_s: the processing time (s).
        span_s: the scans' time span (s).
    """

    grid: LogOddsMap = field(repr=False)
    rows: list[tuple[float, ...]] = field(repr=False)
    mapper: ScanMapper = field(repr=False)
    wall_s: float
    span_s: float

    def estimate_xy_m(self) -> npt.NDArray[np.float64]:
        """(scans, 2) the estimated positions (m, ``map``)."""
        return np.array([row[1:3] for row in self.rows], dtype=np.float64).reshape(-1, 2)


def map_scans(
    stamps_ns: npt.ArrayLike,
    ranges: npt.ArrayLike,
    odometry: npt.ArrayLike,
    angles_rad: npt.ArrayLike,
    *,
    range_min_m: float,
    range_max_m: float,
    resolution_m: float = 0.05,
    gate: UpdateGate | None = None,
    matcher: MatcherParams | None = None,
    scan_matching: bool = True,
    loop_closure: bool | LoopParams = True,
    clear_no_return_m: float = 3.0,
    progress: Progress | None = None,
) -> MappedScans:
    """Map scans given with the odometry at each one's stamp: what ``cosim map`` does to a bag.

    Args:
        stamps_ns: (scans,) each scan's time (ns), increasing.
        ranges: (scans, beams) each scan's ranges (m).
        odometry: (scans, 3) the odometry pose (x m, y m, yaw rad; frame ``odom``) at
            each scan.
        angles_rad: (beams,) the beams' angles in the sensor frame (rad).
        range_min_m: shorter readings are invalid (m).
        range_max_m: the lidar's maximum range (m): readings at it are no return (REP 117).
        resolution_m: the map's cell size (m).
        gate: when a scan updates the map (default: slam_toolbox's).
        matcher: the scan-to-map matcher's settings.
        scan_matching: False keeps odometry only.
        loop_closure: True for :class:`~models.mapping.loops.LoopParams`' defaults, False
            for none, or the settings to use (needs scan matching).
        clear_no_return_m: beams without a return clear the map up to this far (m).
        progress: called every 20 scans with (time processed s, span s, wall s).
    """
    stamps = np.asarray(stamps_ns, dtype=np.int64).reshape(-1)
    scans = np.asarray(ranges, dtype=np.float32)
    poses = np.asarray(odometry, dtype=np.float64).reshape(-1, 3)
    angles = np.asarray(angles_rad, dtype=np.float64).reshape(-1)
    if not len(stamps) == len(scans) == len(poses) > 0 or scans.shape[1:] != angles.shape:
        raise ValueError(
            f"{len(stamps)} stamps, ranges of shape {scans.shape}, {len(poses)} odometry poses "
            f"and {len(angles)} angles; expected as many stamps, scans and poses (at least "
            "one) and a range per angle"
        )
    _check_arguments(poses, angles, range_min_m, range_max_m, resolution_m, clear_no_return_m)
    reach = min(range_max_m, MAP_REACH_M)
    if too_large := _oversize(poses, reach, resolution_m, "resolution_m"):
        raise ValueError(f"the odometry {too_large}")
    lo, hi = poses[:, :2].min(axis=0), poses[:, :2].max(axis=0)
    geometry = MapGeometry.covering((lo[0], lo[1], hi[0], hi[1]), resolution_m, reach)
    matcher = matcher or MatcherParams()
    grid = LogOddsMap(geometry, hit_centroids=matcher.refine_against == "walls")
    # readings at the maximum are no return (REP 117, and CARMEN logs' clip value)
    limit_m = range_max_m * 0.999
    far_m = 2.0 * math.hypot(geometry.width, geometry.height) * resolution_m
    if limit_m > far_m:  # never with a real lidar: far_m >= 170 m once range_max >= 30 m
        scans, limit_m = _returns_within(scans, limit_m, far_m), far_m
    loops = LoopParams() if loop_closure is True else (loop_closure or None)
    params = MapperParams(
        gate=gate or UpdateGate(),
        matcher=matcher,
        scan_matching=scan_matching,
        range_min_m=range_min_m,
        range_max_m=limit_m,
        clear_no_return_m=clear_no_return_m,
        loop_closure=loops if scan_matching else None,
    )
    x0, y0, yaw0 = poses[0]
    mapper = ScanMapper(grid, (float(x0), float(y0), float(yaw0)), params, angles)
    rows: list[tuple[float, ...]] = []
    t0 = int(stamps[0])
    span_s = max(1e-9, (int(stamps[-1]) - t0) / 1e9)
    start = time.perf_counter()
    for n, (t_ns, beams, pose) in enumerate(zip(stamps, scans, poses, strict=True)):
        at = (float(pose[0]), float(pose[1]), float(pose[2]))
        mapper.process(int(t_ns), at, beams)
        node = len(mapper.loops.nodes) - 1 if mapper.loops is not None else -1
        rows.append((int(t_ns), *mapper.estimate(at), *at, node))
        if progress is not None and n % 20 == 0:
            progress((int(t_ns) - t0) / 1e9, span_s, time.perf_counter() - start)
    if mapper.loops is not None:
        rows = _smoothed(rows, mapper.loops)
    wall_s = time.perf_counter() - start
    if progress is not None:
        progress(span_s, span_s, wall_s)
    return MappedScans(grid, rows, mapper, wall_s, span_s)


def _check_arguments(
    poses: npt.NDArray[np.float64],
    angles: npt.NDArray[np.float64],
    range_min_m: float,
    range_max_m: float,
    resolution_m: float,
    clear_no_return_m: float,
) -> None:
    """:func:`map_scans`' arguments usable, else a ValueError naming the first that is not."""
    if not np.isfinite(poses).all():
        raise ValueError(f"odometry pose {np.argwhere(~np.isfinite(poses))[0][0]} is not finite")
    if not np.isfinite(angles).all():
        raise ValueError("angles_rad: expected finite angles (rad)")
    if not (math.isfinite(range_min_m) and range_min_m >= 0 and range_max_m > range_min_m):
        raise ValueError(
            f"range_min_m {range_min_m!r}, range_max_m {range_max_m!r}: expected 0 <= "
            "range_min_m < range_max_m"
        )
    if not (math.isfinite(resolution_m) and resolution_m > 0):
        raise ValueError(f"resolution_m {resolution_m!r}: expected a cell size > 0 (m)")
    if not (math.isfinite(clear_no_return_m) and clear_no_return_m >= 0):
        raise ValueError(f"clear_no_return_m {clear_no_return_m!r}: expected a length >= 0 (m)")


def _oversize(
    poses: npt.NDArray[np.float64], reach_m: float, resolution_m: float, flag: str
) -> str | None:
    """Why the map around ``poses`` (m) would be too large at ``resolution_m``, or None.

    The map covers the poses and ``reach_m`` all round (as :func:`map_scans` builds it);
    it may hold :data:`~models.mapping.grid.MAX_CELLS` cells (100 MB of log-odds).
    """
    lo, hi = poses[:, :2].min(axis=0), poses[:, :2].max(axis=0)
    span = (float(hi[0] - lo[0]) + 2 * reach_m, float(hi[1] - lo[1]) + 2 * reach_m)

    def cells(resolution: float) -> tuple[int, int]:
        return math.ceil(span[0] / resolution), math.ceil(span[1] / resolution)

    width, height = cells(resolution_m)
    if width * height <= MAX_CELLS:
        return None
    steps = np.hypot(*np.diff(poses[:, :2], axis=0).T) if len(poses) > 1 else np.zeros(1)
    jump = int(np.argmax(steps))
    fits = max(resolution_m, math.sqrt(span[0] * span[1] / MAX_CELLS))
    while math.prod(cells(fits)) > MAX_CELLS:
        fits *= 1.001
    coarser = (
        f"{flag} {math.ceil(fits * 1000) / 1000:g} or more fits"
        if fits <= RESOLUTION_M[1]
        else f"no {flag} up to {RESOLUTION_M[1]:g} m fits: is the odometry wrong?"
    )
    return (
        f"spans {hi[0] - lo[0]:.1f} m x {hi[1] - lo[1]:.1f} m at the scans (x {lo[0]:.1f} to "
        f"{hi[0]:.1f} m, y {lo[1]:.1f} to {hi[1]:.1f} m; its largest step, {steps[jump]:.1f} m, "
        f"between scans {jump} and {jump + 1}): with the lidar's reach ({reach_m:g} m) all round, "
        f"a map at {flag} {resolution_m:g} would be {width:,} x {height:,} cells; expected at "
        f"most {MAX_CELLS:,} cells ({MAX_CELLS * 4 / 1e6:,.0f} MB): {coarser}"
    )


def _returns_within(
    scans: npt.NDArray[np.float32], limit_m: float, far_m: float
) -> npt.NDArray[np.float32]:
    """Returns farther than ``far_m`` (m) moved to just within it; everything else as is.

    ``far_m`` is twice the map's diagonal: such a return ends outside the map and its beam
    stops at the map's edge either way, so no cell changes; the work per beam stays
    bounded. It is what lets a lidar without a maximum (range_max inf, as
    pointcloud_to_laserscan publishes) keep +inf as no return (REP 117).
    """
    cap = np.nextafter(np.float32(far_m), np.float32(0))
    wide = scans.astype(np.float64)
    returns = np.isfinite(wide) & (wide > cap) & (wide <= limit_m)
    return np.where(returns, cap, scans).astype(np.float32)


def _smoothed(rows: list[tuple[float, ...]], loops: LoopCloser) -> list[tuple[float, ...]]:
    """Every scan's pose from the final graph: its last node's solved pose moved by odometry.

    Online, a scan's estimate is what the robot knew then; after loops closed later, the
    graph knows better (the trajectory an offline user wants).
    """
    smoothed: list[tuple[float, ...]] = []
    for t_ns, _x, _y, _yaw, ox, oy, oyaw, node in rows:
        k = int(node)
        if k < 0:
            smoothed.append((t_ns, _x, _y, _yaw, ox, oy, oyaw, node))
            continue
        moved = relative(loops.nodes[k].odom, (ox, oy, oyaw))
        x, y, yaw = compose(loops.graph.nodes[k], moved)
        smoothed.append((t_ns, x, y, yaw, ox, oy, oyaw, node))
    return smoothed


def _result(recording: Recording, mapped: MappedScans) -> RecordingMap:
    grid, rows, mapper = mapped.grid, mapped.rows, mapped.mapper
    wall_s, span_s = mapped.wall_s, mapped.span_s
    table = np.array(rows, dtype=np.float64)
    t_ns = table[:, 0].astype(np.int64)
    trajectory = pd.DataFrame(
        {"t_s": t_ns / 1e9, "x_m": table[:, 1], "y_m": table[:, 2], "yaw_rad": table[:, 3]}
    )
    summary: dict[str, Any] = {
        "bag": str(recording.bag),
        "scans": len(rows),
        "scans_outside_odometry": recording.skipped,
        "map_updates": mapper.updates,
        "matched": mapper.matched,
        "loop_closures": mapper.loops.closures if mapper.loops is not None else 0,
        "loop_closures_not_needed": mapper.loops.not_needed if mapper.loops is not None else 0,
        "recording_s": round(span_s, 3),
        "wall_time_s": round(wall_s, 3),
        "real_time_factor": round(span_s / wall_s, 1) if wall_s > 0 else None,
    }
    drawn = None
    if recording.reference is not None:
        keep = np.isfinite(recording.reference[:, 0])
        if keep.sum() >= 2:
            ref_xy = recording.reference[keep, :2]
            summary["ate_m"] = round(ate_rmse(table[keep, 1:3], ref_xy, align=True), 4)
            summary["ate_odom_m"] = round(ate_rmse(table[keep, 4:6], ref_xy, align=True), 4)
            summary["reference_poses"] = int(keep.sum())
            rotation, shift = align_se2(ref_xy, table[keep, 1:3])
            drawn = ref_xy @ rotation.T + shift
    return RecordingMap(grid, summary, trajectory, table[:, 1:3], table[:, 4:6], drawn)
