"""Choosing recorded topics with record.topics glob patterns."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

import cosim
from cosim.core.bus import Advertisement, TopicQos
from cosim.core.errors import ConfigError
from cosim.core.messages import Clock, LaserScan, Odometry, Twist
from cosim.recording.selection import select_topics

ADVERTISED = {
    topic: Advertisement(topic, kind, TopicQos.DEFAULT)
    for topic, kind in [
        ("/clock", Clock),
        *((f"/robot_{i}/scan", LaserScan) for i in range(1, 13)),
        *((f"/robot_{i}/odom", Odometry) for i in range(1, 13)),
        *((f"/robot_{i}/cmd_vel", Twist) for i in range(1, 13)),
    ]
}


def _select(*patterns: str) -> list[str]:
    return list(select_topics(patterns, ADVERTISED, origin="s.toml"))


def test_patterns_add_and_exclamation_marks_remove_in_order():
    assert _select("*", "!/robot_*/cmd_vel", "!/robot_*/odom") == [
        "/clock",
        *(f"/robot_{i}/scan" for i in range(1, 13)),
    ]
    assert _select("!/clock", "/clock") == ["/clock"]
    assert _select("/robot_1?/scan") == ["/robot_10/scan", "/robot_11/scan", "/robot_12/scan"]


def test_an_exclusion_matching_nothing_is_allowed():
    assert _select("/clock", "!/fleet/*") == ["/clock"]


def test_a_pattern_matching_nothing_names_itself_and_the_topic_families():
    with pytest.raises(ConfigError) as raised:
        _select("/clock", "/robot_*/lidar")
    message = str(raised.value)
    assert message.startswith("s.toml: [record] topics: pattern '/robot_*/lidar'")
    assert "/robot_*/scan" in message and "/robot_7/scan" not in message


@given(st.lists(st.text(max_size=12), max_size=4))
def test_any_patterns_select_advertised_topics_or_raise_one_line(patterns):
    try:
        chosen = _select(*patterns)
    except ConfigError as error:
        assert "\n" not in str(error)
    else:
        assert set(chosen) <= set(ADVERTISED)


def test_empty_patterns_are_refused_when_the_scenario_loads():
    with pytest.raises(ConfigError, match=r"\[record\] topics = \['\*', '!'\]: expected non-empty"):
        cosim.load_scenario("warehouse-random", overrides={"record.topics": ["*", "!"]})
