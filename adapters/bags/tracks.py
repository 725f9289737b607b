"""Recorded pose tracks: a robot's trajectory from a ROS 2 bag or a CSV file.

Bags: a topic of ``geometry_msgs/msg/PoseStamped`` or ``TransformStamped`` (as Vicon
bridges such as ros2-vicon-receiver publish), ``PoseWithCovarianceStamped`` (AMCL) or
``nav_msgs/msg/Odometry``. Stamps are the messages' header stamps, or the bag's log
times when every header stamp is zero. CSV: a header ``t_s,x_m,y_m,yaw_rad`` and one row
per pose, times strictly increasing. Poses are planar: x, y and the yaw of the rotation.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from adapters.bags.reader import bag_info, read_messages
from cosim.core.errors import BagError, CosimError
from models.geometry.angles import wrap_angles
from models.geometry.se2 import yaw_of_quaternion

POSE_TYPES = (
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/TransformStamped",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
    "nav_msgs/msg/Odometry",
)
"""The message types a pose track is read from."""

CSV_COLUMNS = ("t_s", "x_m", "y_m", "yaw_rad")


class TrackError(CosimError):
    """A CSV file given as a pose track is not one (file, row, column, value named)."""


@dataclass(frozen=True)
class PoseTrack:
    """A planar trajectory.

    Attributes:
        t_ns: (n,) int64 stamps (ns), increasing.
        x_m, y_m, yaw_rad: (n,) poses in ``frame_id``.
        frame_id: the poses' frame (``""`` when a CSV does not say).
        source: the file (and topic) it was read from, for messages.
        stamps: ``"header"`` (message stamps), ``"log"`` (bag log times) or ``"csv"``.
    """

    t_ns: npt.NDArray[np.int64]
    x_m: npt.NDArray[np.float64]
    y_m: npt.NDArray[np.float64]
    yaw_rad: npt.NDArray[np.float64]
    frame_id: str
    source: str
    stamps: Literal["header", "log", "csv"]

    def __len__(self) -> int:
        return len(self.t_ns)

    def at(self, t_ns: int) -> int:
        """Index of the last pose stamped at or before ``t_ns`` (-1 if none)."""
        return int(np.searchsorted(self.t_ns, t_ns, side="right")) - 1

    def relative(self) -> npt.NDArray[np.int64]:
        """Stamps relative to the first (ns)."""
        return np.asarray(self.t_ns - self.t_ns[0], dtype=np.int64)


yaw_of = yaw_of_quaternion
"""Yaw (rad) of a quaternion ``(x, y, z, w)``."""


def _planar(message: Any, msgtype: str) -> tuple[Any, Any, Any]:
    """(header, position-like, quaternion) of a pose-like message (one of POSE_TYPES)."""
    if msgtype == "geometry_msgs/msg/PoseStamped":
        return message.header, message.pose.position, message.pose.orientation
    if msgtype == "geometry_msgs/msg/TransformStamped":
        t = message.transform
        return message.header, t.translation, t.rotation
    # PoseWithCovarianceStamped and Odometry both hold a PoseWithCovariance
    return message.header, message.pose.pose.position, message.pose.pose.orientation


def planar_pose(message: Any, msgtype: str) -> tuple[float, float, float]:
    """x_m, y_m, yaw_rad of a decoded pose-like message (one of :data:`POSE_TYPES`)."""
    _header, p, q = _planar(message, msgtype)
    return float(p.x), float(p.y), yaw_of_quaternion(q.x, q.y, q.z, q.w)


def pose_topics(path: str | Path) -> dict[str, str]:
    """Topic -> type of the bag's pose-like topics.

    Raises:
        BagError: when ``path`` is not a readable bag.
    """
    return {t.name: t.msgtype for t in bag_info(path).topics if t.msgtype in POSE_TYPES}


def read_pose_track(path: str | Path, topic: str | None = None) -> PoseTrack:
    """Read a pose track from a bag (topic ``topic``) or a ``.csv`` file.

    Args:
        path: a bag (folder with metadata.yaml, ``.mcap`` or ``.db3``) or a ``.csv``.
        topic: the bag topic; None when the bag has exactly one pose-like topic.

    Raises:
        BagError: not a bag, no such topic, a topic of another type, or no messages.
        TrackError: a CSV that is not a pose track.
    """
    path = Path(path)
    if path.suffix.lower() == ".csv":
        if topic:
            raise TrackError(f"{path}: a CSV holds one track; no topic ({topic!r}) expected")
        return read_csv_track(path)
    candidates = pose_topics(path)
    if topic is None:
        if len(candidates) != 1:
            listed = ", ".join(f"{t} ({m})" for t, m in sorted(candidates.items()))
            raise BagError(
                f"{path}: expected exactly one pose topic to replay, found "
                f"{len(candidates)}{': ' + listed if listed else ''}; name one"
            )
        topic = next(iter(candidates))
    elif topic not in candidates:
        types = {t.name: t.msgtype for t in bag_info(path).topics}
        if topic in types:
            raise BagError(
                f"{path}: topic {topic} is {types[topic]}: expected one of {', '.join(POSE_TYPES)}"
            )
        raise BagError(
            f"{path}: no topic {topic}; pose topics are {', '.join(sorted(candidates)) or 'none'}"
        )
    msgtype = candidates[topic]
    header_ns: list[int] = []
    log_ns: list[int] = []
    poses: list[tuple[float, float, float]] = []
    frame = ""
    for m in read_messages(path, [topic]):
        header = _planar(m.message, msgtype)[0]
        header_ns.append(int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec))
        log_ns.append(m.t_ns)
        poses.append(planar_pose(m.message, msgtype))
        frame = frame or str(header.frame_id)
    source = f"{path} {topic}"
    if not poses:
        raise BagError(f"{path}: topic {topic} has no messages")
    by_header = any(header_ns)
    stamps = np.asarray(header_ns if by_header else log_ns, dtype=np.int64)
    order = np.argsort(stamps, kind="stable")
    array = np.asarray(poses, dtype=float)[order]
    stamps = stamps[order]
    keep = np.concatenate([[True], np.diff(stamps) > 0])  # one pose per stamp
    return PoseTrack(
        stamps[keep],
        array[keep, 0],
        array[keep, 1],
        array[keep, 2],
        frame,
        source,
        "header" if by_header else "log",
    )


def read_csv_track(path: Path) -> PoseTrack:
    """Read ``t_s,x_m,y_m,yaw_rad`` rows (see the module docstring).

    Raises:
        TrackError: naming the file, the row (the header is row 1), the column and value.
    """
    try:
        text = path.read_text(encoding="utf-8-sig")  # a spreadsheet's byte-order mark is fine
    except (OSError, UnicodeDecodeError) as error:
        raise TrackError(f"{path}: cannot read a pose track ({error})") from None
    try:
        rows = list(csv.reader(text.splitlines()))
    except csv.Error as error:
        raise TrackError(f"{path}: not a CSV pose track ({error})") from None
    if not rows:
        raise TrackError(f"{path}: empty; expected a header {','.join(CSV_COLUMNS)} and rows")
    header = [name.strip() for name in rows[0]]
    extra = [name for name in header if name not in CSV_COLUMNS]
    missing = [name for name in CSV_COLUMNS if name not in header]
    if extra or missing or len(header) != len(CSV_COLUMNS):
        what = (
            f"unknown column {extra[0]!r}"
            if extra
            else f"missing column {missing[0]!r}"
            if missing
            else "a repeated column"
        )
        raise TrackError(f"{path}: row 1: {what}; expected the header {','.join(CSV_COLUMNS)}")
    columns = [header.index(name) for name in CSV_COLUMNS]
    values: list[tuple[float, float, float, float]] = []
    for number, row in enumerate(rows[1:], start=2):
        if not row or all(not cell.strip() for cell in row):
            continue
        if len(row) != len(header):
            raise TrackError(
                f"{path}: row {number}: {len(row)} values; expected {len(header)} "
                f"({','.join(header)})"
            )
        parsed = []
        for column in columns:
            cell = row[column].strip()
            try:
                value = float(cell)
            except ValueError:
                value = math.nan
            if not math.isfinite(value):
                raise TrackError(
                    f"{path}: row {number}: {header[column]} = {cell!r}: expected a finite number"
                )
            parsed.append(value)
        t, x, y, yaw = parsed
        if values and t <= values[-1][0]:
            raise TrackError(
                f"{path}: row {number}: t_s = {t!r}: expected a time after {values[-1][0]!r} "
                "(times strictly increasing)"
            )
        if abs(t) > 1e9:
            raise TrackError(f"{path}: row {number}: t_s = {t!r}: expected |t_s| <= 1e9 s")
        values.append((t, x, y, yaw))
    if not values:
        raise TrackError(f"{path}: no rows; expected at least one pose under the header")
    array = np.asarray(values, dtype=float)
    t_ns = np.round(array[:, 0] * 1e9).astype(np.int64)
    if np.any(np.diff(t_ns) <= 0):
        raise TrackError(f"{path}: two rows closer than 1 ns in time; expected distinct times")
    headings = wrap_angles(array[:, 3])
    return PoseTrack(t_ns, array[:, 1], array[:, 2], headings, "", str(path), "csv")
