import math

import numpy as np
import pytest

from models.mocap.sampling import MocapParams, measure

N = 20_000
EXACT = MocapParams(noise_std_m=0.0, noise_std_rad=0.0)


def test_measurement_noise_has_the_requested_spread_on_x_y_and_yaw():
    rng = np.random.default_rng(11)
    params = MocapParams(noise_std_m=0.02, noise_std_rad=0.05)
    truth = np.tile([4.0, -3.0, 0.25], (N, 1))
    m = measure(truth, rng.standard_normal((N, 3)), rng.random(N), params)
    error = m.poses - truth
    assert np.std(error, axis=0) == pytest.approx([0.02, 0.02, 0.05], rel=0.03)
    assert np.abs(np.mean(error, axis=0)) == pytest.approx([0, 0, 0], abs=0.002)
    assert abs(np.corrcoef(error[:, 0], error[:, 1])[0, 1]) < 0.03  # axes independent


def test_the_same_draws_give_the_same_frame():
    rng = np.random.default_rng(3)
    truth = rng.uniform(-5, 5, (50, 3))
    normals, uniforms = rng.standard_normal((50, 3)), rng.random(50)
    params = MocapParams(noise_std_m=0.01, dropout=0.2)
    a, b = measure(truth, normals, uniforms, params), measure(truth, normals, uniforms, params)
    assert np.array_equal(a.poses, b.poses) and np.array_equal(a.seen, b.seen)


def test_without_noise_a_measurement_is_exactly_the_truth():
    rng = np.random.default_rng(1)
    truth = np.column_stack(
        [rng.uniform(-50, 50, N), rng.uniform(-50, 50, N), rng.uniform(-math.pi, math.pi, N)]
    )
    truth[:4, 2] = [0.1, -math.pi, 3.0, -1e-300]
    m = measure(truth, rng.standard_normal((N, 3)), rng.random(N), EXACT)
    assert np.array_equal(m.poses, truth)
    assert m.seen.all()


def test_dropouts_occur_with_the_requested_probability():
    rng = np.random.default_rng(8)
    m = measure(np.zeros((N, 3)), np.zeros((N, 3)), rng.random(N), MocapParams(dropout=0.15))
    assert 1 - m.seen.mean() == pytest.approx(0.15, abs=0.01)


def test_no_body_drops_out_at_probability_zero_and_every_body_at_one():
    uniforms = np.array([0.0, 0.5, np.nextafter(1.0, 0.0)])
    assert measure(np.zeros((3, 3)), np.zeros((3, 3)), uniforms, MocapParams()).seen.all()
    gone = measure(np.zeros((3, 3)), np.zeros((3, 3)), uniforms, MocapParams(dropout=1.0))
    assert not gone.seen.any()


@pytest.mark.parametrize(
    "yaw",
    [
        math.pi,
        -math.pi,
        np.nextafter(-math.pi, -math.inf),  # -tiny % 2pi rounds up to 2pi
        np.nextafter(math.pi, math.inf),
        3 * math.pi,
        -3 * math.pi + 0.2,
        100.0,
        -1e6,
        7.5,
    ],
)
def test_a_measured_yaw_is_wrapped_into_minus_pi_to_pi_as_the_same_heading(yaw):
    m = measure(np.array([[0.0, 0.0, yaw]]), np.zeros((1, 3)), np.ones(1), EXACT)
    wrapped = m.poses[0, 2]
    assert -math.pi <= wrapped < math.pi
    assert math.cos(wrapped) == pytest.approx(math.cos(yaw), abs=1e-9)
    assert math.sin(wrapped) == pytest.approx(math.sin(yaw), abs=1e-9)


def test_noise_that_carries_a_yaw_past_pi_wraps_it():
    m = measure(
        np.array([[0.0, 0.0, 3.1]]),
        np.array([[0.0, 0.0, 1.0]]),
        np.ones(1),
        MocapParams(noise_std_rad=0.1),
    )
    assert m.poses[0, 2] == pytest.approx(3.2 - 2 * math.pi)


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("noise_std_m", -0.001),
        ("noise_std_rad", -1.0),
        ("latency_ms", -5.0),
        ("noise_std_m", math.nan),
        ("dropout", 1.01),
        ("dropout", -0.1),
        ("rate_hz", 0.0),
        ("rate_hz", -10.0),
    ],
)
def test_impossible_mocap_parameters_are_refused_naming_the_key(key, value):
    with pytest.raises(ValueError, match=rf"^{key} = "):
        MocapParams(**{key: value})


def test_the_edges_of_the_parameter_ranges_are_allowed():
    params = MocapParams(noise_std_m=0.0, noise_std_rad=0.0, latency_ms=0.0, dropout=1.0)
    assert params.dropout == 1.0
