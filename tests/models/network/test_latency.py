import numpy as np
import pytest
from scipy import stats

from models.errors import ModelError
from models.network.latency import (
    ConstantLatency,
    EmpiricalLatency,
    LognormalLatency,
    NormalLatency,
    ms_to_ns,
)

N = 20_000


def _sample_ms(model, seed):
    return model.sample(np.random.default_rng(seed), N) / 1e6


def test_a_constant_latency_is_exact_in_nanoseconds():
    assert ConstantLatency(5.0).sample(np.random.default_rng(0), 3).tolist() == [5_000_000] * 3
    assert ConstantLatency(0.1).sample(np.random.default_rng(0), 1).tolist() == [100_000]


def test_milliseconds_round_to_the_nearest_nanosecond_with_ties_to_even():
    assert ms_to_ns([1.0000004, 1.0000006, 0.0]).tolist() == [1_000_000, 1_000_001, 0]
    # these products are exactly x.5 ns in binary floating point
    assert ms_to_ns([0.5e-6, 1.5e-6, 2.5e-6, 3.5e-6]).tolist() == [0, 2, 2, 4]


def test_a_heavily_truncated_normal_latency_matches_its_distribution():
    model = NormalLatency(2.0, 3.0)  # a third of the untruncated mass is below 0
    sample = _sample_ms(model, 1)
    assert sample.min() >= 0.0
    assert stats.kstest(sample, model.cdf).pvalue > 0.01
    assert sample.mean() == pytest.approx(model.truncated_mean_ms, rel=0.02)


def test_the_ks_check_rejects_a_normal_that_was_not_truncated():
    model = NormalLatency(2.0, 3.0)
    sample = _sample_ms(model, 1)
    untruncated = stats.norm(2.0, 3.0).cdf
    assert stats.kstest(sample, untruncated).pvalue < 1e-6


def test_a_lognormal_latency_has_the_configured_mean_and_standard_deviation():
    model = LognormalLatency(20.0, 10.0)
    sample = _sample_ms(model, 2)
    assert stats.kstest(sample, model.cdf).pvalue > 0.01
    assert sample.mean() == pytest.approx(20.0, rel=0.02)
    assert sample.std() == pytest.approx(10.0, rel=0.05)
    assert model.sigma**2 == pytest.approx(np.log(1.25))
    assert model.mu == pytest.approx(np.log(20.0) - np.log(1.25) / 2)


def test_the_ks_check_rejects_a_normal_with_the_lognormals_moments():
    sample = _sample_ms(LognormalLatency(20.0, 10.0), 2)
    assert stats.kstest(sample, stats.norm(20.0, 10.0).cdf).pvalue < 1e-6


def test_empirical_latency_draws_only_the_measured_samples_with_their_frequencies():
    measured = np.random.default_rng(3).gamma(2.0, 4.0, 500)
    model = EmpiricalLatency(measured)
    sample = _sample_ms(model, 4)
    assert set(np.round(sample, 6)) <= set(np.round(measured, 6))
    assert stats.kstest(sample, model.cdf).pvalue > 0.01
    assert model.mean_ms == pytest.approx(measured.mean())


def test_the_ks_check_rejects_an_empirical_sample_shifted_by_half_a_millisecond():
    measured = np.random.default_rng(3).gamma(2.0, 4.0, 500)
    sample = _sample_ms(EmpiricalLatency(measured), 4)
    assert stats.kstest(sample + 0.5, EmpiricalLatency(measured).cdf).pvalue < 1e-6


def test_zero_jitter_makes_normal_and_lognormal_constant():
    rng = np.random.default_rng(0)
    assert NormalLatency(3.0, 0.0).sample(rng, 2).tolist() == [3_000_000] * 2
    assert LognormalLatency(3.0, 0.0).sample(rng, 2).tolist() == [3_000_000] * 2


def test_draws_depend_only_on_the_generator():
    model = LognormalLatency(5.0, 1.0)
    first = model.sample(np.random.default_rng(9), 100)
    again = model.sample(np.random.default_rng(9), 100)
    assert first.tolist() == again.tolist()


@pytest.mark.parametrize(
    ("make", "key"),
    [
        (lambda: ConstantLatency(-1.0), "network.latency_ms"),
        (lambda: ConstantLatency(float("nan")), "network.latency_ms"),
        (lambda: NormalLatency(-1.0, 1.0), "network.latency_ms"),
        (lambda: NormalLatency(1.0, -1.0), "network.jitter_ms"),
        (lambda: LognormalLatency(5.0, -0.1), "network.jitter_ms"),
        (lambda: LognormalLatency(0.0, 1.0), "network.latency_ms"),
        (lambda: LognormalLatency(float("inf"), 1.0), "network.latency_ms"),
        (lambda: EmpiricalLatency([]), "network.latency_csv"),
        (lambda: EmpiricalLatency([1.0, -2.0]), "network.latency_csv"),
    ],
)
def test_a_negative_or_impossible_latency_is_refused_with_its_key(make, key):
    with pytest.raises(ModelError) as error:
        make()
    assert error.value.key == key
