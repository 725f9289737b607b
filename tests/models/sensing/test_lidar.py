import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.sensing.lidar import (
    ScanGeometry,
    apply_sensor_model,
    beam_directions,
    cast_reference,
    hits_within,
    seen_beyond,
)
from models.world.warehouse import box_segments


def test_a_360_degree_scan_has_no_duplicated_beam():
    geometry = ScanGeometry(360, 2 * math.pi, 0.1, 10.0)
    angles = geometry.angles()
    assert geometry.angle_min_rad == -math.pi
    assert geometry.angle_increment_rad == pytest.approx(2 * math.pi / 360)
    assert angles[-1] == pytest.approx(math.pi - 2 * math.pi / 360)


def test_a_narrow_scan_spans_the_field_of_view_end_to_end():
    geometry = ScanGeometry(271, math.radians(270), 0.1, 10.0)
    angles = geometry.angles()
    assert angles[0] == pytest.approx(-math.radians(135))
    assert angles[-1] == pytest.approx(math.radians(135))


def test_rays_hit_an_axis_aligned_box_at_the_analytic_distance():
    segments = box_segments(np.array([[2.0, -1.0, 3.0, 1.0]]))
    origins = np.array([[0.0, 0.0]])
    beams = np.array([0.0, math.atan2(0.5, 2.0), math.pi])
    ranges = cast_reference(origins, np.array([0.0]), beams, segments, np.zeros((0, 3)), 10.0)
    assert ranges[0, 0] == pytest.approx(2.0)
    assert ranges[0, 1] == pytest.approx(math.hypot(2.0, 0.5))
    assert ranges[0, 2] == math.inf


def test_rays_hit_circles_and_ignore_the_robots_own_body():
    circles = np.array([[0.0, 0.0, 0.3], [4.0, 0.0, 0.5]])
    origins = np.array([[0.0, 0.0], [4.0, 0.0]])
    ranges = cast_reference(
        origins,
        np.array([0.0, math.pi]),
        np.array([0.0, math.pi]),
        np.zeros((0, 4)),
        circles,
        10.0,
        exclude=np.array([0, 1]),
    )
    assert ranges[0, 0] == pytest.approx(3.5)
    assert ranges[0, 1] == math.inf
    assert ranges[1, 0] == pytest.approx(3.7)


def test_hits_beyond_the_maximum_range_read_infinity():
    segments = box_segments(np.array([[5.0, -1.0, 6.0, 1.0]]))
    ranges = cast_reference(
        np.array([[0.0, 0.0]]), np.array([0.0]), np.array([0.0]), segments, np.zeros((0, 3)), 4.0
    )
    assert ranges[0, 0] == math.inf


def _draws(shape, seed):
    rng = np.random.default_rng(seed)
    return rng.standard_normal(shape), rng.random(shape)


def test_the_sensor_model_follows_rep_117():
    geometry = ScanGeometry(4, 2 * math.pi, 0.5, 10.0)
    exact = np.array([0.2, 3.0, math.inf, 9.9999])
    out = apply_sensor_model(exact, geometry, 0.0, 0.0, *_draws(4, 1))
    assert out.dtype == np.float32
    assert out[0] == -math.inf and out[1] == 3.0 and out[2] == math.inf
    dropped = apply_sensor_model(exact, geometry, 0.0, 1.0, *_draws(4, 1))
    assert np.all(np.isnan(dropped))


def test_the_sensor_model_works_on_a_whole_fleet_at_once():
    geometry = ScanGeometry(360, 2 * math.pi, 0.1, 10.0)
    exact = np.full((50, 360), 4.0)
    normals, uniforms = _draws((50, 360), 2)
    fleet = apply_sensor_model(exact, geometry, 0.05, 0.1, normals, uniforms)
    one = apply_sensor_model(exact[7], geometry, 0.05, 0.1, normals[7], uniforms[7])
    np.testing.assert_array_equal(fleet[7], one)


def test_range_noise_has_the_configured_standard_deviation_and_dropout_its_rate():
    geometry = ScanGeometry(20000, 2 * math.pi, 0.1, 10.0)
    exact = np.full(20000, 5.0)
    out = apply_sensor_model(exact, geometry, 0.02, 0.1, *_draws(20000, 3))
    hits = out[~np.isnan(out)]
    assert np.std(hits - 5.0) == pytest.approx(0.02, rel=0.03)
    assert abs(np.mean(hits - 5.0)) < 0.001
    assert np.isnan(out).mean() == pytest.approx(0.1, abs=0.01)


def test_beam_directions_are_unit_vectors_at_the_beam_angles():
    yaws = np.array([0.3, -2.0])
    beams = np.linspace(-math.pi, math.pi, 7)
    dx, dy = beam_directions(yaws, beams)
    np.testing.assert_allclose(np.hypot(dx, dy), 1.0, atol=1e-15)
    np.testing.assert_allclose(
        np.arctan2(dy, dx), np.angle(np.exp(1j * (yaws[:, None] + beams))), atol=1e-12
    )


def _numpy_sensor_model(ranges, geometry, noise_std_m, dropout_prob, normals, uniforms):
    """The sensor model in numpy terms (numpy's promotion rules decide the precisions)."""
    out = np.where(np.isfinite(ranges), ranges + normals * noise_std_m, np.inf)
    out = np.where(out > geometry.range_max_m, np.inf, out)
    out = np.where(out < geometry.range_min_m, -np.inf, out)
    out = np.where(uniforms < dropout_prob, np.nan, out)
    return out.astype(np.float32)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_the_sensor_model_matches_its_numpy_formulation_bit_for_bit(dtype):
    rng = np.random.default_rng(12)
    geometry = ScanGeometry(360, 2 * math.pi, 0.1, 10.0)
    for noise, dropout in [(0.01, 0.0), (0.0, 0.0), (0.05, 0.1), (0.3, 0.7), (0.02, 1.0)]:
        exact = rng.uniform(0.0, 10.2, (6, 360))
        exact[rng.random(exact.shape) < 0.2] = math.inf
        exact[0, :4] = [math.nan, -math.inf, 0.1, 10.0]
        normals = rng.standard_normal((6, 360)).astype(dtype)
        uniforms = rng.random((6, 360)).astype(dtype)
        uniforms[0, :2] = dtype(dropout)  # ties with the dropout probability
        block = np.stack([normals, normals], axis=1)  # a strided view, as BlockDraws gives
        got = apply_sensor_model(exact, geometry, noise, dropout, block[:, 0], uniforms)
        want = _numpy_sensor_model(exact, geometry, noise, dropout, normals, uniforms)
        assert got.dtype == np.float32 and got.shape == want.shape
        np.testing.assert_array_equal(got.view(np.int32), want.view(np.int32))


def test_the_sensor_model_refuses_draws_of_another_shape():
    geometry = ScanGeometry(4, 2 * math.pi, 0.1, 10.0)
    normals, uniforms = _draws((2, 4), 5)
    with pytest.raises(ValueError, match=r"draws of shapes \(2, 4\) and \(4,\)"):
        apply_sensor_model(np.full((2, 4), 3.0), geometry, 0.01, 0.0, normals, uniforms[0])


def _numpy_hits_within(ranges, seen, poses, angles, within_m):
    """Hits within range in numpy terms (numpy's promotion rules decide the comparisons)."""
    keep = np.isfinite(ranges) & (ranges > 0) & (ranges <= within_m) & seen[:, None]
    r = np.where(keep, ranges, 0.0).astype(np.float64)
    c, s = np.cos(poses[:, 2:3]), np.sin(poses[:, 2:3])
    x = poses[:, 0:1] + r * (c * np.cos(angles) - s * np.sin(angles))
    y = poses[:, 1:2] + r * (s * np.cos(angles) + c * np.sin(angles))
    start = np.zeros(len(ranges) + 1, dtype=np.int64)
    np.cumsum(keep.sum(axis=1), out=start[1:])
    return np.stack([x[keep], y[keep]], axis=1), start


@settings(max_examples=60, deadline=None)
@given(
    robots=st.integers(0, 5),
    beams=st.integers(1, 40),
    within_m=st.floats(0.0, 12.0),
    seed=st.integers(0, 2**32 - 1),
)
def test_hits_within_range_match_their_numpy_formulation_bit_for_bit(robots, beams, within_m, seed):
    rng = np.random.default_rng(seed)
    ranges = rng.uniform(-1.0, 11.0, (robots, beams)).astype(np.float32)
    specials = np.array([np.nan, np.inf, -np.inf, 0.0, np.float32(within_m)], dtype=np.float32)
    mask = rng.random(ranges.shape) < 0.3
    ranges[mask] = rng.choice(specials, int(mask.sum()))
    seen = rng.random(robots) < 0.8
    poses = np.column_stack(
        [rng.uniform(-50, 50, robots), rng.uniform(-50, 50, robots), rng.uniform(-7, 7, robots)]
    )
    angles = ScanGeometry(beams, 2 * math.pi, 0.1, 10.0).angles()
    points, start = hits_within(ranges, seen, poses, np.cos(angles), np.sin(angles), within_m)
    want_points, want_start = _numpy_hits_within(ranges, seen, poses, angles, within_m)
    np.testing.assert_array_equal(start, want_start)
    np.testing.assert_array_equal(points.view(np.int64), want_points.view(np.int64))


def test_hits_within_range_leave_out_robots_without_a_scan_and_beams_without_a_hit():
    angles = ScanGeometry(4, 2 * math.pi, 0.1, 10.0).angles()  # -180, -90, 0, 90 deg
    ranges = np.array([[1.0, np.inf, 2.0, np.nan], [1.0, 1.0, 1.0, 1.0]], dtype=np.float32)
    poses = np.array([[1.0, 2.0, 0.0], [0.0, 0.0, 0.0]])
    points, start = hits_within(
        ranges, np.array([True, False]), poses, np.cos(angles), np.sin(angles), 1.5
    )
    assert list(start) == [0, 1, 1]
    assert points == pytest.approx(np.array([[0.0, 2.0]]))


def _numpy_seen_beyond(pose, ranges, angle_min, increment, range_max, points, tolerance):
    """Seen-through points in numpy terms."""
    x, y, yaw = pose
    dx, dy = points[:, 0] - x, points[:, 1] - y
    dist = np.hypot(dx, dy)
    bearing = (np.arctan2(dy, dx) - yaw - angle_min) % (2 * math.pi)
    beam = np.rint(bearing / increment).astype(np.int64)
    inside = beam < len(ranges)
    seen = ranges[np.minimum(beam, len(ranges) - 1)].astype(np.float64)
    seen = np.where(seen == np.inf, range_max, seen)
    seen = np.where(seen == -np.inf, 0.0, seen)
    return inside & (dist < range_max) & (seen > dist + tolerance)


@settings(max_examples=80, deadline=None)
@given(
    beams=st.integers(2, 400),  # the navigation's scan memory takes 1 rad for a single beam
    full=st.booleans(),
    count=st.integers(0, 60),
    seed=st.integers(0, 2**32 - 1),
)
def test_points_seen_through_match_their_numpy_formulation(beams, full, count, seed):
    rng = np.random.default_rng(seed)
    geometry = ScanGeometry(beams, 2 * math.pi if full else 4.0, 0.1, 10.0)
    ranges = rng.uniform(-1.0, 11.0, beams).astype(np.float32)
    specials = np.array([np.nan, np.inf, -np.inf], dtype=np.float32)
    mask = rng.random(beams) < 0.3
    ranges[mask] = rng.choice(specials, int(mask.sum()))
    pose = np.array([rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-7, 7)])
    points = pose[:2] + rng.uniform(-12, 12, (count, 2))
    args = (geometry.angle_min_rad, geometry.angle_increment_rad, 10.0, points, 0.2)
    got = seen_beyond(pose, ranges, *args)
    np.testing.assert_array_equal(got, _numpy_seen_beyond(pose, ranges, *args))
