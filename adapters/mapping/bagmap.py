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
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd

from adapters.mocap.tracks import planar_pose
from cosim.core.bags import BagMessage, bag_info, read_messages
from cosim.core.errors import BagError
from models.mapping.grid import LogOddsMap, MapGeometry
from models.mapping.loops import LoopCloser, LoopParams
from models.mapping.matcher import MatcherParams
from models.mapping.quality import align_se2, ate_rmse
from models.mapping.se2 import compose, relative
from models.mapping.slam import MapperParams, ScanMapper, UpdateGate

SCAN_TYPES = ("sensor_msgs/msg/LaserScan",)
ODOM_TYPES = ("nav_msgs/msg/Odometry",)
REFERENCE_TYPES = (
    "nav_msgs/msg/Odometry",
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
)
MAP_REACH_M = 30.0
"""The map reaches this far beyond the odometry's extent (m); returns beyond fall off."""

Progress = Callable[[float, float, float], None]
"""(recording time processed s, recording duration s, wall s)."""


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


@dataclass(frozen=True)
class _Track:
    """Timed planar poses, to interpolate."""

    t_ns: npt.NDArray[np.int64]
    xyyaw: npt.NDArray[np.float64]

    def at(self, t_ns: int) -> tuple[float, float, float] | None:
        """The pose at ``t_ns`` (linear, yaw unwrapped), None outside the track."""
        t = self.t_ns
        if len(t) == 0 or t_ns < t[0] or t_ns > t[-1]:
            return None
        k = int(np.searchsorted(t, t_ns))
        if t[k] == t_ns or k == 0:
            x, y, yaw = self.xyyaw[k]
            return float(x), float(y), float(yaw)
        a = (t_ns - t[k - 1]) / (t[k] - t[k - 1])
        p, q = self.xyyaw[k - 1], self.xyyaw[k]
        dyaw = math.remainder(q[2] - p[2], 2 * math.pi)
        return (
            float(p[0] + a * (q[0] - p[0])),
            float(p[1] + a * (q[1] - p[1])),
            float(math.remainder(p[2] + a * dyaw, 2 * math.pi)),
        )


def _stamp_ns(message: BagMessage) -> int:
    header = getattr(message.message, "header", None)
    if header is not None:
        stamp = int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)
        if stamp > 0:
            return stamp
    return message.t_ns


def _pose(message: BagMessage) -> tuple[float, float, float]:
    return planar_pose(message.message, message.msgtype)


def _check_types(bag: Path, wanted: Sequence[tuple[str, str, Sequence[str]]]) -> None:
    """Every (option, topic, accepted types) present and typed right, else one BagError line."""
    topics = {t.name: t for t in bag_info(bag).topics}
    for option, topic, accepted in wanted:
        found = topics.get(topic)
        if found is None:
            listing = ", ".join(f"{t.name} ({t.msgtype})" for t in topics.values()) or "none"
            raise BagError(
                f"{bag}: {option} {topic}: no such topic; expected one of {', '.join(accepted)} "
                f"(the bag has {listing})"
            )
        if found.msgtype not in accepted:
            raise BagError(
                f"{bag}: {option} {topic} is {found.msgtype}; expected {', '.join(accepted)}"
            )
        if found.count == 0:
            raise BagError(f"{bag}: {option} {topic} has no messages")


def _track(messages: list[BagMessage]) -> _Track:
    rows = sorted((_stamp_ns(m), *_pose(m)) for m in messages)
    t = np.array([r[0] for r in rows], dtype=np.int64)
    xyyaw = np.array([r[1:] for r in rows], dtype=np.float64).reshape(-1, 3)
    return _Track(t, xyyaw)


def check_topics(
    bag: Path, scan_topic: str, odom_topic: str, reference_topic: str | None
) -> list[str]:
    """The topics to read, checked present and of the right types.

    Raises:
        BagError: not a bag, or a topic missing, empty or of the wrong type (one line).
    """
    wanted: list[tuple[str, str, Sequence[str]]] = [
        ("--scan", scan_topic, SCAN_TYPES),
        ("--odom", odom_topic, ODOM_TYPES),
    ]
    if reference_topic is not None:
        wanted.append(("--reference", reference_topic, REFERENCE_TYPES))
    _check_types(bag, wanted)
    return sorted({topic for _, topic, _ in wanted})


@dataclass(frozen=True)
class Recording:
    """A recording's scans with the odometry (and reference) at each one's stamp.

    Attributes:
        bag: where it was read from.
        stamps_ns: (scans,) each scan's stamp (ns), increasing.
        ranges_m: (scans, beams) the ranges (m).
        angles_rad: (beams,) the beams' angles in the sensor frame (rad).
        range_min_m: shorter readings are invalid (m).
        range_max_m: the lidar's maximum range (m).
        odometry: (scans, 3) x m, y m, yaw rad (frame ``odom``), interpolated.
        reference: (scans, 3) the reference pose at each scan, NaN outside it; None
            without a reference topic.
        skipped: scans outside the odometry's time span, left out.
    """

    bag: Path
    stamps_ns: npt.NDArray[np.int64] = field(repr=False)
    ranges_m: npt.NDArray[np.float32] = field(repr=False)
    angles_rad: npt.NDArray[np.float64] = field(repr=False)
    range_min_m: float
    range_max_m: float
    odometry: npt.NDArray[np.float64] = field(repr=False)
    reference: npt.NDArray[np.float64] | None = field(repr=False)
    skipped: int


def read_recording(
    bag: Path,
    *,
    scan_topic: str = "/scan",
    odom_topic: str = "/odom",
    reference_topic: str | None = None,
) -> Recording:
    """A bag's scans, each with the odometry (and reference) interpolated at its stamp.

    Raises:
        BagError: not a bag, a topic missing or of the wrong type, scans of different
            sizes, no scan that odometry covers.
    """
    bag = Path(bag)
    topics = check_topics(bag, scan_topic, odom_topic, reference_topic)
    messages = list(read_messages(bag, topics))
    scans = [m for m in messages if m.topic == scan_topic]
    odom = _track([m for m in messages if m.topic == odom_topic])
    reference = (
        _track([m for m in messages if m.topic == reference_topic]) if reference_topic else None
    )
    paired = [(s, odom.at(_stamp_ns(s))) for s in scans]
    usable = [(s, o) for s, o in paired if o is not None]
    if not usable:
        raise BagError(
            f"{bag}: no scan on {scan_topic} falls within the odometry on {odom_topic} "
            "(their stamps do not overlap)"
        )
    scan0 = usable[0][0].message
    angles = scan0.angle_min + scan0.angle_increment * np.arange(len(scan0.ranges))
    ranges = np.zeros((len(usable), len(angles)), dtype=np.float32)
    for n, (scan, _) in enumerate(usable):
        beams = np.asarray(scan.message.ranges, dtype=np.float32)
        if len(beams) != len(angles):
            raise BagError(
                f"{bag}: {scan_topic} scan {n} has {len(beams)} beams; expected "
                f"{len(angles)} like the first (one lidar per topic)"
            )
        ranges[n] = beams
    stamps = np.array([_stamp_ns(s) for s, _ in usable], dtype=np.int64)
    at_reference = None
    if reference is not None:
        nowhere = (math.nan, math.nan, math.nan)
        at_reference = np.array([reference.at(int(t)) or nowhere for t in stamps])
    return Recording(
        bag,
        stamps,
        ranges,
        np.asarray(angles, dtype=np.float64),
        float(scan0.range_min),
        float(scan0.range_max),
        np.array([o for _, o in usable], dtype=np.float64),
        at_reference,
        len(scans) - len(usable),
    )


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
        BagError: not a bag, a topic missing or of the wrong type, no scan that odometry
            covers.
    """
    recording = read_recording(
        bag, scan_topic=scan_topic, odom_topic=odom_topic, reference_topic=reference_topic
    )
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
    xy = poses[:, :2]
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    reach = min(range_max_m, MAP_REACH_M)
    geometry = MapGeometry.covering((lo[0], lo[1], hi[0], hi[1]), resolution_m, reach)
    grid = LogOddsMap(geometry)
    loops = LoopParams() if loop_closure is True else (loop_closure or None)
    params = MapperParams(
        gate=gate or UpdateGate(),
        matcher=matcher or MatcherParams(),
        scan_matching=scan_matching,
        range_min_m=range_min_m,
        range_max_m=range_max_m * 0.999,  # readings at the maximum are no return (REP 117)
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
