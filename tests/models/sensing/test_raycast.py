import itertools
import math

import numpy as np
import pytest

from models.errors import ModelError
from models.sensing.lidar import cast_reference
from models.sensing.raycast import StaticScene, cast_batch
from models.world.warehouse import WarehouseSpec, box_segments, generate_warehouse

NO_CIRCLES = np.zeros((0, 3))
NO_SEGMENTS = np.zeros((0, 4))


def _cast(segments, origins, yaws, beams, circles=NO_CIRCLES, exclude=None, range_max=10.0):
    origins = np.asarray(origins, dtype=float).reshape(-1, 2)
    if exclude is None:
        exclude = np.full(len(origins), -1, dtype=np.int64)
    return cast_batch(
        StaticScene(np.asarray(segments, dtype=float).reshape(-1, 4)),
        origins,
        np.asarray(yaws, dtype=float),
        np.asarray(beams, dtype=float),
        np.asarray(circles, dtype=float).reshape(-1, 3),
        np.asarray(exclude, dtype=np.int64),
        range_max,
    )


def _assert_matches_reference(scene, origins, yaws, beams, circles, exclude, range_max):
    got = cast_batch(scene, origins, yaws, beams, circles, exclude, range_max)
    want = cast_reference(origins, yaws, beams, scene.segments, circles, range_max, exclude)
    assert got.shape == want.shape
    # a hit within rounding of range_max may land on either side of it
    borderline = np.abs(np.where(np.isfinite(want), want, got) - range_max) <= 1e-6
    agree = np.isfinite(got) == np.isfinite(want)
    assert np.all(agree | borderline), np.argwhere(~(agree | borderline))[:5]
    both = np.isfinite(got) & np.isfinite(want)
    err = np.abs(got[both] - want[both])
    assert err.size == 0 or err.max() <= 1e-4


def _random_spec(rng):
    layout = ["random", "all_rows", "two_corridors"][int(rng.integers(3))]
    width = float(rng.uniform(10.0, 24.0))
    height = float(rng.uniform(10.0, 24.0))
    if layout == "two_corridors":  # three bands of racks need a wide hall
        width += 14.0
    return layout, (round(width, 1), round(height, 1))


def _random_world(rng):
    """A random warehouse with some shelves (as many of a random count as fit) and robots."""
    while True:
        layout, size = _random_spec(rng)
        # random layouts that are nearly full take long to give up: ask for fewer
        most = 20 if layout != "random" else max(5, int(size[0] * size[1] / 30))
        for shelves in range(int(rng.integers(4, most)), 0, -1):
            spec = WarehouseSpec(
                size_m=size,
                layout=layout,
                shelf_count=shelves,
                robot_count=int(rng.integers(3, 9)),
                placement="dock" if rng.random() < 0.3 else "random",
            )
            try:
                return generate_warehouse(spec, rng)
            except ModelError:
                continue


def _near_obstacle_poses(world, rng, count):
    """Origins 1-5 cm off box sides, half of them exactly on the line of a box edge."""
    boxes = world.boxes
    poses = []
    for _ in range(count):
        x0, y0, x1, y1 = boxes[int(rng.integers(len(boxes)))]
        gap = rng.uniform(0.01, 0.05)
        side = int(rng.integers(4))
        along_x = x0 if rng.random() < 0.5 else rng.uniform(x0, x1)
        along_y = y1 if rng.random() < 0.5 else rng.uniform(y0, y1)
        point = [
            (along_x, y0 - gap),
            (x1 + gap, along_y),
            (along_x, y1 + gap),
            (x0 - gap, along_y),
        ][side]
        if rng.random() < 0.3:  # a ray origin lying on a wall's line, beyond its end
            point = (x1 + gap, y0) if side % 2 == 0 else (x0, y1 + gap)
        poses.append((*point, rng.choice([0.0, math.pi / 2, math.pi, rng.uniform(-4, 4)])))
    return np.array(poses)


@pytest.mark.parametrize("seed", range(24))
def test_every_beam_in_random_warehouses_matches_the_reference(seed):
    rng = np.random.default_rng(seed)
    world = _random_world(rng)
    scene = StaticScene(world.segments(), cell_m=float(rng.choice([0.3, 0.5, 1.0])))
    robots = world.starts
    near = _near_obstacle_poses(world, rng, 8)
    humans = np.column_stack([near[:3, :2] + rng.uniform(-0.4, 0.4, (3, 2)), np.full(3, 0.25)])
    circles = np.vstack([np.column_stack([robots[:, :2], np.full(len(robots), 0.33)]), humans])
    poses = np.vstack([robots, near])
    exclude = np.concatenate([np.arange(len(robots)), np.full(len(near), -1)]).astype(np.int64)
    range_max = float(rng.choice([3.0, 10.0, 1000.0]))
    beams = np.concatenate(
        [-math.pi + 2 * math.pi / 90 * np.arange(90), [0.0, math.pi / 2, -math.pi / 2]]
    )
    origins = poses[:, :2].copy()
    _assert_matches_reference(scene, origins, poses[:, 2], beams, circles, exclude, range_max)

    # beams aimed at every box corner from every origin, and just beside it
    corners = np.concatenate([world.boxes[:, [0, 1]], world.boxes[:, [2, 3]]])
    corners = np.concatenate([corners, world.boxes[:, [0, 3]], world.boxes[:, [2, 1]]])
    aim_from = np.repeat(origins, len(corners), axis=0)
    aim_to = np.tile(corners, (len(origins), 1))
    yaws = np.arctan2(aim_to[:, 1] - aim_from[:, 1], aim_to[:, 0] - aim_from[:, 0])
    ex = np.repeat(exclude, len(corners))
    _assert_matches_reference(
        scene, aim_from, yaws, np.array([0.0, 1e-12, -1e-12]), circles, ex, range_max
    )


def test_random_diagonal_segments_and_origins_outside_the_grid_match_the_reference():
    rng = np.random.default_rng(99)
    for _ in range(5):
        segments = rng.uniform(-5, 5, (40, 4))
        segments[:5, 2] = segments[:5, 0]  # a few vertical and horizontal ones
        segments[5:10, 3] = segments[5:10, 1]
        scene = StaticScene(segments, cell_m=float(rng.uniform(0.2, 2.0)))
        circles = np.column_stack([rng.uniform(-7, 7, (15, 2)), rng.uniform(0.1, 1.5, 15)])
        origins = rng.uniform(-9, 9, (30, 2))
        origins[:5] = segments[:5, :2]  # on segment endpoints
        origins[5:10] = circles[:5, :2]  # inside circles
        exclude = np.concatenate([np.full(5, -1), np.arange(5), np.full(20, -1)]).astype(np.int64)
        beams = rng.uniform(-math.pi, math.pi, 64)
        yaws = rng.uniform(-math.pi, math.pi, 30)
        for range_max in (2.0, 30.0):
            _assert_matches_reference(scene, origins, yaws, beams, circles, exclude, range_max)


def test_boxes_lying_on_grid_lines_match_the_reference_for_beams_through_grid_corners():
    rng = np.random.default_rng(7)
    frame = np.array([[-0.2, -0.2, 12.2, 12.2]])
    grid = StaticScene(box_segments(frame), cell_m=0.5).grid
    gx0, gy0, cell = grid[:3]
    # boxes whose edges are grid lines, so every corner is a grid corner
    cells = rng.integers(2, 20, (12, 2))
    sizes = rng.integers(1, 4, (12, 2))
    boxes = np.column_stack(
        [
            gx0 + cells[:, 0] * cell,
            gy0 + cells[:, 1] * cell,
            gx0 + (cells[:, 0] + sizes[:, 0]) * cell,
            gy0 + (cells[:, 1] + sizes[:, 1]) * cell,
        ]
    )
    scene = StaticScene(box_segments(np.vstack([frame, boxes])), cell_m=0.5)
    np.testing.assert_array_equal(scene.grid, grid)
    corners = np.concatenate([boxes[:, [0, 1]], boxes[:, [2, 3]], boxes[:, [0, 3]]])
    # origins on grid corners and on grid lines, aimed at box corners and along lines
    origins = np.column_stack(
        [gx0 + rng.integers(1, 24, 40) * cell, gy0 + rng.integers(1, 24, 40) * cell]
    )
    origins[20:, 1] += rng.uniform(0, cell, 20)
    aim_from = np.repeat(origins, len(corners), axis=0)
    aim_to = np.tile(corners, (len(origins), 1))
    yaws = np.arctan2(aim_to[:, 1] - aim_from[:, 1], aim_to[:, 0] - aim_from[:, 0])
    circles = np.column_stack([gx0 + rng.integers(1, 24, (6, 2)) * cell, np.full(6, cell)])
    beams = np.array([0.0, math.pi / 4, math.pi / 2, -math.pi / 4, 1e-12])
    exclude = np.full(len(aim_from), -1, dtype=np.int64)
    for range_max in (3.0, 100.0):
        _assert_matches_reference(scene, aim_from, yaws, beams, circles, exclude, range_max)
        _assert_matches_reference(
            scene, origins, np.zeros(len(origins)), beams, circles, exclude[:40], range_max
        )


def test_a_beam_along_a_wall_line_hits_the_box_corner_at_the_exact_distance():
    box = box_segments(np.array([[2.0, -1.0, 3.0, 1.0]]))
    # origins on the lines of the bottom and left edges, looking along them
    ranges = _cast(box, [[0.0, -1.0], [2.0, -3.0]], [0.0, math.pi / 2], [0.0, math.pi])
    assert ranges[0, 0] == 2.0
    assert ranges[1, 0] == pytest.approx(2.0, abs=1e-12)
    assert ranges[0, 1] == math.inf and ranges[1, 1] == math.inf


def test_a_beam_grazing_past_a_corner_by_rounding_misses_it_like_the_reference():
    # sin(pi) is 1.2e-16, so this beam runs just above the top edge and past the corner
    box = box_segments(np.array([[2.0, -1.0, 3.0, 1.0]]))
    ranges = _cast(box, [[5.0, 1.0]], [0.0], [math.pi])
    want = cast_reference(
        np.array([[5.0, 1.0]]), np.array([0.0]), np.array([math.pi]), box, NO_CIRCLES, 10.0
    )
    assert ranges[0, 0] == want[0, 0] == math.inf


def test_a_beam_along_an_isolated_segment_does_not_see_it_like_the_reference():
    ranges = _cast([[2.0, 0.0, 4.0, 0.0]], [[0.0, 0.0]], [0.0], [0.0, 0.1])
    assert ranges[0, 0] == math.inf
    assert ranges[0, 1] == math.inf


def test_a_beam_aimed_at_a_box_corner_hits_it():
    box = box_segments(np.array([[2.0, 1.0, 3.0, 2.0]]))
    ranges = _cast(box, [[0.0, 0.0]], [math.atan2(1.0, 2.0)], [0.0])
    assert ranges[0, 0] == pytest.approx(math.hypot(2.0, 1.0), abs=1e-12)


def test_beams_through_exact_grid_cell_corners_and_from_cell_boundaries_hit():
    scene = StaticScene(box_segments(np.array([[0.0, 0.0, 10.0, 10.0]])), cell_m=1.0)
    gx0, gy0, cell = scene.grid[:3]
    # a diagonal through cell corners, and rays starting on a grid line
    origins = np.array([[gx0 + 3 * cell, gy0 + 3 * cell], [gx0 + 4 * cell, 5.0]])
    ranges = cast_batch(
        scene,
        origins,
        np.zeros(2),
        np.array([math.pi / 4, 0.0, math.pi / 2, math.pi]),
        NO_CIRCLES,
        np.full(2, -1),
        100.0,
    )
    wall_x, wall_y = 10.0 - origins[:, 0], 10.0 - origins[:, 1]
    assert ranges[0, 0] == pytest.approx(min(wall_x[0], wall_y[0]) * math.sqrt(2), abs=1e-9)
    assert ranges[1, 1] == pytest.approx(wall_x[1], abs=1e-12)
    assert ranges[1, 2] == pytest.approx(wall_y[1], abs=1e-12)
    assert ranges[1, 3] == pytest.approx(origins[1, 0], abs=1e-12)


def test_a_robot_inside_another_circle_sees_that_circle_s_far_side():
    circles = [[0.0, 0.0, 0.3], [0.5, 0.0, 1.0]]
    ranges = _cast(NO_SEGMENTS, [[0.0, 0.0]], [0.0], [0.0, math.pi], circles, [0])
    assert ranges[0, 0] == pytest.approx(1.5, abs=1e-12)
    assert ranges[0, 1] == pytest.approx(0.5, abs=1e-12)


def test_a_robot_never_sees_its_own_body_but_sees_the_others():
    walls = box_segments(np.array([[-5.0, -5.0, 5.0, 5.0]]))
    circles = [[0.0, 0.0, 0.33], [2.0, 0.0, 0.33]]
    ranges = _cast(walls, [[0.0, 0.0], [2.0, 0.0]], [0.0, 0.0], [0.0, math.pi], circles, [0, 1])
    assert ranges[0, 0] == pytest.approx(1.67, abs=1e-12)
    assert ranges[0, 1] == pytest.approx(5.0, abs=1e-12)
    assert ranges[1, 0] == pytest.approx(3.0, abs=1e-12)
    assert ranges[1, 1] == pytest.approx(1.67, abs=1e-12)


def test_an_empty_scene_reads_infinity_everywhere():
    ranges = _cast(NO_SEGMENTS, [[0.0, 0.0], [3.0, 4.0]], [0.0, 1.0], np.linspace(-3, 3, 7))
    assert ranges.shape == (2, 7)
    assert np.all(ranges == math.inf)


def test_circles_are_seen_without_any_segments():
    ranges = _cast(NO_SEGMENTS, [[0.0, 0.0]], [0.0], [0.0], [[50.0, 0.0, 1.0]], range_max=100.0)
    assert ranges[0, 0] == pytest.approx(49.0, abs=1e-12)


def test_hits_beyond_the_range_read_infinity_and_a_huge_range_sees_across_the_world():
    box = box_segments(np.array([[5.0, -1.0, 6.0, 1.0]]))
    ranges = _cast(box, [[-100.0, 0.0]], [0.0], [0.0, math.pi], range_max=50.0)
    assert ranges[0, 0] == math.inf
    far = _cast(box, [[-100.0, 0.0]], [0.0], [0.0, math.pi], range_max=1e6)
    assert far[0, 0] == pytest.approx(105.0, abs=1e-12)
    assert far[0, 1] == math.inf


def test_a_scene_spanning_a_huge_area_still_finds_its_segments():
    scene = StaticScene(np.array([[-1e5, 3.0, 1e5, 3.0]]), cell_m=0.1)
    assert scene.grid[3] * scene.grid[4] <= 4_000_000
    ranges = cast_batch(
        scene,
        np.zeros((1, 2)),
        np.zeros(1),
        np.array([math.pi / 2]),
        NO_CIRCLES,
        np.full(1, -1),
        5.0,
    )
    assert ranges[0, 0] == pytest.approx(3.0, abs=1e-12)


def test_circles_are_binned_in_every_cell_their_padded_box_touches_and_spill_outside_the_grid():
    rng = np.random.default_rng(11)
    scene = StaticScene(box_segments(np.array([[0.0, 0.0, 10.0, 10.0]])), cell_m=1.0)
    gx0, gy0, cell, nx, ny = scene.grid
    circles = np.column_stack([rng.uniform(-3, 13, (40, 2)), rng.uniform(0.05, 1.5, 40)])
    circles[0] = [gx0 + 3 * cell, gy0 + 2 * cell, cell]  # a box edge on grid lines
    circles[1, 0] = np.nan
    start, data, ids, spilled = scene.bin_circles(circles)
    pad = 1e-7  # models.sensing.raycast._PAD_M
    lo = circles[:, :2] - (circles[:, 2:] + pad)
    hi = circles[:, :2] + (circles[:, 2:] + pad)
    inside = np.all((lo > [gx0, gy0]) & (hi < [gx0 + nx * cell, gy0 + ny * cell]), axis=1)
    np.testing.assert_array_equal(spilled, np.flatnonzero(~inside))
    assert 1 in spilled
    expected = []
    for c in range(int(nx * ny)):
        i, j = c % int(nx), c // int(nx)
        touches = (
            (np.floor((lo[:, 0] - gx0) / cell) <= i)
            & (np.floor((hi[:, 0] - gx0) / cell) >= i)
            & (np.floor((lo[:, 1] - gy0) / cell) <= j)
            & (np.floor((hi[:, 1] - gy0) / cell) >= j)
        )
        expected.append(np.flatnonzero(inside & touches))
    np.testing.assert_array_equal(start, np.cumsum([0] + [len(e) for e in expected]))
    np.testing.assert_array_equal(ids, np.concatenate(expected))
    np.testing.assert_array_equal(data, circles[ids])


def test_the_scene_cell_follows_the_spacing_of_the_segments_within_one_to_two_metres():
    from models.sensing.raycast import scene_cell_m

    hall = box_segments(np.array([[0.0, 0.0, 30.0, 30.0]]))
    sparse = np.vstack([hall, box_segments(np.array([[10.0, 10.0, 12.0, 10.8]] * 20))])
    assert scene_cell_m(sparse) == 2.0  # 84 segments in 30 m x 30 m
    dense = np.vstack([hall] * 300)
    assert scene_cell_m(dense) == 1.0  # 1,200 segments
    assert scene_cell_m(np.zeros((0, 4))) == 1.0
    middle = np.vstack([hall] * 76)  # 304 segments, as fleet50's hall
    assert scene_cell_m(middle) == pytest.approx(0.7 * math.sqrt(900.0 / 304))


def test_ranges_do_not_depend_on_the_scene_cell():
    rng = np.random.default_rng(13)
    world = _random_world(rng)
    origins = world.starts[:, :2]
    circles = np.column_stack([origins, np.full(len(origins), 0.3)])
    exclude = np.arange(len(origins), dtype=np.int64)
    beams = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    ranges = [
        cast_batch(
            StaticScene(world.segments(), cell_m=cell),
            origins,
            world.starts[:, 2],
            beams,
            circles,
            exclude,
            10.0,
        )
        for cell in (0.5, 1.0, 1.37, 2.0, 3.0)
    ]
    for other in ranges[1:]:
        np.testing.assert_array_equal(other, ranges[0])


@pytest.mark.parametrize("seed", range(4))
def test_ranges_are_the_same_whatever_the_sensors_are_cut_into(seed):
    rng = np.random.default_rng(seed)
    world = _random_world(rng)
    scene = StaticScene(world.segments())
    n = len(world.starts)
    beams = np.linspace(-math.pi, math.pi, 90, endpoint=False)
    circles = np.column_stack([world.starts[:, :2], np.full(n, 0.3)])
    args = (scene, world.starts[:, :2], world.starts[:, 2], beams, circles, np.arange(n), 10.0)
    whole = cast_batch(*args)
    cuts = sorted(set(rng.integers(1, n, size=2).tolist()))

    def slices(count, rows):
        bounds = [0, *cuts, count]
        for start, stop in itertools.pairwise(bounds):
            rows(start, stop)

    assert np.array_equal(cast_batch(*args, slices=slices), whole)
