"""ROS 2 names on DDS: the topic prefix and type mangling of rmw_cyclonedds."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

from adapters.ros2dds.naming import dds_topic, dds_type, ros_topic, ros_type

ROS_TOPICS = st.from_regex(r"(/[A-Za-z_][A-Za-z0-9_]{0,8}){1,4}", fullmatch=True)
ROS_TYPES = st.from_regex(
    r"[A-Za-z][A-Za-z0-9_]{0,10}/msg/[A-Za-z][A-Za-z0-9_]{0,10}", fullmatch=True
)


def test_a_ros_topic_gets_the_rt_prefix():
    assert dds_topic("/robot_0/cmd_vel") == "rt/robot_0/cmd_vel"
    assert dds_topic("/clock") == "rt/clock"


def test_a_ros_type_gets_the_dds_namespace_and_a_trailing_underscore():
    assert dds_type("geometry_msgs/msg/Twist") == "geometry_msgs::msg::dds_::Twist_"
    assert ros_type("sensor_msgs::msg::dds_::LaserScan_") == "sensor_msgs/msg/LaserScan"


@pytest.mark.parametrize(
    ("name", "rule"),
    [
        ("robot_0/cmd_vel", "start with '/'"),
        ("/robot_0/", "end with '/'"),
        ("/", "end with '/'"),
        ("/robot_0//cmd_vel", "empty token"),
        ("/robot_0/0scan", "not starting with a digit"),
        ("/robot-0/scan", "letters, digits and '_'"),
        ("/robot 0", "letters, digits and '_'"),
        ("", "start with '/'"),
    ],
)
def test_an_invalid_ros_topic_is_rejected_naming_the_value_and_the_rule(name, rule):
    with pytest.raises(ValueError, match=rule) as caught:
        dds_topic(name)
    assert repr(name) in str(caught.value)


@pytest.mark.parametrize(
    "name", ["geometry_msgs/Twist", "geometry_msgs/srv/Twist", "/geometry_msgs/msg/Twist", ""]
)
def test_an_invalid_ros_type_is_rejected_naming_the_value(name):
    with pytest.raises(ValueError, match="package/msg/Name") as caught:
        dds_type(name)
    assert repr(name) in str(caught.value)


@pytest.mark.parametrize("name", ["geometry_msgs::msg::Twist_", "Twist_", "a::msg::dds_::Twist"])
def test_a_dds_type_that_is_not_ros_is_rejected(name):
    with pytest.raises(ValueError, match="package::msg::dds_::Name_"):
        ros_type(name)


@pytest.mark.parametrize(
    "name", ["rq/robot_0/get_mapRequest", "DCPSParticipant", "rt", "rt/", "rt//a"]
)
def test_a_topic_that_is_not_a_ros_topic_maps_to_none(name):
    assert ros_topic(name) is None


@given(ROS_TOPICS)
def test_valid_topics_round_trip(name):
    assert ros_topic(dds_topic(name)) == name


@given(ROS_TYPES)
def test_valid_types_round_trip(name):
    assert ros_type(dds_type(name)) == name


@given(st.text())
def test_any_text_either_maps_to_a_topic_or_raises_value_error(text):
    try:
        mapped = dds_topic(text)
    except ValueError:
        assert ros_topic("rt" + text) is None
    else:
        assert mapped == "rt" + text
        assert ros_topic(mapped) == text


@given(st.text())
def test_any_text_either_maps_to_a_type_or_raises_value_error(text):
    for convert in (dds_type, ros_type):
        try:
            result = convert(text)
        except ValueError:
            continue
        assert isinstance(result, str)


@given(st.text())
def test_any_dds_topic_maps_to_a_ros_topic_or_none(text):
    assert ros_topic(text) in (None, text[2:])
