"""Fleet coordination messages: tasks, claims and service, every header in map."""

import pytest

from cosim.core.messages import (
    ServiceReply,
    ServiceRequest,
    TaskClaim,
    TaskDone,
    TaskInfo,
    TaskSet,
)

TASK_SET = TaskSet(
    13,
    4,
    (TaskInfo(1, 2.0, 3.0, ("robot_1", "robot_2"), "robot_1"), TaskInfo(2, 5.0, 6.0, ())),
)
MESSAGES = [
    TASK_SET,
    TaskSet(13, 0, ()),
    TaskClaim(14, 4, 1, "robot_1", 12.5, "claim"),
    TaskClaim(14, 4, 1, "robot_1", 0.0, "release"),
    ServiceRequest(15, 1, "robot_3"),
    ServiceReply(16, 1, "robot_3", True),
    ServiceReply(16, 1, "robot_3", False),
    TaskDone(17, 1, "robot_3"),
]


@pytest.mark.parametrize("message", MESSAGES, ids=lambda m: type(m).__name__)
def test_a_coordination_message_decodes_back_to_itself(message):
    assert type(message).from_cdr(message.to_cdr()) == message


@pytest.mark.parametrize("message", MESSAGES, ids=lambda m: type(m).__name__)
def test_a_coordination_message_is_stamped_in_map(message):
    assert message.to_cdr()[12:20] == b"\x04\x00\x00\x00map\x00"  # after the stamp


@pytest.mark.parametrize(
    ("cls", "text"),
    [
        (TaskInfo, "uint32 task_id\nfloat64 x\nfloat64 y\nstring[] eligible\nstring holder\n"),
        (TaskSet, "std_msgs/Header header\nuint32 epoch\ncosim_msgs/TaskInfo[] tasks\n"),
        (
            TaskClaim,
            "std_msgs/Header header\nuint32 epoch\nuint32 task_id\nstring robot\n"
            "float64 cost\nstring state\n",
        ),
        (ServiceRequest, "std_msgs/Header header\nuint32 task_id\nstring robot\n"),
        (ServiceReply, "std_msgs/Header header\nuint32 task_id\nstring robot\nbool granted\n"),
        (TaskDone, "std_msgs/Header header\nuint32 task_id\nstring robot\n"),
    ],
    ids=lambda v: getattr(v, "__name__", ""),
)
def test_each_message_is_its_cosim_msgs_type_with_fields_in_si_units(cls, text):
    assert cls.ros_type == f"cosim_msgs/msg/{cls.__name__}"
    assert cls.wire.msg_text() == text


def test_a_task_nobody_holds_has_an_empty_holder():
    assert TaskInfo(2, 5.0, 6.0, ()).holder == ""
    back = TaskSet.from_cdr(TASK_SET.to_cdr())
    assert [t.holder for t in back.tasks] == ["robot_1", ""]
    assert back.tasks[0].eligible == ("robot_1", "robot_2")
