"""The wire types: primitives as CDR lays them out, structs as .msg files declare them."""

import struct as _struct

import numpy as np
import pytest

from cosim.core.messages import std
from cosim.core.messages.wire import (
    FLOAT64,
    HEADER,
    INT32,
    NS_PER_S,
    PRIMITIVES,
    STRING,
    UINT8,
    Array,
    Sequence,
    Struct,
    struct,
    type_name,
)


def test_the_encapsulation_header_is_xcdr1_little_endian_without_options():
    assert bytes([0x00, 0x01, 0x00, 0x00]) == HEADER
    assert NS_PER_S == 10**9


@pytest.mark.parametrize("primitive", PRIMITIVES.values(), ids=lambda p: p.name)
def test_every_primitive_is_as_large_as_its_struct_code_and_its_numpy_type(primitive):
    assert _struct.calcsize("<" + primitive.code) == primitive.size
    assert np.dtype(primitive.numpy).itemsize == primitive.size
    assert np.dtype(primitive.numpy).byteorder in ("<", "|", "=")
    assert _struct.unpack("<" + primitive.code, bytes(primitive.size))[0] == primitive.zero


def test_the_primitives_are_those_of_ros_2_by_their_msg_names():
    assert set(PRIMITIVES) == {
        "bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32",
        "int64", "uint64", "float32", "float64",
    }  # fmt: skip
    assert all(name == p.name for name, p in PRIMITIVES.items())


def test_a_struct_is_named_package_msg_name():
    for bad in ("Point", "geometry_msgs/Point", "geometry_msgs/srv/Point", "a//B", "a/msg/"):
        with pytest.raises(ValueError, match=r"expected 'package/msg/Name'"):
            struct(bad, x=FLOAT64)


def test_a_struct_naming_a_field_twice_is_refused():
    with pytest.raises(ValueError, match=r"'t_msgs/msg/T' names a field twice: \['x', 'x'\]"):
        Struct("t_msgs/msg/T", (("x", FLOAT64), ("x", INT32)))


def test_structs_are_equal_only_to_themselves():
    a = struct("t_msgs/msg/Same", x=FLOAT64)
    b = struct("t_msgs/msg/Same", x=FLOAT64)
    assert a == a and a != b


def test_a_field_type_is_found_by_name_and_a_missing_one_names_the_fields_there_are():
    assert std.POINT.field_type("y") is FLOAT64
    with pytest.raises(KeyError, match=r"geometry_msgs/msg/Point has no field 'w'.*'x', 'y', 'z'"):
        std.POINT.field_type("w")


def test_the_msg_text_names_nested_types_as_package_slash_name():
    assert std.POSE_WITH_COVARIANCE.msg_text() == (
        "geometry_msgs/Pose pose\nfloat64[36] covariance\n"
    )
    assert std.PATH.msg_text() == "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n"
    assert std.POSE.short == "geometry_msgs/Pose"


@pytest.mark.parametrize(
    ("kind", "name"),
    [
        (FLOAT64, "float64"),
        (STRING, "string"),
        (Sequence(UINT8), "uint8[]"),
        (Array(FLOAT64, 36), "float64[36]"),
        (Sequence(std.POINT), "geometry_msgs/Point[]"),
        (Array(STRING, 2), "string[2]"),
        (std.TIME, "builtin_interfaces/Time"),
    ],
)
def test_a_field_type_is_named_as_a_msg_file_names_it(kind, name):
    assert type_name(kind) == name


def test_dependencies_are_every_nested_type_depth_first_each_once_without_itself():
    assert [k.ros_type for k in std.ODOMETRY.dependencies()] == [
        "builtin_interfaces/msg/Time",
        "std_msgs/msg/Header",
        "geometry_msgs/msg/Point",
        "geometry_msgs/msg/Quaternion",
        "geometry_msgs/msg/Pose",
        "geometry_msgs/msg/PoseWithCovariance",
        "geometry_msgs/msg/Vector3",
        "geometry_msgs/msg/Twist",
        "geometry_msgs/msg/TwistWithCovariance",
    ]
    assert std.POINT.dependencies() == []
    # through sequences and arrays too
    assert std.POSE_STAMPED in std.PATH.dependencies()


def test_a_struct_declared_field_by_field_keeps_its_order_and_its_defaults():
    kind = struct(
        "t_msgs/msg/Ordered",
        defaults={"w": 1.0},
        z=FLOAT64,
        a=FLOAT64,
        w=FLOAT64,
        nanoseconds=False,
    )
    assert kind.names() == ["z", "a", "w"]
    assert kind.defaults == (("w", 1.0),)
    assert repr(kind) == "t_msgs/msg/Ordered"
