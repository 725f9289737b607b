import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from models.mocap.gate import PoseGate, stale
from models.mocap.sampling import MocapParams, measure

GATE = PoseGate(max_speed_mps=1.0, max_yaw_rate_radps=2.0, tolerance_m=0.05, tolerance_rad=0.2)


def test_measurement_noise_and_dropouts_follow_the_parameters():
    rng = np.random.default_rng(5)
    params = MocapParams(noise_std_m=0.01, noise_std_rad=0.02, dropout=0.1)
    truth = np.tile([1.0, 2.0, 0.3], (20_000, 1))
    m = measure(truth, rng.standard_normal((20_000, 3)), rng.random(20_000), params)
    error = m.poses - truth
    assert np.std(error[:, 0]) == pytest.approx(0.01, rel=0.03)
    assert np.std(error[:, 1]) == pytest.approx(0.01, rel=0.03)
    assert np.std(error[:, 2]) == pytest.approx(0.02, rel=0.03)
    assert 1 - m.seen.mean() == pytest.approx(0.1, abs=0.01)


def test_without_noise_a_measurement_is_the_truth_with_yaw_wrapped():
    truth = np.array([[1.0, 2.0, 3.5]])
    m = measure(truth, np.ones((1, 3)), np.ones(1), MocapParams(noise_std_m=0, noise_std_rad=0))
    assert m.poses[0, :2].tolist() == [1.0, 2.0]
    assert m.poses[0, 2] == pytest.approx(3.5 - 2 * math.pi)


@pytest.mark.parametrize(
    ("key", "value"), [("noise_std_m", -1.0), ("dropout", 1.5), ("rate_hz", 0.0)]
)
def test_impossible_mocap_parameters_are_refused_by_name(key, value):
    with pytest.raises(ValueError, match=key):
        MocapParams(**{key: value})


def test_the_gate_accepts_a_robot_driving_at_its_top_speed_and_rejects_a_jump():
    last = (1.0, 1.0, 0.0)
    assert GATE.check_one(last, 0, (1.01, 1.0, 0.0), 10_000_000) == "ok"
    assert GATE.check_one(last, 0, (2.0, 1.0, 0.0), 10_000_000) == "jump"
    assert GATE.check_one(last, 0, (1.0, 1.0, 1.0), 10_000_000) == "jump"  # 1 rad in 10 ms
    assert GATE.check_one(last, 10, (1.0, 1.0, 0.0), 10) == "out_of_order"
    assert GATE.check_one(None, 0, (9.0, 9.0, 0.0), 0) == "ok"
    assert GATE.check_one((0.0, 0.0, 3.1), 0, (0.0, 0.0, -3.1), 1_000_000) == "ok"  # wraps


def test_the_array_gate_agrees_with_the_one_pose_gate():
    rng = np.random.default_rng(2)
    last = rng.uniform(-1, 1, (500, 3))
    new = last + rng.normal(0, 0.05, (500, 3))
    stamps = rng.integers(-5_000_000, 50_000_000, 500)
    result = GATE.check(last, np.zeros(500, dtype=np.int64), new, stamps, np.ones(500, bool))
    for k in range(500):
        one = GATE.check_one(tuple(last[k]), 0, tuple(new[k]), int(stamps[k]))
        assert one == ("ok" if result.accepted[k] else "jump" if result.jump[k] else "out_of_order")


@given(
    st.floats(-50, 50), st.floats(-50, 50), st.floats(-50, 50), st.floats(-50, 50),
    st.integers(1, 10**9),
)  # fmt: skip
def test_an_accepted_pose_never_lies_beyond_what_the_robot_can_drive(x0, y0, x1, y1, dt_ns):
    if GATE.check_one((x0, y0, 0.0), 0, (x1, y1, 0.0), dt_ns) == "ok":
        assert math.hypot(x1 - x0, y1 - y0) <= 1.0 * dt_ns / 1e9 + 0.05 + 1e-12


def test_a_pose_is_stale_only_once_it_is_older_than_the_limit():
    stamps = np.array([0, 0, 0], dtype=np.int64)
    has = np.array([True, True, False])
    assert stale(stamps, 200, 200, has).tolist() == [False, False, True]
    assert stale(stamps, 201, 200, has).tolist() == [True, True, True]


def test_the_one_pose_gate_never_accepts_a_pose_that_is_not_a_number():
    assert GATE.check_one(None, 0, (math.nan, 1.0, 0.0), 1) == "jump"
    assert GATE.check_one((0.0, 0.0, 0.0), 0, (0.0, 0.0, math.inf), 10**9) == "jump"
