"""The wire types as annotations: what each alias is on the wire and what it holds decoded."""

from typing import get_args

import numpy as np
import pytest

from cosim.core.messages import (
    Bytes,
    Duration,
    Float32s,
    Float64s,
    FrameId,
    Header,
    Int32s,
    Message,
    Strings,
    Time,
    bool_,
    float32,
    float64,
    int8,
    int16,
    int32,
    int64,
    ros_message,
    std,
    string,
    uint8,
    uint16,
    uint32,
    uint64,
)
from cosim.core.messages.aliases import HeaderFrame, HeaderStamp
from cosim.core.messages.wire import type_name

SCALARS = {
    "bool": (bool_, bool),
    "int8": (int8, int),
    "uint8": (uint8, int),
    "int16": (int16, int),
    "uint16": (uint16, int),
    "int32": (int32, int),
    "uint32": (uint32, int),
    "int64": (int64, int),
    "uint64": (uint64, int),
    "float32": (float32, float),
    "float64": (float64, float),
    "string": (string, str),
}


@pytest.mark.parametrize("name", SCALARS)
def test_a_scalar_alias_is_its_python_type_to_the_checker_and_its_ros_type_on_the_wire(name):
    alias, python = SCALARS[name]
    held, wire = get_args(alias)
    assert held is python and type_name(wire) == name


@pytest.mark.parametrize(
    ("alias", "name"),
    [
        (Float32s, "float32[]"),
        (Float64s, "float64[]"),
        (Int32s, "int32[]"),
        (Strings, "string[]"),
        (Bytes, "uint8[]"),
        (Time, "builtin_interfaces/Time"),
        (Duration, "builtin_interfaces/Duration"),
    ],
)
def test_a_sequence_or_time_alias_names_its_msg_type(alias, name):
    assert type_name(get_args(alias)[1]) == name


def test_header_and_frame_id_are_markers_not_wire_types():
    assert isinstance(get_args(Header)[1], HeaderStamp) and get_args(Header)[0] is int
    assert isinstance(get_args(FrameId)[1], HeaderFrame) and get_args(FrameId)[0] is str


@ros_message("alias_test_msgs/msg/Everything")
class Everything(Message):
    stamp_ns: Header
    frame: FrameId
    flag: bool_
    small: int8
    byte: uint8
    short: int16
    ushort: uint16
    count: int32
    ucount: uint32
    big: int64
    ubig: uint64
    single: float32
    double: float64
    text: string
    ranges: Float32s
    values: Float64s
    ids: Int32s
    names: Strings
    data: Bytes
    at_ns: Time
    span_ns: Duration


def _everything() -> Everything:
    return Everything(
        stamp_ns=5,
        frame="base",
        flag=True,
        small=-128,
        byte=255,
        short=-32768,
        ushort=65535,
        count=-(2**31),
        ucount=2**32 - 1,
        big=-(2**63),
        ubig=2**64 - 1,
        single=0.5,
        double=-1e300,
        text="ü",
        ranges=np.array([1.5, np.inf], np.float32),
        values=(1.0, -2.0),
        ids=(-1, 7),
        names=("a", "b"),
        data=b"\x00\x7f",
        at_ns=3 * 10**9 + 1,
        span_ns=2 * 10**9,
    )


def test_a_message_of_every_alias_declares_each_as_its_ros_type():
    assert Everything.wire.msg_text().splitlines() == [
        "std_msgs/Header header",
        "bool flag",
        "int8 small",
        "uint8 byte",
        "int16 short",
        "uint16 ushort",
        "int32 count",
        "uint32 ucount",
        "int64 big",
        "uint64 ubig",
        "float32 single",
        "float64 double",
        "string text",
        "float32[] ranges",
        "float64[] values",
        "int32[] ids",
        "string[] names",
        "uint8[] data",
        "builtin_interfaces/Time at",
        "builtin_interfaces/Duration span",
    ]
    assert Everything.wire.field_type("header") is std.HEADER


def test_every_alias_decodes_to_what_it_holds_extremes_included():
    message = _everything()
    back = Everything.from_cdr(message.to_cdr())
    assert isinstance(back.ranges, np.ndarray) and back.ranges.dtype == np.float32
    assert back.ranges.tolist() == [1.5, np.inf]
    assert type(back.values) is tuple and type(back.ids) is tuple and type(back.names) is tuple
    assert type(back.data) is bytes
    expected = {k: getattr(message, k) for k in Everything.__dataclass_fields__ if k != "ranges"}
    assert {k: getattr(back, k) for k in expected} == expected
