import numpy as np
import pytest

from cosim.core.rng import RngStreams


def test_the_same_seed_and_name_give_the_same_numbers():
    a = RngStreams(7).stream("lidar/robot_1").random(5)
    b = RngStreams(7).stream("lidar/robot_1").random(5)
    np.testing.assert_array_equal(a, b)


def test_different_seeds_give_different_numbers():
    a = RngStreams(7).stream("lidar/robot_1").random(5)
    b = RngStreams(8).stream("lidar/robot_1").random(5)
    assert not np.array_equal(a, b)


def test_a_stream_does_not_depend_on_which_other_streams_were_issued_before():
    alone = RngStreams(3).stream("waypoints/robot_2").random(4)
    streams = RngStreams(3)
    for name in ("world", "lidar/robot_1", "humans", "network/base"):
        streams.stream(name).random(100)
    crowded = streams.stream("waypoints/robot_2").random(4)
    np.testing.assert_array_equal(alone, crowded)


def test_different_names_give_independent_streams():
    streams = RngStreams(3)
    assert not np.array_equal(streams.stream("a").random(4), streams.stream("b").random(4))


def test_a_name_can_be_issued_only_once():
    streams = RngStreams(3)
    streams.stream("world")
    with pytest.raises(ValueError, match="already issued"):
        streams.stream("world")


def test_the_global_numpy_state_is_untouched():
    np.random.seed(123)
    expected = np.random.random(3)
    np.random.seed(123)
    RngStreams(1).stream("x").random(10)
    np.testing.assert_array_equal(np.random.random(3), expected)


def test_block_draws_give_each_component_exactly_its_own_stream():
    from cosim.core.rng import BlockDraws

    blocks = BlockDraws([RngStreams(2).stream(f"c{i}") for i in range(3)], width=4, budget=24)
    assert blocks.block == 2
    drawn = np.stack([blocks.draw().copy() for _ in range(5)], axis=1)  # (3, 5, 4)
    for i in range(3):
        alone = RngStreams(2).stream(f"c{i}")
        expected = np.concatenate([alone.standard_normal((2, 4)) for _ in range(3)])[:5]
        np.testing.assert_array_equal(drawn[i], expected)
