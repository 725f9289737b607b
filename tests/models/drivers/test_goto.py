import math

import numpy as np

from models.drivers.goto import GoToGains, go_to_goal
from models.fleet.kinematics import DriveLimits, FleetState


def test_the_controller_turns_in_place_before_driving_to_a_goal_behind():
    v, w, arrived = go_to_goal(
        np.array([0.0]),
        np.array([0.0]),
        np.array([0.0]),
        np.array([-3.0]),
        np.array([0.1]),
        1.0,
        GoToGains(),
    )
    assert v[0] == 0.0 and w[0] != 0.0 and not arrived[0]


def test_robots_reach_their_goals_under_the_kinematic_limits():
    fleet = FleetState(["a", "b"], np.array([[0.0, 0.0, 0.0], [3.0, 3.0, math.pi]]), 0.3)
    goals = np.array([[4.0, 2.0], [-1.0, 5.0]])
    limits = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
    for _ in range(400):
        v, w, arrived = go_to_goal(
            fleet.x, fleet.y, fleet.yaw, goals[:, 0], goals[:, 1], 1.0, GoToGains()
        )
        fleet.v_cmd, fleet.w_cmd = v, w
        fleet.step(limits, 0.05)
    assert arrived.all()
    assert np.hypot(fleet.x - goals[:, 0], fleet.y - goals[:, 1]).max() < 0.25
