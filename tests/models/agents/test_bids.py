import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from models.agents.bids import highest_bid

INF = float("inf")


def test_the_highest_bid_among_free_servable_tasks_wins():
    bids = np.array([0.2, 0.9, 0.7, 0.95])
    cost = np.array([3.0, 4.0, 5.0, INF])  # task 3 is out of reach
    assert highest_bid(bids, cost, {0, 1, 2, 3}) == 1
    assert highest_bid(bids, cost, {0, 2}) == 2  # 1 is taken
    assert highest_bid(bids, cost, {3}) is None
    assert highest_bid(np.array([0.0, 0.3, 0.0, 0.0]), cost, {0, 2}) is None  # 0 declines


def test_tasks_past_the_last_slot_get_no_bid_and_ties_go_to_the_first():
    assert highest_bid(np.array([0.5, 0.5]), np.array([1.0, 2.0, 0.5]), {0, 1, 2}) == 0
    assert highest_bid(np.array([0.5, 0.5]), np.array([1.0, 2.0, 0.5]), {2}) is None


@given(
    st.lists(st.floats(0, 1), min_size=1, max_size=8),
    st.lists(st.one_of(st.floats(0, 100), st.just(INF)), min_size=0, max_size=10),
    st.sets(st.integers(-2, 12)),
)
def test_the_choice_is_always_free_servable_within_the_slots_and_bid_highest(bids, cost, free):
    choice = highest_bid(np.array(bids), np.array(cost, dtype=float), free)
    slots = min(len(bids), len(cost))
    allowed = [j for j in free if 0 <= j < slots and cost[j] < INF and bids[j] > 0]
    if not allowed:
        assert choice is None
        return
    assert choice in allowed
    assert bids[choice] == max(bids[j] for j in allowed)
