"""Navigation goals, their progress and robot states (cosim_msgs), every header in map."""

import math

import pytest

from cosim.core.messages import NavGoal, NavStatus, RobotState


def test_a_goal_without_a_heading_sends_nan_and_gets_it_back():
    goal = NavGoal(3, 2, 1.5, 2.5)
    assert math.isnan(goal.yaw_rad)
    back = NavGoal.from_cdr(goal.to_cdr())
    assert (back.stamp_ns, back.goal_id, back.x_m, back.y_m) == (3, 2, 1.5, 2.5)
    assert math.isnan(back.yaw_rad)
    assert NavGoal.from_cdr(NavGoal(3, 2, 1.5, 2.5, -3.0).to_cdr()).yaw_rad == -3.0


@pytest.mark.parametrize(
    "message",
    [
        NavStatus(3, 2, "progress", 1.0, 2.0, 7.5),
        NavStatus(3, 2**32 - 1, "unreachable", -1.0, 0.0, 0.0),
        RobotState(3, "robot_7", 1.0, 2.0, 0.1, 0.5, 0.33),
    ],
    ids=lambda m: type(m).__name__,
)
def test_a_status_and_a_robot_state_decode_back_to_themselves(message):
    assert type(message).from_cdr(message.to_cdr()) == message


def test_an_unknown_remaining_distance_is_sent_as_nan():
    back = NavStatus.from_cdr(NavStatus(1, 1, "accepted", 0.0, 0.0, math.nan).to_cdr())
    assert math.isnan(back.remaining_m)


@pytest.mark.parametrize(
    ("cls", "text"),
    [
        (NavGoal, "std_msgs/Header header\nuint32 goal_id\nfloat64 x\nfloat64 y\nfloat64 yaw\n"),
        (
            NavStatus,
            "std_msgs/Header header\nuint32 goal_id\nstring state\nfloat64 x\nfloat64 y\n"
            "float64 remaining\n",
        ),
        (
            RobotState,
            "std_msgs/Header header\nstring robot\nfloat64 x\nfloat64 y\nfloat64 yaw\n"
            "float64 v\nfloat64 radius\n",
        ),
    ],
    ids=lambda v: getattr(v, "__name__", ""),
)
def test_each_message_is_its_cosim_msgs_type_with_fields_in_si_units(cls, text):
    assert cls.ros_type == f"cosim_msgs/msg/{cls.__name__}"
    assert cls.wire.msg_text() == text


def test_every_navigation_header_is_in_map():
    for message in (NavGoal(0, 0, 0.0, 0.0), RobotState(0, "r", 0, 0, 0, 0, 0)):
        assert message.to_cdr()[12:20] == b"\x04\x00\x00\x00map\x00"
