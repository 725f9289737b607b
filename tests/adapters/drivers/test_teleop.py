"""The teleop driver in-process: operator commands on the bus move a robot; silence stops it."""

from __future__ import annotations

import math

import numpy as np

import cosim
from adapters.drivers.teleop import DEADMAN_S, teleop_topic
from cosim.core.hosts import HostId
from cosim.core.messages import Twist
from cosim.core.timebase import s_to_ns
from cosim.runner.assembly import Assembly, assemble
from cosim.scenario.sections import RobotsConfig
from models.fleet.kinematics import FleetState


def _teleop_lab_room() -> Assembly:
    scenario = cosim.load_scenario("lab-room", overrides={"robots.driver": "teleop"})
    assembly = assemble(scenario)
    for _name, adapter in assembly.adapters:
        adapter.start(assembly.run)
    return assembly


def _command(assembly: Assembly, at_s: float, v_mps: float, w_radps: float) -> None:
    run = assembly.run
    run.kernel.at(
        s_to_ns(at_s),
        lambda: run.bus.publish(teleop_topic("robot_1"), Twist(v_mps, w_radps), HostId("robot_1")),
    )


def test_a_teleop_robot_follows_its_commands_and_stops_after_the_dead_man_timeout() -> None:
    assembly = _teleop_lab_room()
    run = assembly.run
    fleet = run.service(FleetState)
    start = (float(fleet.x[0]), float(fleet.y[0]))
    others = np.stack([fleet.x[1:], fleet.y[1:]], axis=1).copy()
    for k in range(10):  # 0.4 m/s forward and a slight left turn for 1 s, every 0.1 s
        _command(assembly, 0.1 * k, 0.4, 0.2)
    run.kernel.run(s_to_ns(1.0))
    assert fleet.v[0] > 0.3 and fleet.w[0] > 0.1
    driven = math.dist(start, (float(fleet.x[0]), float(fleet.y[0])))
    assert 0.25 < driven < 0.4
    run.kernel.run(s_to_ns(0.9 + DEADMAN_S + 0.3))  # the last command at 0.9 s, then silence
    assert fleet.v_cmd[0] == 0.0 and fleet.w_cmd[0] == 0.0
    assert abs(fleet.v[0]) < 1e-9 and abs(fleet.w[0]) < 1e-9
    stopped = (float(fleet.x[0]), float(fleet.y[0]))
    run.kernel.run(s_to_ns(3.0))
    assert math.dist((float(fleet.x[0]), float(fleet.y[0])), stopped) < 1e-6
    np.testing.assert_array_equal(np.stack([fleet.x[1:], fleet.y[1:]], axis=1), others)
    summary = dict(next(a for n, a in assembly.adapters if n == "teleop").finish(run))
    assert summary == {"teleop_commands": 10, "teleop_deadman_stops": 1}


def test_teleop_commands_beyond_the_robots_limits_are_clipped_to_them() -> None:
    assembly = _teleop_lab_room()
    run = assembly.run
    fleet = run.service(FleetState)
    robots = run.settings(RobotsConfig)
    for k in range(20):
        _command(assembly, 0.1 * k, 50.0, -40.0)
    run.kernel.run(s_to_ns(1.95))
    assert fleet.v_cmd[0] == robots.max_speed_mps
    assert fleet.w_cmd[0] == -robots.max_yaw_rate_radps
