from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
import pytest

import cosim
from adapters.mocap.settings import MocapConfig
from adapters.mocap.simulated import SimulatedSource
from adapters.mocap.topics import pose_topic
from cosim.core.errors import ConfigError
from cosim.core.messages import PoseStamped
from cosim.runner.assembly import assemble
from models.fleet.kinematics import FleetState

NAMES = ["robot_1", "robot_2", "robot_3"]
SMALL = {
    "world.size_m": [12.0, 12.0],
    "world.shelf_count": 4,
    "robots.count": 2,
    "lidar.beams": 60,
    "record.messages": False,
}


def scenario(**overrides: object) -> cosim.Scenario:
    return cosim.load_scenario("warehouse-random", overrides={**SMALL, **overrides})


def test_a_simulated_system_measures_the_simulated_robots_without_a_wall_clock():
    assert SimulatedSource.name == "simulated"
    assert (SimulatedSource.external, SimulatedSource.live, SimulatedSource.uses_dds) == (
        False,
        False,
        False,
    )
    assert SimulatedSource.describe(MocapConfig(), "") == "the simulated motion capture"


def test_it_tracks_the_robots_named_or_every_robot_by_no_body():
    every = SimulatedSource.tracks(MocapConfig(source="simulated"), {}, NAMES)
    assert every == [(name, "") for name in NAMES]
    some = replace(MocapConfig(source="simulated"), robots=("robot_3", "robot_1"))
    assert SimulatedSource.tracks(some, {"robot_2": "mocap"}, NAMES) == [
        ("robot_3", ""),
        ("robot_1", ""),
    ]


def test_only_it_reads_mocap_robots():
    assert SimulatedSource.keys == ("robots",)
    with pytest.raises(ConfigError) as refused:
        scenario(**{"mocap.source": "ros2", "mocap.robots": ["robot_1"]})
    assert str(refused.value) == (
        "--set mocap.robots: [mocap] robots = ['robot_1']: expected no robots unless source "
        "is 'simulated'"
    )


Frames = dict[str, list[tuple[int, PoseStamped]]]


def measured(duration_s: float = 0.5, **mocap: object) -> tuple[Frames, Any, Callable[[int], Any]]:
    """The simulated system alone on standing robots: each robot's (send time, pose)."""
    overrides = {f"mocap.{k}": v for k, v in mocap.items()}
    s = scenario(**{"robots.count": 3, "mocap.source": "simulated", **overrides})
    assembly = assemble(s)
    run = assembly.run
    frames: Frames = {name: [] for name in NAMES}
    for name in NAMES:
        run.bus.monitor(
            pose_topic(name), lambda t, m, _src, now: frames[t.split("/")[1]].append((now, m))
        )
    adapter = dict(assembly.adapters)["mocap"]
    adapter.start(run)
    run.kernel.run(int(duration_s * 1e9))
    fleet = run.service(FleetState)
    return frames, adapter.finish(run), lambda i: (fleet.x[i], fleet.y[i], fleet.yaw[i])


def test_frames_come_at_the_rate_and_are_sent_the_latency_after_the_instant_they_show():
    frames, summary, _ = measured(rate_hz=50.0, latency_ms=3.0)
    for name in NAMES:
        stamps = [m.stamp_ns for _, m in frames[name]]
        assert stamps == [k * 20_000_000 for k in range(25)]
        assert all(now - m.stamp_ns == 3_000_000 for now, m in frames[name])
        assert all(m.frame_id == "map" for _, m in frames[name])
    assert summary["mocap_poses"] == 75 and summary["mocap_dropouts"] == 0


def test_without_latency_a_frame_is_sent_at_its_instant():
    frames, _, _ = measured(rate_hz=20.0, latency_ms=0.0)
    assert all(now == m.stamp_ns for now, m in frames["robot_2"])
    assert len(frames["robot_2"]) == 10


def test_without_noise_the_poses_are_the_ground_truth():
    frames, _, truth = measured(noise_std_m=0.0, noise_std_rad=0.0)
    for i, name in enumerate(NAMES):
        assert all((m.x_m, m.y_m, m.yaw_rad) == pytest.approx(truth(i)) for _, m in frames[name])


def test_the_noise_has_the_configured_spread_around_the_truth():
    # the intake's jump check set wide: it would refuse the noisiest frames of standing robots
    frames, _, truth = measured(
        duration_s=2.0, noise_std_m=0.02, noise_std_rad=0.05, jump_tolerance_m=1.0
    )
    x, _, yaw = truth(0)
    errors = np.array([m.x_m - x for _, m in frames["robot_1"]])
    yaws = np.array([m.yaw_rad - yaw for _, m in frames["robot_1"]])
    assert len(errors) == 200
    assert abs(errors.mean()) < 0.005 and 0.016 < errors.std() < 0.024
    assert 0.04 < yaws.std() < 0.06


def test_only_the_robots_named_are_measured():
    frames, summary, _ = measured(robots=["robot_2"])
    assert [len(frames[name]) for name in NAMES] == [0, 50, 0]
    assert summary["mocap_poses"] == 50


def test_a_dropped_body_is_missing_from_its_frame_and_counted():
    frames, summary, _ = measured(dropout=1.0)
    assert all(f == [] for f in frames.values())
    assert summary["mocap_dropouts"] == 3 * 50 and summary["mocap_poses"] == 0
    frames, summary, _ = measured(duration_s=2.0, dropout=0.3)
    assert summary["mocap_dropouts"] + summary["mocap_poses"] == 3 * 200
    assert 0.2 < summary["mocap_dropouts"] / 600 < 0.4


def test_the_same_seed_measures_the_same_and_each_robots_noise_is_its_own():
    first, _, _ = measured()
    again, _, _ = measured()
    assert first == again
    alone, _, _ = measured(robots=["robot_1"])
    assert alone["robot_1"] == first["robot_1"]  # measuring others draws nothing of its stream


def run_watching(s: cosim.Scenario, topic: str) -> tuple[list[tuple[int, object]], object]:
    """Run ``s`` and keep every publication on ``topic`` with its time."""
    from cosim.runner.execute import _run_assembled

    assembly = assemble(s)
    seen: list[tuple[int, object]] = []
    assembly.run.bus.monitor(topic, lambda _t, message, _src, t_ns: seen.append((t_ns, message)))
    return seen, _run_assembled(s, assembly, None)


def test_simulated_poses_carry_the_configured_noise_latency_and_stamp():
    s = scenario(
        **{
            "scenario.duration_s": 4.0,
            "mocap.source": "simulated",
            "mocap.noise_std_m": 0.01,
            "mocap.latency_ms": 7.0,
        }
    )
    seen, result = run_watching(s, "/robot_1/pose")
    truth = result.tables["poses"]
    truth = truth[truth.robot == "robot_1"].set_index("t_s")
    errors = []
    for t_ns, message in seen:
        assert t_ns - message.stamp_ns == 7_000_000  # sent 7 ms after the frame instant
        if message.stamp_ns % 100_000_000 == 0:  # frames on the 10 Hz pose samples
            row = truth.loc[round(message.stamp_ns / 1e9, 1)]
            errors += [message.x_m - row.x_m, message.y_m - row.y_m]
    assert len(errors) > 60
    assert 0.006 < float(np.std(errors)) < 0.014
