"""Moving discs from several sources, read as one union in the order sources registered."""

import numpy as np
import pytest

from models.world.obstacles import DynamicObstacles


def test_no_source_means_no_discs():
    obstacles = DynamicObstacles()
    assert obstacles.discs.shape == (0, 3) and obstacles.names == [] and len(obstacles) == 0


def test_the_union_follows_the_order_sources_first_registered_in():
    obstacles = DynamicObstacles()
    obstacles.update("people", np.array([[1.0, 2.0, 0.3]]), ["p0"], ["person"])
    obstacles.update("forklifts", np.array([[5.0, 5.0, 1.0], [6.0, 5.0, 1.0]]), ["f0", "f1"])
    obstacles.update("people", np.array([[1.5, 2.0, 0.3], [0.0, 0.0, 0.3]]), ["p0", "p1"])
    assert obstacles.names == ["p0", "p1", "f0", "f1"]
    assert obstacles.discs.tolist() == [
        [1.5, 2.0, 0.3],
        [0.0, 0.0, 0.3],
        [5.0, 5.0, 1.0],
        [6.0, 5.0, 1.0],
    ]
    assert len(obstacles) == 4


def test_each_disc_says_what_it_is_dynamic_unless_told():
    obstacles = DynamicObstacles()
    obstacles.update("people", np.array([[1, 2, 0.3], [3, 4, 0.3]]), ["a", "b"], ["person"] * 2)
    obstacles.update("carts", np.array([[0, 0, 0.5]]), ["c"])
    assert [obstacles.kind(i) for i in range(3)] == ["person", "person", "dynamic"]
    with pytest.raises(IndexError):
        obstacles.kind(3)


def test_a_source_may_empty_its_discs_and_flat_discs_are_read_three_by_three():
    obstacles = DynamicObstacles()
    obstacles.update("people", np.array([1.0, 2.0, 0.3, 4.0, 5.0, 0.3]), ["a", "b"])
    assert obstacles.discs.shape == (2, 3)
    obstacles.update("people", np.zeros((0, 3)), [])
    assert len(obstacles) == 0 and obstacles.names == []


@pytest.mark.parametrize(("names", "kinds"), [(["a"], None), (["a", "b"], ["person"]), ([], None)])
def test_names_or_kinds_that_do_not_match_the_discs_are_refused_naming_the_source(names, kinds):
    obstacles = DynamicObstacles()
    with pytest.raises(ValueError, match=r"^people: 2 discs"):
        obstacles.update("people", np.zeros((2, 3)), names, kinds)


def test_a_source_given_an_array_it_keeps_changing_does_not_change_the_union():
    obstacles = DynamicObstacles()
    mine = np.array([[1.0, 1.0, 0.2]])
    obstacles.update("people", mine, ["a"])
    first = obstacles.discs.copy()
    obstacles.update("people", mine * 2, ["a"])
    assert obstacles.discs.tolist() == [[2.0, 2.0, 0.4]] and first.tolist() == [[1.0, 1.0, 0.2]]
