"""Loop closure as the mapper uses it: updates in, a re-solved pose and a rebuilt map out.

The checks a closure passes are tested in ``test_closure_checks.py``, the search in
``test_loop_search.py`` and the graph of updates in ``test_update_graph.py``.
"""

import math
from dataclasses import replace

import numpy as np

from models.geometry.se2 import compose
from models.mapping.grid import LogOddsMap
from models.mapping.loop_params import LoopParams
from models.mapping.loops import LoopCloser
from tests.models.mapping.conftest import LAP, MATCHED, ROOM, Lidar, integrate, room_map

LIDAR = Lidar(ROOM)
TRUTH = LAP + LAP[:20]
"""A lap of the room (25 m) and half of it again."""


def _drive(
    sideways_per_node_m: float, params: LoopParams | None = None, nodes: int = len(TRUTH)
) -> tuple[LoopCloser, LogOddsMap, list[tuple[int, tuple[float, float, float]]]]:
    """Updates along ``TRUTH`` whose estimates drift to the left from the sixth on.

    Returns:
        The loop closer, the map it rebuilds, and every (node, re-solved pose) it returned.
    """
    closer = LoopCloser(
        params or LoopParams(), LIDAR.angles, range_min_m=0.1, range_max_m=10.0,
        clear_no_return_m=3.0,
    )  # fmt: skip
    grid = room_map()
    solved = []
    for k, pose in enumerate(TRUTH[:nodes]):
        estimate = compose(pose, (0.0, sideways_per_node_m * max(0, k - 5), 0.0))
        integrate(grid, LIDAR, estimate)
        closer.add(estimate, pose, LIDAR.scan(pose), True, MATCHED)
        closed = closer.close(grid)
        if closed is not None:
            solved.append((k, closed))
    return closer, grid, solved


def _counts(closer: LoopCloser) -> tuple[int, int, int, int, int]:
    return (
        closer.closures, closer.not_needed, closer.waiting, closer.implausible, closer.rejected
    )  # fmt: skip


def test_no_loop_is_found_before_the_path_is_long_enough_to_come_back():
    closer, _, solved = _drive(0.0, nodes=16)  # 9.4 m of path: under min_path_m
    assert solved == [] and _counts(closer) == (0, 0, 0, 0, 0)


def test_loops_are_searched_at_most_every_every_nodes_updates():
    closer = LoopCloser(
        replace(LoopParams(), every_nodes=3), LIDAR.angles, range_min_m=0.1, range_max_m=10.0,
        clear_no_return_m=3.0,
    )  # fmt: skip
    searched = []
    candidates = closer.search.candidates

    def spied(poses: np.ndarray, k: int) -> tuple[int, list[int]] | None:
        searched.append(k)
        return candidates(poses, k)

    closer.search.candidates = spied  # type: ignore[method-assign]
    for pose in TRUTH[:12]:
        closer.add(pose, pose, LIDAR.scan(pose), True, MATCHED)
        closer.close(room_map())
    assert searched == [2, 5, 8, 11]


def test_a_revisit_the_estimate_already_agrees_with_is_recognised_but_not_added():
    closer, _, solved = _drive(0.0)
    assert closer.not_needed > 0 and closer.closures == 0
    assert solved == [] and not any(closer.updates.loop_edges)


def test_a_drifted_revisit_is_closed_and_the_newest_pose_comes_back_nearer_the_truth():
    closer, _, solved = _drive(0.005)
    assert closer.closures > 0 and sum(closer.updates.loop_edges) == closer.closures
    for k, pose in solved:
        drifted = compose(TRUTH[k], (0.0, 0.005 * (k - 5), 0.0))
        assert math.dist(pose[:2], TRUTH[k][:2]) < math.dist(drifted[:2], TRUTH[k][:2])
    assert closer.graph.nodes[solved[-1][0]] == solved[-1][1]


def test_a_map_moved_by_a_solve_is_rebuilt_from_every_scan_at_its_solved_pose():
    always = replace(LoopParams(), rebuild_shift_m=0.0)
    _, _, solved = _drive(0.005, always)
    first = solved[0][0]
    closer, grid, _ = _drive(0.005, always, nodes=first + 1)  # up to the first solve
    rebuilt = room_map()
    for pose, node in zip(closer.graph.nodes, closer.nodes, strict=True):
        rebuilt.integrate(
            pose, LIDAR.angles, node.ranges, range_min_m=0.1, range_max_m=10.0,
            clear_no_return_m=3.0,
        )  # fmt: skip
    assert closer.graph.nodes[first] == solved[0][1]
    assert np.array_equal(grid.logodds, rebuilt.logodds)


def test_a_revisit_asking_for_more_drift_than_the_path_allows_is_refused():
    closer, _, solved = _drive(0.02)
    assert closer.implausible > 0 and closer.closures == 0 and solved == []
    assert len(closer.graph.edges) == len(TRUTH) - 1


def test_the_graph_and_its_nodes_are_those_of_the_updates():
    closer, _, _ = _drive(0.0, nodes=3)
    assert closer.graph is closer.updates.graph and closer.nodes is closer.updates.nodes
    assert [node.odom for node in closer.nodes] == TRUTH[:3]
