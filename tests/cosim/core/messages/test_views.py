"""Views of standard types: bindings onto paths, what is left zero, what decodes back."""

import math
import struct
from typing import NamedTuple

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.core.messages import Const, Each, Message, Outer, Planar, Rows, ros_message, std
from cosim.core.messages.decoding import decode_tree


@ros_message(
    std.POSE_STAMPED,
    wire={
        "header.stamp": "stamp_ns",
        "header.frame_id": Const("view/frame"),
        "pose": Planar("x_m", "y_m", "yaw_rad", z="z_m", yaw_nan=0.25),
    },
)
class Placed(Message):
    stamp_ns: int
    x_m: float
    y_m: float
    yaw_rad: float
    z_m: float = 0.0


def _pose(message: Message) -> tuple[tuple[float, ...], tuple[float, ...]]:
    _, pose = decode_tree(std.POSE_STAMPED, message.to_cdr())
    return pose


def test_a_planar_pose_is_a_position_and_a_rotation_about_z():
    position, rotation = _pose(Placed(1, 2.0, -3.0, math.pi / 2, z_m=0.5))
    assert position == (2.0, -3.0, 0.5)
    assert rotation == pytest.approx((0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)))


@settings(max_examples=60, deadline=None)
@given(yaw=st.floats(-50.0, 50.0), x=st.floats(-1e6, 1e6), y=st.floats(-1e6, 1e6))
def test_a_planar_pose_decodes_to_the_same_position_and_the_yaw_wrapped_to_pi(yaw, x, y):
    back = Placed.from_cdr(Placed(0, x, y, yaw).to_cdr())
    assert (back.x_m, back.y_m) == (x, y)
    assert -math.pi <= back.yaw_rad <= math.pi
    turn = back.yaw_rad - yaw
    assert math.remainder(turn, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)


def test_a_nan_yaw_is_written_as_the_declared_yaw():
    _, rotation = _pose(Placed(0, 0.0, 0.0, math.nan))
    assert rotation == pytest.approx((0.0, 0.0, math.sin(0.125), math.cos(0.125)))


def test_a_constant_is_written_but_not_read_back():
    header, _ = decode_tree(std.POSE_STAMPED, Placed(7, 0.0, 0.0, 0.0).to_cdr())
    assert header == (7, "view/frame")
    assert not hasattr(Placed.from_cdr(Placed(7, 0.0, 0.0, 0.0).to_cdr()), "frame_id")


@ros_message(
    std.TWIST,
    wire={
        "linear.x": "v_mps",
        "linear.y": Const(math.nan),
        "linear.z": Const(np.float64(2.5)),
        "angular.z": "w_radps",
    },
)
class Odd(Message):
    v_mps: float
    w_radps: float


def test_constants_that_are_no_python_literal_are_written_as_they_are():
    linear, angular = decode_tree(std.TWIST, Odd(1.0, -1.0).to_cdr())
    assert linear[0] == 1.0 and math.isnan(linear[1]) and linear[2] == 2.5
    assert angular == (0.0, 0.0, -1.0)


def test_what_a_view_does_not_bind_is_zero_on_the_wire_even_a_quaternions_w():
    @ros_message(std.ODOMETRY, wire={"header.stamp": "stamp_ns"})
    class Bare(Message):
        stamp_ns: int

    data = Bare(10**9 + 1).to_cdr()
    # stamp (1 s, 1 ns), an empty frame id, an empty child frame id, then zeros only
    assert data[4:12] == struct.pack("<iI", 1, 1)
    assert set(data[12:]) <= {0, 1}  # the string lengths (1: the NUL) and zeros
    header, child, (pose, cov), _ = decode_tree(std.ODOMETRY, data)
    assert header == (10**9 + 1, "") and child == ""
    assert pose == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0)) and not cov.any()


class Ping(NamedTuple):
    peer: str
    delay_s: float


@ros_message(
    std.TF_MESSAGE,
    wire={
        "transforms": Each(
            "pings",
            Ping,
            {
                "header.stamp": Outer("stamp_ns"),
                "child_frame_id": "peer",
                "transform.translation.x": "delay_s",
            },
        )
    },
)
class Pings(Message):
    stamp_ns: int
    pings: tuple[Ping, ...]


def test_each_element_becomes_a_struct_carrying_the_enclosing_messages_outer_attribute():
    message = Pings(42, (Ping("a", 0.5), Ping("b", 1.5)))
    (transforms,) = decode_tree(std.TF_MESSAGE, message.to_cdr())
    assert [(t[0], t[1], t[2][0][0]) for t in transforms] == [
        ((42, ""), "a", 0.5),
        ((42, ""), "b", 1.5),
    ]
    assert Pings.from_cdr(message.to_cdr()) == message


def test_an_outer_attribute_decodes_from_the_first_element_and_as_zero_without_one():
    assert Pings.from_cdr(Pings(42, ()).to_cdr()) == Pings(0, ())


def _rows(message: "Track") -> list[tuple[object, ...]]:
    return [((message.stamp_ns, "map"), ((x, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))) for x in message.xs]


def _xs(rows: list[tuple[object, ...]]) -> tuple[float, ...]:
    return tuple(pose[0][0] for _, pose in rows)  # type: ignore[index]


@ros_message(
    std.PATH,
    wire={"header.stamp": "stamp_ns", "poses": Rows("xs", _rows, _xs)},
)
class Track(Message):
    stamp_ns: int
    xs: tuple[float, ...]


def test_rows_are_made_by_a_function_of_the_message_and_decoded_by_another():
    message = Track(3, (1.0, 2.0, 4.0))
    _, poses = decode_tree(std.PATH, message.to_cdr())
    assert [p[0] for p in poses] == [(3, "map")] * 3
    assert Track.from_cdr(message.to_cdr()) == message
    assert Track.from_cdr(Track(3, ()).to_cdr()) == Track(3, ())


@ros_message(
    std.MARKER,
    wire={
        "header.stamp": "stamp_ns",
        "header.frame_id": "frame",
        "scale": "size_m",
        "color": "rgba",
        "lifetime": "stamp_ns",
        "text": "label",
    },
)
class Label(Message):
    stamp_ns: int
    frame: str
    size_m: tuple[float, float, float]
    rgba: tuple[float, float, float, float]

    @property
    def label(self) -> str:
        return f"{self.frame}@{self.stamp_ns}"


def test_a_struct_binds_to_a_tuple_one_attribute_may_fill_two_paths_and_a_property_one():
    message = Label(5, "map", (1.0, 2.0, 0.5), (0.25, 0.5, 0.75, 1.0))
    tree = decode_tree(std.MARKER, message.to_cdr())
    fields = dict(zip(std.MARKER.names(), tree, strict=True))
    assert fields["scale"] == (1.0, 2.0, 0.5)
    assert fields["color"] == (0.25, 0.5, 0.75, 1.0)
    assert fields["lifetime"] == 5 and fields["header"] == (5, "map")
    assert fields["text"] == "map@5"
    assert Label.from_cdr(message.to_cdr()) == message  # the property is not read back
