"""What robots share to map together: localized scans and compressed map updates."""

import dataclasses
import zlib

import numpy as np
import pytest

from cosim.core.messages import LocalizedScan, MapUpdate


def _scan(ranges: np.ndarray) -> LocalizedScan:
    return LocalizedScan(25, "robot_3", 1.0, 2.0, 0.5, -3.1, 0.0175, 0.1, 10.0, ranges)


def test_a_localized_scan_decodes_back_with_float32_beams_and_ranges():
    ranges = np.array([0.5, np.inf, np.nan, 9.75], np.float32)
    back = LocalizedScan.from_cdr(_scan(ranges).to_cdr())
    assert (back.stamp_ns, back.robot, back.x_m, back.y_m, back.yaw_rad) == (
        25,
        "robot_3",
        1.0,
        2.0,
        0.5,
    )
    # the beam geometry is float32 on the wire
    assert back.angle_min_rad == float(np.float32(-3.1))
    assert back.angle_increment_rad == float(np.float32(0.0175))
    assert back.ranges_m.dtype == np.float32 and back.ranges_m.tobytes() == ranges.tobytes()


def test_a_localized_scans_ranges_are_read_only():
    scan = _scan(np.ones(3, np.float32))
    with pytest.raises(ValueError):
        scan.ranges_m[0] = 2.0
    assert not LocalizedScan.from_cdr(scan.to_cdr()).ranges_m.flags.writeable


def test_a_map_update_is_zlib_int8_unless_said_and_decodes_back():
    cells = np.array([[1, -2], [127, -128]], np.int8)
    data = zlib.compress(cells.tobytes())
    update = MapUpdate(26, "robot_2", 4, 10, -3, 2, 2, 0.05, data=data)
    assert update.encoding == "zlib-int8"
    back = MapUpdate.from_cdr(update.to_cdr())
    assert dataclasses.replace(back, scale=0.05) == update
    assert back.scale == float(np.float32(0.05))
    assert np.frombuffer(zlib.decompress(back.data), np.int8).reshape(2, 2).tolist() == (
        cells.tolist()
    )


def test_the_shared_messages_are_their_cosim_msgs_types_with_fields_in_si_units():
    assert LocalizedScan.wire.msg_text() == (
        "std_msgs/Header header\nstring robot\nfloat64 x\nfloat64 y\nfloat64 yaw\n"
        "float32 angle_min\nfloat32 angle_increment\nfloat32 range_min\nfloat32 range_max\n"
        "float32[] ranges\n"
    )
    assert MapUpdate.wire.msg_text() == (
        "std_msgs/Header header\nstring robot\nuint32 seq\nint32 ix0\nint32 iy0\n"
        "uint32 width\nuint32 height\nfloat32 scale\nstring encoding\nuint8[] data\n"
    )
    assert {LocalizedScan.ros_type, MapUpdate.ros_type} == {
        "cosim_msgs/msg/LocalizedScan",
        "cosim_msgs/msg/MapUpdate",
    }
