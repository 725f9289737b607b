"""A class's values both ways: the declared class a field holds, decoded values as held."""

import enum
from typing import Annotated

import numpy as np

from cosim.core.messages import Float64s, Message, TaskInfo, TaskSet, ros_message, uint8
from cosim.core.messages.binding import ClassBinding, convert, element_class
from cosim.core.messages.wire import UINT8, Sequence


def test_the_element_class_is_the_declared_class_a_field_holds_alone_or_in_a_tuple():
    assert element_class(TaskInfo) is TaskInfo
    assert element_class(tuple[TaskInfo, ...]) is TaskInfo
    assert element_class(Annotated[tuple[TaskInfo, ...], "meta"]) is TaskInfo


def test_a_field_of_no_declared_class_has_no_element_class():
    for hint in (float, str, Float64s, tuple[float, ...], tuple[TaskInfo, TaskInfo], dict):
        assert element_class(hint) is None


def test_decoded_sequences_become_tuples_nested_rows_included():
    assert convert(np.array([1.0, 2.5]), Float64s, None) == (1.0, 2.5)
    assert type(convert(np.array([1.0]), Float64s, None)[0]) is float
    rows = [(0, 1, 2, 3.5), [1, 0, -1, 0.0]]
    assert convert(rows, tuple[tuple[int, int, int, float], ...], None) == (
        (0, 1, 2, 3.5),
        (1, 0, -1, 0.0),
    )


def test_decoded_bytes_are_bytes_for_a_bytes_field_and_numbers_for_a_tuple_field():
    assert convert(b"\x01\x02", bytes, None) == b"\x01\x02"
    assert convert(bytearray(b"\x01"), Annotated[bytes, Sequence(UINT8)], None) == b"\x01"
    assert convert(b"\x01\xff", tuple[int, ...], None) == (1, 255)


class Mode(enum.IntEnum):
    IDLE = 0
    BUSY = 3


def test_a_decoded_integer_becomes_the_member_of_an_enum_field():
    assert convert(3, Mode, None) is Mode.BUSY
    assert convert(0, Annotated[Mode, UINT8], None) is Mode.IDLE


def test_a_decoded_struct_becomes_the_declared_class_and_a_list_of_them_a_tuple():
    info = TaskInfo(3, 1.0, 2.0, ("robot_1",), "robot_1")
    tree = (3, 1.0, 2.0, ["robot_1"], "robot_1")
    assert convert(tree, TaskInfo, TaskInfo) == info
    assert convert([tree, tree], tuple[TaskInfo, ...], TaskInfo) == (info, info)


def test_other_values_pass_through_unchanged():
    assert convert("map", str, None) == "map"
    assert convert(7, int, None) == 7


@ros_message("binding_test_msgs/msg/Status")
class Status(Message):
    mode: Annotated[Mode, UINT8]
    level: uint8


def test_a_declared_class_carries_a_binding_that_builds_its_arguments_from_a_decoded_tree():
    binding = Status._binding  # type: ignore[attr-defined]
    assert isinstance(binding, ClassBinding)
    assert binding.build((3, 9)) == {"mode": Mode.BUSY, "level": 9}
    back = Status.from_cdr(Status(Mode.BUSY, 9).to_cdr())
    assert back.mode is Mode.BUSY
    tree = ((5, "map"), 2, [(3, 1.0, 2.0, [], "")])
    sets = TaskSet._binding.build(tree)  # type: ignore[attr-defined]
    assert sets == {"stamp_ns": 5, "epoch": 2, "tasks": (TaskInfo(3, 1.0, 2.0, ()),)}
