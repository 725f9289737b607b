import math

import numpy as np
import pytest

from models.geometry.occupancy import FREE, OCCUPIED, UNKNOWN
from models.mapping.quality import align_se2, ate_rmse, dilate, map_scores, observable


def _room() -> tuple[np.ndarray, np.ndarray]:
    truth = np.zeros((40, 60), dtype=np.int8)
    truth[[0, -1], :] = OCCUPIED
    truth[:, [0, -1]] = OCCUPIED
    truth[10:20, 20:30] = OCCUPIED  # a shelf: its inside is never seen
    room = np.ones_like(truth, dtype=bool)
    return truth, room


def test_a_perfect_map_scores_one_and_the_inside_of_a_shelf_is_not_observable():
    truth, room = _room()
    seen = observable(truth, room)
    assert not seen[15, 25] and seen[10, 25] and seen[5, 5]
    cells = np.where(seen, truth, UNKNOWN).astype(np.int8)
    assert map_scores(cells, truth, seen) == (1.0, 1.0, 1.0, 1.0)


def test_an_empty_map_covers_nothing_and_has_no_wrong_cell():
    truth, room = _room()
    scores = map_scores(np.full_like(truth, UNKNOWN), truth, observable(truth, room))
    assert scores.coverage == 0.0 and scores.accuracy == 0.0


def test_obstacles_one_cell_off_keep_the_tolerant_iou_and_halve_the_strict_one():
    truth, room = _room()
    seen = observable(truth, room)
    cells = np.where(seen, truth, UNKNOWN).astype(np.int8)
    shifted = cells.copy()
    shifted[10:20, 20:30] = UNKNOWN
    shifted[10:20, 21:31] = np.where(truth[10:20, 20:30] == OCCUPIED, OCCUPIED, FREE)
    scores = map_scores(shifted, truth, seen)
    assert scores.iou > 0.95
    assert scores.iou_strict < scores.iou


def test_a_phantom_obstacle_in_free_space_lowers_iou_and_accuracy():
    truth, room = _room()
    seen = observable(truth, room)
    cells = np.where(seen, truth, UNKNOWN).astype(np.int8)
    cells[30:36, 40:50] = OCCUPIED
    scores = map_scores(cells, truth, seen)
    assert scores.iou < 0.9 and scores.accuracy < 1.0 and scores.coverage == 1.0


def test_alignment_recovers_a_rigid_motion_and_the_ate_is_then_zero():
    rng = np.random.default_rng(3)
    ref = rng.uniform(-10, 10, (50, 2))
    angle = 0.7
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    est = ref @ rot.T + [3.0, -2.0]
    rotation, shift = align_se2(est, ref)
    assert np.allclose(est @ rotation.T + shift, ref)
    assert ate_rmse(est, ref, align=True) == pytest.approx(0.0, abs=1e-9)
    assert ate_rmse(est, ref, align=False) > 1.0
    assert ate_rmse(ref + np.array([0.3, 0.4]), ref, align=False) == pytest.approx(0.5)


def _scores_by_masks(cells, truth, seen):
    """The scores as first written, with whole-grid masks and shifted-OR dilations."""
    known = cells != UNKNOWN
    coverage = np.count_nonzero(known & seen) / max(1, int(np.count_nonzero(seen)))
    mapped = cells == OCCUPIED
    real = (truth == OCCUPIED) & known
    union = np.count_nonzero(mapped | real)
    strict = np.count_nonzero(mapped & real) / union if union else 1.0
    right = np.count_nonzero(mapped & dilate(truth == OCCUPIED))
    missed = np.count_nonzero(real & ~dilate(mapped))
    total = np.count_nonzero(mapped) + missed
    iou = right / total if total else 1.0
    correct = np.count_nonzero(known & (cells == truth))
    accuracy = correct / max(1, int(np.count_nonzero(known)))
    return (float(coverage), float(iou), float(accuracy), float(strict))


@pytest.mark.parametrize("seed", range(6))
def test_scores_counted_cell_by_cell_equal_the_scores_of_whole_grid_masks(seed):
    rng = np.random.default_rng(seed)
    shape = tuple(rng.integers(1, 30, 2))
    values = np.array([UNKNOWN, FREE, OCCUPIED], dtype=np.int8)
    cells = rng.choice(values, shape, p=rng.dirichlet(np.ones(3)))
    truth = rng.choice(values[1:], shape, p=[0.8, 0.2])
    seen = rng.random(shape) < 0.7
    assert map_scores(cells, truth, seen) == _scores_by_masks(cells, truth, seen)


def test_scores_of_an_empty_map_and_an_empty_truth_equal_those_of_whole_grid_masks():
    truth, room = _room()
    empty = np.full_like(truth, UNKNOWN)
    seen = observable(truth, room)
    assert map_scores(empty, truth, seen) == _scores_by_masks(empty, truth, seen)
    free = np.zeros_like(truth)
    assert map_scores(truth, free, seen) == _scores_by_masks(truth, free, seen)
