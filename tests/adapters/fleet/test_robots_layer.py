from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pytest

from adapters.fleet.robots_layer import RobotsLayer
from adapters.fleet.topics import ROBOT_STATES
from cosim.core.adapter import RunContext
from cosim.core.bus import Bus
from cosim.core.hosts import HostId
from cosim.core.kernel import Kernel
from cosim.core.link import DELIVERED, Transfer
from cosim.core.messages import RobotState
from cosim.core.recorder import Recorder
from cosim.core.rng import RngStreams
from cosim.core.timebase import s_to_ns

NAMES = ["robot_1", "robot_2", "robot_3"]
HOSTS = [HostId(n) for n in NAMES]
RADIUS_M = 0.3
LATENCY_NS = 20_000_000


@dataclass
class SlowLink:
    """20 ms to every host; nothing of ``silent`` arrives."""

    silent: str = ""

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> list[Transfer]:
        if src == self.silent:
            return [Transfer(d, "lost", None) for d in dsts]
        return [Transfer(d, DELIVERED, t_ns + LATENCY_NS) for d in dsts]


def started(
    silent: str = "", rate_hz: float = 10.0, timeout_s: float = 1.0
) -> tuple[RunContext, RobotsLayer, np.ndarray, np.ndarray]:
    kernel = Kernel()
    recorder = Recorder()
    run = RunContext(None, kernel, Bus(kernel, SlowLink(silent), recorder), RngStreams(1), recorder)  # type: ignore[arg-type]
    layer = RobotsLayer(NAMES, HOSTS, RADIUS_M, timeout_s)
    layer.advertise(run)
    poses = np.array([[1.0, 1.0, 0.0], [4.0, 1.0, 1.5], [7.0, 2.0, -1.0]])
    speeds = np.array([0.5, 0.0, 0.2])
    layer.start(run, rate_hz, poses, speeds)
    return run, layer, poses, speeds


def test_the_layer_broadcasts_robot_states_on_its_topic():
    run, _, _, _ = started()
    assert run.bus.advertised()[ROBOT_STATES].message_type is RobotState
    seen: list[RobotState] = []
    run.bus.monitor(ROBOT_STATES, lambda _t, m, _src, _now: seen.append(m))
    run.kernel.run(s_to_ns(0.25))  # broadcasts at 0, 0.1 and 0.2 s
    assert len(seen) == 9
    assert seen[1] == RobotState(0, "robot_2", 4.0, 1.0, 1.5, 0.0, RADIUS_M)
    assert [m.stamp_ns for m in seen[::3]] == [0, s_to_ns(0.1), s_to_ns(0.2)]


def test_each_robot_knows_the_others_footprints_but_not_its_own():
    run, layer, _, _ = started()
    run.kernel.run(s_to_ns(0.05))
    now = run.kernel.now_ns
    assert layer.discs(0, now).tolist() == [[4.0, 1.0, RADIUS_M], [7.0, 2.0, RADIUS_M]]
    assert layer.discs(2, now).tolist() == [[1.0, 1.0, RADIUS_M], [4.0, 1.0, RADIUS_M]]


def test_nothing_is_known_before_the_first_broadcast_arrives_over_the_network():
    run, layer, _, _ = started()
    run.kernel.run(LATENCY_NS)  # arrivals at exactly 20 ms are not processed yet
    assert layer.discs(0, run.kernel.now_ns).shape == (0, 3)
    run.kernel.run(LATENCY_NS + 1)
    assert len(layer.discs(0, run.kernel.now_ns)) == 2


def test_the_poses_are_read_at_each_broadcast_so_the_others_follow_a_moving_robot():
    run, layer, poses, _ = started()
    run.kernel.run(s_to_ns(0.05))
    poses[1] = (5.5, 3.0, 0.0)  # robot_2 moved; the caller updates the array in place
    assert layer.discs(0, run.kernel.now_ns)[0].tolist() == [4.0, 1.0, RADIUS_M]
    run.kernel.run(s_to_ns(0.15))
    assert layer.discs(0, run.kernel.now_ns)[0].tolist() == [5.5, 3.0, RADIUS_M]


def test_a_robot_never_heard_from_is_unknown_to_the_others():
    run, layer, _, _ = started(silent="robot_3")
    run.kernel.run(s_to_ns(0.5))
    now = run.kernel.now_ns
    assert layer.discs(0, now).tolist() == [[4.0, 1.0, RADIUS_M]]
    assert len(layer.discs(2, now)) == 2  # robot_3 still hears the others


def test_a_robot_not_heard_from_for_the_timeout_is_forgotten():
    run, layer, _, _ = started(timeout_s=1.0)
    run.kernel.run(s_to_ns(0.95))  # last broadcast at 0.9 s, heard at 0.92 s
    heard_ns = s_to_ns(0.9) + LATENCY_NS
    assert len(layer.discs(0, heard_ns + s_to_ns(1.0))) == 2
    assert len(layer.discs(0, heard_ns + s_to_ns(1.0) + 1)) == 0


def test_every_robots_discs_pack_into_one_array_with_offsets():
    run, layer, _, _ = started(silent="robot_3")
    run.kernel.run(s_to_ns(0.05))
    discs, start = layer.all_discs(run.kernel.now_ns)
    assert start.tolist() == [0, 1, 2, 4]
    for i in range(3):
        assert discs[start[i] : start[i + 1]].tolist() == layer.discs(i, run.kernel.now_ns).tolist()


def test_an_empty_fleet_packs_to_no_discs():
    layer = RobotsLayer([], [], RADIUS_M, 1.0)
    discs, start = layer.all_discs(0)
    assert discs.shape == (0, 3) and start.tolist() == [0]


def test_each_robot_knows_the_others_velocities_in_map_row_for_row_with_their_discs():
    run, layer, _, _ = started()
    run.kernel.run(s_to_ns(0.05))  # heard at 20 ms what was sent at 0
    now = run.kernel.now_ns
    neighbours = layer.neighbours(0, now)
    assert neighbours.shape == (2, 5)
    np.testing.assert_allclose(neighbours[:, :2], layer.discs(0, now)[:, :2])
    # robot_2 stands still; robot_3 drives at 0.2 m/s heading -1 rad
    np.testing.assert_allclose(neighbours[0, 2:4], [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(neighbours[1, 2:4], [0.2 * np.cos(-1.0), 0.2 * np.sin(-1.0)])
    # robot_1's own heading 0 at 0.5 m/s, as robot_2 heard it
    np.testing.assert_allclose(layer.neighbours(1, now)[0, 2:4], [0.5, 0.0], atol=1e-12)


def test_the_age_of_what_a_robot_heard_counts_from_when_it_was_sent_so_latency_is_part_of_it():
    run, layer, _, _ = started()
    run.kernel.run(s_to_ns(0.05))
    now = run.kernel.now_ns  # the latest state was sent at 0 and arrived at 20 ms
    assert layer.neighbours(0, now)[:, 4].tolist() == [now / 1e9, now / 1e9]
    assert layer.neighbours(0, s_to_ns(0.07))[:, 4] == pytest.approx([0.07, 0.07])
    run.kernel.run(s_to_ns(0.125))  # the state sent at 0.1 s arrived at 0.12 s
    assert layer.neighbours(0, s_to_ns(0.125))[:, 4] == pytest.approx([0.025, 0.025])


def test_every_robots_neighbours_pack_row_for_row_with_the_discs():
    run, layer, _, speeds = started(silent="robot_3")
    speeds[1] = 0.4
    run.kernel.run(s_to_ns(0.15))
    now = run.kernel.now_ns
    discs, neighbours, start = layer.all_neighbours(now)
    assert (discs.tolist(), start.tolist()) == tuple(x.tolist() for x in layer.all_discs(now))
    assert neighbours.shape == (len(discs), 5)
    for i in range(3):
        rows = slice(start[i], start[i + 1])
        assert neighbours[rows].tolist() == layer.neighbours(i, now).tolist()
        np.testing.assert_array_equal(neighbours[rows, :2], discs[rows, :2])
    empty = RobotsLayer([], [], RADIUS_M, 1.0).all_neighbours(0)
    assert [a.shape for a in empty[:2]] == [(0, 3), (0, 5)] and empty[2].tolist() == [0]
