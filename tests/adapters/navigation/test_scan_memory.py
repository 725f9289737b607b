import math

import numpy as np
import pytest

from adapters.navigation.scan_memory import MovingMemory, ScanMemory

ANGLES = -math.pi + 2 * math.pi / 8 * np.arange(8)  # every 45 deg, beam 4 looks ahead


def test_near_hits_are_packed_per_robot_in_map_frame():
    memory = ScanMemory(2, ANGLES, 10.0)
    ranges = np.full(8, np.inf, dtype=np.float32)
    ranges[4] = 2.0  # ahead
    memory.add(0, np.array([1.0, 1.0, math.pi / 2]), ranges)
    points, start = memory.near(3.0)
    assert list(start) == [0, 1, 1]
    assert points[0] == pytest.approx([1.0, 3.0])


def test_points_the_latest_scan_sees_through_are_cleared():
    memory = ScanMemory(1, ANGLES, 10.0)
    ranges = np.full(8, 5.0, dtype=np.float32)
    memory.add(0, np.array([0.0, 0.0, 0.0]), ranges)
    points = np.array([[2.0, 0.0], [6.0, 0.0], [0.0, -2.0]])
    assert list(memory.seen_through(0, points, 0.2)) == [True, False, True]


def test_moving_memory_forgets_after_its_span_and_dedups_cells():
    memory = MovingMemory(1_000_000_000)
    memory.remember(0, np.array([0, 1]), np.array([[1.0, 1.0], [5.0, 5.0]]))
    memory.remember(500_000_000, np.array([0]), np.array([[1.02, 1.03]]))
    assert len(memory.recall(0, 0.1)) == 1
    memory.remember(1_200_000_000, np.array([1]), np.array([[6.0, 6.0]]))
    assert len(memory.recall(0, 0.1)) == 1  # the first tick is forgotten, the second kept
    assert memory.recall(1, 0.1) == pytest.approx(np.array([[6.0, 6.0]]))


def test_moving_memory_recalls_first_sightings_in_order_on_any_cell_size():
    memory = MovingMemory(10_000_000_000, cell_m=0.1)
    memory.remember(0, np.array([0, 0, 2]), np.array([[1.0, 1.0], [2.0, 2.0], [9.0, 9.0]]))
    memory.remember(1, np.array([0, 0]), np.array([[3.0, 3.0], [1.01, 1.01]]))
    memory.remember(2, np.array([], dtype=np.int64), np.zeros((0, 2)))
    # the first sighting of each cell, oldest first; a robot beyond a tick's owners sees none
    assert memory.recall(0, 0.1) == pytest.approx(np.array([[1.0, 1.0], [2.0, 2.0], [3.0, 3.0]]))
    assert len(memory.recall(1, 0.1)) == 0
    assert len(memory.recall(5, 0.1)) == 0
    # a coarser grid merges cells: the keys are computed for it, not taken from arrival
    assert memory.recall(0, 2.5) == pytest.approx(np.array([[1.0, 1.0], [3.0, 3.0]]))


def test_moving_memory_recalls_exactly_what_a_sort_based_unique_keeps_over_many_instants():
    memory = MovingMemory(2_000_000_000, cell_m=0.1)
    rng = np.random.default_rng(3)
    kept = []
    for tick in range(40):  # 400 ms apart: 6 instants live at once, 300-900 points each
        k = int(rng.integers(300, 900))
        owner = np.sort(rng.integers(0, 3, k))
        points = rng.uniform(0, 50, (k, 2))
        memory.remember(tick * 400_000_000, owner, points)
        kept.append((tick * 400_000_000, owner, points))
        now = tick * 400_000_000
        live = [(o, p) for t, o, p in kept if now - t <= 2_000_000_000]
        for robot in range(3):
            every = np.concatenate([p[o == robot] for o, p in live])
            keys = np.floor(every / 0.1).astype(np.int64)
            _, first = np.unique(keys[:, 0] * 1_000_003 + keys[:, 1], return_index=True)
            np.testing.assert_array_equal(memory.recall(robot, 0.1), every[np.sort(first)])
