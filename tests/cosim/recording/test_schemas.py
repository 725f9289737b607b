"""A recorded topic's channel: its type's ``.msg`` definition, RIHS01 hash and offered QoS."""

from __future__ import annotations

import re

import numpy as np
import pytest
from rosbags.interfaces import QosDurability, QosHistory, QosLiveliness, QosReliability

from cosim.core.bus import Advertisement, TopicQos
from cosim.core.messages import (
    Float64s,
    Header,
    Message,
    OccupancyGrid,
    Twist,
    float64,
    ros_message,
    string,
    uint32,
)
from cosim.recording.schemas import (
    INFINITE,
    ChannelSpec,
    channel_specs,
    definition,
    offered_qos,
    recorded_qos,
    register,
    typestore,
)


@ros_message("testkit_msgs/msg/Reading")
class Reading(Message):
    """A plugin's own message, nested in another."""

    sensor: string
    range_m: float64


@ros_message("testkit_msgs/msg/Survey")
class Survey(Message):
    """A plugin's own message: a header, a number, nested messages and a sequence."""

    stamp_ns: Header
    epoch: uint32
    readings: tuple[Reading, ...]
    costs_m: Float64s


SURVEY = Survey(1_500_000_007, 3, (Reading("left", 1.5), Reading("right", 2.25)), (1.0, 2.5))
RIHS01 = re.compile(r"RIHS01_[0-9a-f]{64}")


def test_a_plugin_message_and_the_types_it_nests_are_registered_from_their_declaration():
    register(Survey.wire)
    store = typestore()
    assert {"testkit_msgs/msg/Survey", "testkit_msgs/msg/Reading"} <= set(store.fielddefs)
    register(Survey.wire)  # again: nothing changes
    assert typestore() is store


def test_a_plugin_message_s_definition_appends_every_nested_definition():
    register(Survey.wire)
    text, digest = definition("testkit_msgs/msg/Survey")
    own, *nested = text.split("=" * 80 + "\n")
    assert own == (
        "std_msgs/Header header\nuint32 epoch\ntestkit_msgs/Reading[] readings\nfloat64[] costs\n"
    )
    assert [part.splitlines()[0] for part in nested] == [
        "MSG: std_msgs/Header",
        "MSG: builtin_interfaces/Time",
        "MSG: testkit_msgs/Reading",
    ]
    assert "string sensor\nfloat64 range" in nested[-1]
    assert RIHS01.fullmatch(digest)
    assert definition("testkit_msgs/msg/Survey") == (text, digest)


def test_a_plugin_message_round_trips_through_the_type_store():
    register(Survey.wire)
    store = typestore()
    decoded = store.deserialize_cdr(SURVEY.to_cdr(), Survey.ros_type)
    assert (decoded.header.stamp.sec, decoded.header.stamp.nanosec) == (1, 500_000_007)
    assert decoded.epoch == 3
    assert [(r.sensor, r.range) for r in decoded.readings] == [("left", 1.5), ("right", 2.25)]
    np.testing.assert_array_equal(decoded.costs, [1.0, 2.5])
    again = store.serialize_cdr(decoded, Survey.ros_type)
    assert again == SURVEY.to_cdr()
    assert Survey.from_cdr(again) == SURVEY


def test_a_standard_type_keeps_humble_s_definition_and_hash():
    text, digest = definition("geometry_msgs/msg/Twist")
    expected, _ = typestore().generate_msgdef("geometry_msgs/msg/Twist", ros_version=2)
    assert text == expected
    assert text.startswith("geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n")
    # the type hash ROS 2's rosidl gives geometry_msgs/msg/Twist (ros2 topic info -v)
    assert digest == "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"


def test_the_channels_of_advertised_topics_come_in_their_order_with_type_and_qos():
    topics = {
        "/survey": Advertisement("/survey", Survey, TopicQos.SENSOR),
        "/robot_1/cmd_vel": Advertisement("/robot_1/cmd_vel", Twist, TopicQos.DEFAULT),
        "/map": Advertisement("/map", OccupancyGrid, TopicQos.LATCHED),
    }
    specs = channel_specs(topics)
    assert [s.topic for s in specs] == ["/survey", "/robot_1/cmd_vel", "/map"]
    assert [s.msgtype for s in specs] == [
        "testkit_msgs/msg/Survey",
        "geometry_msgs/msg/Twist",
        "nav_msgs/msg/OccupancyGrid",
    ]
    assert [s.qos for s in specs] == [TopicQos.SENSOR, TopicQos.DEFAULT, TopicQos.LATCHED]
    for spec in specs:
        assert isinstance(spec, ChannelSpec)
        assert (spec.msgdef, spec.rihs01) == definition(spec.msgtype)
    assert channel_specs({}) == []


def test_only_a_latched_topic_is_recorded_with_a_profile_transient_local_keep_last_1():
    (latched,) = recorded_qos(TopicQos.LATCHED)
    assert latched.durability is QosDurability.TRANSIENT_LOCAL
    assert latched.reliability is QosReliability.RELIABLE
    assert (latched.history, latched.depth) == (QosHistory.KEEP_LAST, 1)
    assert recorded_qos(TopicQos.DEFAULT) == [] and recorded_qos(TopicQos.SENSOR) == []


@pytest.mark.parametrize(
    ("qos", "reliability", "durability", "depth"),
    [
        (TopicQos.DEFAULT, QosReliability.RELIABLE, QosDurability.VOLATILE, 10),
        (TopicQos.SENSOR, QosReliability.BEST_EFFORT, QosDurability.VOLATILE, 5),
        (TopicQos.LATCHED, QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL, 1),
    ],
)
def test_the_offered_profile_is_rclcpp_s_for_such_a_topic(qos, reliability, durability, depth):
    profile = offered_qos(qos)
    assert (profile.reliability, profile.durability, profile.depth) == (
        reliability,
        durability,
        depth,
    )
    assert profile.history is QosHistory.KEEP_LAST
    assert profile.liveliness is QosLiveliness.AUTOMATIC
    assert profile.deadline == profile.lifespan == profile.liveliness_lease_duration == INFINITE
    assert (INFINITE.sec, INFINITE.nsec) == (2_147_483_647, 4_294_967_295)
