import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.navigation.sightings import cell_keys, first_per_cell


def _stretches(points, keys, lo, hi):
    """The stretches ``[lo[k], hi[k])`` of points and keys, one after another."""
    every = np.concatenate([points[a:b] for a, b in zip(lo, hi, strict=True)] or [np.zeros((0, 2))])
    every_keys = np.concatenate(
        [keys[a:b] for a, b in zip(lo, hi, strict=True)] or [np.zeros(0, np.int64)]
    )
    return every, every_keys


def _reference(points, keys):
    """First sighting of each key, in order, by numpy's unique."""
    _, first = np.unique(keys, return_index=True)
    return points[np.sort(first)]


@settings(max_examples=80, deadline=None)
@given(
    count=st.integers(0, 400),
    stretches=st.integers(0, 6),
    span_m=st.sampled_from([0.3, 3.0, 300.0]),
    seed=st.integers(0, 2**32 - 1),
)
def test_first_per_cell_keeps_what_a_sort_based_unique_keeps(count, stretches, span_m, seed):
    rng = np.random.default_rng(seed)
    points = rng.uniform(-span_m, span_m, (count, 2))  # negative cells too
    keys = cell_keys(points, 0.1)
    cuts = np.sort(rng.integers(0, count + 1, 2 * stretches)).reshape(-1, 2)
    lo, hi = cuts[:, 0], cuts[:, 1]
    every, every_keys = _stretches(points, keys, lo, hi)  # as a recall gathers instants
    got = first_per_cell(every, every_keys)
    np.testing.assert_array_equal(got, _reference(every, every_keys))


def test_cell_keys_tell_cells_apart_across_the_origin():
    points = np.array([[-0.05, 0.05], [0.05, -0.05], [0.05, 0.05], [-0.05, -0.05], [0.01, 0.09]])
    keys = cell_keys(points, 0.1)
    assert len(set(keys.tolist())) == 4 and keys[2] == keys[4]


def test_first_per_cell_of_nothing_is_empty():
    out = first_per_cell(np.zeros((0, 2)), np.zeros(0, np.int64))
    assert out.shape == (0, 2)
    assert first_per_cell(np.ones((2, 2))[1:1], np.zeros(2, np.int64)[1:1]).shape == (0, 2)
    assert first_per_cell(np.ones((2, 2)), np.zeros(2, np.int64)) == pytest.approx(np.ones((1, 2)))
