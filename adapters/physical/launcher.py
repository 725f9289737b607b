"""Stand-in robots for a run: one ``cosim standin`` process per physical robot.

``cosim run SCENARIO --standin`` plays the scenario's physical robots without hardware:
each is a separate process on the run's DDS domain (and interface), started at the
robot's start pose with its drive limits and the motion capture's rate, latency and noise,
so the run talks to it exactly as it would to a real robot. The processes are stopped
(SIGTERM, then SIGKILL) when the run ends, however it ends.

The run's domain is the scenario's ``physical.dds_domain``; with ``"auto"`` it is claimed
here for the run (:func:`adapters.physical.domain.claim_run_domain`) unless the caller
claimed it first, and the run must then be given :attr:`Standins.scenario`, which names it.
Each stand-in is told it by ``--domain`` (and ``ROS_DOMAIN_ID`` in its environment).
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time

from adapters.naming import robot_name
from adapters.physical.domain import RunDomain, claim_run_domain
from adapters.processes import die_with_parent
from adapters.world.warehouse import scenario_warehouse
from cosim.core.errors import BridgeError, ConfigError
from cosim.scenario.model import Scenario

READY_TIMEOUT_S = 20.0
"""How long a stand-in may take to join the DDS domain."""


def start_poses(scenario: Scenario) -> dict[str, tuple[float, float, float]]:
    """Every robot's start pose in ``map``, as the run will place it (same world stream)."""
    world = scenario_warehouse(scenario)
    return {
        robot_name(i): (float(x), float(y), float(yaw))
        for i, (x, y, yaw) in enumerate(world.starts.tolist())
    }


def standin_command(scenario: Scenario, robot: str, seed: int) -> list[str]:
    """The command line of the stand-in playing ``robot``."""
    poses = start_poses(scenario)
    if robot not in poses:
        raise ConfigError(
            f"{scenario.source}: [physical] robots names {robot!r}: expected one of the robots "
            f"{', '.join(poses)}"
        )
    x, y, yaw = poses[robot]
    mocap, robots, physical = scenario.mocap, scenario.robots, scenario.physical
    if physical.dds_domain == "auto":
        raise ConfigError(
            f"{scenario.source}: [physical] dds_domain = 'auto': expected the run's claimed "
            "domain (claim it with adapters.physical.domain.claim_run_domain first)"
        )
    command = [
        sys.executable, "-m", "cosim", "standin",
        "--name", robot,
        "--domain", str(physical.dds_domain),
        "--x-m", repr(x), "--y-m", repr(y), "--yaw-rad", repr(yaw),
        "--rate-hz", repr(min(mocap.rate_hz, 1000.0)),
        "--latency-ms", repr(mocap.latency_ms),
        "--noise-std-m", repr(mocap.noise_std_m),
        "--noise-std-rad", repr(mocap.noise_std_rad),
        "--max-speed-mps", repr(robots.max_speed_mps),
        "--max-yaw-rate-radps", repr(robots.max_yaw_rate_radps),
        "--seed", str(seed),
    ]  # fmt: skip
    if physical.interface:
        command += ["--interface", physical.interface]
    return command


class Standins:
    """The stand-in processes of a scenario's physical robots.

    Args:
        scenario: the scenario; its ``physical.robots`` are played.

    Attributes:
        scenario: the scenario naming the DDS domain the stand-ins are on: run this one.
        domain: the domain claimed here (``dds_domain = "auto"`` not claimed before), held
            until :meth:`stop`; None when the scenario named its domain.

    Raises:
        ConfigError: the scenario has no physical robot.
        BridgeError: no DDS domain can be claimed.
    """

    def __init__(self, scenario: Scenario) -> None:
        if not scenario.physical.robots:
            raise ConfigError(
                f"{scenario.source}: --standin: expected physical.robots in the scenario "
                "(there is no physical robot to stand in for)"
            )
        self.domain: RunDomain | None = None
        if scenario.physical.dds_domain == "auto":
            self.domain = claim_run_domain(scenario)
            assert self.domain is not None  # physical robots use DDS
            scenario = self.domain.scenario
        self.scenario = scenario
        self.processes: dict[str, subprocess.Popen[str]] = {}
        self.output: dict[str, list[str]] = {}

    def start(self) -> list[str]:
        """Start every stand-in and wait until each has joined the DDS domain.

        Raises:
            BridgeError: a stand-in exited or did not come up in time (its output quoted).
        """
        domain = str(self.scenario.physical.dds_domain)
        env = {**os.environ, "PYTHONUNBUFFERED": "1", "ROS_DOMAIN_ID": domain}
        for k, robot in enumerate(self.scenario.physical.robots):
            command = standin_command(self.scenario, robot, self.scenario.seed + k)
            process = subprocess.Popen(
                command,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                text=True,
                env=env,
                preexec_fn=die_with_parent,  # a run killed outright takes its stand-ins along
            )
            self.processes[robot] = process
            self.output[robot] = []
            self._wait_ready(robot, process)
        return list(self.processes)

    def _wait_ready(self, robot: str, process: subprocess.Popen[str]) -> None:
        lines = self.output[robot]
        ready = threading.Event()

        def read() -> None:
            assert process.stdout is not None
            for line in process.stdout:
                lines.append(line.rstrip())
                if "on DDS domain" in line:
                    ready.set()
            ready.set()

        threading.Thread(target=read, daemon=True, name=f"standin-{robot}").start()
        deadline = time.monotonic() + READY_TIMEOUT_S
        while not ready.wait(0.05):
            if time.monotonic() > deadline:
                break
        if process.poll() is not None or not any("on DDS domain" in s for s in lines):
            self.stop()
            said = " / ".join(lines[-3:]) or "no output"
            raise BridgeError(f"stand-in for {robot} did not come up: {said}")

    def stop(self) -> None:
        """Stop every stand-in (SIGTERM, then SIGKILL after 5 s); give back the domain."""
        for process in self.processes.values():
            if process.poll() is None:
                process.terminate()
        for process in self.processes.values():
            try:
                process.wait(timeout=5.0)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
        if self.domain is not None:
            self.domain.close()
