import numpy as np
import pytest

from adapters.navigation.recovery import STALL_M, STALL_S, STUCK_KINDS, StallWatch, stuck_kind
from cosim.core.timebase import s_to_ns

TICK_NS = s_to_ns(0.1)


def _watch(poses: np.ndarray, active: np.ndarray, until_s: float) -> np.ndarray:
    """Feed ``poses(t)`` every 0.1 s up to ``until_s``; the last answer."""
    watch = StallWatch(poses(0.0))
    stalled = np.zeros(len(active), dtype=bool)
    for k in range(round(until_s / 0.1) + 1):
        stalled = watch.update(k * TICK_NS, poses(k * 0.1), active)
    return stalled


def test_a_robot_dithering_in_place_stalls_after_the_span_whatever_it_commands():
    def poses(t_s: float) -> np.ndarray:
        wiggle = 0.05 * (-1) ** round(t_s / 0.1)  # turning left and right by turns
        return np.array([[1.0, 2.0, wiggle]])

    active = np.array([True])
    assert not _watch(poses, active, STALL_S - 0.2)[0]
    assert _watch(poses, active, STALL_S)[0]


def test_robots_that_drive_or_turn_or_have_no_goal_do_not_stall():
    def poses(t_s: float) -> np.ndarray:
        return np.array(
            [
                [0.5 * t_s, 0.0, 0.0],  # drives at 0.5 m/s
                [3.0, 3.0, 0.5 * t_s],  # turns on the spot at 0.5 rad/s
                [5.0, 5.0, 0.0],  # stands, without a goal
            ]
        )

    assert not _watch(poses, np.array([True, True, False]), 3 * STALL_S).any()


def test_a_robot_creeping_slower_than_the_threshold_stalls_and_a_reset_restarts_the_span():
    creep_mps = 0.5 * STALL_M / STALL_S  # half the distance in the whole span

    def poses(t_s: float) -> np.ndarray:
        return np.array([[creep_mps * t_s, 0.0, 0.0]])

    active = np.array([True])
    watch = StallWatch(poses(0.0))
    ticks = round(STALL_S / 0.1)
    for k in range(ticks + 1):
        stalled = watch.update(k * TICK_NS, poses(k * 0.1), active)
    assert stalled[0]
    watch.reset(0, poses(STALL_S)[0], ticks * TICK_NS)  # a new goal
    assert not watch.update((ticks + 1) * TICK_NS, poses(STALL_S + 0.1), active)[0]


@pytest.mark.parametrize(
    ("driven_m", "left_m", "best_m", "kind"),
    [
        (0.0, 12.0, 12.0, "halted"),  # boxed in
        (0.9, 30.0, 12.0, "halted"),  # replanned long but stood still
        (14.0, 24.0, 12.0, "detoured"),  # drove round a rack, the way grew by 12 m
        (10.0, 12.1, 12.0, "slowed"),  # drove 10 m without getting nearer
        (2.0, 16.9, 12.0, "slowed"),  # a detour of less than 5 m
    ],
)
def test_a_stuck_report_says_whether_the_robot_halted_detoured_or_slowed(
    driven_m, left_m, best_m, kind
):
    got, figures = stuck_kind(driven_m, left_m, best_m)
    assert got == kind and got in STUCK_KINDS
    assert figures == f"drove {driven_m:.1f} m, {left_m:.1f} m to go, best {best_m:.1f} m"
