import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, box

from models.fleet.collision import CollisionChecker, OtherKind, disc_box_clearance

BOXES = np.array([[2.0, 2.0, 4.0, 3.0], [6.0, 0.0, 6.5, 8.0]])


def _shapely_clearance(x, y, r, b):
    disc = Point(x, y).buffer(r, quad_segs=256)
    rect = box(*b)
    if disc.intersects(rect):
        return None
    return disc.distance(rect)


@pytest.mark.parametrize(("x", "y"), [(1.0, 1.0), (3.0, 1.5), (4.6, 2.5), (1.2, 3.8)])
def test_disc_box_clearance_matches_shapely_outside(x, y):
    expected = _shapely_clearance(x, y, 0.3, BOXES[0])
    got = disc_box_clearance(np.array([x]), np.array([y]), np.array([0.3]), BOXES[:1])[0]
    assert got == pytest.approx(expected, abs=1e-4)


def test_disc_box_clearance_is_minus_the_depth_when_overlapping():
    got = disc_box_clearance(
        np.array([3.0, 3.0]), np.array([1.9, 2.1]), np.array([0.3, 0.3]), BOXES[[0, 0]]
    )
    np.testing.assert_allclose(got, [-0.2, -0.4])


def test_contacts_with_boxes_robots_and_discs_are_found_with_exact_depths():
    checker = CollisionChecker(BOXES, np.array([0.3, 0.3, 0.3]), margin_m=0.1)
    x = np.array([3.0, 8.0, 8.5])
    y = np.array([1.9, 5.0, 5.0])
    discs = np.array([[3.0, 1.45, 0.2]])
    near, clearance = checker.check(x, y, discs)
    found = {(p.robot, p.kind, p.other): p.clearance_m for p in near}
    assert found[(0, OtherKind.STATIC, 0)] == pytest.approx(-0.2)
    assert found[(1, OtherKind.ROBOT, 2)] == pytest.approx(-0.1)
    assert found[(0, OtherKind.DYNAMIC, 0)] == pytest.approx(0.45 - 0.5)
    assert clearance == pytest.approx(-0.2)


def test_pairs_beyond_the_margin_are_not_reported_but_set_the_smallest_clearance():
    checker = CollisionChecker(BOXES, np.array([0.3, 0.3]), margin_m=0.1)
    x = np.array([1.0, 9.0])
    y = np.array([1.0, 9.0])
    near, clearance = checker.check(x, y)
    assert near == []
    # robot 0 to box 0 corner (2, 2): hypot(1, 1) - 0.3
    assert clearance == pytest.approx(math.sqrt(2) - 0.3, abs=1e-5)


def test_robot_pairs_between_one_and_two_margins_apart_give_their_exact_clearance():
    checker = CollisionChecker(np.zeros((0, 4)), np.array([0.3, 0.3]), margin_m=0.1)
    near, clearance = checker.check(np.array([0.0, 0.75]), np.array([0.0, 0.0]))
    assert near == []
    assert clearance == pytest.approx(0.15)


def test_random_configurations_agree_with_shapely():
    rng = np.random.default_rng(4)
    boxes = np.array([[1.0, 1.0, 3.0, 1.8], [4.0, 4.0, 4.8, 6.0], [0.0, 6.0, 2.0, 6.4]])
    radii = np.full(6, 0.3)
    checker = CollisionChecker(boxes, radii, margin_m=0.1)
    for _ in range(50):
        x = rng.uniform(0, 7, 6)
        y = rng.uniform(0, 7, 6)
        _, clearance = checker.check(x, y)
        discs = [Point(xi, yi).buffer(0.3, quad_segs=256) for xi, yi in zip(x, y, strict=True)]
        rects = [box(*b) for b in boxes]
        gaps = [d.distance(r) for d in discs for r in rects]
        gaps += [
            math.hypot(x[i] - x[j], y[i] - y[j]) - 0.6 for i in range(6) for j in range(i + 1, 6)
        ]
        overlap = any(d.intersects(r) for d in discs for r in rects) or min(gaps) < 0
        if not overlap:
            assert clearance == pytest.approx(min(gaps), abs=1e-3)
        else:
            assert clearance < 1e-9


def test_the_floor_is_never_below_floor_min_m():
    rng = np.random.default_rng(5)
    boxes = np.array([[1.0, 1.0, 3.0, 1.8], [4.0, 4.0, 4.8, 6.0], [0.0, 6.0, 2.0, 6.4]])
    checker = CollisionChecker(boxes, np.full(5, 0.3), margin_m=0.1)
    floors = []
    for _ in range(200):
        x = rng.uniform(0, 7, 5)
        y = rng.uniform(0, 7, 5)
        discs = rng.uniform([0, 0, 0.1], [7, 7, 0.4], (2, 3))
        floor = checker.floor(checker.candidates(x, y, discs))
        assert floor >= checker.floor_min_m
        floors.append(floor)
    assert min(f for f in floors if math.isfinite(f)) < checker.floor_min_m + 0.5


def test_empty_candidate_groups_give_empty_clearances():
    checker = CollisionChecker(BOXES, np.array([0.3, 0.3]), margin_m=0.1)
    x, y = np.array([0.5, 9.0]), np.array([0.5, 9.0])
    gaps = checker.gaps(checker.candidates(x, y), x, y)
    assert [group.kind for group in gaps] == list(OtherKind)
    for group in gaps:
        assert group.pairs.shape == (0, 2)
        assert group.clearance_m.shape == (0,)
        assert group.clearance_m.dtype == np.float64


def _fcl_robot_pairs(checker: CollisionChecker, x, y) -> set[tuple[int, int]]:
    """The robot pairs of FCL's own self-collision of the grown discs (the reference)."""
    from models.fleet import collision

    checker._place_robots(x, y)
    found: list[object] = []
    checker._robots.collide(found, collision._collect)
    return {tuple(sorted((collision._index(a), collision._index(b)))) for a, b in found}


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(2, 120),
    lattice=st.sampled_from([None, 0.5, 0.8, 1.06, 1.2]),
    same_radius=st.booleans(),
    seed=st.integers(0, 10_000),
)
def test_robot_pairs_from_the_kd_tree_are_fcls_pairs_touching_boxes_included(
    n, lattice, same_radius, seed
):
    """On a lattice of 1.06 m the grown boxes (0.33 + 2 x 0.1 m) touch exactly."""
    rng = np.random.default_rng(seed)
    radii = np.full(n, 0.33) if same_radius else rng.uniform(0.15, 0.5, n)
    checker = CollisionChecker(np.zeros((0, 4)), radii, margin_m=0.1)
    if lattice is None:
        x, y = rng.uniform(0.0, 12.0, n), rng.uniform(0.0, 12.0, n)
    else:
        side = math.ceil(math.sqrt(n))
        cells = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2)[:n]
        x, y = cells[:, 0] * lattice + 3.1, cells[:, 1] * lattice + 7.7
    pairs = checker._robot_pairs(x, y)
    assert {tuple(p) for p in pairs.tolist()} == _fcl_robot_pairs(checker, x, y)
    assert np.all(pairs[:, 0] < pairs[:, 1])
    assert pairs.tolist() == sorted(pairs.tolist())
