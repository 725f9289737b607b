"""The search for a loop closure: candidates, the match on old scans, the check on recent ones."""

import math
from dataclasses import replace

import numpy as np
import pytest

from models.geometry.se2 import compose
from models.mapping.loop_params import LoopParams
from models.mapping.loop_search import LoopSearch
from models.mapping.posegraph import Edge
from models.mapping.update_graph import UpdateGraph
from tests.models.mapping.conftest import LAP, ROOM, Lidar, integrate, room_map

LIMITS = (0.1, 10.0, 3.0)


def _lap_and_a_bit(params: LoopParams | None = None) -> LoopSearch:
    """The search over a lap of the room and five updates more (back where it started)."""
    params = params or LoopParams()
    lidar = Lidar(ROOM)
    updates = UpdateGraph(params)
    for pose in LAP + LAP[:5]:
        updates.add(pose, pose, lidar.scan(pose))
    return LoopSearch(params, lidar.angles, updates, LIMITS)


def _poses(search: LoopSearch) -> np.ndarray:
    return np.array(search.updates.graph.nodes)


def test_a_candidate_too_close_along_the_path_is_not_searched():
    search = _lap_and_a_bit()
    poses = _poses(search)
    assert math.dist(poses[10, :2], poses[9, :2]) < LoopParams().search_radius_m
    assert search.candidates(poses, 10) is None  # 10 m of path have not been driven yet


def test_the_nearest_old_node_far_back_along_the_path_is_found_with_its_neighbours():
    search = _lap_and_a_bit()
    poses, k = _poses(search), 44
    found = search.candidates(poses, k)
    assert found is not None
    nearest, chosen = found
    assert nearest == 4  # the same place, a lap ago
    far_back = np.asarray(search.updates.path_m) <= search.updates.path_m[k] - 10.0
    near = np.hypot(*(poses[:, :2] - poses[k, :2]).T) <= 4.0
    assert chosen == np.flatnonzero(far_back & near).tolist()


def test_only_candidates_within_local_nodes_of_the_nearest_make_its_map():
    search = _lap_and_a_bit(replace(LoopParams(), local_nodes=2))
    assert search.candidates(_poses(search), 44) == (4, [2, 3, 4, 5, 6])


def test_no_old_node_within_the_search_radius_means_no_candidates():
    search = _lap_and_a_bit(replace(LoopParams(), search_radius_m=0.2))
    poses = _poses(search)
    poses[44, :2] += (0.3, 0.0)  # 0.3 m from where it was a lap ago
    assert search.candidates(poses, 44) is None


def test_a_drifted_scan_of_an_old_place_matches_where_it_was_taken():
    search = _lap_and_a_bit()
    poses = _poses(search)
    poses[44] = compose(tuple(poses[44]), (0.4, -0.3, 0.05))  # the estimate has drifted
    found = search.match(room_map().geometry, poses, list(range(11)), 44)
    assert found is not None
    pose, covariance = found
    assert math.dist(pose[:2], LAP[4][:2]) < 0.05
    assert abs(pose[2] - LAP[4][2]) < 0.02
    assert np.all(np.linalg.eigvalsh(covariance) > 0)


def test_a_scan_further_off_than_the_loop_window_does_not_match():
    search = _lap_and_a_bit()
    poses = _poses(search)
    poses[44] = compose(tuple(poses[44]), (0.0, 0.0, 1.0))  # 1 rad off: the window is 0.3
    assert search.match(room_map().geometry, poses, list(range(11)), 44) is None


def test_recent_scans_brought_back_onto_the_old_walls_explain_them_better():
    search = _lap_and_a_bit()
    truth = _poses(search)
    drifted = truth.copy()
    for j in range(29, 45):  # the recent nodes, not among the old ones round node 4
        drifted[j] = compose(tuple(truth[j]), (0.3, -0.2, 0.03))
    edge = Edge(4, 44, (0.0, 0.0, 0.0), 0.1, 0.1)
    geometry = room_map().geometry
    as_list = [tuple(p) for p in truth]
    assert search.explains_better(geometry, edge, drifted, as_list)
    assert not search.explains_better(geometry, edge, truth, [tuple(p) for p in drifted])


def test_a_closure_whose_recent_nodes_are_all_old_ones_explains_the_scans_as_well():
    search = _lap_and_a_bit()
    truth = _poses(search)
    edge = Edge(4, 10, (0.0, 0.0, 0.0), 0.1, 0.1)  # node 10 is within 15 nodes of node 4
    assert search.explains_better(room_map().geometry, edge, truth, [(9.0, 9.0, 0.0)] * 45)


def test_a_local_map_reaches_as_far_as_its_scans_see():
    search = _lap_and_a_bit()
    poses = _poses(search)
    local = search.local_map(room_map().geometry, poses, [0, 1, 2])
    lo = poses[:3, :2].min(axis=0) - 10.0  # the matcher's reach is the lidar's 10 m
    assert local.geometry.resolution_m == 0.05
    assert local.geometry.origin_xy_m[0] <= lo[0] and local.geometry.origin_xy_m[1] <= lo[1]
    assert not local.empty


def test_the_map_is_rebuilt_from_every_scan_at_its_pose_in_the_graph():
    search = _lap_and_a_bit()
    lidar = Lidar(ROOM)
    grid = room_map()
    integrate(grid, lidar, (1.0, 1.0, 0.0))  # evidence the rebuild forgets
    search.rebuild(grid)
    expected = room_map()
    for pose in LAP + LAP[:5]:
        integrate(expected, lidar, pose)
    assert np.array_equal(grid.logodds, expected.logodds)
    assert grid.occupied_cells == pytest.approx(expected.occupied_cells)
