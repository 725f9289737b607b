import math

import numpy as np
import pytest

from models.lidar import ScanGeometry, apply_sensor_model, cast_reference
from models.world import box_segments


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
    angles = np.array([[0.0, math.atan2(0.5, 2.0), math.pi]])
    ranges = cast_reference(origins, angles, segments, np.zeros((0, 3)), 10.0)
    assert ranges[0, 0] == pytest.approx(2.0)
    assert ranges[0, 1] == pytest.approx(math.hypot(2.0, 0.5))
    assert ranges[0, 2] == math.inf


def test_rays_hit_circles_and_ignore_the_robots_own_body():
    circles = np.array([[0.0, 0.0, 0.3], [4.0, 0.0, 0.5]])
    origins = np.array([[0.0, 0.0], [4.0, 0.0]])
    angles = np.array([[0.0, math.pi], [math.pi, 0.0]])
    ranges = cast_reference(
        origins, angles, np.zeros((0, 4)), circles, 10.0, exclude=np.array([0, 1])
    )
    assert ranges[0, 0] == pytest.approx(3.5)
    assert ranges[0, 1] == math.inf
    assert ranges[1, 0] == pytest.approx(3.7)


def test_hits_beyond_the_maximum_range_read_infinity():
    segments = box_segments(np.array([[5.0, -1.0, 6.0, 1.0]]))
    ranges = cast_reference(
        np.array([[0.0, 0.0]]), np.array([[0.0]]), segments, np.zeros((0, 3)), 4.0
    )
    assert ranges[0, 0] == math.inf


def test_the_sensor_model_follows_rep_117_and_is_seeded():
    geometry = ScanGeometry(4, 2 * math.pi, 0.5, 10.0)
    exact = np.array([0.2, 3.0, math.inf, 9.9999])
    out = apply_sensor_model(exact, geometry, 0.0, 0.0, np.random.default_rng(1))
    assert out.dtype == np.float32
    assert out[0] == -math.inf and out[1] == 3.0 and out[2] == math.inf
    dropped = apply_sensor_model(exact, geometry, 0.0, 1.0, np.random.default_rng(1))
    assert np.all(np.isnan(dropped))
    a = apply_sensor_model(exact, geometry, 0.05, 0.1, np.random.default_rng(7))
    b = apply_sensor_model(exact, geometry, 0.05, 0.1, np.random.default_rng(7))
    np.testing.assert_array_equal(a, b)


def test_range_noise_has_the_configured_standard_deviation():
    geometry = ScanGeometry(20000, 2 * math.pi, 0.1, 10.0)
    exact = np.full(20000, 5.0)
    out = apply_sensor_model(exact, geometry, 0.02, 0.0, np.random.default_rng(3))
    assert np.std(out - 5.0) == pytest.approx(0.02, rel=0.03)
    assert abs(np.mean(out - 5.0)) < 0.001
