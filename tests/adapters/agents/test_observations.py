import numpy as np
import pytest

from cosim.envs import Agents

ALL = ["pose", "velocity", "goal", "lidar", "inbox", "places"]


@pytest.fixture(scope="module")
def agents():
    agents = Agents("lab-room", overrides={"agents.observe": ALL}, duration_s=2.0)
    agents.reset(seed=5)
    for _ in range(10):
        agents.act(np.arange(4), np.tile([0.3, 0.2], (4, 1)))
        agents.advance_all()
    return agents


def _parts(agents):
    obs, start = agents.observe(), 0
    parts = {}
    for name, part in zip(ALL, agents.episode.parts.observations, strict=True):
        parts[name] = obs[:, start : start + len(part.low)]
        start += len(part.low)
    assert start == obs.shape[1]
    return parts


def test_the_pose_and_velocity_parts_read_the_ground_truth(agents):
    parts, fleet = _parts(agents), agents.episode.view.fleet
    np.testing.assert_allclose(parts["pose"][:, 0], fleet.x, rtol=1e-6)
    np.testing.assert_allclose(parts["pose"][:, 3], np.sin(fleet.yaw), atol=1e-6)
    np.testing.assert_allclose(parts["velocity"][:, 0], fleet.v, atol=1e-6)


def test_the_goal_part_is_the_goal_seen_from_the_robot(agents):
    parts, view = _parts(agents), agents.episode.view
    fleet = view.fleet
    distance = np.hypot(view.goal_xy[:, 0] - fleet.x, view.goal_xy[:, 1] - fleet.y)
    np.testing.assert_allclose(parts["goal"][:, 2], distance, rtol=1e-5)
    np.testing.assert_allclose(
        np.hypot(parts["goal"][:, 0], parts["goal"][:, 1]), distance, rtol=1e-5
    )


def test_the_lidar_part_is_the_nearest_return_per_sector(agents):
    parts, view = _parts(agents), agents.episode.view
    lidar = parts["lidar"]
    assert lidar.shape == (4, 16)
    np.testing.assert_allclose(lidar.min(axis=1), view.ranges_m.min(axis=1), rtol=1e-6)
    assert (lidar < view.range_max_m).any()  # the room's walls are within 10 m


def test_sizes_follow_the_fleet_and_the_settings(agents):
    sizes = {p.name: len(p.low) for p in agents.episode.parts.observations}
    assert sizes == {"pose": 4, "velocity": 2, "goal": 3, "lidar": 16, "inbox": 12, "places": 16}
