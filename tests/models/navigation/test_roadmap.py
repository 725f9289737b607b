"""The traffic roadmap: robot-sized places, clear edges, one-way aisles."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage, sparse
from scipy.sparse import csgraph

from models.errors import ModelError
from models.navigation.lanes import EAST, TWO_WAY
from models.navigation.roadmap import (
    STEPS,
    UNREACHABLE,
    Roadmap,
    build_roadmap,
    one_way,
    one_way_floor,
)

RES = 0.1
CLEARANCE = 0.43  # a 0.33 m robot and a 0.1 m margin


def _distance(obstacle: np.ndarray) -> np.ndarray:
    """Distance (m) from each cell centre to the nearest obstacle cell centre."""
    return ndimage.distance_transform_edt(~obstacle) * RES


def _hall_with_a_box() -> np.ndarray:
    obstacle = np.zeros((80, 100), dtype=bool)  # 10 m x 8 m
    obstacle[0, :] = obstacle[-1, :] = obstacle[:, 0] = obstacle[:, -1] = True
    obstacle[30:50, 40:60] = True
    return obstacle


def _racks() -> np.ndarray:
    """A 10 m x 8 m hall with two 6 m racks 0.8 m deep and a 1.6 m aisle between them."""
    obstacle = np.zeros((80, 100), dtype=bool)
    obstacle[0, :] = obstacle[-1, :] = obstacle[:, 0] = obstacle[:, -1] = True
    obstacle[20:28, 20:80] = obstacle[44:52, 20:80] = True
    return obstacle


def test_places_keep_their_clearance_and_edges_join_neighbours_a_spacing_apart_on_clear_ground():
    obstacle = _hall_with_a_box()
    distance = _distance(obstacle)
    roadmap = build_roadmap(distance, (0.0, 0.0), RES, 0.8, CLEARANCE)
    ix = np.floor(roadmap.xy[:, 0] / RES).astype(int)
    iy = np.floor(roadmap.xy[:, 1] / RES).astype(int)
    assert (distance[iy, ix] >= CLEARANCE).all()
    for k, (dx, dy) in enumerate(STEPS):
        linked = np.flatnonzero(roadmap.neighbours[:, k] >= 0)
        other = roadmap.neighbours[linked, k]
        assert np.allclose(roadmap.xy[other] - roadmap.xy[linked], (0.8 * dx, 0.8 * dy))
        for t in np.linspace(0, 1, 17):  # every point of every edge keeps the clearance
            p = roadmap.xy[linked] + t * (roadmap.xy[other] - roadmap.xy[linked])
            cells = np.floor(p / RES).astype(int)
            assert (distance[cells[:, 1], cells[:, 0]] >= CLEARANCE).all()
    assert len(set(roadmap.component.tolist())) == 1  # round the box: one piece


def test_the_grid_is_shifted_to_put_a_line_of_places_along_a_narrow_aisle():
    roadmap = build_roadmap(_distance(_racks()), (0.0, 0.0), RES, 0.8, CLEARANCE)
    in_aisle = (roadmap.xy[:, 1] > 2.8) & (roadmap.xy[:, 1] < 4.4)
    in_aisle &= (roadmap.xy[:, 0] > 2.0) & (roadmap.xy[:, 0] < 8.0)
    assert in_aisle.sum() >= 7  # a line of places along the 6 m aisle
    along = roadmap.xy[in_aisle]
    assert np.ptp(along[:, 1]) == 0.0


def test_a_floor_without_room_for_a_single_place_is_refused():
    with pytest.raises(ModelError, match=r"navigation\.traffic"):
        build_roadmap(np.full((5, 5), 0.2), (0.0, 0.0), RES, 0.8, CLEARANCE)


def test_one_way_aisles_lose_their_backward_steps_and_hops_follow_the_directions():
    obstacle = _racks()
    roadmap = build_roadmap(_distance(obstacle), (0.0, 0.0), RES, 0.8, CLEARANCE)
    lanes = np.full(obstacle.shape, TWO_WAY, dtype=np.uint8)
    lanes[28:44, 20:80] = EAST  # the aisle between the racks, the way round two-way
    directed = one_way(roadmap, lanes, (0.0, 0.0), RES)
    row = np.flatnonzero((directed.xy[:, 1] > 2.8) & (directed.xy[:, 1] < 4.4))
    inner = row[(directed.xy[row, 0] > 2.5) & (directed.xy[row, 0] < 7.5)]
    assert (directed.neighbours[inner, 1] == -1).all()  # no step west in an east aisle
    assert (directed.neighbours[inner, 0] >= 0).all()  # east is fine
    west, east = inner[np.argmin(directed.xy[inner, 0])], inner[np.argmax(directed.xy[inner, 0])]
    hops_east = directed.hops_to(int(east))
    hops_west = directed.hops_to(int(west))
    straight = round((directed.xy[east, 0] - directed.xy[west, 0]) / 0.8)
    assert hops_east[west] == straight  # down the aisle
    assert hops_west[east] > straight  # back round the racks
    assert hops_west[east] != UNREACHABLE
    assert len(set(directed.component.tolist())) == 1  # still one strongly connected piece


def test_a_short_lane_that_would_leave_places_without_a_way_out_keeps_them_two_way():
    """A 2.4 m long lane ending in a dead end: east only, its last places could not leave."""
    obstacle = np.zeros((40, 60), dtype=bool)  # 6 m x 4 m
    obstacle[0, :] = obstacle[-1, :] = obstacle[:, 0] = obstacle[:, -1] = True
    obstacle[:14, 30:] = True  # the room's right half is a dead-end corridor 1.2 m wide
    obstacle[26:, 30:] = True
    roadmap = build_roadmap(_distance(obstacle), (0.0, 0.0), RES, 0.8, CLEARANCE)
    assert len(set(roadmap.component.tolist())) == 1
    lanes = np.full(obstacle.shape, TWO_WAY, dtype=np.uint8)
    lanes[14:26, 30:] = EAST
    directed = one_way(roadmap, lanes, (0.0, 0.0), RES)
    assert len(set(directed.component.tolist())) == 1  # every place reaches every other
    dead_end = np.flatnonzero(directed.xy[:, 0] > 3.0)
    assert len(dead_end) >= 2
    assert (directed.neighbours[dead_end, 1] >= 0).any()  # a way back west


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    keep=st.floats(0.3, 1.0),
)
def test_hops_to_a_place_are_the_fewest_steps_along_the_edges_directions(seed, keep):
    """Against scipy's breadth-first shortest paths on the same directed graph."""
    rng = np.random.default_rng(seed)
    roadmap = build_roadmap(_distance(_hall_with_a_box()), (0.0, 0.0), RES, 0.8, CLEARANCE)
    neighbours = np.where(rng.random(roadmap.neighbours.shape) < keep, roadmap.neighbours, -1)
    directed = Roadmap(roadmap.xy, neighbours, roadmap.spacing_m)
    m = len(directed)
    rows, cols = np.nonzero(neighbours >= 0)
    graph = sparse.csr_matrix((np.ones(len(rows)), (rows, neighbours[rows, cols])), shape=(m, m))
    goal = int(rng.integers(m))
    expected = csgraph.shortest_path(graph.T.tocsr(), unweighted=True, indices=goal)
    hops = directed.hops_to(goal)
    reached = np.isfinite(expected)
    assert (hops[~reached] == UNREACHABLE).all()
    np.testing.assert_array_equal(hops[reached], expected[reached].astype(np.int32))


def _two_way(roadmap: Roadmap) -> set[tuple[int, int]]:
    return {
        (u, int(v))
        for u in range(len(roadmap))
        for v in roadmap.neighbours[u]
        if v >= 0 and u in roadmap.neighbours[v]
    }


def test_the_open_floor_becomes_alternating_one_way_streets_that_still_reach_everywhere():
    roadmap = build_roadmap(_distance(_hall_with_a_box()), (0.0, 0.0), RES, 0.8, CLEARANCE)
    lanes = np.full((80, 100), TWO_WAY, dtype=np.uint8)
    streets = one_way_floor(roadmap, lanes, (0.0, 0.0), RES)
    assert len(set(streets.component.tolist())) == 1
    row = np.rint((streets.xy[:, 1] - streets.xy[:, 1].min()) / 0.8).astype(int)
    col = np.rint((streets.xy[:, 0] - streets.xy[:, 0].min()) / 0.8).astype(int)
    both = {u for u, _ in _two_way(streets)}
    one_way_only = np.array([u not in both for u in range(len(streets))])
    east, west, north, south = ((streets.neighbours[:, k] >= 0) & one_way_only for k in range(4))
    # a row runs one way, the next the other; so do the columns
    for r in np.unique(row):
        assert not (east[row == r].any() and west[row == r].any()), r
        assert east[row == r].any() == (west[row == r + 1].any() or not (row == r + 1).any())
    for c in np.unique(col):
        assert not (north[col == c].any() and south[col == c].any()), c
    assert {bool(north[col == c].any()) for c in (0, 1)} == {True, False}
    # only places that would be cut off keep two-way steps: few of them
    assert len(_two_way(streets)) <= 0.05 * int((streets.neighbours >= 0).sum())
    assert len(_two_way(roadmap)) == int((roadmap.neighbours >= 0).sum())


def test_the_streets_run_the_way_of_the_aisles_they_continue():
    obstacle = _racks()
    roadmap = build_roadmap(_distance(obstacle), (0.0, 0.0), RES, 0.8, CLEARANCE)
    lanes = np.full(obstacle.shape, TWO_WAY, dtype=np.uint8)
    lanes[28:44, 20:80] = EAST
    streets = one_way_floor(one_way(roadmap, lanes, (0.0, 0.0), RES), lanes, (0.0, 0.0), RES)
    band = np.flatnonzero((streets.xy[:, 1] > 2.8) & (streets.xy[:, 1] < 4.4))
    inner = band[(streets.xy[band, 0] > 2.5) & (streets.xy[band, 0] < 7.5)]
    (y,) = np.unique(streets.xy[inner, 1])  # the aisle holds one line of places
    line = np.flatnonzero(np.isclose(streets.xy[:, 1], y))
    floor = line[(streets.xy[line, 0] < 1.9) | (streets.xy[line, 0] > 8.1)]
    assert len(floor) >= 4
    assert (streets.neighbours[floor, 1] == -1).all()  # the row goes on east, off the aisle
    assert len(set(streets.component.tolist())) == 1


@settings(max_examples=40, deadline=None)
@given(boxes=st.lists(st.tuples(st.integers(5, 90), st.integers(5, 70)), max_size=6))
def test_streets_keep_together_every_place_that_was_reachable_before(boxes):
    obstacle = _hall_with_a_box()
    for x, y in boxes:
        obstacle[y : y + 8, x : x + 8] = True
    roadmap = build_roadmap(_distance(obstacle), (0.0, 0.0), RES, 0.8, CLEARANCE)
    lanes = np.full(obstacle.shape, TWO_WAY, dtype=np.uint8)
    streets = one_way_floor(roadmap, lanes, (0.0, 0.0), RES)
    for component in np.unique(roadmap.component):
        members = roadmap.component == component
        assert len(np.unique(streets.component[members])) == 1
    # and never a step that was not there
    kept = streets.neighbours >= 0
    assert (streets.neighbours[kept] == roadmap.neighbours[kept]).all()
