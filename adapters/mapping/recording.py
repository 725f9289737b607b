"""Reading a recording for mapping: a bag's scans, each paired with its odometry.

Everything ``cosim map`` takes from a bag is checked here, so that a bad recording is one
line naming the bag, the topic, the message and the value: topics and types, scans of one
lidar with usable angles and limits, poses finite and near their frame's origin with unit
quaternions, stamps increasing on each topic, and some scan the odometry covers.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from adapters.bags.reader import BagMessage, bag_info, read_messages
from adapters.bags.tracks import planar_pose
from cosim.core.errors import BagError
from models.geometry.angles import wrap_angle

SCAN_TYPES = ("sensor_msgs/msg/LaserScan",)
ODOM_TYPES = ("nav_msgs/msg/Odometry",)
REFERENCE_TYPES = (
    "nav_msgs/msg/Odometry",
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
)
MAX_POSITION_M = 1e8
"""A pose farther than this from its frame's origin is refused (m): no frame on Earth
reaches it (UTM and ECEF coordinates stay within 1e7 m); such values are glitches."""
QUATERNION_TOLERANCE = 0.01
"""How far |q|^2 of an orientation may be from 1 (tf2's normalization tolerance)."""


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
        dyaw = wrap_angle(q[2] - p[2])
        return (
            float(p[0] + a * (q[0] - p[0])),
            float(p[1] + a * (q[1] - p[1])),
            float(wrap_angle(p[2] + a * dyaw)),
        )


def _stamp_ns(message: BagMessage) -> int:
    header = getattr(message.message, "header", None)
    if header is not None:
        stamp = int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)
        if stamp > 0:
            return stamp
    return message.t_ns


def _s(t_ns: int) -> str:
    """A stamp as exact seconds, for messages."""
    return f"{t_ns // 1_000_000_000}.{t_ns % 1_000_000_000:09d} s"


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


def _increasing(where: str, kind: str, stamps: list[int]) -> None:
    """One sensor's stamps increase strictly, else one BagError line naming the first not to."""
    for n in range(1, len(stamps)):
        if stamps[n] <= stamps[n - 1]:
            same = "has the same stamp as" if stamps[n] == stamps[n - 1] else "is stamped before"
            raise BagError(
                f"{where} {kind} {n} ({_s(stamps[n])}) {same} {kind} {n - 1} "
                f"({_s(stamps[n - 1])}); expected stamps increasing strictly (one sensor's "
                "clock: did it jump back, or do two publishers share the topic?)"
            )


def _track(bag: Path, option: str, topic: str, messages: list[BagMessage]) -> _Track:
    """A topic's planar poses, checked finite, near the origin and stamped in order.

    Raises:
        BagError: one line naming the message, its stamp, the value and what was expected.
    """
    where = f"{bag}: {option} {topic}"
    stamps, rows = [], []
    for n, m in enumerate(messages):
        t = _stamp_ns(m)
        body = m.message.pose
        pose = getattr(body, "pose", body)  # Odometry's and AMCL's carry a covariance
        p, q = pose.position, pose.orientation
        values = (p.x, p.y, q.x, q.y, q.z, q.w)
        what = f"{where} message {n} ({_s(t)})"
        if not all(math.isfinite(v) for v in values):
            raise BagError(
                f"{what}: position ({p.x:g}, {p.y:g}) m, orientation ({q.x:g}, {q.y:g}, "
                f"{q.z:g}, {q.w:g}); expected finite numbers"
            )
        if max(abs(p.x), abs(p.y)) > MAX_POSITION_M:
            raise BagError(
                f"{what}: position ({p.x:g}, {p.y:g}) m; expected x and y within "
                f"{MAX_POSITION_M:g} m of the frame's origin (no frame on Earth reaches farther)"
            )
        norm2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w
        if abs(norm2 - 1.0) > QUATERNION_TOLERANCE:
            raise BagError(
                f"{what}: orientation ({q.x:g}, {q.y:g}, {q.z:g}, {q.w:g}) has |q|^2 = "
                f"{norm2:g}; expected a unit quaternion (within {QUATERNION_TOLERANCE:g}, as tf2)"
            )
        stamps.append(t)
        rows.append(planar_pose(m.message, m.msgtype))
    _increasing(where, "message", stamps)
    t_ns = np.array(stamps, dtype=np.int64)
    return _Track(t_ns, np.array(rows, dtype=np.float64).reshape(-1, 3))


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


def _check_lidar(where: str, n: int, scan: Any) -> None:
    """A LaserScan's geometry and limits usable (REP 117 readings are all fine), else BagError."""
    beams = len(scan.ranges)
    what = f"{where} scan {n}"
    if beams == 0:
        raise BagError(f"{what} has no ranges; expected at least one beam")
    if not (math.isfinite(scan.angle_min) and abs(scan.angle_min) <= 2 * math.pi):
        raise BagError(f"{what}: angle_min {scan.angle_min:g} rad; expected -2 pi to 2 pi")
    increment = scan.angle_increment
    if not math.isfinite(increment) or (increment == 0 and beams > 1):
        raise BagError(
            f"{what}: angle_increment {increment:g} rad over {beams} beams; expected a "
            "finite, non-zero angle between beams"
        )
    if abs(increment) * (beams - 1) > 2 * math.pi + abs(increment):
        raise BagError(
            f"{what}: angle_increment {increment:g} rad over {beams} beams spans "
            f"{abs(increment) * (beams - 1):g} rad; expected at most one turn (2 pi rad: "
            "an increment in degrees?)"
        )
    low, high = scan.range_min, scan.range_max
    if not (math.isfinite(low) and low >= 0 and high > low):  # high may be inf (no maximum)
        raise BagError(
            f"{what}: range_min {low:g} m, range_max {high:g} m; expected 0 <= range_min < "
            "range_max (m)"
        )


def _same_lidar(where: str, n: int, scan: Any, first: Any) -> None:
    """Every scan of a topic from one lidar: the first's beams, angles and limits."""
    if len(scan.ranges) != len(first.ranges):
        raise BagError(
            f"{where} scan {n} has {len(scan.ranges)} beams; expected {len(first.ranges)} "
            "like the first (one lidar per topic)"
        )
    beam = 0.01 * abs(first.angle_increment)  # angles within a hundredth of a beam
    for name, within in (
        ("angle_min", beam),
        ("angle_increment", beam / len(first.ranges)),
        ("range_min", 0.0),
        ("range_max", 0.0),
    ):
        value, expected = getattr(scan, name), getattr(first, name)
        if not math.isclose(value, expected, rel_tol=1e-6, abs_tol=within):
            raise BagError(
                f"{where} scan {n}: {name} {value:g}; expected {expected:g} like the first "
                "(one lidar per topic)"
            )


def read_recording(
    bag: Path,
    *,
    scan_topic: str = "/scan",
    odom_topic: str = "/odom",
    reference_topic: str | None = None,
) -> Recording:
    """A bag's scans, each with the odometry (and reference) interpolated at its stamp.

    Ranges follow REP 117 and stay as recorded: NaN is no measurement, +inf no return,
    -inf and readings below ``range_min`` too near; the mapper treats each so.

    Raises:
        BagError: one line naming the topic, message and value: not a bag, a topic missing
            or of the wrong type, scans of different sizes or geometries, a scan without
            beams or with unusable angles or limits, a pose not finite, farther than
            :data:`MAX_POSITION_M` or with a quaternion that is not a unit one, stamps not
            increasing on a topic, no scan that odometry covers.
    """
    bag = Path(bag)
    topics = check_topics(bag, scan_topic, odom_topic, reference_topic)
    messages = list(read_messages(bag, topics))
    scans = [m for m in messages if m.topic == scan_topic]
    odom = _track(bag, "--odom", odom_topic, [m for m in messages if m.topic == odom_topic])
    reference = None
    if reference_topic is not None:
        chosen = [m for m in messages if m.topic == reference_topic]
        reference = _track(bag, "--reference", reference_topic, chosen)
    where = f"{bag}: --scan {scan_topic}"
    for n, scan in enumerate(scans):
        _check_lidar(where, n, scan.message)
    scan_stamps = [_stamp_ns(s) for s in scans]
    _increasing(where, "scan", scan_stamps)
    paired = [(n, s, odom.at(t)) for n, (s, t) in enumerate(zip(scans, scan_stamps, strict=True))]
    usable = [(n, s, o) for n, s, o in paired if o is not None]
    if not usable:
        raise BagError(
            f"{bag}: no scan on {scan_topic} falls within the odometry on {odom_topic} "
            "(their stamps do not overlap)"
        )
    scan0 = usable[0][1].message
    angles = scan0.angle_min + scan0.angle_increment * np.arange(len(scan0.ranges))
    for n, scan in enumerate(scans):
        _same_lidar(where, n, scan.message, scan0)
    ranges = np.zeros((len(usable), len(angles)), dtype=np.float32)
    for k, (_, scan, _) in enumerate(usable):
        ranges[k] = np.asarray(scan.message.ranges, dtype=np.float32)
    stamps = np.array([scan_stamps[n] for n, _, _ in usable], dtype=np.int64)
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
        np.array([o for _, _, o in usable], dtype=np.float64),
        at_reference,
        len(scans) - len(usable),
    )
