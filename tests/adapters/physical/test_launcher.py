"""Stand-in robots for a run: their command lines, the domain they share, their processes."""

from __future__ import annotations

import argparse
import io
import sys
from typing import Any, ClassVar

import pytest

import adapters.physical.launcher as launcher
import cosim
from adapters.physical.domain import claim_run_domain
from adapters.physical.launcher import Standins, standin_command, start_poses
from adapters.physical.standin_options import StandinOptions, add_arguments, options_from
from adapters.world.warehouse import scenario_warehouse
from cosim.core.errors import BridgeError, ConfigError


def _named(domain: int = 5, **overrides: Any) -> cosim.Scenario:
    """The lab with one physical robot, on a domain it names (nothing is claimed)."""
    return cosim.load_scenario("lab-real-in-virtual", {"physical.dds_domain": domain, **overrides})


def test_start_poses_are_where_the_run_places_each_robot():
    scenario = cosim.load_scenario("lab-room")
    starts = scenario_warehouse(scenario).starts
    poses = start_poses(scenario)
    assert list(poses) == [f"robot_{i + 1}" for i in range(len(starts))]
    assert [list(p) for p in poses.values()] == starts.tolist()
    assert start_poses(_named())["robot_1"] == pytest.approx((0.6, 0.6, 1.5708))


def test_a_standins_command_line_is_the_robots_start_pose_limits_and_the_mocaps_figures():
    scenario = _named(**{"mocap.rate_hz": 120.0, "mocap.latency_ms": 8.0})
    command = standin_command(scenario, "robot_1", 11)
    assert command[:4] == [sys.executable, "-m", "cosim", "standin"]
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    options = options_from(parser.parse_args(command[4:]))
    mocap, robots = scenario.mocap, scenario.robots
    assert options == StandinOptions(
        name="robot_1",
        domain=5,
        x_m=0.6,
        y_m=0.6,
        yaw_rad=1.5708,
        rate_hz=120.0,
        latency_ms=8.0,
        noise_std_m=mocap.noise_std_m,
        noise_std_rad=mocap.noise_std_rad,
        max_speed_mps=0.5,
        max_yaw_rate_radps=robots.max_yaw_rate_radps,
        seed=11,
    )
    assert "--interface" not in command


def test_the_pose_rate_asked_of_a_standin_is_at_most_1000_hz():
    command = standin_command(_named(**{"mocap.rate_hz": 2000.0}), "robot_1", 1)
    assert command[command.index("--rate-hz") + 1] == "1000.0"


def test_a_network_interface_is_passed_on_to_the_standin():
    command = standin_command(_named(**{"physical.interface": "eth0"}), "robot_1", 1)
    assert command[command.index("--interface") + 1] == "eth0"


def test_a_robot_that_is_not_in_the_scenario_is_refused_naming_the_robots():
    with pytest.raises(ConfigError) as refused:
        standin_command(_named(), "robot_4", 1)
    assert str(refused.value) == (
        "preset lab-real-in-virtual: [physical] robots names 'robot_4': expected one of the "
        "robots robot_1"
    )


def test_standins_need_a_physical_robot_in_the_scenario():
    with pytest.raises(ConfigError, match="no physical robot"):
        Standins(cosim.load_scenario("lab-room"))


def test_standins_of_an_auto_domain_claim_one_and_tell_it_each_standin():
    standins = Standins(cosim.load_scenario("lab-real-in-virtual"))
    try:
        assert standins.domain is not None
        domain = standins.domain.claim.domain
        assert standins.scenario.physical.dds_domain == domain
        command = standin_command(standins.scenario, "robot_1", 1)
        assert command[command.index("--domain") + 1] == str(domain)
    finally:
        standins.stop()  # gives the domain back
    again = claim_run_domain(cosim.load_scenario("lab-real-in-virtual"))
    assert again is not None and again.claim.domain <= domain
    again.close()


def test_a_standin_command_needs_the_runs_claimed_domain():
    with pytest.raises(ConfigError, match="dds_domain = 'auto': expected the run's claimed"):
        standin_command(cosim.load_scenario("lab-real-in-virtual"), "robot_1", 1)


class Process:
    """Stands for a stand-in's process: what it prints (``says``), whether it is up (``code``)."""

    started: ClassVar[list[Process]] = []
    says: ClassVar[str | None] = None
    code_after: ClassVar[int | None] = None

    def __init__(self, command: list[str], *, env: dict[str, str], **_: Any) -> None:
        self.command, self.env = command, env
        name = command[command.index("--name") + 1]
        ready = f"{name}: on DDS domain {env['ROS_DOMAIN_ID']} (loopback), 100 Hz\n"
        self.stdout = io.StringIO(ready if Process.says is None else Process.says)
        self.code = Process.code_after
        self.signals: list[str] = []
        Process.started.append(self)

    def poll(self) -> int | None:
        return self.code

    def terminate(self) -> None:
        self.signals.append("SIGTERM")
        self.code = -15

    def wait(self, timeout: float | None = None) -> int:
        assert self.code is not None
        return self.code

    def kill(self) -> None:
        self.signals.append("SIGKILL")


@pytest.fixture
def processes(monkeypatch: pytest.MonkeyPatch) -> list[Process]:
    Process.started, Process.says, Process.code_after = [], None, None
    monkeypatch.setattr(launcher.subprocess, "Popen", Process)
    return Process.started


def test_every_standin_is_started_on_the_runs_domain_and_stopped_with_sigterm(processes):
    standins = Standins(_named(7))
    assert standins.start() == ["robot_1"]
    [process] = processes
    assert process.env["ROS_DOMAIN_ID"] == "7" and process.env["PYTHONUNBUFFERED"] == "1"
    assert process.command == standin_command(standins.scenario, "robot_1", 1)  # seed + 0
    assert standins.output["robot_1"] == ["robot_1: on DDS domain 7 (loopback), 100 Hz"]
    standins.stop()
    assert process.signals == ["SIGTERM"]
    standins.stop()  # stopped already: not signalled again
    assert process.signals == ["SIGTERM"]


def test_a_standin_that_exits_is_refused_quoting_its_last_lines(processes):
    Process.says, Process.code_after = "starting\nloading\nerror: no such interface\nbye\n", 1
    with pytest.raises(BridgeError) as refused:
        Standins(_named(7)).start()
    assert str(refused.value) == (
        "stand-in for robot_1 did not come up: loading / error: no such interface / bye"
    )
    assert processes[0].signals == []  # gone already


def test_a_standin_that_never_joins_the_domain_is_refused_and_stopped(processes, monkeypatch):
    monkeypatch.setattr(launcher, "READY_TIMEOUT_S", 0.1)
    Process.says = ""
    with pytest.raises(BridgeError, match="stand-in for robot_1 did not come up: no output"):
        Standins(_named(7)).start()
    assert processes[0].signals == ["SIGTERM"]
