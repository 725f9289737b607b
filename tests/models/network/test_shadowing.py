import numpy as np
from hypothesis import example, given
from hypothesis import strategies as st
from shapely.geometry import LineString, box

from models.network.shadowing import boxes_crossed

SHELVES = np.array([[2.0, 0.0, 3.0, 4.0], [5.0, 0.0, 6.0, 4.0], [0.0, 6.0, 8.0, 6.5]])


def test_a_line_across_two_shelves_meets_two_and_one_beside_them_none():
    a = np.array([[0.0, 2.0], [0.0, 5.0], [4.0, 1.0]])
    b = np.array([[8.0, 2.0], [8.0, 5.0], [4.0, 8.0]])
    assert boxes_crossed(a, b, SHELVES).tolist() == [2, 0, 1]


def test_touching_a_corner_and_ending_inside_count_and_stopping_short_does_not():
    a = np.array([[1.0, 5.0], [1.0, 2.0], [1.0, 2.0]])
    b = np.array([[3.0, 3.0], [2.5, 2.0], [1.9, 2.0]])
    # (1, 5) -> (3, 3) passes (2, 4), the first shelf's corner
    assert boxes_crossed(a, b, SHELVES).tolist() == [1, 1, 0]


def test_axis_parallel_lines_inside_and_outside_a_slab():
    a = np.array([[2.5, -1.0], [1.0, -1.0]])
    b = np.array([[2.5, 10.0], [1.0, 10.0]])
    assert boxes_crossed(a, b, SHELVES).tolist() == [2, 1]  # both cross the long one


coord = st.floats(-1.0, 9.0, allow_nan=False)


@example([(0.0, 1.0, 2.0, -9.208399652212099e-294)])  # grazes a corner by 1e-293 m
@example([(4.5, 0.0, 5.0, -5e-324)])  # ends a subnormal below a corner
@given(st.lists(st.tuples(coord, coord, coord, coord), min_size=1, max_size=20))
def test_it_agrees_with_shapely_on_any_segment(segments):
    seg = np.array(segments)
    got = boxes_crossed(seg[:, :2], seg[:, 2:], SHELVES)
    boxes = [box(*s) for s in SHELVES]
    for (x0, y0, x1, y1), n in zip(segments, got, strict=True):
        line = LineString([(x0, y0), (x1, y1)]) if (x0, y0) != (x1, y1) else None
        if line is None:
            line = LineString([(x0, y0), (x0, y0 + 1e-12)])
        want = sum(b.intersects(line) for b in boxes)
        # a segment passing within a nanometre of a box's edge, or touching it along less
        # than a nanometre, may round either way
        grazing = sum(b.distance(line) < 1e-9 and b.intersection(line).length < 1e-9 for b in boxes)
        assert abs(n - want) <= grazing, ((x0, y0, x1, y1), n, want)
