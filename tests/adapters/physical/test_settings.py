"""The ``[physical]`` section: real robots over DDS, their keys, checks and hooks."""

from __future__ import annotations

from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.physical.settings import PhysicalConfig
from cosim.core.errors import ConfigError
from cosim.runner.assembly import adapter_names, needs_realtime


def _physical(**keys: Any) -> PhysicalConfig:
    overrides = {f"physical.{key}": value for key, value in keys.items()}
    return cosim.load_scenario("lab-room", overrides).section(PhysicalConfig)


def test_by_default_no_robot_is_physical_and_nothing_asks_for_dds_or_the_wall_clock():
    cfg = _physical()
    assert (cfg.robots, cfg.dds_domain, cfg.interface) == ((), "auto", "")
    assert (cfg.pose_timeout_s, cfg.drive, cfg.pose, cfg.poll_hz) == (10.0, "cosim", "mocap", 200.0)
    assert cfg.adapters() == () and not cfg.needs_realtime() and not cfg.uses_dds()
    assert cfg.external_poses() == {}


def test_a_physical_robot_asks_for_the_bridge_dds_and_the_wall_clock():
    scenario = cosim.load_scenario("lab-room", {"physical.robots": ["robot_2"]})
    cfg = scenario.section(PhysicalConfig)
    assert cfg.adapters() == ("physical",) and cfg.uses_dds() and cfg.needs_realtime()
    assert "physical" in adapter_names(scenario)
    assert needs_realtime(scenario)
    assert not needs_realtime(cosim.load_scenario("lab-room"))


@pytest.mark.parametrize("pose", ["mocap", "odom"])
def test_each_physical_robot_is_posed_from_where_pose_says(pose):
    cfg = _physical(robots=["robot_1", "robot_3"], pose=pose)
    assert cfg.external_poses() == {"robot_1": pose, "robot_3": pose}


def test_a_robot_named_twice_is_refused():
    with pytest.raises(ConfigError) as refused:
        _physical(robots=["robot_1", "robot_1"])
    assert "[physical] robots = ['robot_1', 'robot_1']: expected each robot named once" in str(
        refused.value
    )


def test_an_auto_domain_with_a_network_interface_is_refused_naming_the_interface():
    with pytest.raises(ConfigError) as refused:
        _physical(robots=["robot_1"], interface="eth0")
    message = str(refused.value)
    assert "[physical] dds_domain = 'auto': expected the robots' ROS_DOMAIN_ID (0-232)" in message
    assert "interface = 'eth0'" in message
    assert _physical(robots=["robot_1"], interface="eth0", dds_domain=3).dds_domain == 3


@pytest.mark.parametrize("domain", [0, 101, 232, "auto"])
def test_a_domain_id_of_0_to_232_or_auto_is_accepted(domain):
    assert _physical(dds_domain=domain).dds_domain == domain


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("dds_domain", 233),
        ("dds_domain", -1),
        ("dds_domain", "any"),
        ("pose_timeout_s", 0.0),
        ("poll_hz", 5000.0),
        ("drive", "nav2"),
        ("pose", "gps"),
    ],
)
def test_a_bad_value_is_refused_in_one_line_naming_the_key(key, value):
    with pytest.raises(ConfigError) as refused:
        _physical(**{key: value})
    message = str(refused.value)
    assert f"physical.{key}" in message and "\n" not in message


@settings(max_examples=60, deadline=None)
@given(
    st.sampled_from(["robots", "dds_domain", "interface", "pose_timeout_s", "poll_hz", "drive"]),
    st.one_of(
        st.integers(-5, 500),
        st.floats(allow_nan=True, allow_infinity=True),
        st.text(max_size=6),
        st.lists(st.sampled_from(["robot_1", "robot_2", "x"]), max_size=3),
    ),
)
def test_any_physical_value_is_accepted_or_refused_naming_the_key(key, value):
    try:
        cfg = _physical(**{key: value})
    except ConfigError as error:
        # the key itself, or a cross-key problem naming it (an interface with "auto")
        assert key in str(error) and "[physical]" in str(error) and "\n" not in str(error)
        return
    assert getattr(cfg, key) is not None
