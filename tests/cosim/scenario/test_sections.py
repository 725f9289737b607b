"""The core sections of a scenario file, their defaults and their cross-field rules."""

from __future__ import annotations

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.scenario.fields import Problem
from cosim.scenario.names import NAME_RULE, name_problem
from cosim.scenario.sections import (
    DEFAULT_TOPICS,
    LidarConfig,
    OdometryConfig,
    RecordConfig,
    RobotsConfig,
    ScenarioSection,
    WorldConfig,
)

CORE = (ScenarioSection, WorldConfig, RobotsConfig, LidarConfig, OdometryConfig, RecordConfig)


def test_the_robot_defaults_are_a_jackal_s_cruising_below_its_top_speed():
    robots = RobotsConfig()
    assert robots.model == "jackal" and robots.radius_m == 0.33
    assert robots.max_speed_mps == 1.0  # the datasheet's top speed, 2.0 m/s, is the bound
    assert (robots.max_accel_mps2, robots.max_yaw_accel_radps2) == (2.0, 3.0)
    assert robots.max_yaw_rate_radps == 2.0
    fields = {f.name: f for f in dataclasses.fields(RobotsConfig)}
    assert fields["max_speed_mps"].metadata["bounds"].le == 2.0


def test_every_core_key_has_a_default_and_a_one_line_doc_and_the_sections_their_order():
    for cls in CORE:
        assert cls() == cls()  # buildable from defaults alone
        for field in dataclasses.fields(cls):
            doc = field.metadata["doc"]
            assert doc and "\n" not in doc, (cls.__name__, field.name)
    assert [cls.ORDER for cls in CORE] == sorted(cls.ORDER for cls in CORE)
    assert not any(problem for cls in CORE for problem in getattr(cls(), "problems", list)())


@pytest.mark.parametrize("name", ["../escape", "a/b", "..", ".", "", " a", "x\ny", "a" * 101])
def test_a_scenario_name_must_be_one_folder_name(name):
    expected = f"{NAME_RULE}; {name_problem(name)}"
    assert list(ScenarioSection(name=name).problems()) == [Problem("name", name, expected)]


@pytest.mark.parametrize("name", ["仓库-1", "склад", "Zürich hall", "गोदाम", "Zu\u0308rich"])
def test_a_scenario_name_in_any_script_is_a_folder_name(name):
    assert not list(ScenarioSection(name=name).problems())


def test_a_scenario_name_is_counted_in_bytes():
    assert not list(ScenarioSection(name="Ü" * 50).problems())  # 100 bytes
    assert list(ScenarioSection(name="Ü" * 50 + "x").problems())


@settings(max_examples=60, deadline=None)
@given(name=st.from_regex(r"[A-Za-z0-9_.+-]{1,100}", fullmatch=True))
def test_any_name_of_letters_digits_and_marks_is_a_folder_name_unless_it_starts_with_a_dot(name):
    refused = bool(list(ScenarioSection(name=name).problems()))
    reserved = len(name) >= 4 and name.startswith("__") and name.endswith("__")
    assert refused == (name.startswith(".") or reserved)


def test_explicit_placement_needs_exactly_one_pose_per_robot():
    two = ((1.0, 1.0, 0.0), (2.0, 1.0, 0.0))
    assert not list(RobotsConfig(count=2, placement="explicit", positions=two).problems())
    assert list(RobotsConfig(count=3, placement="explicit", positions=two).problems()) == [
        Problem(
            "positions",
            [[1.0, 1.0, 0.0], [2.0, 1.0, 0.0]],
            "3 poses [x_m, y_m, yaw_rad] (one per robot) for placement 'explicit'",
        )
    ]


def test_positions_are_refused_unless_placement_is_explicit():
    (problem,) = RobotsConfig(count=1, positions=((1.0, 1.0, 0.0),)).problems()
    assert problem == Problem(
        "positions", [[1.0, 1.0, 0.0]], "no positions unless placement = 'explicit'"
    )


def test_a_lidar_s_valid_range_interval_must_not_be_empty():
    assert list(LidarConfig(range_min_m=10.0, range_max_m=10.0).problems()) == [
        Problem("range_min_m", 10.0, "a value < range_max_m (10)")
    ]
    assert not list(LidarConfig(range_min_m=0.0, range_max_m=0.5).problems())


def test_the_bag_keeps_every_topic_but_protocol_rounds_and_velocity_chatter_by_default():
    assert RecordConfig().topics == DEFAULT_TOPICS
    assert DEFAULT_TOPICS[0] == "*"
    assert all(p.startswith("!") for p in DEFAULT_TOPICS[1:])
    assert "!/robot_*/cmd_vel" in DEFAULT_TOPICS


@pytest.mark.parametrize("topics", [("",), ("*", "!"), ("!!",)])
def test_an_empty_topic_pattern_is_refused(topics):
    (problem, *_) = RecordConfig(topics=topics).problems()
    assert problem == Problem("topics", list(topics), "non-empty glob patterns")
