import math

import numpy as np

from models.mapping.posegraph import Edge, PoseGraph
from models.mapping.se2 import compose, relative


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
