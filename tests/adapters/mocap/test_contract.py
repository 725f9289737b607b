from collections.abc import Mapping
from types import SimpleNamespace
from typing import Any, ClassVar

import pytest

import cosim
from adapters.mocap.contract import (
    MOCAP_SOURCES,
    all_robots_or,
    bodies_or,
    external_poses,
    no_problems,
)
from adapters.mocap.motioncapture import MotionCaptureSource
from adapters.mocap.replay import RecordedSource
from adapters.mocap.ros2 import Ros2PoseSource
from adapters.mocap.settings import MocapConfig
from adapters.mocap.simulated import SimulatedSource
from adapters.unity.pose_source import UnityPoseSource
from cosim.core.errors import RegistryError
from cosim.core.registry import Registry

NAMES = ["robot_1", "robot_2", "robot_3"]
BUILT_IN = {
    "simulated": SimulatedSource,
    "bag": RecordedSource,
    "motioncapture": MotionCaptureSource,
    "ros2": Ros2PoseSource,
    "unity": UnityPoseSource,
}


def test_the_built_in_sources_are_registered_and_keep_the_contract():
    assert MOCAP_SOURCES.installed().load_all() == BUILT_IN


@pytest.mark.parametrize(
    ("name", "external", "live", "uses_dds"),
    [
        ("simulated", False, False, False),
        ("bag", True, False, False),
        ("motioncapture", True, True, False),
        ("ros2", True, True, True),
        ("unity", True, True, False),
    ],
)
def test_each_source_says_where_its_poses_come_from_and_how_the_run_must_go(
    name, external, live, uses_dds
):
    source = BUILT_IN[name]
    assert source.name == name
    assert (source.external, source.live, source.uses_dds) == (external, live, uses_dds)
    cfg = MocapConfig(source=name)
    assert cfg.chosen() is source
    assert (cfg.external, cfg.needs_realtime(), cfg.uses_dds()) == (external, live, uses_dds)


class _Good:
    """Keeps the contract."""

    name: ClassVar[str] = "good"
    external: ClassVar[bool] = False
    live: ClassVar[bool] = False
    uses_dds: ClassVar[bool] = False

    @classmethod
    def tracks(cls, mocap: MocapConfig, outside: Mapping[str, str], names: list[str]) -> Any:
        return all_robots_or(mocap, names)

    @classmethod
    def describe(cls, mocap: MocapConfig, body: str) -> str:
        return "nothing"

    def __init__(self, context: Any) -> None:
        pass

    def start(self, run: Any) -> None:
        pass

    def close(self) -> None:
        pass

    def summary(self) -> Mapping[str, Any]:
        return {}


SEE = "(see adapters.mocap.contract.PoseSource)"


def _broken(**changes: Any) -> type:
    return type("Broken", (_Good,), {"name": "broken", **changes})


def _get(entry: Any) -> Any:
    return Registry(MOCAP_SOURCES, {"broken": entry}).get("broken")


def test_a_source_that_keeps_the_contract_is_accepted():
    assert Registry(MOCAP_SOURCES, {"good": _Good}).get("good") is _Good


@pytest.mark.parametrize(
    ("entry", "problem"),
    [
        (SimpleNamespace(name="broken"), "is not a class (built with a SourceContext)"),
        (_broken(live="yes"), "live = 'yes'; expected True or False"),
        (_broken(external=None), "external = None; expected True or False"),
        (_broken(uses_dds=1), "uses_dds = 1; expected True or False"),
        (_broken(summary=None), f"has no summary() method {SEE}"),
        (_broken(tracks=None), f"has no tracks() method {SEE}"),
        (_broken(describe=None), f"has no describe() method {SEE}"),
        (_broken(start="now"), f"has no start() method {SEE}"),
    ],
)
def test_a_source_breaking_the_contract_is_refused_naming_itself_and_what_is_wrong(entry, problem):
    with pytest.raises(RegistryError) as refused:
        _get(entry)
    message = str(refused.value)
    assert message.startswith("motion capture source 'broken' (")
    assert message.endswith(f": {problem}")


def test_a_source_declaring_another_name_is_refused():
    with pytest.raises(RegistryError, match=r"declares name = 'good'; expected 'broken'"):
        _get(_Good)


class _Posed:
    def __init__(self, poses: dict[str, str]) -> None:
        self.poses = poses

    def external_poses(self) -> Mapping[str, str]:
        return self.poses


def test_robots_posed_from_outside_are_gathered_from_every_section_that_says_so():
    sections = {
        "physical": _Posed({"robot_1": "mocap", "robot_2": "odom"}),
        "other": _Posed({"robot_3": "mocap"}),
        "plain": object(),
    }
    assert external_poses(sections) == {"robot_1": "mocap", "robot_2": "odom", "robot_3": "mocap"}
    assert external_poses({"plain": object()}) == {}


def test_physical_robots_are_posed_from_outside_in_a_scenario():
    s = cosim.load_scenario("lab-room", {"physical.robots": ["robot_2"], "physical.pose": "odom"})
    assert external_poses(s.sections) == {"robot_2": "odom"}


def test_a_simulated_system_tracks_the_robots_named_or_all_without_bodies():
    assert all_robots_or(MocapConfig(), NAMES) == [(n, "") for n in NAMES]
    chosen = MocapConfig(source="simulated", robots=("robot_2",))
    assert all_robots_or(chosen, NAMES) == [("robot_2", "")]


def test_bodies_come_from_the_section_or_from_the_robots_posed_from_outside():
    outside = {"robot_3": "mocap", "robot_1": "mocap"}
    assert bodies_or(MocapConfig(), outside, str.upper) == [
        ("robot_3", "ROBOT_3"),
        ("robot_1", "ROBOT_1"),
    ]
    given = MocapConfig(bodies=(("robot_2", "jackal"),))
    assert bodies_or(given, outside, str.upper) == [("robot_2", "jackal")]
    assert bodies_or(MocapConfig(), {}, str.upper) == []


def test_a_source_without_checks_of_its_own_refuses_nothing():
    assert list(no_problems(MocapConfig(rate_hz=-1.0))) == []
