import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from adapters.agents.boundary import action_problem, observation_problem, reward_problem
from adapters.agents.contract import BoxSpec, ChoiceSpec

NAMES = ["robot_1", "robot_2"]
BOX = BoxSpec((-0.3, -2.0), (0.5, 2.0), ("v_mps", "w_radps"))


@given(arrays(np.float64, st.tuples(st.integers(0, 3), st.integers(0, 3))))
def test_any_array_handed_in_as_velocities_is_accepted_or_named(actions):
    problem = action_problem(BOX, actions, NAMES)
    good = actions.shape == (2, 2) and np.isfinite(actions).all()
    assert (problem is None) == good
    if problem is not None:
        assert "expected" in problem


@given(arrays(np.float64, st.integers(0, 3)))
def test_any_array_handed_in_as_choices_is_accepted_or_named(actions):
    problem = action_problem(ChoiceSpec(5), actions, NAMES)
    good = (
        actions.shape == (2,)
        and np.isfinite(actions).all()
        and bool(np.all((actions == np.round(actions)) & (actions >= 0) & (actions < 5)))
    )
    assert (problem is None) == good


def test_an_observation_outside_its_bounds_names_the_agent_index_and_bounds():
    low, high = np.zeros(3, np.float32), np.ones(3, np.float32)
    block = np.array([[0.5, 0.5, 0.5], [0.5, 1.5, np.nan]], np.float32)
    problem = observation_problem(block, low, high, NAMES)
    assert problem.startswith("observe() wrote 1.5 for robot_2 at index 1")
    assert "[0, 1]" in problem and "2 value(s) out of 6 wrong" in problem
    assert observation_problem(block[:1], low, high, NAMES) is None


def test_reward_totals_of_the_wrong_shape_or_not_finite_are_named():
    assert reward_problem(np.zeros(2), 2) is None
    assert "expected (2,)" in reward_problem(np.zeros(3), 2)
    assert "finite" in reward_problem(np.array([0.0, np.inf]), 2)
    assert "finite" in reward_problem(np.array(["a", "b"]), 2)
