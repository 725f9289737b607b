"""The command line's value types: a value in bounds is taken, any other refused in one line."""

from __future__ import annotations

import argparse

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cosim.cli.values import non_negative_int, port, threads, times


@given(st.integers(1, 64))
def test_a_thread_count_from_1_to_64_is_taken(count: int) -> None:
    assert threads(str(count)) == count


@pytest.mark.parametrize(
    ("text", "said"),
    [("0", "0 is not an integer >= 1"), ("65", "65 is more than 64"), ("x", "'x' is not an")],
)
def test_a_thread_count_out_of_bounds_is_refused_saying_why(text: str, said: str) -> None:
    with pytest.raises(argparse.ArgumentTypeError, match=said):
        threads(text)


@given(st.text(max_size=12))
def test_any_text_is_an_int_a_port_or_one_line_of_refusal(text: str) -> None:
    for convert in (non_negative_int, port):
        try:
            convert(text)
        except argparse.ArgumentTypeError as error:
            assert "\n" not in str(error).strip("\n") or "\n" in text


def test_times_are_split_at_commas_and_each_checked() -> None:
    assert times("10, 20,30") == [10.0, 20.0, 30.0]
    with pytest.raises(argparse.ArgumentTypeError, match="'ten' in 'ten' is not a number"):
        times("ten")
    with pytest.raises(argparse.ArgumentTypeError, match="-1 is not a finite time"):
        times("1,-1")
