import pytest

from models.errors import ModelError
from models.network.interface import InterfaceQueue


def test_a_1250_byte_message_takes_exactly_10_ms_at_1_mbit_s():
    assert InterfaceQueue(1e6, 10).serialization_ns(1250) == 10_000_000


def test_back_to_back_messages_leave_one_serialization_apart():
    queue = InterfaceQueue(1e6, 10)
    assert [queue.enqueue(0, 1250) for _ in range(3)] == [10_000_000, 20_000_000, 30_000_000]


def test_serialization_is_rounded_up_to_the_next_nanosecond():
    # 8 bits at 3 Mbit/s = 2666.67 ns
    assert InterfaceQueue(3e6, 10).serialization_ns(1) == 2667
    # a fractional rate is exact too: 8 bits at 0.5 bit/s = 16 s
    assert InterfaceQueue(0.5, 10).serialization_ns(1) == 16_000_000_000


def test_an_idle_interface_starts_a_message_when_it_arrives():
    queue = InterfaceQueue(1e6, 10)
    assert queue.enqueue(0, 1250) == 10_000_000
    assert queue.enqueue(10_000_000, 1250) == 20_000_000
    assert queue.enqueue(50_000_000, 125) == 51_000_000


def test_a_full_queue_refuses_exactly_the_messages_beyond_its_limit():
    queue = InterfaceQueue(1e6, 3)
    leave = [queue.enqueue(0, 1250) for _ in range(6)]
    # one in transmission + 3 waiting; the 5th and 6th are refused
    assert leave == [10_000_000, 20_000_000, 30_000_000, 40_000_000, None, None]
    # when the first has left, there is room for exactly one more
    assert queue.enqueue(10_000_000, 1250) == 50_000_000
    assert queue.enqueue(10_000_000, 1250) is None
    assert queue.backlog(10_000_000) == 4
    assert queue.backlog(50_000_000) == 0


def test_a_zero_limit_queue_only_accepts_a_message_when_the_interface_is_idle():
    queue = InterfaceQueue(1e6, 0)
    assert queue.enqueue(0, 1250) == 10_000_000
    assert queue.enqueue(9_999_999, 1250) is None
    assert queue.enqueue(10_000_000, 1250) == 20_000_000


def test_an_unlimited_interface_sends_at_once_and_is_never_full():
    queue = InterfaceQueue(None, 0)
    assert [queue.enqueue(5, 10**9) for _ in range(1000)] == [5] * 1000
    assert queue.serialization_ns(10**9) == 0


def test_time_going_backwards_is_a_bug():
    queue = InterfaceQueue(1e6, 1)
    queue.enqueue(100, 1)
    with pytest.raises(ValueError, match="after a message"):
        queue.enqueue(99, 1)


@pytest.mark.parametrize("rate", [0.0, -1e6, float("nan"), float("inf")])
def test_a_rate_that_is_not_positive_is_refused(rate):
    with pytest.raises(ModelError) as error:
        InterfaceQueue(rate, 10)
    assert error.value.key == "network.bandwidth_mbps"


@pytest.mark.parametrize("limit", [-1, 1.5, True])
def test_a_queue_limit_that_is_not_a_count_is_refused(limit):
    with pytest.raises(ModelError) as error:
        InterfaceQueue(1e6, limit)
    assert error.value.key == "network.queue_packets"
