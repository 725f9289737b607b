"""Mapping's compiled loops: the cells a scan updates, the clamped update, scores kept up."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from models.geometry.occupancy import FREE, OCCUPIED, UNKNOWN
from models.mapping.kernels import (
    _fold_hit,
    apply,
    classify,
    rebuild_scores,
    refresh_scores,
    traverse,
)

RES = 0.1
HIT, MISS, LO, HI, OCC = 0.85, -0.08, -2.0, 3.5, 0.62


def _traverse(shape, pose, angles, ranges, *, scan=1, stamp=None, clear_m=2.0, rmax=5.0):
    stamp = np.zeros(shape, dtype=np.int32) if stamp is None else stamp
    cells = np.empty(4096, dtype=np.int64)
    hits = np.empty(4096, dtype=np.bool_)
    n = traverse(
        stamp,
        scan,
        0.0,
        0.0,
        RES,
        *map(float, pose),
        np.asarray(angles, dtype=np.float64),
        np.asarray(ranges, dtype=np.float64),
        0.05,
        rmax,
        clear_m,
        cells,
        hits,
        np.zeros((0, 0, 2), dtype=np.uint8),
        np.zeros((0, 0), dtype=np.uint8),
    )
    width = shape[1]
    listed = [(int(c % width), int(c // width)) for c in cells[:n]]
    return listed, hits[:n].tolist(), stamp


def test_a_beam_along_x_crosses_the_cells_up_to_its_return_and_hits_that_cell():
    listed, hits, _ = _traverse((10, 20), (0.55, 0.45, 0.0), [0.0], [1.0])
    assert listed[0] == (15, 4) and hits[0]
    assert listed[1:] == [(x, 4) for x in range(5, 15)] and not any(hits[1:])


def test_returns_come_first_and_a_cell_is_listed_once_per_scan():
    angles = np.linspace(-0.3, 0.3, 9)
    listed, hits, _ = _traverse((30, 30), (1.05, 1.55, 0.0), angles, np.full(9, 1.2))
    assert len(set(listed)) == len(listed)
    first_miss = hits.index(False)
    assert all(hits[:first_miss]) and not any(hits[first_miss:])


def test_a_cell_with_a_return_is_not_also_cleared_by_another_beam():
    # the second beam passes through the first one's return cell on its way further
    listed, hits, _ = _traverse((10, 40), (0.05, 0.55, 0.0), [0.0, 0.0], [1.0, 3.0])
    marked = dict(zip(listed, hits, strict=True))
    assert marked[(10, 5)] is True and marked[(30, 5)] is True
    assert listed.count((10, 5)) == 1


def test_no_return_clears_only_up_to_the_clearing_distance_and_nan_says_nothing():
    listed, hits, _ = _traverse((10, 60), (0.05, 0.55, 0.0), [0.0, 0.0], [np.inf, 9.0], clear_m=1.0)
    assert not any(hits)
    assert max(x for x, _ in listed) == 10  # 1.0 m of cells from x = 0.05
    assert _traverse((10, 60), (0.05, 0.55, 0.0), [0.0, 0.0], [np.nan, 0.01])[0] == []


def test_a_beam_leaving_the_grid_stops_at_its_edge():
    listed, hits, _ = _traverse((5, 5), (0.25, 0.25, math.pi / 4), [0.0], [100.0], rmax=200.0)
    assert not any(hits) and all(0 <= x < 5 and 0 <= y < 5 for x, y in listed)
    assert (4, 4) in listed


def test_a_new_scan_number_lists_the_cells_again():
    stamp = np.zeros((10, 20), dtype=np.int32)
    first, _, _ = _traverse((10, 20), (0.55, 0.45, 0.0), [0.0], [1.0], scan=1, stamp=stamp)
    again, _, _ = _traverse((10, 20), (0.55, 0.45, 0.0), [0.0], [1.0], scan=1, stamp=stamp)
    later, _, _ = _traverse((10, 20), (0.55, 0.45, 0.0), [0.0], [1.0], scan=2, stamp=stamp)
    assert again == [] and later == first


@settings(max_examples=60, deadline=None)
@given(
    x=st.floats(0.3, 2.7),
    y=st.floats(0.3, 2.7),
    angle=st.floats(-math.pi, math.pi),
    r=st.floats(0.2, 2.5),
)
# from a cell corner, a direction whose y component is too small to move the return out of
# the robot's row: the chain once stepped down a row at once and never came back
@example(x=1.0, y=1.0, angle=-6.552672648180735e-295, r=0.2)
@example(x=1.0, y=1.0, angle=math.pi / 2 + 1e-300, r=0.2)
def test_a_beams_crossed_cells_are_a_4_connected_chain_from_the_robot_to_its_return(x, y, angle, r):
    listed, hits, _ = _traverse((30, 30), (x, y, 0.0), [angle], [r], rmax=3.0)
    end_x, end_y = x + r * math.cos(angle), y + r * math.sin(angle)
    returned = [c for c, h in zip(listed, hits, strict=True) if h]
    crossed = [c for c, h in zip(listed, hits, strict=True) if not h]
    if not (0 <= end_x < 3.0 and 0 <= end_y < 3.0):
        return
    assert returned == [(math.floor(end_x / RES), math.floor(end_y / RES))]
    if returned[0] == (math.floor(x / RES), math.floor(y / RES)):
        return  # a return in the robot's own cell crosses nothing
    assert crossed[0] == (math.floor(x / RES), math.floor(y / RES))
    chain = [*crossed, returned[0]]
    for (ax, ay), (bx, by) in itertools.pairwise(chain):
        assert abs(ax - bx) + abs(ay - by) == 1


def _apply(logodds, cells, hits, flips_capacity=64, changes=None):
    flips = np.empty(flips_capacity, dtype=np.int64)
    changes = np.zeros((0, 0), dtype=np.float32) if changes is None else changes
    count = apply(
        logodds,
        np.asarray(cells, dtype=np.int64),
        np.asarray(hits, dtype=np.bool_),
        len(cells),
        HIT,
        MISS,
        LO,
        HI,
        OCC,
        flips,
        changes,
    )
    return count, flips[: max(count, 0)].tolist()


def test_an_update_adds_hit_or_miss_clamped_and_lists_the_cells_that_flipped():
    logodds = np.array([[0.0, 0.5, 3.4, -1.99]], dtype=np.float32)
    count, flips = _apply(logodds, [0, 1, 2, 3], [False, True, True, False])
    assert logodds.tolist()[0] == pytest.approx([MISS, 0.5 + HIT, HI, LO])
    assert (count, flips) == (1, [1])  # only cell 1 crossed the occupied threshold


def test_a_cell_falling_below_occupied_flips_too():
    logodds = np.array([[0.65, 0.0]], dtype=np.float32)
    count, flips = _apply(logodds, [0], [False])
    assert (count, flips) == (1, [0])


def test_more_flips_than_the_buffer_holds_is_minus_one():
    logodds = np.zeros((1, 5), dtype=np.float32)
    count, _ = _apply(logodds, range(5), [True] * 5, flips_capacity=3)
    assert count == -1
    assert (logodds == np.float32(HIT)).all()  # the update itself is complete


def test_the_changes_made_are_added_to_the_change_grid_when_one_is_kept():
    logodds = np.array([[3.4, 0.0]], dtype=np.float32)
    changes = np.zeros((1, 2), dtype=np.float32)
    _apply(logodds, [0, 1], [True, False], changes=changes)
    assert changes.tolist()[0] == pytest.approx([HI - 3.4, MISS], abs=1e-6)


def test_cells_are_occupied_from_the_occupied_threshold_free_up_to_the_free_one():
    logodds = np.array([[-1.0, -0.6, -0.59, 0.0, 0.61, 0.62, 2.0]], dtype=np.float32)
    cells = np.empty(logodds.shape, dtype=np.int8)
    classify(logodds, np.float32(-0.6), np.float32(0.62), cells)
    assert cells.tolist()[0] == [FREE, FREE, UNKNOWN, UNKNOWN, UNKNOWN, OCCUPIED, OCCUPIED]


def _kernel(sigma=1.5):
    r = math.ceil(3 * sigma)
    off = np.arange(-r, r + 1)
    d2 = off[None, :] ** 2 + off[:, None] ** 2
    return np.where(d2 <= r * r, np.round(255 * np.exp(-0.5 * d2 / sigma**2)), 0).astype(np.uint8)


def _scores_reference(logodds, kernel, c):
    h, w = logodds.shape
    r = kernel.shape[0] // 2
    score = np.zeros((h, w), dtype=np.uint8)
    for iy, ix in np.argwhere(logodds >= OCC):
        for ky in range(-r, r + 1):
            for kx in range(-r, r + 1):
                y, x = iy + ky, ix + kx
                if 0 <= y < h and 0 <= x < w:
                    score[y, x] = max(score[y, x], kernel[ky + r, kx + r])
    coarse = np.zeros_like(score)
    for y in range(h):
        for x in range(w):
            coarse[y, x] = score[y : y + c, x : x + c].max()
    return score, coarse


@pytest.mark.parametrize("c", [4, 3])
def test_scores_rebuilt_are_the_kernels_maximum_and_its_coarse_block_maximum(c):
    rng = np.random.default_rng(c)
    logodds = np.where(rng.random((15, 17)) < 0.08, 1.0, -1.0).astype(np.float32)
    kernel = _kernel()
    score, coarse = np.zeros((15, 17), np.uint8), np.zeros((15, 17), np.uint8)
    count = rebuild_scores(logodds, score, coarse, kernel, OCC, c)
    want_score, want_coarse = _scores_reference(logodds, kernel, c)
    assert count == int((logodds >= OCC).sum())
    assert np.array_equal(score, want_score) and np.array_equal(coarse, want_coarse)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**16),
    flips=st.integers(1, 30),
    c=st.sampled_from([4, 3]),
)
def test_scores_refreshed_around_flipped_cells_equal_scores_rebuilt(seed, flips, c):
    rng = np.random.default_rng(seed)
    shape = (16, 19)
    logodds = np.where(rng.random(shape) < 0.1, 1.0, -1.0).astype(np.float32)
    kernel = _kernel()
    score, coarse = np.zeros(shape, np.uint8), np.zeros(shape, np.uint8)
    before = rebuild_scores(logodds, score, coarse, kernel, OCC, c)
    flipped = rng.choice(shape[0] * shape[1], size=flips, replace=False).astype(np.int64)
    logodds.ravel()[flipped] *= -1.0
    dirty = np.zeros(shape, dtype=np.uint8)
    net = refresh_scores(logodds, score, coarse, kernel, flipped, OCC, c, dirty)
    want_score, want_coarse = np.zeros(shape, np.uint8), np.zeros(shape, np.uint8)
    after = rebuild_scores(logodds, want_score, want_coarse, kernel, OCC, c)
    assert net == after - before
    assert np.array_equal(score, want_score) and np.array_equal(coarse, want_coarse)
    assert not dirty.any()  # left as found, for the next scan


def test_every_return_is_folded_into_its_cells_mean_even_when_its_cell_is_listed_already():
    # two beams end in cell (12, 4) of 0.1 m cells, 0.25 and 0.75 of a cell in; a NaN is skipped
    means = np.zeros((10, 20, 2), dtype=np.uint8)
    counts = np.zeros((10, 20), dtype=np.uint8)
    stamp = np.zeros((10, 20), dtype=np.int32)
    cells = np.empty(4096, dtype=np.int64)
    hits = np.empty(4096, dtype=np.bool_)
    angles = np.zeros(3)
    ranges = np.array([1.175, 1.225, np.nan])
    n = traverse(
        stamp, 1, 0.0, 0.0, RES, 0.05, 0.45, 0.0, angles, ranges, 0.05, 5.0, 2.0,
        cells, hits, means, counts,
    )  # fmt: skip
    assert hits[:n].sum() == 1 and counts[4, 12] == 2 and counts.sum() == 2
    assert np.allclose(means[4, 12] / 255, [0.5, 0.5], atol=1 / 255)


def test_a_cell_full_of_returns_moves_only_for_returns_far_from_its_mean():
    means = np.zeros((1, 1, 2), dtype=np.uint8)
    counts = np.full((1, 1), 255, dtype=np.uint8)  # 255 returns at the corner already
    for _ in range(255):
        _fold_hit(means, counts, 0, 0, 1.0, 0.25)  # a cell away in x, a quarter in y
    assert counts[0, 0] == 255 and means[0, 0, 0] == 128 and means[0, 0, 1] == 0
