import numpy as np
import pytest

from models.navigation.follow import PathBook, paths_blocked

L_PATH = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]])


def test_the_carrot_lies_the_lookahead_ahead_along_the_path():
    book = PathBook(1)
    book.set(0, L_PATH)
    carrot, remaining = book.follow(np.array([2.0]), np.array([0.1]), 1.0)
    assert carrot[0] == pytest.approx([3.0, 0.0])
    assert remaining[0] == pytest.approx(18.0 + 0.1)


def test_the_carrot_turns_the_corner():
    book = PathBook(1)
    book.set(0, L_PATH)
    carrot, _ = book.follow(np.array([9.5]), np.array([0.0]), 1.5)
    assert carrot[0] == pytest.approx([10.0, 1.0])


def test_projection_never_moves_back_along_the_path():
    book = PathBook(1)
    book.set(0, np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 1.0], [0.0, 1.0]]))
    book.follow(np.array([8.0]), np.array([0.9]), 0.5)  # on the way back
    assert book.segment[0] == 2
    book.follow(np.array([5.0]), np.array([0.2]), 0.5)  # nearer the first leg now
    assert book.segment[0] == 2


def test_a_robot_without_a_path_gets_its_own_position():
    book = PathBook(2)
    book.set(1, L_PATH)
    carrot, remaining = book.follow(np.array([4.0, 0.0]), np.array([5.0, 0.0]), 1.0)
    assert carrot[0] == pytest.approx([4.0, 5.0]) and remaining[0] == 0.0


def test_paths_blocked_flags_points_near_the_path_ahead_only():
    book = PathBook(2)
    book.set(0, L_PATH)
    book.set(1, L_PATH)
    owner = np.array([0, 1])
    points = np.array([[5.0, 0.3], [5.0, 3.0]])
    assert list(paths_blocked(book, owner, points, 0.5)) == [True, False]


def test_a_path_over_capacity_is_refused():
    with pytest.raises(ValueError, match="exceeds the capacity"):
        PathBook(1, capacity=2).set(0, L_PATH)
