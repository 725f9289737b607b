"""Assignment-protocol messages: simplex bases, CBBA bids, orders and decisions."""

import math

import pytest

from cosim.core.messages import CbbaBids, SimplexBasis, TaskAssignment, TaskOrder
from cosim.core.messages.assignment import SIMPLEX_COLUMN
from cosim.core.messages.decoding import decode_tree

MESSAGES = [
    SimplexBasis(18, 4, "robot_1", 3, ((0, 1, 2, 3.5), (1, 0, -1, 1e6), (2, -1, 4, 0.0))),
    SimplexBasis(18, 4, "robot_1", 0, ()),
    CbbaBids(19, 4, "robot_2", (1.0, 2.5, -0.0), (0, -1, 2)),
    CbbaBids(19, 4, "robot_2", (), ()),
    TaskOrder(20, 4, "robot_2", -1, 0.0),
    TaskAssignment(21, 4, "robot_2", 3, 8.25, 6),
]


@pytest.mark.parametrize("message", MESSAGES, ids=lambda m: type(m).__name__)
def test_an_assignment_message_decodes_back_to_itself(message):
    assert type(message).from_cdr(message.to_cdr()) == message


def test_a_basis_column_is_a_simplex_column_struct_of_kind_robot_task_and_cost():
    assert SIMPLEX_COLUMN.msg_text() == "uint8 kind\nint32 robot\nint32 task\nfloat64 cost\n"
    assert SimplexBasis.wire.msg_text() == (
        "std_msgs/Header header\nuint32 epoch\nstring robot\nuint32 round\n"
        "cosim_msgs/SimplexColumn[] columns\n"
    )
    *_, columns = decode_tree(SimplexBasis.wire, MESSAGES[0].to_cdr())
    assert columns == [(0, 1, 2, 3.5), (1, 0, -1, 1e6), (2, -1, 4, 0.0)]


def test_bids_and_winners_are_float64_and_int32_sequences_held_as_tuples():
    assert CbbaBids.wire.msg_text().endswith("float64[] bids\nint32[] winners\n")
    back = CbbaBids.from_cdr(MESSAGES[2].to_cdr())
    assert type(back.bids) is tuple and type(back.winners) is tuple
    assert back.winners == (0, -1, 2)


def test_no_task_is_minus_one_and_no_cost_is_nan():
    back = TaskAssignment.from_cdr(TaskAssignment(1, 2, "robot_1", -1, math.nan, 0).to_cdr())
    assert back.task_id == -1 and math.isnan(back.cost_m)
    assert TaskOrder.wire.msg_text() == (
        "std_msgs/Header header\nuint32 epoch\nstring robot\nint32 task_id\nfloat64 cost\n"
    )
    assert TaskAssignment.wire.msg_text().endswith("float64 cost\nuint32 rounds\n")


@pytest.mark.parametrize("message", MESSAGES, ids=lambda m: type(m).__name__)
def test_every_assignment_header_is_in_map(message):
    assert message.to_cdr()[12:20] == b"\x04\x00\x00\x00map\x00"
