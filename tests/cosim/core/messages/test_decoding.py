"""Bytes from outside (the network, a bag, a Unity scene) decode to a message or a WireError."""

import contextlib
import math
import struct
from datetime import timedelta

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cosim.core.errors import WireError
from cosim.core.messages import (
    CbbaBids,
    Clock,
    LaserScan,
    LocalizedScan,
    MapUpdate,
    Marker,
    MarkerArray,
    MarkerType,
    Message,
    NavStatus,
    OccupancyGrid,
    Odometry,
    Path,
    SimplexBasis,
    TaskInfo,
    TaskSet,
    TFMessage,
    Transform,
    Twist,
    std,
)
from cosim.core.messages.decoding import decode_tree

VALID: list[Message] = [
    Twist(0.5, -0.1),
    Clock(3_000_000_007),
    Odometry(1_500_000_001, "robot_1/odom", "robot_1/base_link", 1.0, -2.0, 0.3, 0.5, -0.1),
    LaserScan(9, "robot_1/laser", -1.0, 0.5, 0.1, 10.0, 0.1, np.array([1.0, np.inf], "f4")),
    Path(11, "map", np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 2.0]])),
    NavStatus(3, 2, "progress", 1.0, 2.0, 7.5),
    TaskSet(13, 4, (TaskInfo(1, 2.0, 3.0, ("robot_1", "robot_2"), "robot_1"),)),
    SimplexBasis(18, 4, "robot_1", 3, ((0, 1, 2, 3.5), (1, 0, -1, 1e6))),
    CbbaBids(19, 4, "robot_2", (1.0, 2.5), (0, -1)),
    TFMessage(22, (Transform("map", "robot_1/odom", 0.1, -0.2, 0.05),)),
    OccupancyGrid(23, "map", 0.05, 3, 2, -0.2, -0.2, bytes([0, 100, 255, 0, 0, 100])),
    LocalizedScan(25, "robot_3", 1.0, 2.0, 0.5, -3.1, 0.0175, 0.1, 10.0, np.ones(3, "f4")),
    MapUpdate(26, "robot_2", 4, 10, -3, 20, 5, 0.05, bytes(range(5))),
    MarkerArray(24, (Marker("shelves", 3, MarkerType.CUBE, x_m=1.0, text="ü"),)),
]
CLASSES = [type(m) for m in VALID]
DECODE_FAST = settings(
    max_examples=150,
    deadline=timedelta(seconds=1),  # a count of 2**32 must not make the decoder loop
    suppress_health_check=[HealthCheck.too_slow],
)


def _decodes_or_refuses(cls: type[Message], data: bytes) -> Message | None:
    try:
        return cls.from_cdr(data)
    except WireError:
        return None


def _same(a: Message, b: Message) -> bool:
    return a.to_cdr() == b.to_cdr()


@DECODE_FAST
@given(cls=st.sampled_from(CLASSES), data=st.binary(max_size=300))
def test_random_bytes_decode_to_a_message_or_raise_a_wire_error(cls, data):
    _decodes_or_refuses(cls, b"\x00\x01\x00\x00" + data)
    _decodes_or_refuses(cls, data)


@DECODE_FAST
@given(kind=st.sampled_from(std.STANDARD), data=st.binary(max_size=300))
def test_random_bytes_decode_to_a_tree_of_any_standard_type_or_raise_a_wire_error(kind, data):
    with contextlib.suppress(WireError):
        decode_tree(kind, b"\x00\x01\x00\x00" + data)


@DECODE_FAST
@given(message=st.sampled_from(VALID), data=st.data())
def test_a_valid_message_cut_short_anywhere_is_refused(message, data):
    encoded = message.to_cdr()
    cut = data.draw(st.integers(4, len(encoded) - 1), label="cut")
    with pytest.raises(WireError, match=message.ros_type):
        type(message).from_cdr(encoded[:cut])


@DECODE_FAST
@given(message=st.sampled_from(VALID), data=st.data())
def test_a_valid_message_with_bytes_flipped_decodes_or_raises_a_wire_error(message, data):
    encoded = bytearray(message.to_cdr())
    flips = data.draw(
        st.lists(st.tuples(st.integers(4, len(encoded) - 1), st.integers(1, 255)), max_size=4),
        label="flips",
    )
    for at, mask in flips:
        encoded[at] ^= mask
    decoded = _decodes_or_refuses(type(message), bytes(encoded))
    if not flips:
        assert decoded is not None and _same(decoded, message)


@DECODE_FAST
@given(message=st.sampled_from(VALID), extra=st.binary(min_size=1, max_size=40))
def test_a_valid_message_with_bytes_appended_decodes_only_with_at_most_3_of_padding(message, extra):
    longer = message.to_cdr() + extra
    if len(extra) <= 3:
        assert _same(type(message).from_cdr(longer), message)
    else:
        with pytest.raises(WireError, match=rf"{len(extra)} bytes left over .* expected its end"):
            type(message).from_cdr(longer)


@pytest.mark.parametrize("message", VALID, ids=lambda m: type(m).__name__)
def test_a_valid_message_decodes_from_bytes_bytearray_and_memoryview(message):
    data = message.to_cdr()
    for view in (data, bytearray(data), memoryview(data)):
        assert _same(type(message).from_cdr(view), message)


@pytest.mark.parametrize(
    ("header", "named"),
    [
        (b"\x00\x00\x00\x00", "00 00 00 00"),  # big endian CDR
        (b"\x00\x03\x00\x00", "00 03 00 00"),  # little endian PL_CDR
        (b"\x00\x01\x00", "00 01 00"),
        (b"", "missing"),
    ],
)
def test_a_wrong_encapsulation_header_is_named_with_the_one_expected(header, named):
    body = Twist(1.0, 2.0).to_cdr()[4:]
    data = header + body if len(header) == 4 else header
    with pytest.raises(WireError) as info:
        Twist.from_cdr(data)
    assert str(info.value) == (
        f"geometry_msgs/msg/Twist: encapsulation {named}; expected 00 01 00 00 (CDR, little endian)"
    )


def _clock_frame(frame: bytes, length: int | None = None) -> bytes:
    """A std_msgs/Header: a zero stamp and a frame id of raw bytes."""
    size = len(frame) if length is None else length
    return b"\x00\x01\x00\x00" + bytes(8) + struct.pack("<I", size) + frame


def test_a_string_without_its_nul_is_refused_naming_the_byte():
    with pytest.raises(WireError, match=r"std_msgs/msg/Header: a string of 3 bytes with its NUL"):
        decode_tree(std.HEADER, _clock_frame(b"map"))


def test_a_string_that_is_not_utf8_is_refused():
    with pytest.raises(WireError, match=r"not UTF-8 \(invalid start byte\) at byte 16 of 19"):
        decode_tree(std.HEADER, _clock_frame(b"\xffa\x00"))


def test_an_empty_string_without_even_its_nul_is_refused():
    with pytest.raises(WireError, match="a string of 0 bytes with its NUL"):
        decode_tree(std.HEADER, _clock_frame(b"", 0))


def test_a_count_beyond_the_bytes_is_refused_at_once():
    data = b"\x00\x01\x00\x00" + struct.pack("<I", 2**32 - 1)
    with pytest.raises(WireError, match=r"4294967295 elements in fewer bytes at byte 8 of 8"):
        decode_tree(std.TF_MESSAGE, data)
    with pytest.raises(WireError, match=r"4294967295 float32 cut short"):
        decode_tree(
            std.LASER_SCAN,
            LaserScan(0, "", 0, 0, 0, 0, 0, np.zeros(0, "f4")).to_cdr()[:-4]
            + struct.pack("<I", 2**32 - 1),
        )


def test_a_tree_holds_times_as_ns_strings_numeric_sequences_as_arrays_and_bytes_as_bytes():
    scan = LaserScan(1_000_000_123, "laser", -1.0, 0.5, 0.1, 10.0, 0.1, np.ones(2, "f4"))
    header, *_, ranges, intensities = decode_tree(std.LASER_SCAN, scan.to_cdr())
    assert header == (1_000_000_123, "laser")
    assert isinstance(ranges, np.ndarray) and ranges.dtype == np.float32
    assert ranges.tolist() == [1.0, 1.0] and len(intensities) == 0
    grid = OccupancyGrid(5, "map", 0.05, 2, 1, 0.0, 0.0, bytes([100, 255]))
    *_, data = decode_tree(std.OCCUPANCY_GRID, grid.to_cdr())
    assert data == bytes([100, 255])


def test_a_decoded_scan_keeps_no_return_and_dropout_beams():
    ranges = np.array([np.inf, np.nan, 2.5], "f4")
    back = LaserScan.from_cdr(LaserScan(1, "l", 0.0, 0.1, 0.1, 5.0, 0.1, ranges).to_cdr())
    assert math.isinf(back.ranges_m[0]) and math.isnan(back.ranges_m[1])
    assert back.ranges_m[2] == 2.5 and not back.ranges_m.flags.writeable


def test_an_unknown_marker_shape_is_refused_as_a_wire_error():
    data = bytearray(MarkerArray(0, (Marker("ns", 1, MarkerType.CUBE),)).to_cdr())
    # the marker's type follows its header (stamp, "map"), ns ("ns") and id
    at = data.index(b"ns\x00") + 3 + 1 + 4  # the ns's NUL, its pad to 4, the id
    assert data[at : at + 4] == (1).to_bytes(4, "little")
    data[at : at + 4] = (77).to_bytes(4, "little")
    with pytest.raises(WireError, match="visualization_msgs/msg/MarkerArray: 77 is not a valid"):
        MarkerArray.from_cdr(bytes(data))


def test_an_occupancy_grid_whose_cells_disagree_with_its_size_is_refused():
    data = bytearray(OccupancyGrid(5, "map", 0.05, 2, 1, 0.0, 0.0, bytes(2)).to_cdr())
    width_at = data.index(struct.pack("<II", 2, 1))
    data[width_at : width_at + 4] = struct.pack("<I", 3)
    with pytest.raises(WireError, match=r"nav_msgs/msg/OccupancyGrid: .*3 x 1 cells got 2"):
        OccupancyGrid.from_cdr(bytes(data))
