"""Kernel time: integer nanoseconds, exact periods, seconds at the edges."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cosim.core.timebase import NS_PER_MS, NS_PER_S, ms_to_ns, ns_to_s, period_ns, s_to_ns


def test_the_units_are_nanoseconds():
    assert (NS_PER_S, NS_PER_MS) == (1_000_000_000, 1_000_000)


@pytest.mark.parametrize(
    ("seconds", "ns"),
    [(0.0, 0), (1.5, 1_500_000_000), (0.1, 100_000_000), (1e-9, 1), (4e-10, 0), (-2.0, -2 * 10**9)],
)
def test_seconds_become_the_nearest_integer_nanosecond(seconds, ns):
    assert s_to_ns(seconds) == ns and type(s_to_ns(seconds)) is int


def test_milliseconds_become_the_nearest_integer_nanosecond():
    assert ms_to_ns(2.5) == 2_500_000 and ms_to_ns(0.0000006) == 1
    assert type(ms_to_ns(1)) is int


@given(st.integers(-(2**62), 2**62))
def test_nanoseconds_read_as_seconds_and_back_within_a_nanosecond_per_2_to_the_53(ns):
    assert abs(s_to_ns(ns_to_s(ns)) - ns) <= max(1, abs(ns) // 2**52)


@pytest.mark.parametrize(
    ("rate_hz", "period"),
    [(10, 100_000_000), (50.0, 20_000_000), (1, NS_PER_S), (0.5, 2 * NS_PER_S), (1e9, 1)],
)
def test_the_period_of_a_rate_is_exact_in_nanoseconds(rate_hz, period):
    assert period_ns(rate_hz) == period


def test_a_period_that_is_no_whole_nanosecond_is_rounded_drifting_under_a_nanosecond():
    assert period_ns(3) == 333_333_333
    assert abs(3 * period_ns(3) - NS_PER_S) < 3


@pytest.mark.parametrize("rate_hz", [0, -10.0])
def test_a_rate_that_is_not_positive_is_refused(rate_hz):
    with pytest.raises(ValueError, match=rf"rate must be positive, got {rate_hz} Hz"):
        period_ns(rate_hz)


@pytest.mark.parametrize("rate_hz", [1.5e9, 2e9, 1e12, float("inf")])
def test_a_rate_above_1_ghz_is_refused(rate_hz):
    with pytest.raises(ValueError, match="above 1 GHz"):
        period_ns(rate_hz)
