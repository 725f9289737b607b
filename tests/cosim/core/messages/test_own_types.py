"""Types of one's own: a class's fields are the type's, named without their unit suffixes."""

from dataclasses import field
from typing import Annotated

import pytest

from cosim.core.errors import WireError
from cosim.core.messages import Message, ros_message, std
from cosim.core.messages.own_types import UNIT_SUFFIXES, wire_name
from cosim.core.messages.wire import STRING, Array
from cosim.recording.schemas import register, typestore


@pytest.mark.parametrize("suffix", UNIT_SUFFIXES)
def test_every_unit_suffix_is_dropped_on_the_wire(suffix):
    assert wire_name(f"speed{suffix}", {}) == "speed"


@pytest.mark.parametrize(
    ("name", "wire"),
    [
        ("accel_mps2", "accel"),
        ("area_m2", "area"),
        ("rssi_dbm", "rssi"),
        ("gain_db", "gain"),
        ("rate_hz", "rate"),
        ("heading_deg", "heading"),
        ("epoch", "epoch"),
        ("robots", "robots"),  # a plural is not a unit
        ("_m", "_m"),  # a suffix alone is a name
        ("item_s_count", "item_s_count"),
    ],
)
def test_a_field_name_loses_only_a_trailing_unit_suffix(name, wire):
    assert wire_name(name, {}) == wire


def test_a_wire_name_given_in_the_metadata_wins():
    assert wire_name("cost_m", {"wire": "distance"}) == "distance"
    assert wire_name("cost_m", {"wire": True}) == "cost"  # only a string names it


@ros_message("own_test_msgs/msg/Plain")
class Plain(Message):
    ratio: float
    label: str
    ok: bool
    raw: bytes
    weights: tuple[float, ...]
    names: tuple[str, ...]


def test_plain_python_types_are_float64_string_bool_and_uint8_sequences():
    assert Plain.wire.msg_text() == (
        "float64 ratio\nstring label\nbool ok\nuint8[] raw\nfloat64[] weights\nstring[] names\n"
    )
    message = Plain(0.25, "x", True, b"\x00\xff", (1.0, 2.0), ("a", ""))
    assert Plain.from_cdr(message.to_cdr()) == message


@pytest.mark.parametrize(
    "hint",
    [int, tuple[float, float], tuple[tuple[float, ...], ...], list[float], dict[str, float]],
    ids=repr,
)
def test_an_annotation_without_a_wire_type_is_refused_saying_what_would_do(hint):
    with pytest.raises(WireError, match=r"Odd\.value: annotation .* has no wire type; expected"):
        ros_message("own_test_msgs/msg/Odd")(
            type("Odd", (Message,), {"__annotations__": {"value": hint}})
        )


Point3 = tuple[float, float, float]


@ros_message("own_test_msgs/msg/Corners")
class Corners(Message):
    name: str
    corners: Annotated[tuple[Point3, ...], Array(std.POINT, 2)]
    tags: Annotated[tuple[str, ...], Array(STRING, 2)] = ("", "")


def test_a_fixed_array_of_structs_encodes_as_rosbags_does_and_decodes_back():
    message = Corners("dock", ((1.0, 2.0, 3.0), (-4.0, 5.0, 0.5)), ("left", "right"))
    assert Corners.wire.msg_text() == (
        "string name\ngeometry_msgs/Point[2] corners\nstring[2] tags\n"
    )
    register(Corners.wire)
    store = typestore()
    decoded = store.deserialize_cdr(message.to_cdr(), Corners.ros_type)
    assert [(p.x, p.y, p.z) for p in decoded.corners] == list(message.corners)
    assert store.serialize_cdr(decoded, Corners.ros_type) == message.to_cdr()
    assert len(message.to_cdr()) == message.size_bytes()
    assert Corners.from_cdr(message.to_cdr()) == message


def test_a_fixed_array_left_unset_is_zeros():
    unset = Corners("z", ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
    assert Corners.from_cdr(unset.to_cdr()).tags == ("", "")


@ros_message("own_test_msgs/msg/Leaf")
class Leaf(Message):
    value_m: float


@ros_message("own_test_msgs/msg/Tree")
class Tree(Message):
    root: Leaf
    leaves: tuple[Leaf, ...]
    note: str = field(default="", metadata={"wire": "comment"})


def test_declared_classes_nest_alone_and_in_sequences_and_decode_as_their_class():
    tree = Tree(Leaf(1.0), (Leaf(2.0), Leaf(3.0)), note="n")
    assert Tree.wire.msg_text() == (
        "own_test_msgs/Leaf root\nown_test_msgs/Leaf[] leaves\nstring comment\n"
    )
    back = Tree.from_cdr(tree.to_cdr())
    assert back == tree and isinstance(back.root, Leaf) and isinstance(back.leaves[0], Leaf)
