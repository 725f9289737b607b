import math

import numpy as np
import pytest

from models.geometry.se2 import compose, relative
from models.mapping.posegraph import Edge, PoseGraph, sqrt_information


def _square(drift: float) -> tuple[PoseGraph, list]:
    """A 4 x 4 m square in 16 steps; odometry turns a little too much each step."""
    truth = []
    pose = (0.0, 0.0, 0.0)
    for _ in range(4):
        for _ in range(4):
            truth.append(pose)
            pose = compose(pose, (1.0, 0.0, 0.0))
        pose = compose(pose, (0.0, 0.0, math.pi / 2))
    graph = PoseGraph()
    estimate = truth[0]
    graph.add_node(estimate)
    for k in range(1, len(truth)):
        step = relative(truth[k - 1], truth[k])
        measured = (step[0], step[1], step[2] + drift)
        estimate = compose(estimate, measured)
        graph.add_node(estimate)
        graph.add_edge(Edge(k - 1, k, measured, 0.05, 0.02))
    return graph, truth


def test_a_loop_closure_pulls_a_drifted_square_back_together():
    graph, truth = _square(0.03)
    before = np.hypot(*(np.array(graph.nodes)[:, :2] - np.array(truth)[:, :2]).T).max()
    # the last pose is seen again from the first: it is truly one step before it
    graph.add_edge(Edge(len(truth) - 1, 0, relative(truth[-1], truth[0]), 0.05, 0.02))
    solved = np.array(graph.optimize())
    after = np.hypot(*(solved[:, :2] - np.array(truth)[:, :2]).T).max()
    assert before > 0.5 and after < 0.25
    assert tuple(solved[0]) == truth[0]  # the first node stays


def test_consistent_edges_leave_the_poses_where_they_are():
    graph, _ = _square(0.0)
    assert np.allclose(np.array(graph.optimize()), np.array(graph.nodes), atol=1e-6)


def test_an_edge_sure_across_a_corridor_gives_way_along_it():
    """Two measurements of node 1 disagree by 1 m in x and in y; each is sure of one axis."""
    graph = PoseGraph()
    graph.add_node((0.0, 0.0, 0.0))
    graph.add_node((0.0, 0.0, 0.0))
    along_x_unsure = sqrt_information(np.diag([10.0**2, 0.01**2, 0.01**2]))
    along_y_unsure = sqrt_information(np.diag([0.01**2, 10.0**2, 0.01**2]))
    graph.add_edge(Edge(0, 1, (0.0, 0.0, 0.0), 0.0, 0.0, along_x_unsure))
    graph.add_edge(Edge(0, 1, (1.0, 1.0, 0.0), 0.0, 0.0, along_y_unsure))
    x, y, _ = graph.optimize()[1]
    assert x == pytest.approx(1.0, abs=1e-3)  # the second edge is the one sure of x
    assert y == pytest.approx(0.0, abs=1e-3)  # the first is the one sure of y


def test_residuals_are_zero_where_edges_are_met_and_whitened_where_not():
    graph, _ = _square(0.0)
    assert np.allclose(graph.residuals(), 0.0, atol=1e-12)
    moved = list(graph.nodes)
    moved[1] = (moved[1][0] + 0.1, moved[1][1], moved[1][2])  # 0.1 m = two sigmas of 0.05
    chi2 = graph.residuals(moved)
    assert chi2[0] == pytest.approx(4.0) and chi2[1] == pytest.approx(4.0)
    assert np.allclose(chi2[2:], 0.0, atol=1e-12)


def test_the_square_root_information_whitens_its_covariance():
    covariance = np.array([[0.04, 0.01, 0.0], [0.01, 0.09, 0.002], [0.0, 0.002, 0.01]])
    root = sqrt_information(covariance)
    assert np.allclose(root.T @ root, np.linalg.inv(covariance))
    assert np.allclose(root @ covariance @ root.T, np.eye(3))
