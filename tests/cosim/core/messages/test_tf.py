"""/clock and /tf as ROS 2 tools read them: one stamp, planar transforms, parent and child."""

import math
import struct

import pytest

from cosim.core.messages import Clock, TFMessage, Transform, std
from cosim.core.messages.decoding import decode_tree

TRANSFORMS = (
    Transform("map", "robot_1/odom", 0.1, -0.2, 0.05),
    Transform("robot_1/odom", "robot_1/base_link", 3.0, 4.0, -1.0),
    Transform("robot_1/base_link", "robot_1/laser", 0.2, 0.0, math.pi),
)


def test_each_transform_is_a_transform_stamped_with_the_messages_stamp():
    (stamped,) = decode_tree(std.TF_MESSAGE, TFMessage(1_000_000_022, TRANSFORMS).to_cdr())
    assert [(header, child) for header, child, _ in stamped] == [
        ((1_000_000_022, t.parent), t.child) for t in TRANSFORMS
    ]


def test_a_transform_is_planar_a_translation_in_the_plane_and_a_rotation_about_z():
    (stamped,) = decode_tree(std.TF_MESSAGE, TFMessage(0, TRANSFORMS[1:2]).to_cdr())
    translation, rotation = stamped[0][2]
    assert translation == (3.0, 4.0, 0.0)
    assert rotation == pytest.approx((0.0, 0.0, math.sin(-0.5), math.cos(-0.5)))


def test_transforms_decode_back_to_their_frames_translation_and_yaw():
    back = TFMessage.from_cdr(TFMessage(22, TRANSFORMS).to_cdr())
    assert back.stamp_ns == 22
    for got, want in zip(back.transforms, TRANSFORMS, strict=True):
        assert isinstance(got, Transform)
        assert got[:4] == want[:4]
        assert math.remainder(got.yaw_rad - want.yaw_rad, 2 * math.pi) == pytest.approx(0.0)


def test_a_message_without_transforms_carries_no_stamp_and_decodes_with_stamp_zero():
    message = TFMessage(22, ())
    assert message.to_cdr() == b"\x00\x01\x00\x00" + bytes(4)
    assert TFMessage.from_cdr(message.to_cdr()) == TFMessage(0, ())


def test_the_clock_is_the_simulation_time_in_seconds_and_nanoseconds():
    data = Clock(3_000_000_007).to_cdr()
    assert Clock.ros_type == "rosgraph_msgs/msg/Clock"
    assert data[4:] == struct.pack("<iI", 3, 7)
    assert Clock.from_cdr(data) == Clock(3_000_000_007)
