"""The world generator fits what fits, and names the binding key and its limit otherwise."""

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.errors import ModelError
from models.world.layout import box_gaps
from models.world.warehouse import WarehouseSpec, generate_warehouse


def _world(**kw):
    return generate_warehouse(WarehouseSpec(**kw), np.random.default_rng(1))


def _check_aisles(world, aisle):
    shelves = world.shelves
    for i, shelf in enumerate(shelves):
        others = np.delete(shelves, i, axis=0)
        if len(others):
            gaps = box_gaps(others, shelf)
            # shelves of one rack touch; racks keep an aisle apart
            assert ((np.abs(gaps) < 1e-9) | (gaps >= aisle - 1e-9)).all()
        assert shelf[0] >= aisle - 1e-9 and shelf[2] <= world.size_m[0] - aisle + 1e-9
        assert shelf[3] <= world.size_m[1] - aisle + 1e-9


@pytest.mark.parametrize("size", [(12.0, 20.0), (20.0, 20.0)])
def test_two_corridors_fit_a_small_room_with_shorter_racks_or_turned_shelves(size):
    count = 12 if size[0] == 12.0 else 24
    world = _world(size_m=size, layout="two_corridors", shelf_count=count)
    assert len(world.shelves) == count
    _check_aisles(world, 1.6)


def test_a_band_too_narrow_for_a_shelf_lengthwise_gets_it_turned():
    world = _world(size_m=(12.0, 20.0), layout="two_corridors", shelf_count=12)
    widths = world.shelves[:, 2] - world.shelves[:, 0]
    assert np.allclose(widths, 0.8)  # the 2.0 m x 0.8 m shelves stand along y


def test_racks_are_shortened_to_fit_the_room():
    world = _world(size_m=(9.0, 16.0), layout="all_rows", shelves_per_rack=3, shelf_count=8)
    assert len(world.shelves) == 8  # a 3-shelf rack (6 m) does not fit in 5.8 m
    _check_aisles(world, 1.6)


def test_a_shelf_longer_than_the_room_is_a_shelf_size_problem_with_the_longest_that_fits():
    with pytest.raises(ModelError) as error:
        _world(size_m=(10.0, 10.0), shelf_size_m=(40.0, 0.8))
    assert error.value.key == "world.shelf_size_m"
    assert "at most 6.80 m long" in error.value.expected
    _world(size_m=(10.0, 10.0), shelf_size_m=(6.8, 0.8), shelf_count=1)  # and that fits


def test_a_fleet_that_cannot_fit_is_reported_before_anything_else():
    with pytest.raises(ModelError) as error:
        _world(size_m=(3.0, 3.0), robot_count=200)  # the 24 shelves do not fit either
    assert error.value.key == "robots.count"
    most = int(re.search(r"at most (\d+) robots", error.value.expected).group(1))
    _world(size_m=(3.0, 3.0), robot_count=most, shelf_count=0)  # and that many fit


def test_a_room_too_narrow_for_two_corridors_names_the_width_it_needs():
    with pytest.raises(ModelError) as error:
        _world(size_m=(8.0, 20.0), layout="two_corridors", shelf_count=3)
    assert error.value.key == "world.size_m"
    least = float(re.search(r"at least ([0-9.]+) m wide", error.value.expected).group(1))
    _world(size_m=(least, 20.0), layout="two_corridors", shelf_count=3)


@settings(max_examples=40, deadline=None)
@given(
    width=st.floats(6.0, 40.0),
    height=st.floats(6.0, 40.0),
    layout=st.sampled_from(["all_rows", "two_corridors", "random"]),
    shelves=st.integers(1, 120),
    per_rack=st.integers(1, 5),
    robots=st.integers(1, 30),
)
def test_whatever_is_refused_names_a_limit_that_then_builds(
    width, height, layout, shelves, per_rack, robots
):
    spec = {
        "size_m": (width, height),
        "layout": layout,
        "shelf_count": shelves,
        "shelves_per_rack": per_rack,
        "robot_count": robots,
    }
    try:
        world = _world(**spec)
    except ModelError as error:
        found = re.search(r"at most (?:about )?(\d+) (shelves|robots)", error.expected)
        if found is None:
            return  # a size problem: named with its own limit (tested above)
        most, what = int(found.group(1)), found.group(2)
        key = {"shelves": "shelf_count", "robots": "robot_count"}[what]
        assert error.key in ("world.shelf_count", "robots.count")
        if layout == "random" or most == 0:
            return  # random packing is a search: its "about" is a best effort
        retry = {**spec, key: most}
        try:
            _world(**retry)
        except ModelError as again:  # the robots bound was the binding one, now the shelves
            assert again.key != error.key
        return
    assert len(world.shelves) == shelves
    _check_aisles(world, 1.6)
