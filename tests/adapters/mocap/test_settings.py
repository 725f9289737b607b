from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from adapters.mocap.tracking import tracked_robots
from adapters.physical.bridge import physical_robots
from cosim import load_scenario
from cosim.core.errors import ConfigError

NAMES = ["robot_1", "robot_2", "robot_3"]


def scenario(**overrides: object):
    three = {"robots.count": 3, "robots.placement": "dock", "robots.positions": []}
    return load_scenario("lab-room", {**three, **overrides})


def test_mocap_is_off_by_default_and_its_defaults_are_vicon_like():
    cfg = scenario().mocap
    assert cfg.source == "none"
    assert (cfg.rate_hz, cfg.noise_std_m, cfg.max_age_ms) == (100.0, 0.001, 200.0)


def test_a_bag_source_without_a_file_names_the_key_and_what_it_needs():
    with pytest.raises(ConfigError, match=r"\[mocap\] file = '': expected a bag or CSV file"):
        scenario(**{"mocap.source": "bag"})


def test_a_file_relative_to_a_scenario_file_is_resolved_against_its_folder(tmp_path: Path):
    path = tmp_path / "s.toml"
    path.write_text('[mocap]\nsource = "bag"\nfile = "track.csv"\n')
    assert load_scenario(path).mocap.file == str(tmp_path / "track.csv")


def test_an_unknown_source_is_refused_with_the_choices():
    with pytest.raises(ConfigError, match="motioncapture"):
        scenario(**{"mocap.source": "vicon"})


def test_a_robot_tracked_twice_is_refused():
    with pytest.raises(ConfigError, match="each robot tracked once"):
        scenario(
            **{
                "mocap.source": "ros2",
                "mocap.bodies": [["robot_1", "/a"], ["robot_1", "/b"]],
            }
        )


def test_a_physical_robot_without_a_live_pose_is_refused():
    s = scenario(**{"physical.robots": ["robot_1"]})
    with pytest.raises(ConfigError, match=r"physical.pose = 'odom'"):
        physical_robots(s, NAMES)


def test_a_physical_robot_that_is_not_in_the_fleet_is_named():
    s = scenario(**{"physical.robots": ["robot_9"], "physical.pose": "odom"})
    with pytest.raises(ConfigError, match=r"\[physical\] robots names 'robot_9'"):
        physical_robots(s, NAMES)


def test_a_dds_domain_beyond_232_is_refused():
    with pytest.raises(ConfigError, match="dds_domain"):
        scenario(**{"physical.dds_domain": 233})


VALUES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-5, 300),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
    st.lists(st.text(max_size=6), max_size=3),
    st.lists(st.lists(st.text(max_size=6), max_size=3), max_size=3),
)
KEYS = [
    "mocap.source",
    "mocap.robots",
    "mocap.bodies",
    "mocap.rate_hz",
    "mocap.latency_ms",
    "mocap.noise_std_m",
    "mocap.dropout",
    "mocap.max_age_ms",
    "mocap.file",
    "mocap.system",
    "mocap.topic_pattern",
    "mocap.connect_timeout_s",
    "mocap.hostname",
    "physical.robots",
    "physical.dds_domain",
    "physical.interface",
    "physical.drive",
    "physical.pose",
    "physical.poll_hz",
    "navigation.goals",
]


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(st.dictionaries(st.sampled_from(KEYS), VALUES, max_size=4))
def test_any_mocap_or_physical_values_load_or_fail_with_a_config_error(overrides):
    try:
        s = scenario(**overrides)
    except ConfigError as error:
        assert "\n" not in str(error)
        return
    try:
        tracked_robots(s, NAMES)
        physical_robots(s, NAMES)
    except ConfigError:
        pass


def test_a_series_goal_outside_the_room_is_named_before_the_run():
    from cosim.runner.assembly import assemble

    s = load_scenario("lab-real-in-virtual", {"navigation.goals": [[1.0, 1.0], [5.0, 2.0]]})
    with pytest.raises(ConfigError, match=r"goals has \[5, 2\]: expected points inside"):
        assemble(s)
