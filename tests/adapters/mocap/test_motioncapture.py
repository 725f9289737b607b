from dataclasses import dataclass, field, replace
from typing import Any

import pytest

import cosim
from adapters.mocap import motioncapture as module
from adapters.mocap.feed import SYSTEMS, mock_bodies
from adapters.mocap.motioncapture import MotionCaptureSource
from adapters.mocap.settings import MocapConfig
from cosim.core.adapter import RunContext
from cosim.core.errors import ConfigError
from cosim.runner.assembly import assemble
from models.fleet.kinematics import FleetState

NAMES = ["robot_1", "robot_2", "robot_3"]
VICON = MocapConfig(source="motioncapture", system="vicon", hostname="10.0.0.5")


def test_a_motion_capture_system_is_live_from_outside_without_dds():
    assert MotionCaptureSource.name == "motioncapture"
    flags = (MotionCaptureSource.external, MotionCaptureSource.live, MotionCaptureSource.uses_dds)
    assert flags == (True, True, False)
    assert MotionCaptureSource.keys == ("bodies",)
    assert MotionCaptureSource.settings_hint == "mocap.system, mocap.hostname and mocap.bodies"


def test_it_tracks_the_bodies_named_or_each_robot_from_outside_by_a_body_of_its_name():
    outside = {"robot_3": "mocap", "robot_1": "mocap"}
    assert MotionCaptureSource.tracks(VICON, outside, NAMES) == [
        ("robot_3", "robot_3"),
        ("robot_1", "robot_1"),
    ]
    named = replace(VICON, bodies=(("robot_2", "jackal"),))
    assert MotionCaptureSource.tracks(named, outside, NAMES) == [("robot_2", "jackal")]


def test_it_says_which_rigid_body_of_which_system_at_which_host_it_listens_for():
    assert MotionCaptureSource.describe(VICON, "jackal") == (
        "rigid body 'jackal' of the vicon motion capture at '10.0.0.5'"
    )
    mock = MocapConfig(source="motioncapture", system="mock")
    assert MotionCaptureSource.describe(mock, "b") == (
        "rigid body 'b' of the mock motion capture at 'no host'"
    )


@pytest.mark.parametrize(
    ("system", "hostname", "problems"),
    [
        ("vicon", "10.0.0.5", []),
        ("mock", "", []),
        ("vicom", "10.0.0.5", [("system", "vicom", f"one of {', '.join(SYSTEMS)}")]),
        ("optitrack", "", [("hostname", "", "the optitrack server's address")]),
        (
            "vicon",
            "10.0.0.5 ",
            [("hostname", "10.0.0.5 ", "an address without spaces")],
        ),
        (
            "qualisys",
            " ",
            [
                ("hostname", " ", "the qualisys server's address"),
                ("hostname", " ", "an address without spaces"),
            ],
        ),
    ],
)
def test_it_needs_a_known_backend_and_the_address_of_a_real_system(system, hostname, problems):
    cfg = MocapConfig(source="motioncapture", system=system, hostname=hostname)
    found = [(p.key, p.value, p.expected) for p in MotionCaptureSource.problems(cfg)]
    assert found == problems


def test_a_hostname_with_spaces_is_refused_in_one_line():
    with pytest.raises(ConfigError) as refused:
        cosim.load_scenario(
            "lab-room",
            {"mocap.source": "motioncapture", "mocap.system": "mock", "mocap.hostname": "a b"},
        )
    assert str(refused.value) == (
        "--set mocap.hostname: [mocap] hostname = 'a b': expected an address without spaces"
    )


@dataclass
class FakeFeed:
    """What the source reads of a :class:`~adapters.mocap.feed.MotionCaptureFeed`."""

    system: str = ""
    hostname: str = ""
    bodies: list[str] = field(default_factory=list)
    options: dict[str, Any] = field(default_factory=dict)
    samples: list[tuple[int, str, float, float, float]] = field(default_factory=list)
    connected: bool = False
    frames: int = 0
    occluded: int = 0
    failed: str | None = None
    never_seen: list[str] = field(default_factory=list)
    closed: int = 0

    def drain(self) -> list[tuple[int, str, float, float, float]]:
        taken, self.samples = self.samples, []
        return taken

    def failure(self) -> str | None:
        return self.failed

    def missing_bodies(self) -> list[str]:
        return self.never_seen

    def close(self) -> None:
        self.closed += 1


def built(
    monkeypatch: pytest.MonkeyPatch, **mocap: object
) -> tuple[RunContext, MotionCaptureSource, FakeFeed]:
    """The lab room's source (robot_1 as 'jackal', robot_2 as 'husky'), started on a fake feed."""
    overrides = {
        "mocap.source": "motioncapture",
        "mocap.bodies": [["robot_1", "jackal"], ["robot_2", "husky"]],
        "mocap.connect_timeout_s": 2.0,
        **{f"mocap.{k}": v for k, v in mocap.items()},
    }
    assembly = assemble(cosim.load_scenario("lab-room", overrides))
    source = dict(assembly.adapters)["mocap"].source
    assert isinstance(source, MotionCaptureSource)
    made: list[FakeFeed] = []

    def feed(system: str, *, hostname: str, bodies: list[str], options: dict[str, Any]) -> Any:
        made.append(FakeFeed(system, hostname, bodies, options))
        return made[-1]

    monkeypatch.setattr(module, "MotionCaptureFeed", feed)
    source.start(assembly.run)  # the kernel is not run: nothing is polled
    return assembly.run, source, made[0]


def test_building_the_source_opens_nothing(monkeypatch):
    def refuse(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("connected while being built")

    monkeypatch.setattr(module, "MotionCaptureFeed", refuse)
    overrides = {"mocap.source": "motioncapture", "mocap.system": "mock"}
    overrides["mocap.bodies"] = [["robot_1", "jackal"]]  # type: ignore[assignment]
    assembly = assemble(cosim.load_scenario("lab-room", overrides))
    assert isinstance(dict(assembly.adapters)["mocap"].source, MotionCaptureSource)


def test_a_real_system_is_asked_for_the_tracked_bodies_at_its_host(monkeypatch):
    _, _, feed = built(monkeypatch, system="vicon", hostname="10.0.0.5")
    assert (feed.system, feed.hostname, feed.bodies, feed.options) == (
        "vicon",
        "10.0.0.5",
        ["jackal", "husky"],
        {},
    )


def test_a_mock_system_holds_each_body_where_its_robot_starts(monkeypatch):
    run, _, feed = built(monkeypatch, system="mock")
    fleet = run.service(FleetState)
    starts = {b: (fleet.x[i], fleet.y[i], fleet.yaw[i]) for b, i in (("jackal", 0), ("husky", 1))}
    assert feed.options == {"rigid_bodies": mock_bodies(starts)}


def test_frames_become_samples_of_the_tracked_robots_stamped_on_the_kernels_clock(monkeypatch):
    run, source, feed = built(monkeypatch, system="mock")
    wall = run.kernel.wall_ns
    feed.samples = [
        (wall(250_000_000), "husky", 1.0, 2.0, 0.5),
        (wall(260_000_000), "stranger", 9.0, 9.0, 0.0),
        (wall(270_000_000), "jackal", 3.0, 4.0, -0.5),
    ]
    assert source.take(300_000_000) == [
        (1, 250_000_000, 1.0, 2.0, 0.5),
        (0, 270_000_000, 3.0, 4.0, -0.5),
    ]
    assert source.take(400_000_000) == []


def test_it_names_the_system_and_its_host_in_what_went_wrong(monkeypatch):
    _, source, feed = built(monkeypatch, system="vicon", hostname="10.0.0.5")
    assert source.where() == "the vicon motion capture at '10.0.0.5'"
    assert source.failure() is None
    feed.failed = "connection lost: timeout"
    assert source.failure() == "the vicon motion capture at '10.0.0.5': connection lost: timeout"


@pytest.mark.parametrize(
    ("connected", "frames", "occluded", "said"),
    [
        (
            False,
            0,
            0,
            "the vicon motion capture at '10.0.0.5' did not answer within 2 s (no connection)",
        ),
        (
            True,
            0,
            0,
            "the vicon motion capture at '10.0.0.5' accepted the connection but sent no frame "
            "within 2 s",
        ),
        (
            True,
            40,
            0,
            "no pose of robot_2 within 2 s from the vicon motion capture at '10.0.0.5': "
            "listened for rigid body 'husky' (40 frames came, none with it)",
        ),
        (
            True,
            40,
            7,
            "no pose of robot_2 within 2 s from the vicon motion capture at '10.0.0.5': "
            "listened for rigid body 'husky' (40 frames came, none with it, 7 times occluded)",
        ),
    ],
)
def test_a_silent_robot_is_explained_by_how_far_the_system_got(
    monkeypatch, connected, frames, occluded, said
):
    _, source, feed = built(monkeypatch, system="vicon", hostname="10.0.0.5")
    feed.connected, feed.frames, feed.occluded = connected, frames, occluded
    assert source.silence(1) == said


def test_closing_counts_the_bodies_never_seen_and_ends_the_feed(monkeypatch):
    _, source, feed = built(monkeypatch, system="mock")
    feed.never_seen = ["husky"]
    source.close()
    source.close()
    assert feed.closed == 1
    assert source.summary() == {"mocap_connected": False, "mocap_missing_bodies": 1}
