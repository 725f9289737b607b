"""The graph of map updates: its steps, their covariances, and the edges of closures."""

import math

import numpy as np
import pytest

from models.mapping.loop_params import LoopParams
from models.mapping.update_graph import UpdateGraph, in_frame
from tests.models.mapping.conftest import MATCHED, closure, out_and_back

SCAN = np.full(8, 5.0, np.float32)


def test_a_step_is_as_sure_as_odometry_and_matching_together():
    updates = out_and_back()
    fused = np.linalg.inv(updates.steps[5])
    odometry = np.linalg.inv(updates.odometry_covariance((0.5, 0.0, 0.0)))
    assert np.allclose(fused, odometry + np.linalg.inv(MATCHED))


def test_an_unmatched_step_is_as_sure_as_odometry_alone():
    updates = UpdateGraph(LoopParams())
    updates.add((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), SCAN)
    updates.add((1.0, 0.0, 0.5), (1.0, 0.0, 0.5), SCAN)
    assert np.allclose(updates.steps[1], updates.odometry_covariance((1.0, 0.0, 0.5)))
    # 10 % of the distance plus 2 cm; 5 % of the turn, 0.01 rad per metre plus 0.005 rad
    assert np.allclose(np.sqrt(np.diag(updates.steps[1])), (0.12, 0.12, 0.04))


def test_the_path_length_adds_up_the_steps_between_updates():
    updates = out_and_back()
    assert updates.path_m[0] == 0.0
    assert updates.path_m[19] == pytest.approx(9.5)
    assert updates.path_m[20] == pytest.approx(9.5 + 2.0)  # the U-turn: 2 m north
    assert updates.path_m[-1] == pytest.approx(9.5 + 2.0 + 9.5)
    assert len(updates.graph.edges) == len(updates.loop_edges) == 39
    assert not any(updates.loop_edges)


def test_an_update_keeps_its_odometry_and_a_copy_of_its_scan():
    updates = UpdateGraph(LoopParams())
    scan = np.full(8, 3.0)
    updates.add((1.0, 2.0, 0.0), (0.5, 0.5, 0.1), scan)
    scan[:] = 0.0
    assert updates.nodes[0].odom == (0.5, 0.5, 0.1)
    assert updates.nodes[0].ranges.dtype == np.float32 and np.all(updates.nodes[0].ranges == 3.0)


def test_the_chain_covariance_grows_with_the_path_and_its_lever():
    updates = out_and_back()
    near, far = updates.chain_covariance(0, 5), updates.chain_covariance(0, 19)
    along, sideways = far[0, 0] / near[0, 0], far[1, 1] / near[1, 1]
    assert along == pytest.approx(19 / 5, rel=0.01)  # step variances add up
    assert sideways > 2 * along  # and heading errors swing the far end further
    assert np.all(np.linalg.eigvalsh(far) > 0)


def test_the_chain_covariance_in_map_axes_is_the_same_either_way_and_zero_at_one_node():
    updates = out_and_back()
    assert np.array_equal(updates.chain_covariance_map(3, 30), updates.chain_covariance_map(30, 3))
    assert np.array_equal(updates.chain_covariance_map(7, 7), np.zeros((3, 3)))
    # node 21 heads west: its frame's x is map's -x, so the map axes keep the same variances
    in_map = updates.chain_covariance_map(21, 25)
    assert np.allclose(np.diag(in_map), np.diag(updates.chain_covariance(21, 25)))


def test_a_covariance_turned_a_quarter_turn_swaps_its_axes():
    covariance = np.diag([4.0, 1.0, 0.5])
    turned = in_frame(covariance, math.pi / 2)
    assert np.allclose(turned, np.diag([1.0, 4.0, 0.5]))


def test_a_corridor_match_constrains_nothing_along_the_corridor():
    updates = out_and_back()
    along_x = np.diag([0.3**2, 0.02**2, 0.01**2])  # the match's spread, map axes
    edge = updates.closure(2, 37, updates.graph.nodes[37], along_x)
    covariance = np.linalg.inv(edge.whitening().T @ edge.whitening())
    assert math.sqrt(covariance[0, 0]) == pytest.approx(LoopParams().ambiguous_sigma_m)
    assert math.sqrt(covariance[1, 1]) == pytest.approx(0.02)


def test_a_closure_is_seen_from_its_old_node():
    updates = out_and_back()
    edge = updates.closure(2, 37, (1.0, 2.5, math.pi / 2), np.diag([0.02**2, 0.02**2, 0.01**2]))
    assert (edge.a, edge.b) == (2, 37)
    assert np.allclose(edge.z, (0.0, 2.5, math.pi / 2))  # node 2 is at (1, 0) heading east


def test_closures_solved_with_stay_in_the_graph_until_dropped():
    updates = out_and_back()
    drifted = closure(updates, 2, 37, (0.1, 0.0, 0.0))
    solved = updates.solve_with([drifted, closure(updates, 3, 36, (0.1, 0.0, 0.0))])
    assert len(solved) == 40 and solved[0] == updates.graph.nodes[0]
    assert updates.loop_edges[-2:] == [True, True] and updates.graph.edges[-2] is drifted
    updates.drop(2)
    assert len(updates.graph.edges) == len(updates.loop_edges) == 39
    assert not any(updates.loop_edges)
