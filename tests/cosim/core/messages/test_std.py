"""ROS 2's standard types as declared here are field for field those of Humble and Jazzy."""

import pytest
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Nodetype

from cosim.core.messages import std
from cosim.core.messages.wire import Array, Primitive, Sequence, Struct, Text, WireType

STORES = {
    "humble": get_typestore(Stores.ROS2_HUMBLE),
    "jazzy": get_typestore(Stores.ROS2_JAZZY),
}


def _fielddef(kind: WireType) -> tuple[object, object]:
    """A declared field type as rosbags' type store writes it."""
    if isinstance(kind, Primitive | Text):
        return (Nodetype.BASE, (kind.name, 0))
    if isinstance(kind, Struct):
        return (Nodetype.NAME, kind.ros_type)
    if isinstance(kind, Sequence):
        return (Nodetype.SEQUENCE, (_fielddef(kind.element), 0))
    assert isinstance(kind, Array)
    return (Nodetype.ARRAY, (_fielddef(kind.element), kind.length))


JAZZY_ADDS = {"sensor_msgs/msg/Range": [("variance", (Nodetype.BASE, ("float32", 0)))]}
"""Fields Jazzy appends to a Humble type (Jazzy's sensor_msgs/Range adds a ``variance``).

The declarations are Humble's, which the bags embed (:func:`cosim.recording.schemas.typestore`);
a Humble message is a prefix of the Jazzy one."""


@pytest.mark.parametrize("kind", std.STANDARD, ids=lambda k: k.ros_type)
def test_every_standard_type_has_exactly_the_fields_of_ros_2_humble(kind):
    _, fields = STORES["humble"].fielddefs[kind.ros_type]
    ours = [(name, _fielddef(field_kind)) for name, field_kind in kind.fields]
    assert ours == list(fields)


@pytest.mark.parametrize("kind", std.STANDARD, ids=lambda k: k.ros_type)
def test_every_standard_type_has_exactly_the_fields_of_ros_2_jazzy_but_for_what_jazzy_appends(
    kind,
):
    _, fields = STORES["jazzy"].fielddefs[kind.ros_type]
    ours = [(name, _fielddef(field_kind)) for name, field_kind in kind.fields]
    assert ours + JAZZY_ADDS.get(kind.ros_type, []) == list(fields)


def test_humble_and_jazzy_differ_in_no_standard_type_but_those_named():
    humble, jazzy = STORES["humble"].fielddefs, STORES["jazzy"].fielddefs
    differ = {k.ros_type for k in std.STANDARD if humble[k.ros_type][1] != jazzy[k.ros_type][1]}
    assert differ == set(JAZZY_ADDS)


def test_the_standard_types_are_declared_once_each():
    names = [kind.ros_type for kind in std.STANDARD]
    assert len(names) == len(set(names))
    module_types = [v for v in vars(std).values() if isinstance(v, Struct)]
    assert set(map(id, module_types)) == set(map(id, std.STANDARD))


def test_every_type_a_standard_type_nests_is_the_declared_standard_type_itself():
    declared = {kind.ros_type: kind for kind in std.STANDARD}
    for kind in std.STANDARD:
        for nested in kind.dependencies():
            assert declared[nested.ros_type] is nested, (kind.ros_type, nested.ros_type)


def test_times_and_durations_are_integer_nanoseconds_and_nothing_else_is():
    assert {k.ros_type for k in std.STANDARD if k.nanoseconds} == {
        "builtin_interfaces/msg/Time",
        "builtin_interfaces/msg/Duration",
    }


def test_a_quaternion_left_unset_is_the_identity_rotation():
    assert dict(std.QUATERNION.defaults) == {"w": 1.0}
    assert all(not k.defaults for k in std.STANDARD if k is not std.QUATERNION)


@pytest.mark.parametrize("kind", [std.ODOMETRY, std.MARKER, std.LASER_SCAN], ids=repr)
def test_the_msg_text_of_a_standard_type_lists_its_fields_as_ros_2_names_them(kind):
    store = STORES["humble"]
    text, _ = store.generate_msgdef(kind.ros_type, ros_version=2)
    own = text.split("=" * 80)[0]
    lines = [line.split("#")[0].strip() for line in own.splitlines()]
    fields = [line for line in lines if line and "=" not in line]
    assert fields == kind.msg_text().splitlines()
