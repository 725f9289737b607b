"""CDR sizes: how many bytes a message takes on the wire as ROS 2 sends it.

XCDR1, little endian, after a 4-byte encapsulation header; alignment counts from the end
of that header. Each function takes the offset (bytes) before a field and returns the
offset after it. Checked against rosbags' serializer in the tests.
"""

from __future__ import annotations

from functools import lru_cache

ENCAPSULATION = 4
"""Bytes of the CDR encapsulation header in front of every message."""


def align(offset: int, alignment: int) -> int:
    """Round ``offset`` up to a multiple of ``alignment``."""
    return (offset + alignment - 1) // alignment * alignment


def uint32(offset: int) -> int:
    """After a uint32 or int32 field (also the length of a sequence)."""
    return align(offset, 4) + 4


def string(offset: int, text: str) -> int:
    """After a string: uint32 length (counting the NUL), the UTF-8 bytes, the NUL."""
    return uint32(offset) + len(text.encode("utf-8")) + 1


def header(offset: int, frame_id: str) -> int:
    """After a std_msgs/Header: builtin_interfaces/Time (int32, uint32) and the frame id."""
    return string(align(offset, 4) + 8, frame_id)


def doubles(offset: int, count: int) -> int:
    """After ``count`` float64 fields."""
    return align(offset, 8) + 8 * count


def float_seq(offset: int, count: int) -> int:
    """After a sequence of ``count`` float32."""
    return uint32(offset) + 4 * count


@lru_cache(maxsize=4096)
def odometry_size(frame_id: str, child_frame_id: str) -> int:
    """Size of a nav_msgs/Odometry: header, child frame, pose and twist with covariances."""
    offset = header(0, frame_id)
    offset = string(offset, child_frame_id)
    offset = doubles(offset, 7 + 36)
    return ENCAPSULATION + doubles(offset, 6 + 36)


@lru_cache(maxsize=4096)
def scan_size(frame_id: str, beams: int) -> int:
    """Size of a sensor_msgs/LaserScan with ``beams`` ranges and no intensities."""
    offset = header(0, frame_id)
    offset = align(offset, 4) + 7 * 4
    offset = float_seq(offset, beams)
    return ENCAPSULATION + float_seq(offset, 0)
