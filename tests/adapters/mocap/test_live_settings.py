"""The live sources' settings are checked before a run: patterns, systems, hosts, waits."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim import load_scenario
from cosim.core.errors import ConfigError
from tests.conftest import cosim_main

ROS2 = {"mocap.source": "ros2", "physical.robots": ["robot_1"]}


def scenario(**overrides: object):
    return load_scenario("lab-room", overrides)


def test_a_topic_pattern_with_an_unknown_token_names_the_key_the_value_and_the_known_tokens():
    with pytest.raises(ConfigError) as caught:
        scenario(**ROS2, **{"mocap.topic_pattern": "/{robot}/{body}"})
    assert str(caught.value) == (
        "--set mocap.topic_pattern: [mocap] topic_pattern = '/{robot}/{body}': expected only "
        "the tokens {robot} (not {body})"
    )


def test_cosim_check_refuses_an_unknown_token_in_one_line():
    done = cosim_main("check", "lab-mixed", "--set", 'mocap.topic_pattern="/{name}/pose"')
    assert done.returncode == 2
    assert done.stderr == (
        "cosim: error: --set mocap.topic_pattern: [mocap] topic_pattern = '/{name}/pose': "
        "expected only the tokens {robot} (not {name})\n"
    )


@pytest.mark.parametrize(
    ("pattern", "expected"),
    [
        ("/{robot/pose", "braces only around a token ({robot})"),
        ("/{robot!r}/pose", "only the tokens {robot} (not {robot!r})"),
        ("/{robot:>5}/pose", "only the tokens {robot} (not {robot:>5})"),
        ("{robot}/pose", "a ROS 2 topic once filled in (ROS topic 'robot_1/pose' must be abs"),
        ("/{robot}/po se", "a ROS 2 topic once filled in (ROS topic '/robot_1/po se' has token"),
        ("/{robot}//pose", "a ROS 2 topic once filled in (ROS topic '/robot_1//pose' must not"),
    ],
)
def test_a_topic_pattern_that_gives_no_ros_topic_is_refused(pattern: str, expected: str):
    with pytest.raises(ConfigError, match=r"\[mocap\] topic_pattern = ") as caught:
        scenario(**ROS2, **{"mocap.topic_pattern": pattern})
    assert f"expected {expected}" in str(caught.value)


def test_a_ros2_body_that_is_no_ros_topic_is_refused():
    with pytest.raises(ConfigError, match=r"bodies = \['robot_1', 'pose'\]: expected a ROS 2"):
        scenario(**{"mocap.source": "ros2", "mocap.bodies": [["robot_1", "pose"]]})


def test_the_connect_timeout_defaults_to_ten_seconds_and_must_be_positive():
    assert scenario().mocap.connect_timeout_s == 10.0
    with pytest.raises(ConfigError, match=r"\[mocap\] connect_timeout_s = 0: expected a number"):
        scenario(**{"mocap.connect_timeout_s": 0})


def test_a_motion_capture_system_the_library_lacks_is_refused_with_the_known_ones():
    with pytest.raises(ConfigError, match=r"system = 'vicom': expected one of vicon, optitrack"):
        scenario(**{"mocap.source": "motioncapture", "mocap.system": "vicom"})


def test_a_motion_capture_system_other_than_mock_needs_its_hostname():
    with pytest.raises(ConfigError, match=r"hostname = '': expected the vicon server's address"):
        scenario(**{"mocap.source": "motioncapture", "mocap.bodies": [["robot_1", "j"]]})
    ok = scenario(**{"mocap.source": "motioncapture", "mocap.system": "mock"})
    assert ok.mocap.hostname == ""


PATTERNS = st.one_of(
    st.text(alphabet="/{}!:_rbotpseaxy1 ", max_size=16),
    st.builds(lambda a, b: f"/{a}{{robot}}{b}", st.text(max_size=6), st.text(max_size=6)),
)
TIMEOUTS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-5, 5000), st.text(max_size=4)
)


@pytest.mark.slow
@settings(max_examples=150, deadline=None)
@given(
    source=st.sampled_from(["ros2", "motioncapture", "none"]),
    pattern=PATTERNS,
    timeout=TIMEOUTS,
    system=st.sampled_from(["vicon", "mock", "vrpn", "Vicon", "", "x y"]),
    host=st.sampled_from(["", "10.0.0.5", "a b", "localhost"]),
)
def test_any_live_source_settings_load_or_fail_with_one_config_error_line(
    source: str, pattern: str, timeout: object, system: str, host: str
):
    overrides = {
        "mocap.source": source,
        "mocap.topic_pattern": pattern,
        "mocap.connect_timeout_s": timeout,
        "mocap.system": system,
        "mocap.hostname": host,
    }
    if source != "none":
        overrides["physical.robots"] = ["robot_1"]
    try:
        s = scenario(**overrides)
    except ConfigError as error:
        assert "\n" not in str(error)
        return
    assert 0 < s.mocap.connect_timeout_s <= 3600
    if source == "ros2":
        topic = s.mocap.topic_pattern.replace("{robot}", "robot_1")
        assert topic.startswith("/") and "{" not in topic and "}" not in topic
