import numpy as np
import pytest

from cosim.envs import WarehouseAECEnv, WarehouseEnv, WarehouseParallelEnv


def test_an_rgb_frame_shows_the_room_and_the_robots_where_they_are():
    env = WarehouseEnv("lab-room", render_mode="rgb_array", duration_s=2.0)
    env.reset(seed=1)
    first = env.render()
    for _ in range(10):
        env.step(np.tile([0.5, 0.0], (4, 1)).astype(np.float32))
    later = env.render()
    assert first.dtype == np.uint8 and first.ndim == 3 and first.shape[2] == 3
    assert first.shape == later.shape
    assert first.shape[0] > first.shape[1]  # the 4 m x 8 m room stands upright
    assert (first != later).any()  # the robots moved (and the clock)
    assert (first < 100).all(axis=2).mean() > 0.01  # the walls are drawn dark


def test_without_a_render_mode_nothing_is_drawn_and_others_are_refused():
    assert WarehouseEnv("lab-room", duration_s=1.0).render() is None
    parallel = WarehouseParallelEnv("lab-room", duration_s=1.0, render_mode="rgb_array")
    parallel.reset(seed=1)
    assert parallel.render().ndim == 3
    with pytest.raises(ValueError, match="'rgb_array'"):
        WarehouseAECEnv("lab-room", render_mode="human")
