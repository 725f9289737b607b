"""A plugin's message declared once: on the bus, in CDR, in a bag any tool reads."""

import dataclasses
import math
from dataclasses import field

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from cosim.core.bus import Advertisement, TopicQos
from cosim.core.errors import WireError
from cosim.core.messages import (
    Bytes,
    Const,
    Float32s,
    Float64s,
    FrameId,
    Header,
    Message,
    Planar,
    Strings,
    bool_,
    float64,
    int32,
    ros_message,
    std,
    string,
    uint32,
)
from cosim.recording.bag import BagSink
from cosim.recording.schemas import channel_specs
from tests.bags import mcap_file, read_mcap


@ros_message("labkit_test_msgs/msg/Reading")
class Reading(Message):
    name: string
    value_m: float64
    valid: bool_ = True


@ros_message("labkit_test_msgs/msg/Sample", frame_id="labkit/base_link")
class Sample(Message):
    stamp_ns: Header
    count: uint32
    label: string
    values_m: Float64s
    readings: tuple[Reading, ...]
    best: Reading
    offset: int32 = -3
    blob: Bytes = b""


SAMPLE = Sample(
    1_700_000_000_123_456_789,
    7,
    "bench ü",
    (0.5, -1.25, math.pi),
    (Reading("left", 0.25), Reading("right", 4.0, valid=False), Reading("", -0.0)),
    Reading("best", 1e-3),
    offset=-40_000,
    blob=bytes([0, 1, 255]),
)
EMPTY = Sample(0, 0, "", (), (), Reading("", 0.0))


@pytest.mark.parametrize("message", [SAMPLE, EMPTY], ids=["full", "empty"])
def test_a_declared_message_round_trips_through_its_cdr(message):
    assert Sample.from_cdr(message.to_cdr()) == message


@pytest.mark.parametrize("message", [SAMPLE, EMPTY], ids=["full", "empty"])
def test_a_declared_message_reports_the_length_of_its_encoding_as_its_size(message):
    data = message.to_cdr()
    assert len(data) == message.size_bytes()
    assert data[:4] == b"\x00\x01\x00\x00"


def test_the_declared_type_is_the_classes_fields_with_their_wire_names_and_types():
    assert Sample.ros_type == "labkit_test_msgs/msg/Sample"
    assert Sample.wire.msg_text() == (
        "std_msgs/Header header\n"
        "uint32 count\n"
        "string label\n"
        "float64[] values\n"
        "labkit_test_msgs/Reading[] readings\n"
        "labkit_test_msgs/Reading best\n"
        "int32 offset\n"
        "uint8[] blob\n"
    )
    assert Reading.wire.msg_text() == "string name\nfloat64 value\nbool valid\n"
    assert [k.ros_type for k in Sample.wire.dependencies()] == [
        "builtin_interfaces/msg/Time",
        "std_msgs/msg/Header",
        "labkit_test_msgs/msg/Reading",
    ]


def test_a_header_field_is_the_stamp_of_a_header_in_the_declared_frame():
    assert Sample.wire.field_type("header") is std.HEADER
    assert "stamp_ns" not in Sample.wire.names()
    # the frame rides in the header on the wire although no attribute holds it
    assert b"labkit/base_link\x00" in SAMPLE.to_cdr()


def test_a_declared_message_is_a_frozen_slotted_dataclass():
    assert dataclasses.is_dataclass(Sample)
    assert set(Sample.__slots__) >= {f.name for f in dataclasses.fields(Sample)}
    with pytest.raises(dataclasses.FrozenInstanceError):
        SAMPLE.count = 8  # type: ignore[misc]


@pytest.fixture(scope="module")
def sample_bag(tmp_path_factory):
    path = tmp_path_factory.mktemp("declared") / "bag"
    sink = BagSink(path, storage="mcap", compression="none")
    topic = "/labkit/sample"
    sink.open(channel_specs({topic: Advertisement(topic, Sample, TopicQos.DEFAULT)}))
    sink.write(0, 5, SAMPLE.to_cdr())
    sink.write(0, 6, EMPTY.to_cdr())
    sink.close()
    return path


def _assert_decoded_is(decoded, message: Sample) -> None:
    stamp = decoded.header.stamp
    assert stamp.sec * 10**9 + stamp.nanosec == message.stamp_ns
    assert decoded.header.frame_id == "labkit/base_link"
    assert (decoded.count, decoded.label, decoded.offset) == (
        message.count,
        message.label,
        message.offset,
    )
    assert list(decoded.values) == list(message.values_m)
    assert bytes(decoded.blob) == message.blob
    readings = [(r.name, r.value, r.valid) for r in decoded.readings]
    assert readings == [(r.name, r.value_m, r.valid) for r in message.readings]
    best = decoded.best
    assert (best.name, best.value, best.valid) == (
        message.best.name,
        message.best.value_m,
        message.best.valid,
    )


def test_a_declared_message_round_trips_through_a_bag_read_by_rosbags(sample_bag):
    with AnyReader([sample_bag]) as reader:
        (connection,) = reader.connections
        assert connection.msgtype == "labkit_test_msgs/msg/Sample"
        rows = list(reader.messages())
        decoded = [reader.deserialize(raw, connection.msgtype) for _, _, raw in rows]
        assert [Sample.from_cdr(raw) for _, _, raw in rows] == [SAMPLE, EMPTY]
    assert [t for _, t, _ in rows] == [5, 6]
    for got, want in zip(decoded, [SAMPLE, EMPTY], strict=True):
        _assert_decoded_is(got, want)


def test_a_declared_message_round_trips_through_a_bag_read_by_the_mcap_library(sample_bag):
    bag = read_mcap(mcap_file(sample_bag))
    assert bag.types == {"/labkit/sample": "labkit_test_msgs/msg/Sample"}
    assert bag.log_ns["/labkit/sample"] == [5, 6]
    for got, want in zip(bag.messages["/labkit/sample"], [SAMPLE, EMPTY], strict=True):
        _assert_decoded_is(got, want)


# -- names, frames and attributes left off the wire ------------------------------------------
@ros_message("labkit_test_msgs/msg/Framed")
class Framed(Message):
    stamp_ns: Header
    frame: FrameId
    speed_mps: float64 = field(metadata={"wire": "velocity"})
    ranges_m: Float32s = field(default_factory=lambda: np.zeros(0, np.float32))
    tags: Strings = ()
    cache: dict[str, int] = field(default_factory=dict, metadata={"wire": False})


def test_a_frame_id_field_is_the_header_frame_and_a_wire_name_replaces_the_unit_suffix():
    assert Framed.wire.msg_text() == (
        "std_msgs/Header header\nfloat64 velocity\nfloat32[] ranges\nstring[] tags\n"
    )
    message = Framed(3, "robot_2/odom", 1.5, np.array([1.0, np.inf], np.float32), ("a", "b"))
    back = Framed.from_cdr(message.to_cdr())
    assert (back.stamp_ns, back.frame, back.speed_mps, back.tags) == (
        3,
        "robot_2/odom",
        1.5,
        ("a", "b"),
    )
    assert back.ranges_m.dtype == np.float32 and back.ranges_m.tolist() == [1.0, np.inf]


def test_a_field_marked_off_the_wire_is_not_sent_and_comes_back_as_its_default():
    message = Framed(3, "map", 0.0, cache={"kept": 1})
    assert "cache" not in Framed.wire.names()
    assert Framed.from_cdr(message.to_cdr()).cache == {}


# -- a view of a standard type -----------------------------------------------------------------
@ros_message(
    std.POSE_STAMPED,
    wire={
        "header.stamp": "stamp_ns",
        "header.frame_id": Const("labkit/dock"),
        "pose": Planar("x_m", "y_m", "yaw_rad"),
    },
)
class Dock(Message):
    stamp_ns: int
    x_m: float
    y_m: float
    yaw_rad: float


def test_a_plugin_view_of_a_standard_type_is_sent_as_that_type_and_decodes_back():
    dock = Dock(9, 1.0, -2.0, 0.75)
    assert Dock.ros_type == "geometry_msgs/msg/PoseStamped" and Dock.wire is std.POSE_STAMPED
    back = Dock.from_cdr(dock.to_cdr())
    assert (back.stamp_ns, back.x_m, back.y_m) == (9, 1.0, -2.0)
    assert back.yaw_rad == pytest.approx(0.75)
    assert b"labkit/dock\x00" in dock.to_cdr()


# -- declaration errors -----------------------------------------------------------------------
def test_an_int_field_without_a_width_is_refused_naming_the_class_and_field():
    with pytest.raises(WireError, match=r"Counter\.count: annotation .*int.* no wire type") as info:

        @ros_message("labkit_test_msgs/msg/Counter")
        class Counter(Message):
            count: int

    assert "uint32" in str(info.value)  # says what was expected


def test_a_field_of_an_undeclared_class_is_refused_naming_the_class_and_field():
    class Plain:
        pass

    with pytest.raises(WireError, match=r"Holder\.thing"):

        @ros_message("labkit_test_msgs/msg/Holder")
        class Holder(Message):
            thing: Plain


def test_a_view_binding_a_path_the_type_does_not_have_is_refused_naming_class_and_field():
    with pytest.raises(WireError, match=r"Spin: wire path 'angular\.w'.*has no field 'w'"):

        @ros_message(std.TWIST, wire={"angular.w": "w_radps"})
        class Spin(Message):
            w_radps: float


def test_a_view_path_into_a_primitive_is_refused():
    with pytest.raises(WireError, match=r"Deep: wire path 'linear\.x\.y' goes into float64"):

        @ros_message(std.TWIST, wire={"linear.x.y": "v_mps"})
        class Deep(Message):
            v_mps: float


def test_a_view_leaving_a_required_field_unbound_is_refused_naming_it():
    with pytest.raises(WireError, match=r"Half: fields \['w_radps'\] are bound to no path"):

        @ros_message(std.TWIST, wire={"linear.x": "v_mps"})
        class Half(Message):
            v_mps: float
            w_radps: float


def test_a_view_binding_an_attribute_the_class_does_not_have_is_refused_naming_it():
    with pytest.raises(WireError, match=r"Typo: wire\['linear\.x'\] binds 'v_mp', no attribute"):

        @ros_message(std.TWIST, wire={"linear.x": "v_mp"})
        class Typo(Message):
            v_mps: float = 0.0


def test_a_type_name_that_is_not_package_msg_name_is_refused_naming_the_class():
    with pytest.raises(WireError, match=r"Loose: message type 'Loose'.*'package/msg/Name'"):

        @ros_message("Loose")
        class Loose(Message):
            value: float64


def test_two_fields_with_one_wire_name_are_refused():
    with pytest.raises(WireError, match=r"Twice: .* names a field twice"):

        @ros_message("labkit_test_msgs/msg/Twice")
        class Twice(Message):
            cost_m: float64
            cost: float64


def test_a_message_class_not_declared_says_so_instead_of_encoding():
    class Undeclared(Message):
        pass

    with pytest.raises(WireError, match="Undeclared is not declared with @ros_message"):
        Undeclared().to_cdr()
    with pytest.raises(WireError, match="Undeclared is not declared"):
        Undeclared().size_bytes()
    with pytest.raises(WireError, match="Undeclared is not declared"):
        Undeclared.from_cdr(b"\x00\x01\x00\x00")


@ros_message("labkit_test_msgs/msg/Checked")
class Checked(Message):
    low: int32
    high: int32

    def __post_init__(self) -> None:
        if self.low > self.high:
            raise ValueError(f"low {self.low} above high {self.high}")


def test_bytes_the_class_refuses_to_hold_are_a_wire_error_naming_the_type():
    data = bytearray(Checked(1, 2).to_cdr())
    data[4:8] = (5).to_bytes(4, "little")
    with pytest.raises(WireError, match=r"labkit_test_msgs/msg/Checked: low 5 above high 2"):
        Checked.from_cdr(bytes(data))


@pytest.mark.parametrize("derived", ["size_bytes", "to_cdr", "from_cdr"])
def test_a_message_defining_its_own_size_or_encoding_is_refused_when_declared(derived):
    # the declaration would replace it silently; a size of one's own could disagree with
    # the bytes the bag records and the network model sizes
    body = {"__annotations__": {"stamp_ns": "uint32"}, derived: lambda self: 0}
    with pytest.raises(WireError) as refused:
        ros_message("padded_msgs/msg/Padded")(type("Padded", (Message,), body))
    assert f"Padded defines {derived}(): a declared message's size, encoding and decoding" in (
        str(refused.value)
    )
    assert str(refused.value).endswith(f"expected no {derived} of its own")
