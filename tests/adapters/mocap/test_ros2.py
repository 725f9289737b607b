import math
from dataclasses import dataclass, field, replace
from types import SimpleNamespace
from typing import Any

import pytest

import cosim
from adapters.mocap import ros2 as module
from adapters.mocap.ros2 import Ros2PoseSource, pattern_tracks, topic_bodies_problems
from adapters.mocap.settings import MocapConfig
from adapters.ros2dds.qos import QosKind
from adapters.ros2dds.session import DdsSession
from adapters.ros2dds.types import PoseStamped as DdsPoseStamped
from cosim.core.adapter import RunContext
from cosim.runner.assembly import assemble

NAMES = ["robot_1", "robot_2", "robot_3"]
ROS2 = MocapConfig(source="ros2")


def test_ros2_topics_are_live_from_outside_over_dds():
    assert Ros2PoseSource.name == "ros2"
    flags = (Ros2PoseSource.external, Ros2PoseSource.live, Ros2PoseSource.uses_dds)
    assert flags == (True, True, True)
    assert Ros2PoseSource.keys == ("bodies",)
    assert "physical.dds_domain" in Ros2PoseSource.settings_hint
    assert Ros2PoseSource.describe(ROS2, "/vicon/jackal/jackal") == (
        "geometry_msgs/PoseStamped on /vicon/jackal/jackal"
    )


def test_it_tracks_the_bodies_named_or_each_robot_from_outside_on_the_pattern():
    outside = {"robot_2": "mocap", "robot_3": "odom"}
    pattern = replace(ROS2, topic_pattern="/vicon/{robot}/{robot}")
    assert pattern_tracks(pattern, outside) == [
        ("robot_2", "/vicon/robot_2/robot_2"),
        ("robot_3", "/vicon/robot_3/robot_3"),
    ]
    named = replace(pattern, bodies=(("robot_1", "/jackal/pose"),))
    assert Ros2PoseSource.tracks(named, outside, NAMES) == [("robot_1", "/jackal/pose")]


def test_without_bodies_the_pattern_must_name_the_robot():
    [problem] = list(topic_bodies_problems(replace(ROS2, topic_pattern="/tracked/pose")))
    assert (problem.key, problem.value, problem.expected) == (
        "topic_pattern",
        "/tracked/pose",
        "a pattern containing {robot}",
    )
    with_bodies = replace(ROS2, topic_pattern="/tracked/pose", bodies=(("robot_1", "/a"),))
    assert list(Ros2PoseSource.problems(with_bodies)) == []


@pytest.mark.parametrize("body", ["pose", "/a//b", "/a/1b", "/a/"])
def test_every_body_must_be_an_absolute_ros_topic(body):
    [problem] = list(topic_bodies_problems(replace(ROS2, bodies=(("robot_1", body),))))
    assert (problem.key, problem.value) == ("bodies", ["robot_1", body])
    assert problem.expected.startswith(f"a ROS 2 topic for ros2 (ROS topic {body!r} ")


@dataclass
class Subscription:
    topic: str
    kind: Any
    qos: QosKind
    samples: list[Any] = field(default_factory=list)
    malformed: int = 0

    def take(self) -> list[Any]:
        taken, self.samples = self.samples, []
        return taken


@dataclass
class Participant:
    domain: int = 7
    interface: str = ""
    subscriptions: list[Subscription] = field(default_factory=list)
    closed: int = 0

    def subscription(self, topic: str, kind: Any, qos: QosKind) -> Subscription:
        self.subscriptions.append(Subscription(topic, kind, qos))
        return self.subscriptions[-1]

    def close(self) -> None:
        self.closed += 1


def pose(stamp_ns: int, x: float, y: float, yaw: float, norm: float = 1.0) -> Any:
    """A received geometry_msgs/PoseStamped, as the DDS types hand it over."""
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    return SimpleNamespace(
        header=SimpleNamespace(stamp=SimpleNamespace(sec=sec, nanosec=nanosec)),
        pose=SimpleNamespace(
            position=SimpleNamespace(x=x, y=y, z=0.0),
            orientation=SimpleNamespace(
                x=0.0, y=0.0, z=norm * math.sin(yaw / 2), w=norm * math.cos(yaw / 2)
            ),
        ),
    )


BODIES = [["robot_1", "/vicon/jackal/jackal"], ["robot_3", "/vicon/husky/husky"]]


def started(monkeypatch: pytest.MonkeyPatch) -> tuple[RunContext, Ros2PoseSource, Participant]:
    """robot_1 and robot_3 tracked on two topics, on a DDS stand-in (no socket opened)."""
    participant = Participant()
    sessions: list[DdsSession] = []

    def session(run: RunContext) -> DdsSession:
        sessions.append(DdsSession(participant))  # type: ignore[arg-type]
        return sessions[-1]

    monkeypatch.setattr(module, "dds_session", session)
    overrides = {
        "robots.count": 3,
        "robots.placement": "dock",
        "robots.positions": [],
        "mocap.source": "ros2",
        "mocap.bodies": BODIES,
        "mocap.connect_timeout_s": 1.5,
    }
    assembly = assemble(cosim.load_scenario("lab-room", overrides))
    source = dict(assembly.adapters)["mocap"].source
    assert isinstance(source, Ros2PoseSource)
    assert sessions == []  # building the source joins no domain
    source.start(assembly.run)  # the kernel is not run: nothing is polled
    return assembly.run, source, participant


def test_it_subscribes_to_every_bodys_topic_with_the_sensor_data_profile(monkeypatch):
    _, _, participant = started(monkeypatch)
    assert [(s.topic, s.kind, s.qos) for s in participant.subscriptions] == [
        ("/vicon/jackal/jackal", DdsPoseStamped, QosKind.SENSOR_DATA),
        ("/vicon/husky/husky", DdsPoseStamped, QosKind.SENSOR_DATA),
    ]


def test_samples_become_poses_at_the_senders_stamps_and_what_is_no_pose_is_counted(monkeypatch):
    run, source, participant = started(monkeypatch)
    wall = run.kernel.wall_ns
    jackal, husky = participant.subscriptions
    jackal.samples = [
        pose(wall(100_000_000), 1.0, 2.0, 0.5),
        pose(wall(110_000_000), 9.0, 9.0, 0.0, 2.0),
    ]
    husky.samples = [pose(wall(120_000_000), 3.0, 1.0, -1.0), pose(0, math.nan, 0.0, 0.0)]
    husky.malformed = 4
    taken = source.take(200_000_000)
    assert [(i, t) for i, t, *_ in taken] == [(0, 100_000_000), (2, 120_000_000)]
    assert taken[0][2:] == pytest.approx((1.0, 2.0, 0.5))
    assert taken[1][2:] == pytest.approx((3.0, 1.0, -1.0))
    assert source.take(300_000_000) == []
    source.close()
    # taken, not polled: the run never heard them
    assert source.summary() == {
        "mocap_connected": False,
        "mocap_dds_invalid": 2,
        "mocap_dds_malformed": 4,
    }
    assert participant.closed == 1


def test_a_silent_robot_names_its_topic_and_the_dds_domain(monkeypatch):
    _, source, _ = started(monkeypatch)
    assert source.silence(2) == (
        "no pose of robot_3 within 1.5 s: listened for geometry_msgs/PoseStamped on "
        "/vicon/husky/husky on DDS domain 7 on loopback (mocap.source = 'ros2')"
    )
